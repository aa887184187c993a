"""Short CAM segments: corner velocity and minimum cruise ratio (issue 4, item 5).

A wavy line of 60 segments of 1 mm with 10-30 degree turns (1000 pulses/mm, per-axis limits
100 mm/s and 1000 mm/s^2) runs three ways: exact stops, corners at a corner velocity of
10 mm/s, and the same with a minimum cruise ratio of 0.5 and 0.9. Each run prints its time, the
sign reversals of the recorded path acceleration (the saw-tooth) and the largest change
of an axis velocity within one servo cycle (the corner steps).

Run: python examples/group_cam_zigzag.py
"""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState

V, A = 100_000.0, 1e6  # per-axis limits, pps and pps^2


def wavy(n: int = 60) -> np.ndarray:
    """Vertices (pulses): headings alternate +-turn/2 about x, turns 10-30 degrees."""
    turn = np.radians(10.0 + 20.0 * ((0.618034 * np.arange(n)) % 1.0))
    head = np.where(np.arange(n) % 2 == 0, 0.5, -0.5) * turn
    steps = 1000.0 * np.stack([np.cos(head), np.sin(head)], axis=1)
    return np.concatenate([[[0.0, 0.0]], np.cumsum(steps, axis=0)]) + 5000.0


def run(pts: np.ndarray, corner_v: float, ratio: float) -> dict:
    """One run from rest at pts[0] to rest at pts[-1]; its time, reversals, steps."""
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=V, acc_time=V / A)
    g.set_axis_limit_policy("slow")
    g.set_max_pulse_speed([V, V])
    g.set_max_pulse_acc([A, A])
    g.set_corner_velocity(corner_v)   # 0: exact stop at every corner
    g.set_min_cruise_ratio(ratio)     # 0: time-optimal

    def idle() -> bool:
        return g.state is GroupState.IDLE and g.queue_length == 0 and not any(
            a.is_moving for a in g.axes)

    g.ptp(pts[0])
    ctl.step()
    ctl.run_until(idle, 30)
    t0 = ctl.time
    for p in pts[1:]:
        g.line(p)
    ctl.step()
    ctl.run_until(idle, 60)
    t = t0 + np.arange(int(round((ctl.time - t0) / ctl.period)) + 1) * ctl.period
    smp = [ctl.history.sample(a.index, t) for a in g.axes]
    v = np.stack([s.v for s in smp], axis=1)
    acc = np.stack([s.a for s in smp], axis=1)
    tang = (v * acc).sum(axis=1) / np.maximum(np.linalg.norm(v, axis=1), 1e-9)
    sign = np.sign(tang[np.abs(tang) > 1e-3 * A])
    return {"time": ctl.time - t0,
            "reversals": int(np.count_nonzero(sign[1:] != sign[:-1])),
            "step": max(float(np.abs(np.diff(s.v)).max()) for s in smp),
            "end": [a.position for a in g.axes]}


def main() -> dict:
    pts = wavy()
    out = {}
    for label, cv, r in (("exact stop", 0.0, 0.0), ("corner 10 mm/s", 10_000.0, 0.0),
                         ("corner 10 mm/s + ratio 0.5", 10_000.0, 0.5),
                         ("corner 10 mm/s + ratio 0.9", 10_000.0, 0.9)):
        res = out[label] = run(pts, cv, r)
        print(f"{label}: {res['time']:.3f} s, {res['reversals']} reversals, largest axis "
              f"velocity change in one cycle {res['step'] / 1000:.2f} mm/s, "
              f"end {res['end']} (target {pts[-1].tolist()})")
    return out


if __name__ == "__main__":
    main()
