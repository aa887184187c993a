"""Streaming for the program runner: ops -> group commands, outputs and barriers.

`feed` runs in the runner's cycle hook: it hands motion to the group up to the window,
writes M64/M65 outputs as it reaches them, queues M62/M63 and M67 for the next move's
start (syncout.py), waits for the queue to empty at barriers (M68, blend changes, M0/M1,
M2, spindle/coolant/tool actions) and hands probe moves, input waits and synchronised moves
to the request handlers (runrequests.py). `end_of_pass` starts the next repeat.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MotionError
from . import canon
from .analogout import AnalogOut
from .convert import Op
from .css import SpindleMode
from .probing import Probe
from .rigidtap import RigidTap
from .runcompile import at_restart, restart_pass
from .runfeed import ceiling_rps, planned_rps, x_reader
from .runoverride import flush as flush_overrides
from .runoverride import pushed as override_pushed
from .runoverride import queue_switch, starts_sync
from .runoverride import reset as reset_overrides
from .runtypes import RunEvent, RunState
from .source import GCodeError

if TYPE_CHECKING:
    from ..control.groups.group import Group
    from ..path.geometry import Line
    from .runner import ProgramRunner


def set_output(run: ProgramRunner, op: Op, index: int, level: bool, kind: str,
               t: float | None = None) -> None:
    """Write output `index` now; the event at `t` (default now: an M62/M63 whose move
    started earlier in the cycle carries that instant)."""
    run._ctl.hardware.write_output(None, f"do{index}", level)
    run.synced.levels[index] = level
    run.events.append(RunEvent(run._ctl.time if t is None else t, kind, op.line,
                              f"do{index} = {int(level)}", index=index, level=level))


def write_analog(run: ProgramRunner, op: Op) -> None:
    assert isinstance(op.source, AnalogOut)
    run.analog.set(op.source.index, op.source.value)
    run._event("analog_output", op.line, op.text, index=op.index)


def record_synced(run: ProgramRunner, t: float, op: Op, index: int, level: bool) -> None:
    run.events.append(RunEvent(t, "sync_output", op.line, f"do{index} = {int(level)}",
                              index=index, level=level))


def idle(run: ProgramRunner) -> bool:
    g = run.group
    assert g is not None
    if not _IDLE:  # the groups are imported on first use (as the runner imports them)
        from ..control.groups.group import GroupState

        _IDLE.append(GroupState.IDLE)
    return g.state is _IDLE[0] and g.queue_length == 0


_IDLE: list[object] = []  # GroupState.IDLE


def idle_past(run: ProgramRunner, index: int) -> bool:
    # the command already ran (a short move started and ended within one cycle)
    return run.group is not None and run._idle() and index < run._pushed


def feed_ready(run: ProgramRunner, g: Group) -> bool:
    """Whether `_feed` would change anything now (mirrors its tests)."""
    p = run._pass
    opts = run.options
    if p.pc >= len(p.ops):
        return run._idle() and not run.synced.armed and not run.synced_analog.armed
    if g.queue_length >= opts.window:
        return False
    op = p.ops[p.pc]
    if opts.single_block and run._step_line is not None and op.line != run._step_line:
        return run._idle()
    if starts_sync(run, op):
        return run._idle()
    if op.kind in ("line", "arc", "delay", "feedmode", "override") or (
            op.kind in ("analog", "output") and op.synced) or (
            op.kind == "action" and not op.barrier):
        return True
    return run._idle()


def feed(run: ProgramRunner, g: Group) -> None:  # noqa: C901 - one dispatch over the op kinds
    p = run._pass
    opts = run.options
    while p.pc < len(p.ops) and g.queue_length < opts.window:
        op = p.ops[p.pc]
        if opts.single_block and run._step_line is not None and op.line != run._step_line:
            if not run._idle():
                return
            run.state = RunState.PAUSED
            run._step_line = None
            run._event("single_block", run._last_line, "block done")
            return
        synced = isinstance(op.source, canon.SyncedFeed | RigidTap) \
            and run.spindle is not None
        if isinstance(op.source, Probe) or op.kind in ("wait", "orient", "usermcode") \
                or synced:
            if not run._idle():
                return
            run._begin_request(g, op)
            p.pc += 1
            run._last_line = op.line
            return
        if op.kind in ("line", "arc", "delay"):
            if starts_sync(run, op) and not run._idle():
                return  # no blend into G33/G76/G33.1 (LinuxCNC stops first)
            planned = planned_rps(run, op) if (
                run._per_rev and run.spindle is not None and op.kind != "delay") else 0.0
            if planned > 0.0:  # G95: planned at the highest speed, the override scales
                ceiling = ceiling_rps(run, planned)
                op = replace(op, feed=op.feed * ceiling / planned)
            if op.kind == "line":
                idx = push(run, g, op, run._ahead.take(p.ops, p.pc))
            else:
                idx = run._push(g, op)
            if planned > 0.0:
                run._per_rev_ops[idx] = ceiling
            run._line_of[idx] = op.line
            run.op_of[idx] = op
            if op.target is not None:
                run.starts_of[idx] = run._cursor
                run._cursor = op.target
            if op.kind != "delay":
                run.synced.bind(idx, run.starts_of[idx])
                run.synced_analog.bind(idx)
        elif op.kind == "feedmode":
            run._per_rev = op.synced
        elif op.kind == "analog":
            if op.synced:
                run.synced_analog.pending.append(op)
            else:  # M68: after the motion before it (LinuxCNC's task waits for it)
                if not run._idle():
                    return
                run._write_analog(op)
        elif op.kind == "output":
            if op.synced:
                run.synced.pending.append(op)
            else:  # M64/M65: after the motion before it (LinuxCNC's task waits for it)
                if not run._idle():
                    return
                run._set_output(op, op.index, op.level, "output")
        elif op.kind == "override":  # M48-M53: where the next command starts
            queue_switch(run, op)
        elif op.kind == "action" and not op.barrier:
            run._event("message", op.line, op.text)
        else:  # barriers: blend, pause, end, spindle/coolant/tool
            if not run._idle():
                return
            if op.kind == "blend":
                if op.tolerance is None:
                    g.disable_blend()
                else:
                    g.enable_blend(op.tolerance)
            elif op.kind == "action":
                if isinstance(op.source, canon.Spindle) and run.spindle is not None:
                    run.spindle.apply(op.source)
                elif isinstance(op.source, SpindleMode) and run.spindle is not None:
                    k = op.source.x_axis
                    run.spindle.set_mode(op.source, x_reader(run, k))
                for index, level in op.outputs:
                    run._set_output(op, index, level, "output")
                run._event("action", op.line, op.text)
            elif op.kind == "pause" and (not op.optional or opts.optional_stop):
                p.pc += 1
                run._last_line = op.line
                run.state = RunState.PAUSED
                run._event("program_pause", op.line, "M1" if op.optional else "M0")
                return
            elif op.kind == "end":
                p.pc = len(p.ops)
                run._last_line = op.line
                break
        p.pc += 1
        run._last_line = op.line
        if opts.single_block:
            run._step_line = op.line
    if p.pc >= len(p.ops) and run._idle() and not run.synced.armed \
            and not run.synced_analog.armed:
        run._end_of_pass()


def push(run: ProgramRunner, g: Group, op: Op,
         ahead: tuple[np.ndarray, Line | None] | None = None) -> int:
    """Queue a line, arc or delay op; `ahead`: a line's prepared (end, line) (runahead)."""
    run._pushed += 1
    at_rest = run._idle()
    if op.kind == "delay":
        idx = g.delay(op.seconds)
    elif op.kind == "line":
        assert op.end is not None  # set_feed + line, without re-checking the compiler's
        if ahead is None:
            idx = g._queue_line(op.end, op.feed)
        else:
            idx = g._queue_line(ahead[0], op.feed, ahead[1])
    else:
        g.set_feed(op.feed)
        assert op.end is not None and op.centre is not None
        idx = g.arc(op.centre, op.end, plane=op.plane, direction=op.direction,
                    turns=op.turns)
    override_pushed(run, idx, op, at_rest)  # M48-M53 waiting for this command
    return idx


def end_of_pass(run: ProgramRunner) -> None:
    flush_overrides(run)
    run.synced.flush()
    run.synced_analog.flush()
    run.passes_done += 1
    limit = run.passes  # None: until the program ends with M2/M30 (not at an M99)
    if run.passes_done >= (limit or 0) and (limit is not None or not at_restart(run)):
        run._finish(RunState.DONE, f"{run.passes_done} pass(es) done")
        return
    run._event("repeat", run._last_line, f"pass {run.passes_done + 1}")
    if restart_pass(run):  # M99 in the main program: the interpretation goes on
        return
    reset_overrides(run)
    pos = run._positions()
    run._cursor = pos
    if run._live:
        try:
            run._pass = run._live_pass(pos)
        except (GCodeError, MotionError) as err:
            run.error = str(err)
            run._event("fault", 0, str(err))
            run._finish(RunState.ERROR, run.error)
    elif np.array_equal(pos, run._pass.start):
        run._pass.pc = 0
    else:  # a program that does not return to its start: re-plan from here
        try:
            run._pass = run._compile(pos)
        except (GCodeError, MotionError) as err:
            run.error = str(err)
            run._event("fault", 0, str(err))
            run._finish(RunState.ERROR, run.error)
