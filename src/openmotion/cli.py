"""The `openmotion` command line: plan and plot profiles, run the demo, check machine files."""

from __future__ import annotations

import argparse
import math
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from .errors import MotionError

#: Quantized count checks longer than this many samples are skipped (time and memory).
MAX_CHECK_SAMPLES = 2_000_000

class _FMT(argparse.ArgumentDefaultsHelpFormatter):
    """Shows every option's default in --help (not the None/False of optional flags)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        if action.default is None or action.default is False:
            return action.help
        return super()._get_help_string(action)


#: Python parameter names of the planners and runner -> the flags a user typed.
_FLAGS = {"str_vel": "--str-vel", "max_vel": "--max-vel", "tacc": "--tacc", "tdec": "--tdec",
          "vs_acc": "--vs-acc", "vs_dec": "--vs-dec", "v_max": "--v-max", "a_max": "--a-max",
          "j_max": "--j-max", "d_max": "--d-max", "distance": "--distance",
          "period": "--period", "acc_time": "--acc-time", "repeat": "--repeat"}
_FLAG_RE = re.compile(r"(?<![-\w])(" + "|".join(sorted(_FLAGS, key=len, reverse=True))
                      + r")(?![\w])")


def flag_names(message: str) -> str:
    """`message` with the Python parameter names replaced by the command-line flags."""
    return _FLAG_RE.sub(lambda m: _FLAGS[m.group(1)], message)


def _add_profile_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "profile", formatter_class=_FMT,
        help="plan a T, S or jerk-limited move, print its phases and plot it",
        description="Plan one single-axis move (units: pulses, pulses/s, s), print its "
        "phases and save a position/velocity/acceleration/jerk plot (PNG and HTML).",
    )
    p.add_argument("kind", choices=("t", "s", "jerk"),
                   help="t: PCL6045 trapezoid, s: PCL6045 S-curve, jerk: time-optimal")
    p.add_argument("--distance", type=float, required=True, help="pulses (signed)")
    p.add_argument("--str-vel", type=float, default=0.0, help="start velocity (t, s)")
    p.add_argument("--max-vel", type=float, help="maximum velocity (t, s)")
    p.add_argument("--tacc", type=float, help="acceleration time (t, s)")
    p.add_argument("--tdec", type=float, help="deceleration time (t, s); default tacc")
    p.add_argument("--vs-acc", type=float, default=0.0, help="S region at accel (s)")
    p.add_argument("--vs-dec", type=float, default=0.0, help="S region at decel (s)")
    p.add_argument("--v-max", type=float, help="velocity limit (jerk)")
    p.add_argument("--a-max", type=float, help="acceleration limit (jerk)")
    p.add_argument("--j-max", type=float, help="jerk limit (jerk)")
    p.add_argument("--d-max", type=float, help="deceleration limit (jerk); default a-max")
    p.add_argument("--period", type=float, default=0.001,
                   help="sample period for the quantized count check (s)")
    p.add_argument("--plot", default="out/profile.png",
                   help="PNG path ('' for none); an .html twin is written beside it")


def _need(args: argparse.Namespace, *names: str) -> None:
    missing = [n for n in names if getattr(args, n) is None]
    if missing:
        flags = ", ".join("--" + n.replace("_", "-") for n in missing)
        raise MotionError(f"profile {args.kind} needs {flags}")


def _plan_from_args(args: argparse.Namespace):
    from .profile import jerk_limited, scurve, trapezoid

    if args.kind in ("t", "s"):
        _need(args, "max_vel", "tacc")
        tdec = args.tacc if args.tdec is None else args.tdec
        if args.kind == "t":
            return trapezoid(distance=args.distance, str_vel=args.str_vel,
                             max_vel=args.max_vel, tacc=args.tacc, tdec=tdec)
        return scurve(distance=args.distance, str_vel=args.str_vel, max_vel=args.max_vel,
                      tacc=args.tacc, tdec=tdec, vs_acc=args.vs_acc, vs_dec=args.vs_dec)
    _need(args, "v_max", "a_max", "j_max")
    return jerk_limited(args.distance, args.v_max, args.a_max, args.j_max, d_max=args.d_max)


def format_phases(profile) -> str:
    """A table of a profile's phases, as `openmotion profile` prints it."""
    lines = [
        f"{'phase':<24}{'t start':>11}{'duration':>11}{'v start':>13}{'v end':>13}"
        f"{'accel':>13}{'jerk':>13}{'distance':>14}",
    ]
    for ph in profile.phases():
        lines.append(
            f"{ph.label:<24}{_cell(ph.t_start, 11, 6)}{_cell(ph.duration, 11, 6)}"
            f"{_cell(ph.v_start, 13, 4)}{_cell(ph.v_end, 13, 4)}{ph.a_start:>13.4g}"
            f"{ph.jerk:>13.4g}{_cell(ph.distance, 14, 4)}"
        )
    lines.append(f"total duration {profile.duration:.9f} s, distance {profile.distance:.6f} "
                 f"pulses, end position {profile.end.p:.6f}")
    return "\n".join(lines)


