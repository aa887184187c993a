"""StrVel on a group path (HSL-4XMO 4.6): the vector speed jumps from rest to StrVel, ramps
to the feed, ramps down to StrVel and jumps to rest, as a PCL6045 interpolation does. The
same XY contour runs with StrVel 0 (MCCL) and 5 mm/s on the simulated XYZU table, as a
T-curve path and as an S-curve path (jump to StrVel, then an S acceleration from a = 0).

Run: python examples/group_strvel.py
"""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState


def run(str_vel: float, jerk: float | None = None) -> dict:
    """Run the contour with `str_vel` (mm/s), as an S path with `jerk` (mm/s^3) if given;
    the speeds and path accelerations just after the start and just before the end (from
    the recorded history), the time and the end position."""
    ctl = Controller()
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=20.0, acc_time=0.1, units=True)  # mm/s, s
    g.set_str_vel(str_vel)
    if jerk is not None:
        g.set_path_shape("S", jerk=jerk)
    g.enable_blend(0.05)  # mm
    g.line([30.0, 0.0])
    g.line([30.0, 20.0])
    g.arc([20.0, 20.0], [10.0, 20.0], direction="CCW")
    ctl.step()
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                  and not any(a.is_moving for a in g.axes), 30)
    ppu = np.array([a.units.pulses_per_unit for a in g.axes])
    rec = [ctl.history.records(a.index) for a in g.axes]
    first = [np.nonzero((r["v0"] != 0.0) | (r["a0"] != 0.0))[0][0] for r in rec]
    t_start = min(float(r["ts"][k]) for r, k in zip(rec, first, strict=True))
    t_end = max(ctl.history.end_time(a.index) for a in g.axes)
    smp = [ctl.history.sample(a.index, [t_start, t_end - 1e-9]) for a in g.axes]
    speed = np.linalg.norm(np.array([s.v for s in smp]) / ppu[:, None], axis=0)
    acc = np.linalg.norm(np.array([s.a for s in smp]) / ppu[:, None], axis=0)
    return {"str_vel": str_vel, "shape": "T" if jerk is None else "S",
            "start_speed": float(speed[0]), "end_speed": float(speed[1]),
            "start_accel": float(acc[0]), "end_accel": float(acc[1]),
            "time": t_end - t_start, "end": g.position.tolist()}


def main() -> list[dict]:
    out = [run(0.0), run(5.0), run(0.0, 4000.0), run(5.0, 4000.0)]
    for r in out:
        print(f"{r['shape']} StrVel {r['str_vel']:4.1f} mm/s: after the start "
              f"{r['start_speed']:.3f} mm/s, {r['start_accel']:.3f} mm/s^2; before the end "
              f"{r['end_speed']:.3f} mm/s, {r['end_accel']:.3f} mm/s^2; {r['time']:.3f} s, "
              f"ends at {r['end']}")
    return out


if __name__ == "__main__":
    main()
