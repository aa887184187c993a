"""`openmotion run PROGRAM`: run a program on the simulated machine, summary + HTML report.

Virtual time by default (as fast as the simulation goes) with a progress line on stderr
when it is a terminal (progress.py: executed line, machine time, %, ETA); `--realtime` paces the
controller to the wall clock on its thread. A point table (.toml/.csv) runs its points in
table order.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import signal
import sys
import threading
import time
from pathlib import Path

from ..errors import MotionError
from .points import PointTable
from .progress import RunProgress
from .report import format_summary, g54_origin, summarize, write_report
from .runner import ProgramRunner, RunOptions, RunState

#: Controller time (s) between progress updates in virtual time.
_CHUNK = 0.25


def run_job(args: argparse.Namespace) -> int:
    """The `run` subcommand; returns the exit code (0 done, 1 fault/abort, 130 Ctrl-C: the
    axes decelerate along the path, the summary and report cover what ran)."""
    from ..config import default_machine
    from ..control import Controller
    from ..machine_file import apply_machine_settings

    if args.repeat is not None and (isinstance(args.repeat, bool)
                                    or not isinstance(args.repeat, int) or args.repeat < 1):
        raise MotionError(f"--repeat must be an integer >= 1, got {args.repeat!r}")
    acc_time = getattr(args, "acc_time", 0.05)
    if not (isinstance(acc_time, float | int) and 0.0 < acc_time < 1e3):
        raise MotionError(f"--acc-time must be in (0, 1000) s, got {acc_time!r}")
    override = getattr(args, "feed_override", 100.0)
    if not (isinstance(override, float | int) and 1.0 <= override <= 200.0):
        raise MotionError(f"--feed-override must be in [1, 200] %, got {override!r}")
    spindle_pct = getattr(args, "spindle_override", 100.0)
    if not (isinstance(spindle_pct, float | int) and 1.0 <= spindle_pct <= 200.0):
        raise MotionError(f"--spindle-override must be in [1, 200] %, got {spindle_pct!r}")
    user_m = [d for arg in (getattr(args, "user_m_path", None) or [])
              for d in str(arg).split(os.pathsep) if d]
    user_m_timeout = getattr(args, "user_m_timeout", 60.0)
    try:
        user_opts = RunOptions(user_m_path=tuple(user_m),
                               user_m_timeout=user_m_timeout)
    except MotionError as exc:  # name the flag, not the field
        raise MotionError(str(exc).replace("user_m_", "--user-m-").replace(
            "_timeout", "-timeout")) from None
    cfg, settings = (read_machine_arg(args.machine, "--machine") if args.machine
                     else (default_machine(), {}))
    path = Path(args.program)
    if not path.is_file():
        raise MotionError(f"program {str(path)!r}: no such file")
    spindle = getattr(args, "spindle_axis", None)
    cfg = with_spindle(cfg, spindle)
    probe_input = getattr(args, "probe_input", None)
    boxes = parse_probe_boxes(getattr(args, "probe_box", None) or [], probe_input)
    adaptive = getattr(args, "adaptive_feed_input", None)
    try:
        RunOptions(adaptive_feed_input=adaptive)
    except MotionError:
        raise MotionError(f"--adaptive-feed-input must be an analog input 'ai<n>', "
                          f"got {adaptive!r}") from None
    analog = parse_analog_inputs(getattr(args, "analog_input", None) or [])
    ctl = Controller(cfg)
    try:   # the file's stop responses (e.g. decelerate on a limit) and home tables
        apply_machine_settings(ctl, settings)
    except MotionError as exc:
        raise MotionError(f"{args.machine}: {exc}") from None
    probe = attach_probe(ctl, probe_input)
    schedule_analog_inputs(ctl, analog)
    ctl.enable_all()
    gcode: dict[str, object] = {}
    if path.suffix in (".toml", ".csv"):
        table = PointTable.load(path)
        program: object = table.to_gcode(range(len(table)))
        sets_g54 = False
    else:
        program = path
        sets_g54 = sets_work_offset(path.read_text(encoding="utf-8", errors="replace"))
        gcode["require_end"] = not getattr(args, "allow_no_end", False)
    params = {} if sets_g54 else work_origin(ctl)
    gcode["parameters"] = params
    run = ProgramRunner(ctl, program,  # type: ignore[arg-type]
                        options=RunOptions(repeat=args.repeat, acc_time=float(acc_time),
                                           probe_input=probe_input, spindle_axis=spindle,
                                           adaptive_feed_input=adaptive,
                                           user_m_path=user_opts.user_m_path,
                                           user_m_timeout=user_opts.user_m_timeout),
                        file=str(path), gcode=gcode)
    if probe is not None:
        place_boxes(probe, run, boxes)
    if all(op.kind in ("end", "blend") for op in run.ops):
        raise MotionError(f"{path}: the program holds no moves or actions, nothing to run")
    if params:
        print("G54 origin at the middle of the travel: " + ", ".join(
            f"#{k} = {v:g}" for k, v in sorted(params.items())), file=sys.stderr)
    bar = RunProgress(ctl, run)
    with _CtrlC() as stop:  # from here on Ctrl-C stops the job cleanly
        print(f"{path}: {len(run.commands)} commands, {len(run.ops)} moves/actions on "
              f"{''.join(run.letters)} of machine '{cfg.name}', acceleration time "
              f"{acc_time:g} s, feed override {override:g} %", file=sys.stderr)
        run.set_feed_override(float(override))  # the whole job (M50 P0 / M49 ignore it)
        run.set_spindle_override(float(spindle_pct))
        run.start()
        _drive(ctl, run, stop, args.realtime, bar)
        if run.state is RunState.ERROR:   # a fault's decelerating stop (e.g. the machine
            _axes_to_rest(ctl, args.realtime)   # file's el = "decel") ends before the summary
        if stop.pressed and run.state in (RunState.RUNNING, RunState.PAUSED):
            line = run.current_line
            run.abort()  # decelerating stop along the path
            _settle(ctl, run, args.realtime)
            bar.close()
            print(f"aborted at line {line} (Ctrl-C) after {ctl.time - run.t_start:.3f} s of "
                  "machine time; the axes stopped along the path", file=sys.stderr)
    bar.close()
    summary = summarize(run)
    print(format_summary(summary))
    bar.status("writing the report ...")
    options = (f"machine '{cfg.name}' ({''.join(run.letters)}), acceleration time "
               f"{acc_time:g} s, feed override {override:g} %, "
               f"{run.passes_done} pass(es)")
    # drawn in program coordinates: G54 as the job set it (the program's own G10 offsets
    # are not followed: then machine coordinates)
    origin = g54_origin(run, params) if not sets_g54 else None
    report = write_report(run, args.out, path.stem, options, origin)
    print(f"report: {report}")
    if getattr(args, "report", False):
        import webbrowser

        if not webbrowser.open(report.resolve().as_uri()):
            print(f"no web browser found: open {report} yourself", file=sys.stderr)
    if stop.pressed:
        return 130
    return 0 if run.state is RunState.DONE else 1


def load_machine_arg(path: str, what: str):
    """load_machine with messages naming the flag or argument `what` (no raw [Errno 2]), and
    refusing a machine without axes (nothing could run on it)."""
    return read_machine_arg(path, what)[0]


def read_machine_arg(path: str, what: str):
    """The machine and its per-axis settings (responses, home tables) of `path`, checked as
    `load_machine_arg` does."""
    from ..machine_file import read_machine_file

    cfg, settings = read_machine_file(path, what)
    if not cfg.axes:
        raise MotionError(f"{os.fspath(path)}: the machine has no axes (add an [axes.<name>] "
                          "table per axis)")
    return cfg, settings


def with_spindle(cfg, name: str | None):
    """`--spindle-axis NAME`: the machine's axis NAME drives M3/M4/M5, G33/G76/G33.1, G95
    and G96; a machine without it gets a simulated spindle of that name (hw/sim/spindle.py:
    servo with a 4096-count encoder and an index)."""
    from dataclasses import replace

    from ..hw.sim.spindle import spindle_axis

    if name is None:
        return cfg
    if not isinstance(name, str) or not name.strip():
        raise MotionError(f"--spindle-axis must be an axis name, got {name!r}")
    if any(a.name == name for a in cfg.axes):
        return cfg
    return replace(cfg, axes=(*cfg.axes, spindle_axis(name)))


_BOX = re.compile(r"([XYZABCUVW])(-?[\d.eE+-]*):(-?[\d.eE+-]*)$")


def parse_probe_boxes(texts: list[str], probe_input: str | None
                      ) -> list[dict[str, tuple[float, float]]]:
    """`--probe-box "X10:50 Y8:38 Z:20"` (machine units; an empty bound is unbounded):
    one box of the simulated workpiece the probe touches."""
    if texts and probe_input is None:
        raise MotionError("--probe-box needs --probe-input (the board input of the probe)")
    out = []
    for text in texts:
        box: dict[str, tuple[float, float]] = {}
        for part in text.upper().split():
            m = _BOX.match(part)
            try:
                lo = float(m.group(2)) if m and m.group(2) else -math.inf
                hi = float(m.group(3)) if m and m.group(3) else math.inf
            except ValueError:
                m = None
            if m is None or m.group(1) in box or not lo < hi:
                raise MotionError(f"--probe-box {text!r}: each part must be <axis letter>"
                                  f"<lo>:<hi> with lo < hi (machine units), got {part!r}")
            box[m.group(1)] = (lo, hi)
        if not box:
            raise MotionError(f"--probe-box {text!r} names no axis (e.g. 'X10:50 Z:20')")
        out.append(box)
    return out


_ANALOG = re.compile(r"ai(\d+)=([^@]+)(?:@(.+))?$")


def parse_analog_inputs(texts: list[str]) -> list[tuple[int, float, float]]:
    """`--analog-input ai<n>=V[@T]`: (channel, value, machine time s) in the given order."""
    out = []
    for text in texts:
        m = _ANALOG.match(text.strip())
        try:
            ch, v, t = (int(m.group(1)), float(m.group(2)),
                        float(m.group(3)) if m.group(3) else 0.0) if m else (0, 0.0, -1.0)
        except ValueError:
            m = None
        if m is None or not math.isfinite(v) or not (math.isfinite(t) and t >= 0.0):
            raise MotionError(f"--analog-input {text!r}: must be ai<n>=<value>[@<time s "
                              f">= 0>] with finite numbers, e.g. ai0=0.5@2")
        out.append((ch, v, t))
    return out


def schedule_analog_inputs(ctl, analog: list[tuple[int, float, float]]) -> None:
    """The --analog-input values on the simulated machine's analog inputs, at their times."""
    from ..hw.sim.machine import SimMachine

    if not analog:
        return
    hw = ctl.hardware
    if not isinstance(hw, SimMachine):
        raise MotionError("--analog-input needs the simulated machine")
    for ch, v, t in sorted(analog, key=lambda a: a[2]):  # a stable sort: order kept per time
        try:
            hw.scenario.set_analog_input(ch, v, at=hw.time + t)
        except MotionError as exc:
            raise MotionError(f"--analog-input ai{ch}: {exc}") from None


