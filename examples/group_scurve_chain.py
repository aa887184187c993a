"""S-curve path chains (issue 4): the same paths run with a T-curve and with an S-curve
path speed (jerk 2e7 pps^3), per-axis limits 50 000 pps and 500 000 pps^2, feed 40 000 pps,
path acceleration 400 000 pps^2 (smoothing window tj = 2*400 000/2e7 = 0.04 s).

For each path it prints the times, the largest path jerk / J (exact, from the executed
plans), the largest axis speed and acceleration / limit and the largest axis jerk / J
(recorded, sampled every ~10 us), the largest distance from the programmed path and the
smallest speed inside the run. The axis jerk exceeds J where the curvature steps (line-arc
joints, both ends of a blend arc): only the path jerk is limited.

Run: python examples/group_scurve_chain.py
"""

from __future__ import annotations

import math

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.groups.pathexec import contour_error
from openmotion.path import Arc, Line

VMAX, AMAX = 50_000.0, 500_000.0
FEED, ACC_T, JERK = 40_000.0, 0.1, 2.0e7


def polygon(n: int, r: float) -> list:
    """A closed n-gon of radius r starting at (r, 0)."""
    ang = 2.0 * math.pi * np.arange(1, n + 1) / n
    return [("line", [r * math.cos(a), r * math.sin(a)]) for a in ang]


def cam(n: int, seg: float, seed: int = 1) -> list:
    """n short segments turning 1.5-4 deg at each corner, in S-bends of 150 segments."""
    rng = np.random.default_rng(seed)
    turn = rng.uniform(1.5, 4.0, n) * np.where((np.arange(n) // 150) % 2, 1.0, -1.0)
    head = np.cumsum(np.deg2rad(turn))
    pts = np.round(np.cumsum(np.stack([np.cos(head), np.sin(head)], 1) * seg, 0), 3)
    return [("line", p) for p in pts.tolist()]


PATHS = {
    # name: (start, commands, blend tolerance or None for exact stops)
    "40-gon R=20000, T=61.6": ((20_000.0, 0.0), polygon(40, 20_000.0), 61.6),
    "line-arc-line, T=40": ((0.0, 0.0), [("line", [20_000, 0]),
                                         ("arc", [25_000, 0], [30_000, 0], "CW"),
                                         ("line", [40_000, -10_000])], 40.0),
    "zig-zag, exact stops": ((0.0, 0.0), [("line", [10_000.0 * (k + 1),
                                                    6_000.0 * (k % 2 == 0)])
                                          for k in range(6)], None),
    "CAM stream 500 x 300, T=20": ((0.0, 0.0), cam(500, 300.0), 20.0),
}


def elements(start, prog) -> list:
    els, p = [], np.array(start, dtype=float)
    for cmd in prog:
        els.append(Line(p, cmd[1]) if cmd[0] == "line" else
                   Arc(p, cmd[1], cmd[2], direction=cmd[3]))
        p = np.array(els[-1].end, dtype=float)
    return els


def run(start, prog, tol, jerk: float | None) -> dict:
    """Run `prog` from `start` (T path when jerk is None) and measure it."""
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=ACC_T)
    g.set_max_pulse_speed([VMAX, VMAX])
    g.set_max_pulse_acc([AMAX, AMAX])
    if start != (0.0, 0.0):
        g.line(start)  # move to the start first (not measured)
        ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0, 10)
    if jerk:
        g.set_path_shape("S", jerk=jerk)
    if tol is not None:
        g.enable_blend(tol)
    plans: list = []

    def record(c: Controller, t: float) -> None:
        r = g._run
        if r is not None and r.plan is not None and (not plans or plans[-1] is not r.plan):
            plans.append(r.plan)
    todo = iter(prog)

    def feed(c: Controller, t: float) -> None:  # a sender keeping 200 commands queued
        while g.queue_length < 200:
            cmd = next(todo, None)
            if cmd is None:
                return
            if cmd[0] == "line":
                g.line(cmd[1])
            else:
                g.arc(cmd[1], cmd[2], direction=cmd[3])
    ctl.add_cycle_hook(record)
    ctl.add_cycle_hook(feed)
    t0 = ctl.time
    ctl.step()
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                  and not any(a.is_moving for a in g.axes), 120)
    t1 = ctl.time
    t = np.linspace(t0, t1, int((t1 - t0) * 1e5) + 1)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    v = np.hypot(sx.v, sy.v)
    inner = (t > t0 + 0.2) & (t < t1 - 0.2)
    els = elements(start, prog)
    xy = np.stack([sx.p, sy.p], axis=1)[::10]
    return {
        "time": t1 - t0,
        "path_jerk": max(float(np.max(np.abs(p.sprof.j), initial=0.0)) for p in plans),
        "v": max(np.abs(sx.v).max(), np.abs(sy.v).max()) / VMAX,
        "a": max(np.abs(sx.a).max(), np.abs(sy.a).max()) / AMAX,
        "j": max(np.abs(sx.j).max(), np.abs(sy.j).max()),
        "dev": float(contour_error(xy, els).max()),
        "vmin": float(v[inner].min()) if inner.any() else 0.0,
        "end": g.position.tolist() == list(els[-1].end),
    }


def main() -> None:
    print(f"{'path':28} {'T [s]':>7} {'S [s]':>7} {'pathJ/J':>8} {'v/lim':>6} {'a/lim':>6} "
          f"{'axJ/J':>6} {'dev T':>6} {'dev S':>6} {'vmin S':>7} exact")
    for name, (start, prog, tol) in PATHS.items():
        rt = run(start, prog, tol, None)
        rs = run(start, prog, tol, JERK)
        print(f"{name:28} {rt['time']:7.3f} {rs['time']:7.3f} {rs['path_jerk'] / JERK:8.4f} "
              f"{rs['v']:6.3f} {rs['a']:6.3f} {rs['j'] / JERK:6.2f} {rt['dev']:6.2f} "
              f"{rs['dev']:6.2f} {rs['vmin']:7.0f} {rt['end'] and rs['end']}")


if __name__ == "__main__":
    main()
