"""`openmotion run PROGRAM`: run a program on the simulated machine, summary + HTML report.

Virtual time by default (as fast as the simulation goes) with a text progress bar on
stderr for jobs longer than a few seconds of machine time; `--realtime` paces the
controller to the wall clock on its thread. A point table (.toml/.csv) runs its points in
table order.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from ..errors import MotionError
from .points import PointTable
from .report import format_summary, summarize, write_report
from .runner import ProgramRunner, RunOptions, RunState

#: Controller time (s) between progress updates in virtual time.
_CHUNK = 1.0


def run_job(args: argparse.Namespace) -> int:
    """The `run` subcommand; returns the exit code (0 done, 1 fault/abort)."""
    from ..config import default_machine, load_machine
    from ..control import Controller

    if isinstance(args.repeat, bool) or not isinstance(args.repeat, int) or args.repeat < 1:
        raise MotionError(f"--repeat must be an integer >= 1, got {args.repeat!r}")
    cfg = load_machine(args.machine) if args.machine else default_machine()
    ctl = Controller(cfg)
    ctl.enable_all()
    path = Path(args.program)
    if path.suffix in (".toml", ".csv"):
        table = PointTable.load(path)
        program: object = table.to_gcode(range(len(table)))
    else:
        program = path
    params = work_origin(ctl)
    run = ProgramRunner(ctl, program, options=RunOptions(repeat=args.repeat),  # type: ignore[arg-type]
                        file=str(path), gcode={"parameters": params})
    if params:
        print("G54 origin at the middle of the travel: " + ", ".join(
            f"#{k} = {v:g}" for k, v in sorted(params.items())), file=sys.stderr)
    print(f"{path}: {len(run.commands)} commands, {len(run.ops)} moves/actions on "
          f"{''.join(run.letters)} of machine '{cfg.name}'", file=sys.stderr)
    run.start()
    if args.realtime:
        with ctl.start_realtime():
            while run.state is RunState.RUNNING:
                time.sleep(0.05)
                _progress(run)
    else:
        while run.state is RunState.RUNNING:
            ctl.run_until(lambda: run.state is not RunState.RUNNING, _CHUNK)
            _progress(run)
    print(file=sys.stderr)
    summary = summarize(run)
    print(format_summary(summary))
    report = write_report(run, args.out, path.stem)
    print(f"report: {report}")
    return 0 if run.state is RunState.DONE else 1


def work_origin(ctl) -> dict[int, float]:
    """G54 offsets (#5221 + letter order) putting program zero at the middle of every
    linear axis that has both limit switches (machine 0 is the home corner on most tables,
    so a program drawn around 0 would run into the MEL)."""
    from .options import AXIS_LETTERS, MM_PER_INCH
    from .runner import machine_axes, travel_limits

    out = {}
    for letter, index in machine_axes(ctl).items():
        t = travel_limits(ctl, index)
        unit = ctl.config.axes[index].unit
        if letter in "ABC" or t is None or not all(map(math.isfinite, t)) \
                or unit not in ("mm", "inch"):
            continue
        mid = 0.5 * (t[0] + t[1])
        out[5221 + AXIS_LETTERS.index(letter)] = mid if unit == "mm" else mid * MM_PER_INCH
    return out


def _progress(run: ProgramRunner) -> None:
    width = 30
    done = int(run.progress * width)
    n = min(run.passes_done + 1, run.options.repeat)
    print(f"\r[{'#' * done}{'.' * (width - done)}] pass {n}/"
          f"{run.options.repeat} line {run.current_line}", end="", file=sys.stderr)
