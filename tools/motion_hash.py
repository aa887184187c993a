"""Fingerprint of the motion a planner change must keep: compare it between two checkouts.

Runs bench/bench_stream.py's group feeder (N rose segments of 0.05 mm, blended, the queue
kept full) and examples/programs/cam_rose.ngc through the program runner, in virtual
time, and prints a SHA-256 of every axis position (and the group's command index) at
every cycle. Two checkouts that print the same digests move every axis identically, bit
for bit, cycle by cycle; a faster planner (issue 14) is checked this way against the one
it replaces:

    PYTHONPATH=<old>/src python tools/motion_hash.py [N]
    PYTHONPATH=<new>/src python tools/motion_hash.py [N]
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))

import bench_stream as bs  # noqa: E402
from openmotion.control import Controller  # noqa: E402
from openmotion.control.groups.group import Group, GroupState  # noqa: E402
from openmotion.program.runjob import work_origin  # noqa: E402
from openmotion.program.runner import ProgramRunner, RunState  # noqa: E402


def stream_digest(n: int) -> tuple[int, str]:
    """(cycles, digest) of the group feeder streaming n segments."""
    h = hashlib.sha256()
    ctl = bs.controller()
    g = Group(ctl, ["x", "y"], units=True, feed=bs.FEED, acc_time=bs.ACC_TIME)
    g.set_axis_limit_policy("slow")
    g.enable_blend(bs.TOL)
    g.ptp([30.0, 0.0])
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0, 10.0)
    pts = bs.points(n)
    done = [False]

    def feed(c: Controller, t: float) -> None:
        while g.queue_length < bs.QUEUE:
            p = next(pts, None)
            if p is None:
                done[0] = True
                return
            g.line(p)

    ctl.add_cycle_hook(feed)
    cycles = 0
    while not (done[0] and g.state is GroupState.IDLE and g.queue_length == 0):
        ctl.step()
        cycles += 1
        h.update(np.array([a.position for a in g.axes] + [g.current_index],
                          dtype=float).tobytes())
    return cycles, h.hexdigest()


def program_digest(path: Path) -> tuple[int, str]:
    """(cycles, digest) of a G-code program run on the default table."""
    h = hashlib.sha256()
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, path.read_text(), gcode={"parameters": work_origin(ctl)})
    run.start()
    cycles = 0
    while run.state is RunState.RUNNING:
        ctl.step()
        cycles += 1
        h.update(np.array([a.position for a in ctl.axes], dtype=float).tobytes())
    if run.state is not RunState.DONE:
        raise SystemExit(f"{path.name}: {run.state} {run.error}")
    return cycles, h.hexdigest()


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    cycles, digest = stream_digest(n)
    print(f"stream {n} segments: {cycles} cycles, {digest}")
    cycles, digest = program_digest(ROOT / "examples" / "programs" / "cam_rose.ngc")
    print(f"cam_rose.ngc: {cycles} cycles, {digest}")


if __name__ == "__main__":
    main()
