"""Blended line/arc corners (issue 4): a part outline of lines and arcs, run with exact stops
and with corner tolerances of 10 and 50 pulses (10 and 50 um at 1000 pulses/mm).

The outline: a bottom line, a bulging right arc, a top of two bumps (arc-arc corners of
9 and 127 degrees) and a bulging left arc, then an overlap along the bottom. No joint is
tangent, so with T = 0 the group stops at every one. With T > 0 each corner gets the
fillet tangent to both elements (`path.blend_corner`); the run prints its time, the largest
distance from the programmed outline and the largest axis acceleration / limit.

Run: python examples/group_arc_blend.py
"""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.groups.pathexec import contour_error
from openmotion.path import Arc, Line

VMAX, AMAX = 50_000.0, 500_000.0  # per-axis limits, pps and pps^2

#: (kind, centre, end) in pulses; every arc CCW
OUTLINE = [
    ("line", None, [40_000, 0]),
    ("arc", [20_000, 15_000], [40_000, 30_000]),   # 53 deg corner with the bottom line
    ("arc", [30_000, 25_000], [20_000, 30_000]),   # 9 deg
    ("arc", [10_000, 25_000], [0, 30_000]),        # 127 deg between the bumps
    ("arc", [20_000, 15_000], [0, 0]),             # 9 deg
    ("line", None, [10_000, 0]),                   # 53 deg, overlap along the bottom
]


def elements() -> list:
    """The programmed outline as path elements (for the contour error)."""
    out, p = [], np.zeros(2)
    for kind, centre, end in OUTLINE:
        out.append(Line(p, end) if kind == "line" else Arc(p, centre, end))
        p = np.array(end, dtype=float)
    return out


def run(tol: float) -> dict:
    """Run the outline with blend tolerance `tol` (0: exact stops)."""
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=40_000.0, acc_time=0.1)
    g.set_max_pulse_speed([VMAX, VMAX])
    g.set_max_pulse_acc([AMAX, AMAX])
    g.enable_blend(tol)
    t0 = ctl.time
    for kind, centre, end in OUTLINE:
        if kind == "line":
            g.line(end)
        else:
            g.arc(centre, end, direction="CCW")
    ctl.step()
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                  and not any(a.is_moving for a in g.axes), 60)
    t = np.linspace(t0, ctl.time, 30_001)
    smp = [ctl.history.sample(a.index, t) for a in g.axes]
    xy = np.stack([s.p for s in smp], axis=1)
    return {"time": ctl.time - t0, "end": g.position.tolist(),
            "deviation": float(contour_error(xy, elements()).max()),
            "accel": max(float(np.abs(s.a).max()) for s in smp) / AMAX}


def main() -> dict:
    out = {}
    for tol in (0.0, 10.0, 50.0):
        r = out[tol] = run(tol)
        print(f"T = {tol:4.0f} pulses: {r['time']:.3f} s, largest distance from the outline "
              f"{r['deviation']:.2f} pulses, axis accel <= {r['accel']:.3f} x limit, "
              f"end {r['end']}")
    return out


if __name__ == "__main__":
    main()