def attach_probe(ctl, probe_input: str | None):
    """`--probe-input di<n>`: a simulated touch probe on that board input."""
    from ..hw.sim.machine import SimMachine
    from ..hw.sim.probe import SimProbe

    if probe_input is None:
        return None
    if not isinstance(ctl.hardware, SimMachine):
        return None
    return SimProbe.attach(ctl.hardware, probe_input)


def place_boxes(probe, run: ProgramRunner,
                boxes: list[dict[str, tuple[float, float]]]) -> None:
    """The --probe-box workpiece in the probe's load positions (command pulses)."""
    ppu = dict(zip(run.letters, run.scales.ppu, strict=True))
    axis = dict(zip(run.letters, run.axis_indices, strict=True))
    placed = []
    for box in boxes:
        bad = [L for L in box if L not in axis]
        if bad:
            raise MotionError(f"--probe-box: axis {bad[0]} is not one of the program's "
                              f"axes ({''.join(run.letters)})")
        placed.append({axis[L]: tuple(sorted((lo * ppu[L], hi * ppu[L])))
                       for L, (lo, hi) in box.items()})
    probe.place(placed)


_COMMENT = re.compile(r"\([^)]*\)|;.*")
_G54_WRITE = re.compile(r"#\s*522[1-9]\s*=")
_G10 = re.compile(r"G0*10(?![\d.])")
_L = re.compile(r"L0*(2|20)(?![\d.])")
_P = re.compile(r"P0*([01])(?![\d.])")