def _cell(x: float, width: int, digits: int) -> str:
    """`x` right-aligned in `width` with `digits` decimals, or in %g when that does not fit
    (so huge values never run into the next column)."""
    text = f"{x:.{digits}f}"
    if len(text) >= width:
        text = f"{x:.{max(1, width - 8)}g}"
    return f"{text:>{width}}"


def _check_writable(folder: Path, flag: str) -> None:
    """Fail now, not after the work, when `folder` cannot be created or written."""
    import tempfile

    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise MotionError(f"{flag} {str(folder)!r} is not a writable folder "
                          f"({exc.strerror or exc})") from None


def cmd_profile(args: argparse.Namespace) -> int:
    from .profile.quantize import check_quantized, quantize

    if args.plot:
        _check_writable(Path(args.plot).parent, "--plot")
    if not (isinstance(args.period, float) and math.isfinite(args.period) and args.period > 0):
        raise MotionError(f"--period must be a positive number of seconds, got {args.period!r}")
    profile = _plan_from_args(args)
    print(format_phases(profile))
    samples = profile.duration / args.period
    if samples > MAX_CHECK_SAMPLES:
        print(f"quantized check skipped: the move lasts {profile.duration:.6g} s, "
              f"{samples:.3g} samples at --period {args.period:g} s exceed "
              f"{MAX_CHECK_SAMPLES:,}; pass --period {profile.duration / MAX_CHECK_SAMPLES:.3g}"
              " or more to check it")
    else:
        counts = quantize(profile, args.period)
        worst = check_quantized(counts, profile, args.period)
        print(f"quantized at {args.period * 1e3:g} ms: {counts.size} counts, last count "
              f"{int(counts[-1])}, max |count - position| {worst:.3f} pulse")
    if args.plot:
        from .plot import plot_profile

        paths = plot_profile(profile, args.plot, title=f"openmotion profile {args.kind}",
                             html=True)
        for path in paths:
            print(f"wrote {path}")
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo, run_realtime_demo

    if not args.realtime:
        _check_writable(Path(args.out), "--out")
    if args.realtime:
        return run_realtime_demo(args.seconds)
    return run_demo(Path(args.out))


def cmd_config(args: argparse.Namespace) -> int:
    from .config import default_machine, dumps_machine
    from .machine_file import check_machine_settings
    from .program.runjob import read_machine_arg

    cfg, settings = (read_machine_arg(args.file, "machine file") if args.file
                     else (default_machine(), {}))
    try:   # the home tables' mode rules need the axes (units, speeds): the UI's own check
        check_machine_settings(cfg, settings)
    except MotionError as exc:
        raise MotionError(f"{args.file}: {exc}") from None
    print(dumps_machine(cfg, settings), end="")
    print(f"# OK: machine '{cfg.name}' with {len(cfg.axes)} axes is valid", file=sys.stderr)
    return 0


