"""The runner's requests: a probe move, an M66 wait, a synchronised move, an M19
orientation, a user M-code (M100-M199) - started when the motion before them has ended
(`begin_request`), polled each cycle (`answer`) until done; a probe or wait answer
continues the live interpretation. Split from runner.py (one job: what happens between
two pieces of the program)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import MotionError
from . import canon
from .convert import Op
from .orient import Orient
from .probing import InputResult, Probe, ProbeResult, WaitInput
from .rigidtap import RigidTap
from .rigidtap_run import RigidTapMove
from .runtypes import RunState
from .runwait import InputWait, ProbeMove
from .spindle import OrientMove, SyncMove
from .usermcodes import UserCommand, UserMCode

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from ..control.groups.group import Group
    from ..hw.interface import InputEdge
    from .runner import ProgramRunner


def on_probe_edge(run: ProgramRunner, ctl: Controller, e: InputEdge) -> None:
    """The probe makes contact while no probe move runs and the axes move: LinuxCNC's
    "Probe tripped during non-probe move." (the cycle hook then stops the run)."""
    if e.axis is None and e.signal == run.options.probe_input and e.level \
            and not isinstance(run._request, ProbeMove) and run.group is not None \
            and not run._idle() and run.running:
        run._stray_trip = "Probe tripped during non-probe move."


def begin_request(run: ProgramRunner, g: Group, op: Op) -> None:
    """At rest before a probe move, an M66, an M19 or a synchronised move: arm the probe
    (and start the move), watch the input, orient, or wait for the spindle's index."""
    pos = run._positions()
    if isinstance(op.source, Probe):
        assert run.options.probe_input is not None
        req = ProbeMove(run._ctl, run.axis_indices, run.options.probe_input,
                        op.source, pos, run.scales.ppu)
        run._request = req
        run._event("probe", op.line, f"G{op.source.code / 10:g} on "
                    f"{run.options.probe_input}")
        if not req.at_start and not np.array_equal(op.target, pos):
            idx = run._push(g, op)
            run._line_of[idx] = op.line
            run.op_of[idx] = op
            run.starts_of[idx] = pos
    elif isinstance(op.source, WaitInput):
        run._request = InputWait(run._ctl, op.source, run.analog_in)
        run._event("wait", op.line, f"M66 P{op.index} L{op.source.mode}")
    elif isinstance(op.source, RigidTap):
        assert run.spindle is not None
        drive = run.spindle
        if drive.rpm == 0.0:
            raise MotionError("G33.1 needs the spindle turning")
        cmd = canon.Spindle(True, drive.rpm > 0.0, abs(drive.rpm), None, op.line, op.file)
        vmax = float(np.max(run.scales.vmax_units))

        def push_tap(end: np.ndarray, feed: float, line: int, src: Op = op) -> int:
            run._pushed += 1
            g.set_feed(feed)
            idx = g.line(end)
            run._line_of[idx] = line
            run.op_of[idx] = src
            run.starts_of[idx] = run._positions()
            return idx

        run._request = RigidTapMove(drive, g, op.source, cmd, vmax, push_tap)
        run._event("action", op.line, f"G33.1 rigid tap K{op.source.pitch:g}")
        run._pass.pc += 1  # the way back (the second op) is part of the tap
        op = run._pass.ops[run._pass.pc]
    elif isinstance(op.source, UserMCode):  # LinuxCNC's task waits for it to exit
        run._request = UserCommand(op.source, run.options.user_m_timeout,
                                   block=not run._ctl.realtime)
        run._event("user_mcode", op.line, op.text)
    elif isinstance(op.source, Orient):
        if run.spindle is None:
            run._event("action", op.line, f"{op.text}: no spindle axis (ignored)")
            return
        run._request = OrientMove(run.spindle, op.source)
        run._event("action", op.line, op.text)
    else:
        assert isinstance(op.source, canon.SyncedFeed) and run.spindle is not None
        # the consecutive synchronised lines (a G76 pass with its tapers) run as one
        p = run._pass
        chain = [op]
        while p.pc + len(chain) < len(p.ops) and isinstance(
                p.ops[p.pc + len(chain)].source, canon.SyncedFeed):
            chain.append(p.ops[p.pc + len(chain)])
        lines = []
        at = pos / run.scales.ppu
        for o in chain:
            assert o.end is not None and isinstance(o.source, canon.SyncedFeed)
            lines.append((at, o.end.copy(), o.source.pitch))
            at = o.end
        vmax = float(np.max(run.scales.vmax_units))

        def push(rps: float, chain: list[Op] = chain, start: np.ndarray = pos
                 ) -> list[int]:
            idxs = []
            for o in chain:
                assert o.end is not None and isinstance(o.source, canon.SyncedFeed)
                run._pushed += 1
                g.set_feed(min(o.source.pitch * rps, vmax))
                idx = g.line(o.end)
                run._line_of[idx] = o.line
                run.op_of[idx] = o
                run.starts_of[idx] = start
                start = o.target if o.target is not None else start
                idxs.append(idx)
            run._event("sync_start", chain[0].line, "spindle index: synchronised move")
            return idxs

        run._request = SyncMove(run.spindle, g, lines, push)
        p.pc += len(chain) - 1
        op = chain[-1]
    run._cursor = op.target if op.target is not None else pos


def answer(run: ProgramRunner, g: Group) -> bool:
    """A probe or wait in progress: True once its answer is in and the rest of the
    program (up to the next request) is queued as ops."""
    req = run._request
    if isinstance(req, RigidTapMove):
        done = req.poll(run.scales.ppu)
        if done:
            run.rigid_taps.append(req)
            run._event("tap_end", run._last_line, f"rigid tap: overrun {req.overrun_in:.4g} "
                       f"past the end, {req.overrun_out:.4g} past the start (machine units)")
            req.close()
            run._request = None
        return done
    if isinstance(req, UserCommand):
        try:
            done = req.poll()
        except MotionError as err:  # a failed or hung program: the run stops (LinuxCNC)
            run._request = None
            run.error = f"line {req.cmd.line}: {err}"
            run._event("fault", req.cmd.line, str(err))
            run._finish(RunState.ERROR, run.error)
            return False
        if done:
            run._event("user_mcode_end", req.cmd.line, f"M{req.cmd.code} exited with 0"
                       + (f": {req.output[-200:]}" if req.output else ""))
            run._request = None
        return done
    if isinstance(req, SyncMove | OrientMove):
        done = req.poll(run.scales.ppu) if isinstance(req, SyncMove) else req.poll()
        if done:
            if isinstance(req, SyncMove):
                run.sync_moves.append(req)
                run._event("sync_end", run._last_line, f"tool within "
                            f"{req.steady_error:.3g} of pitch x spindle revolutions "
                            "(settled, machine units)")
            req.close()
            run._request = None
        return done
    if isinstance(req, ProbeMove):
        if req.tripped and not req.stopping:
            req.stopping = True
            if not run._idle():
                g.abort()  # stop along the path, decelerating
            t = req.trip_time
            run._event("probe_trip", run._last_line,
                        "tripped" + ("" if t is None else f" at t={t:.6f}"))
        if not run._idle():
            return False
        rest = run._positions()
        result: ProbeResult | InputResult = req.result(rest)
    else:
        assert req is not None
        got = req.poll()
        if got is None:
            return False
        result = got
        rest = run._positions()
        run._event("input", run._last_line, f"M66 read {result.value:g}")
    req.close()
    run._request = None
    assert run._session is not None
    chunk = run._session.advance(result)  # GCodeError: a fault at this line
    run._cursor = rest
    run._pass.ops.extend(run._convert(chunk, rest))
    return True