def sets_work_offset(text: str) -> bool:
    """True when a G-code program sets the G54 origin itself (G10 L2/L20 P1 or P0, or
    #5221..#5229 = ...), so the runner must not put its own there."""
    for raw in text.upper().splitlines():
        line = _COMMENT.sub("", raw).replace(" ", "")
        if _G54_WRITE.search(line) or (_G10.search(line) and _L.search(line)
                                       and _P.search(line)):
            return True
    return False


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


class _CtrlC:
    """While active, the first Ctrl-C (SIGINT) only sets `pressed` so the job can stop
    cleanly between controller cycles; a second one interrupts at once."""

    def __init__(self) -> None:
        self.pressed = False
        self._old: object = None

    def _handler(self, signum: int, frame: object) -> None:
        if self.pressed:
            raise KeyboardInterrupt
        self.pressed = True

    def __enter__(self) -> _CtrlC:
        if threading.current_thread() is threading.main_thread():
            self._old = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)  # type: ignore[arg-type]


def _drive(ctl, run: ProgramRunner, stop: _CtrlC, realtime: bool, bar: RunProgress) -> None:
    """Run the controller until the program ends or Ctrl-C is pressed."""
    if realtime:
        with ctl.start_realtime():
            while run.state is RunState.RUNNING and not stop.pressed:
                time.sleep(0.05)
                bar.update()
        return
    while run.state is RunState.RUNNING and not stop.pressed:
        ctl.run_until(lambda: run.state is not RunState.RUNNING or stop.pressed, _CHUNK)
        bar.update()


def _axes_to_rest(ctl, realtime: bool, limit: float = 120.0) -> None:
    """After a fault: let axes still stopping (a decelerating fault stop) come to rest (at
    most `limit` s machine time), so the summary and report show where they stopped."""
    def at_rest() -> bool:
        return not any(ax.is_moving for ax in ctl.axes)

    if realtime:
        with ctl.start_realtime():
            t_end = time.monotonic() + limit
            while not at_rest() and time.monotonic() < t_end:
                time.sleep(0.01)
    elif not at_rest():
        ctl.run_until(at_rest, limit)


def _settle(ctl, run: ProgramRunner, realtime: bool, limit: float = 120.0) -> None:
    """After abort(): let the group decelerate to rest (at most `limit` s machine time)."""
    from ..control.groups.group import GroupState

    def at_rest() -> bool:
        return run.group is None or run.group.state in (GroupState.IDLE, GroupState.ERROR)

    if realtime:
        with ctl.start_realtime():
            t_end = time.monotonic() + limit
            while not at_rest() and time.monotonic() < t_end:
                time.sleep(0.01)
    else:
        ctl.run_until(at_rest, limit)