def cmd_examples(args: argparse.Namespace) -> int:
    from .examples_cmd import copy_example, examples_root, list_examples

    if args.name:
        print(f"wrote {copy_example(args.name, args.to)}")
        return 0
    items = list_examples()
    width = max(len(n) for n, _ in items)
    for name, what in items:
        print(f"{name:<{width}}  {what}")
    print(f"# {len(items)} examples in {examples_root()}; copy one with "
          "`openmotion examples NAME [--to DIR]`", file=sys.stderr)
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from .program.runjob import run_job

    _check_writable(Path(args.out), "--out")
    return run_job(args)


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    ap = argparse.ArgumentParser(prog="openmotion", description=__doc__, formatter_class=_FMT)
    ap.add_argument("--version", action="version", version=f"openmotion {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    _add_profile_parser(sub)
    d = sub.add_parser("demo", formatter_class=_FMT,
                       help="run the demo on the simulated XYZU table")
    d.add_argument("--out", default="out", help="folder for plots and traces")
    d.add_argument("--realtime", action="store_true",
                   help="instead: run a 4-axis job paced to the wall clock, print jitter")
    d.add_argument("--seconds", type=float, default=2.0, help="length of the real-time run")
    c = sub.add_parser("config", formatter_class=_FMT,
                       help="validate a machine file and print the resolved machine")
    c.add_argument("file", nargs="?", help="TOML machine file (default: the XYZU table)")
    e = sub.add_parser("examples", formatter_class=_FMT,
                       help="list the example programs and machine files, or copy one out")
    e.add_argument("name", nargs="?", help="example to copy (e.g. gcode/bolt_circle.ngc)")
    e.add_argument("--to", default=".", help="folder to copy it into")
    r = sub.add_parser("run", formatter_class=_FMT,
                       help="run a G-code program or point table on the simulated machine, "
                       "print a summary and write an HTML report")
    r.add_argument("program", help="G-code file (.ngc, .nc, ...) or point table (.toml, .csv)")
    r.add_argument("--machine", help="TOML machine file (default: the XYZU table)")
    r.add_argument("--realtime", action="store_true", help="pace the run to the wall clock")
    r.add_argument("--repeat", type=int, default=None,
                   help="run the program N times (default: once; a program whose main "
                   "program ends with M99 restarts until Ctrl-C, as in LinuxCNC)")
    r.add_argument("--out", default="out", help="folder for the report")
    r.add_argument("--allow-no-end", action="store_true",
                   help="run a G-code file that ends without M2, M30 or a closing %% (by "
                   "default refused, as LinuxCNC does: the file may be truncated)")
    r.add_argument("--report", action="store_true",
                   help="open the interactive report in the web browser when the run ends")
    r.add_argument("--acc-time", type=float, default=0.05,
                   help="seconds from rest to the programmed feed (path acceleration = "
                   "feed / acc-time)")
    r.add_argument("--feed-override", type=float, default=100.0,
                   help="feed override in %% of the programmed feed (1 .. 200; the "
                   "program's M50 P0 / M49 run at 100 %%)")
    r.add_argument("--spindle-override", type=float, default=100.0,
                   help="spindle speed override in %% of S (1 .. 200; M51 P0 / M49 ignore "
                   "it)")
    r.add_argument("--probe-input", metavar="di<n>",
                   help="board input the G38.x probe is wired to (a simulated probe)")
    r.add_argument("--probe-box", action="append", metavar="'X10:50 Y8:38 Z:20'",
                   help="a box of the workpiece the simulated probe touches, machine units "
                   "(repeat for more boxes; an empty bound is unbounded)")
    r.add_argument("--adaptive-feed-input", metavar="ai<n>",
                   help="analog input that scales the feed while M52 P1 is on (0 .. 1, "
                   "LinuxCNC's motion.adaptive-feed); set its value with --analog-input")
    r.add_argument("--analog-input", action="append", metavar="ai<n>=V[@T]",
                   help="simulated analog input ai<n> reads V from machine time T s "
                   "(default 0; repeat for a schedule, e.g. ai0=1 ai0=0.5@2); read by "
                   "M66 E and --adaptive-feed-input")
    r.add_argument("--user-m-path", action="append", metavar="DIR[:DIR...]",
                   help="folders holding user M-codes M100-M199 (executables named M1nn), "
                   "searched in order (LinuxCNC's PROGRAM_PREFIX, then USER_M_PATH); "
                   "repeat or separate with ':'")
    r.add_argument("--user-m-timeout", type=float, default=60.0, metavar="S",
                   help="seconds a user M-code may run before the job stops")
    r.add_argument("--spindle-axis", metavar="NAME",
                   help="axis that is the spindle (M3/M4/M5, G33, G76, G33.1, G95, G96); "
                   "added as a simulated spindle when the machine has none")
    from .remote.ui_cmd import add_parser as add_ui_parser  # `openmotion ui` (remote/)

    add_ui_parser(sub, _FMT)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    handler = {"profile": cmd_profile, "demo": cmd_demo, "config": cmd_config,
               "run": cmd_run, "examples": cmd_examples}.get(args.command) or args.handler
    try:
        return handler(args)
    except (MotionError, OSError) as exc:
        text = flag_names(str(exc)) if args.command == "profile" else str(exc)
        print(f"openmotion: error: {text}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C outside a run's own handling (setup, a 2nd press)
        print("openmotion: interrupted (Ctrl-C)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
