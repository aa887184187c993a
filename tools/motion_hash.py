"""Fingerprint of the motion a planner change must keep: compare it between two checkouts.

Runs bench/bench_stream.py's group feeder (N rose segments of 0.05 mm, blended, the queue
kept full) and examples/programs/cam_rose.ngc through the program runner, in virtual
time, and prints a SHA-256 of every axis position (and the group's command index) at
every cycle. Two checkouts that print the same digests move every axis identically, bit
for bit, cycle by cycle; a faster planner (issue 14) is checked this way against the one
it replaces:

    PYTHONPATH=<old>/src python tools/motion_hash.py [N] [--save old.npz]
    PYTHONPATH=<new>/src python tools/motion_hash.py [N] [--compare old.npz]

A change allowed to move the result by rounding only (issue 14: "bit for bit or within
1e-9") is checked with `--save` on the old checkout and `--compare` on the new one: it
prints the largest difference of any axis position in any cycle (pulses), and of the
command index, between the two runs (a different cycle count is reported as such).
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


def stream_digest(n: int, rows: list | None = None) -> tuple[int, str]:
    """(cycles, digest) of the group feeder streaming n segments (each cycle's positions
    and command index appended to `rows` when given)."""
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
        row = np.array([a.position for a in g.axes] + [g.current_index], dtype=float)
        h.update(row.tobytes())
        if rows is not None:
            rows.append(row)
    return cycles, h.hexdigest()


def program_digest(path: Path, rows: list | None = None) -> tuple[int, str]:
    """(cycles, digest) of a G-code program run on the default table (rows as above)."""
    h = hashlib.sha256()
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, path.read_text(), gcode={"parameters": work_origin(ctl)})
    run.start()
    cycles = 0
    while run.state is RunState.RUNNING:
        ctl.step()
        cycles += 1
        row = np.array([a.position for a in ctl.axes], dtype=float)
        h.update(row.tobytes())
        if rows is not None:
            rows.append(row)
    if run.state is not RunState.DONE:
        raise SystemExit(f"{path.name}: {run.state} {run.error}")
    return cycles, h.hexdigest()


def _compare(name: str, new: np.ndarray, old: np.ndarray) -> None:
    if new.shape != old.shape:
        print(f"  {name}: {len(new)} cycles against {len(old)} saved: DIFFERENT")
        return
    diff = np.abs(new - old)
    pos = float(diff[:, :-1].max(initial=0.0)) if name == "stream" else float(diff.max())
    idx = float(diff[:, -1].max(initial=0.0)) if name == "stream" else 0.0
    print(f"  {name}: largest position difference {pos:.3g} pulses, command index "
          f"difference {idx:g}")


def main() -> None:
    args = sys.argv[1:]
    save = compare = None
    if "--save" in args:
        save = args.pop(args.index("--save") + 1)
        args.remove("--save")
    if "--compare" in args:
        compare = args.pop(args.index("--compare") + 1)
        args.remove("--compare")
    n = int(args[0]) if args else 1000
    s_rows: list = []
    p_rows: list = []
    cycles, digest = stream_digest(n, s_rows)
    print(f"stream {n} segments: {cycles} cycles, {digest}")
    cycles, digest = program_digest(ROOT / "examples" / "programs" / "cam_rose.ngc", p_rows)
    print(f"cam_rose.ngc: {cycles} cycles, {digest}")
    runs = {"stream": np.array(s_rows), "cam_rose": np.array(p_rows)}
    if save:
        np.savez_compressed(save, **runs)
    if compare:
        old = np.load(compare)
        for name, new in runs.items():
            _compare(name, new, old[name])


if __name__ == "__main__":
    main()
