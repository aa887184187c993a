"""A blended contour on the simulated XYZU table: lines with rounded corners, an arc, a hold
and continue half-way, then the contour error of the recorded run.

Run: python examples/group_contour.py
"""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.groups.pathexec import contour_error
from openmotion.path import Arc, Line


def main() -> None:
    ctl = Controller()
    ctl.enable_all()
    g = Group(ctl, {"x": "x", "y": "y"}, feed=40_000.0, acc_time=0.05)  # pps, s
    g.enable_blend(50.0)  # corners pass within 50 pulses (0.05 mm) of the programmed point
    corners = [[40_000, 0], [40_000, 30_000], [10_000, 30_000]]
    for p in corners:
        g.line(p)
    g.arc([10_000, 15_000], [10_000, 0], direction="CCW")  # left side: a half circle
    t0 = ctl.time
    ctl.advance(1.0)
    g.hold()
    ctl.run_until(lambda: g.state is GroupState.HELD, 5)
    print(f"held at {g.position} (command {g.current_index})")
    ctl.advance(0.3)
    g.cont()
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0, 30)
    print(f"done at {g.position} after {ctl.time - t0:.3f} s")

    t = np.linspace(t0, ctl.time, 20_001)
    xy = np.stack([ctl.history.sample(a.index, t).p for a in g.axes], axis=1)
    path = [Line([0, 0], corners[0]), Line(corners[0], corners[1]),
            Line(corners[1], corners[2]), Arc(corners[2], [10_000, 15_000], [10_000, 0])]
    err = contour_error(xy, path)
    print(f"largest distance from the programmed contour: {err.max():.3f} pulses (tolerance 50)")


if __name__ == "__main__":
    main()
