"""The `openmotion` command line: plan and plot profiles, run the demo, check machine files."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from .errors import MotionError


def _add_profile_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "profile",
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
            f"{ph.label:<24}{ph.t_start:>11.6f}{ph.duration:>11.6f}{ph.v_start:>13.4f}"
            f"{ph.v_end:>13.4f}{ph.a_start:>13.4g}{ph.jerk:>13.4g}{ph.distance:>14.4f}"
        )
    lines.append(f"total duration {profile.duration:.9f} s, distance {profile.distance:.6f} "
                 f"pulses, end position {profile.end.p:.6f}")
    return "\n".join(lines)


def cmd_profile(args: argparse.Namespace) -> int:
    from .profile.quantize import check_quantized, quantize

    profile = _plan_from_args(args)
    print(format_phases(profile))
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

    if args.realtime:
        return run_realtime_demo(args.seconds)
    return run_demo(Path(args.out))


def cmd_config(args: argparse.Namespace) -> int:
    from .config import default_machine, dumps_machine, load_machine

    cfg = load_machine(args.file) if args.file else default_machine()
    print(dumps_machine(cfg), end="")
    print(f"# OK: machine '{cfg.name}' with {len(cfg.axes)} axes is valid", file=sys.stderr)
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from .program.runjob import run_job

    return run_job(args)


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    ap = argparse.ArgumentParser(prog="openmotion", description=__doc__)
    ap.add_argument("--version", action="version", version=f"openmotion {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    _add_profile_parser(sub)
    d = sub.add_parser("demo", help="run the demo on the simulated XYZU table")
    d.add_argument("--out", default="out", help="folder for plots and traces")
    d.add_argument("--realtime", action="store_true",
                   help="instead: run a 4-axis job paced to the wall clock, print jitter")
    d.add_argument("--seconds", type=float, default=2.0, help="length of the real-time run")
    c = sub.add_parser("config", help="validate a machine file and print the resolved machine")
    c.add_argument("file", nargs="?", help="TOML machine file (default: the XYZU table)")
    r = sub.add_parser("run", help="run a G-code program or point table on the simulated "
                       "machine, print a summary and write an HTML report")
    r.add_argument("program", help="G-code file (.ngc, .nc, ...) or point table (.toml, .csv)")
    r.add_argument("--machine", help="TOML machine file (default: the XYZU table)")
    r.add_argument("--realtime", action="store_true", help="pace the run to the wall clock")
    r.add_argument("--repeat", type=int, default=1, help="run the program N times")
    r.add_argument("--out", default="out", help="folder for the report")
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    handler = {"profile": cmd_profile, "demo": cmd_demo, "config": cmd_config,
               "run": cmd_run}[args.command]
    try:
        return handler(args)
    except (MotionError, OSError) as exc:
        print(f"openmotion: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
