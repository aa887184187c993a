"""The push path by CPU time: us per command from a compiled program to the group's queue.

Issue 14: the program runner's feed (program/runqueue.py) hands every compiled line to the
group. Measured on the default table with its soft limits (the program runner's group:
machine units, policy "slow", blending on), N lines of a rose (0.05 mm, as cam_rose.ngc),
the group idle (nothing runs, so no join is counted: that is the chain planner's part):

- `Group.line` called by a user (every value validated), after `set_feed`;
- `Group._queue_line`, the runner's entry for the compiler's already checked points;
- the runner's whole feed per command (`runqueue.feed`: its bookkeeping and the push) on
  examples/programs/cam_rose.ngc, all of it pushed in one call (window = the program).

    python bench/bench_push.py [N]   (default 20000)
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.program.runjob import work_origin
from openmotion.program.runner import ProgramRunner, RunOptions

ROOT = Path(__file__).resolve().parents[1]
CAM_ROSE = ROOT / "examples" / "programs" / "cam_rose.ngc"


def _group(ctl: Controller, run: ProgramRunner, n: int) -> Group:
    g = Group(ctl, run.axis_indices, queue_size=n + 1, feed=40.0,
              units=run.scales.axis_units(run.letters))
    g.set_axis_limit_policy("slow")
    g.enable_blend(0.005)
    return g


def per_call(n: int) -> tuple[float, float]:
    """(us per set_feed + Group.line, us per Group._queue_line) over n rose points."""
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, "G21 G90 G1 X1 F600 M2")
    rest = [0.0] * (len(run.axis_indices) - 2)
    pts = [np.array([10.0 + 5.0 * math.cos(k * 1e-3), 10.0 + 5.0 * math.sin(k * 1e-3), *rest])
           for k in range(1, n + 1)]
    g = _group(ctl, run, n)
    c0 = time.process_time()
    for p in pts:
        g.set_feed(40.0)
        g.line(p)
    c1 = time.process_time()
    g.close()
    g = _group(ctl, run, n)
    c2 = time.process_time()
    for p in pts:
        g._queue_line(p, 40.0)
    c3 = time.process_time()
    return 1e6 * (c1 - c0) / n, 1e6 * (c3 - c2) / n


def per_feed() -> tuple[int, float]:
    """(commands, us per command) of the runner's feed pushing all of cam_rose at once."""
    ctl = Controller()
    ctl.enable_all()
    text = CAM_ROSE.read_text()
    run = ProgramRunner(ctl, text, gcode={"parameters": work_origin(ctl)},
                        options=RunOptions(window=len(text.splitlines()) + 8))
    run.start()
    g = run.group
    assert g is not None
    c0 = time.process_time()
    run._feed(g)
    c1 = time.process_time()
    n = g.queue_length
    return n, 1e6 * (c1 - c0) / max(1, n)


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    line, fast = per_call(n)
    cmds, feed = per_feed()
    print(f"{'push path (CPU)':44} {'us/command':>10}")
    print(f"{'set_feed + Group.line (public, validated)':44} {line:10.2f}")
    print(f"{'Group._queue_line (the runner entry)':44} {fast:10.2f}   "
          f"{line / fast:.1f}x faster")
    print(f"{'runner feed, cam_rose (' + str(cmds) + ' commands)':44} {feed:10.2f}")


if __name__ == "__main__":
    main()
