"""Compiling for the program runner: G-code (or canonical commands) -> one pass of `Op`s.

A pass is the whole program converted to machine units from a start position; a program
with G38.x / M66 is interpreted piece by piece against the machine (`live_pass`, then
`convert_chunk` after each answer, runrequests.py), and so is one whose main program ends
with M99: each restart is a new pass of the same interpretation (`restart_pass`). M67/M68
values are checked against the board here, before anything moves.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MotionError
from . import canon
from .analogout import AnalogOut
from .convert import ConvertOptions, Op, convert
from .interp import Interpreter, compile_text
from .parser import parse_program
from .runtypes import RunState
from .source import GCodeError

if TYPE_CHECKING:
    from .runner import ProgramRunner


@dataclass
class RunPass:
    """One pass of the program: its ops, the start position (pulses), the next op."""

    ops: list[Op]
    start: np.ndarray
    pc: int = 0


def compile_pass(run: ProgramRunner, start: np.ndarray) -> RunPass:
    cmds = run._commands
    if cmds is None:
        assert run._text is not None
        cmds = compile_text(run._text, run._goptions(start), run.file)
    run.commands = cmds
    ops = convert(cmds, run.scales, start, ConvertOptions(
        run.options.rapid_ratio, run.options.feed_mode, run.options.chord_tol))
    run._check_analog(cmds)
    return RunPass(ops, start.copy())


def live_pass(run: ProgramRunner, start: np.ndarray) -> RunPass:
    """Start interpreting the program against the machine: the ops up to the first
    probe or input wait (the rest follows each answer, `_answer`)."""
    assert run._text is not None
    opts = run._goptions(start)
    program = parse_program(run._text, run.file, opts.max_line_length)
    run._session = Interpreter(program, opts).session()
    chunk = run._session.advance()
    run._rpm = 0.0
    return RunPass(run._convert(chunk, start), start.copy())


def convert_chunk(run: ProgramRunner, chunk: list[canon.Command], start: np.ndarray) -> list[Op]:
    ops = convert(chunk, run.scales, start, ConvertOptions(
        run.options.rapid_ratio, run.options.feed_mode, run.options.chord_tol),
        rpm=run._rpm)
    for c in chunk:
        if isinstance(c, canon.Spindle):
            run._rpm = c.speed if c.on else 0.0
    run._check_analog(chunk)
    return ops


def check_analog(run: ProgramRunner, cmds: Sequence[object]) -> None:
    """M67/M68 values against the board's range, before anything moves."""
    for c in cmds:
        if isinstance(c, AnalogOut):
            try:
                run.analog.check(c.index, c.value)
            except MotionError as exc:
                raise GCodeError(f"M{67 if c.synced else 68}: {exc}", line=c.line,
                                 file=c.file) from None


#: Op kinds that do nothing on the machine by themselves (a pass made only of these would
#: repeat endlessly in no time).
_IDLE_KINDS = ("end", "blend", "feedmode", "override")


def at_restart(run: ProgramRunner) -> bool:
    """Whether the pass just ended at an M99 of the main program (End(restart=True))."""
    ops = run._pass.ops
    return bool(ops) and ops[-1].kind == "end" and getattr(ops[-1].source, "restart", False)


def restart_pass(run: ProgramRunner) -> bool:
    """At the end of a pass: if it ended at an M99 of the main program, the next pass
    (the interpretation goes on at the program's top, every state kept, from where the
    axes are) and True; False for any other end. A fault ends the run (still True)."""
    s = run._session
    end = None if s is None else s.request
    if s is None or not (isinstance(end, canon.End) and end.restart):
        return False
    if not any(op.kind not in _IDLE_KINDS and (op.kind != "action" or op.barrier)
               for op in run._pass.ops):
        run.error = (f"line {end.line}: M99 restarts the program, but the pass neither "
                     "moved, waited nor switched anything: it would repeat endlessly")
        run._event("fault", end.line, run.error)
        run._finish(RunState.ERROR, run.error)
        return True
    pos = run._positions()
    try:
        ops = run._convert(s.advance(True), pos)
    except (GCodeError, MotionError) as err:
        run.error = str(err)
        run._event("fault", end.line, str(err))
        run._finish(RunState.ERROR, run.error)
        return True
    run._cursor = pos
    run._pass = RunPass(ops, pos.copy())
    return True
