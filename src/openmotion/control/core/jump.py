"""Virtual time that jumps: cross the cycles in which nothing needs the control layer.

Cycle by cycle, the controller hands every moving axis one cubic piece per cycle, advances
the hardware, and runs its hooks. Most cycles change nothing a hook or a user can see: the
motion goes on, no edge comes, no hook acts. When the back end executes timed pieces by
itself (hw.interface.QueuedHardware) and every cycle hook can say when it must next run
(`Controller.add_cycle_hook(hook, due=...)`), `plan_jump` finds the last cycle before
which nothing needs Python:

- the cycle in which an axis's motion reaches its end (it settles there);
- the first cycle ending at or after the earliest cycle hook's due time, and the cycle
  before the first one containing a pre-advance hook's due time (that one runs on its own);
- the cycles asked for (`advance`, `run_until`).

`jump` then queues, for every moving axis, the very pieces the cycle-by-cycle path would
have commanded (same `ActiveMotion.piece` calls, same floats), lets the back end run them
(`run_cycles`), which stops early at the end of the first cycle with an input edge that
some edge hook acts on (`add_edge_hook(..., signals=...)`; edges no hook acts on, such as
encoder index pulses with nobody latching them, are dropped), and
finishes that landing cycle exactly as `Controller.step` finishes a cycle. The cycles in
between are the ones that would have been no-ops, so counters, events, histories and
outputs are identical (tests/test_jump_equivalence.py runs both ways). Jump observers
(`Controller.add_jump_observer`) get the command and actual (feedback) positions of the
crossed cycles, so a per-cycle record (the program runner's trace) stays complete.

Jumping is off, and every cycle runs, while anything needs each cycle: a sample hook (a
servo loop closed in Python), a pre-advance or cycle hook without a due function, a
command transform, an axis waiting for INP or a done gate. The recorder does not stop
jumps: the back end reports the readback at every cycle end (`run_cycles(trace=True)`)
and the crossed cycles are recorded from it and the pieces' end states (`record_trace`),
the very rows `Controller._record` writes cycle by cycle.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...hw.interface import AXIS_INPUTS, PieceBlock, QueuedHardware
from . import motion as _motion

if TYPE_CHECKING:
    from .controller import Controller

#: Pieces are fed ahead in chunks of cycles, doubling from FIRST_CHUNK to MAX_CHUNK, so a
#: jump that an edge ends early wastes little planning and memory stays flat. With the
#: compiled pieces (openmotion._kernel) a cycle's piece costs far less than a chunk's
#: Python overhead, so chunks start at FIRST_CHUNK_COMPILED.
FIRST_CHUNK = 32
FIRST_CHUNK_COMPILED = 256
MAX_CHUNK = 2048


def first_cycle_at(ctl: Controller, t: float) -> int:
    """The first cycle number whose end time (origin + k * period) is >= t."""
    origin, period = ctl._t_origin, ctl.period
    if t <= ctl._time:
        return ctl._n
    k = max(ctl._n, math.ceil((t - origin) / period))
    while k > ctl._n and origin + (k - 1) * period >= t:
        k -= 1
    while origin + k * period < t:
        k += 1
    return k


_QUEUED: dict[type, bool] = {}


def _queued(hw: object) -> bool:
    """isinstance(hw, QueuedHardware), cached per class (a Protocol check is slow)."""
    t = type(hw)
    ok = _QUEUED.get(t)
    if ok is None:
        ok = _QUEUED[t] = isinstance(hw, QueuedHardware)
    return ok


def plan_jump(ctl: Controller, cycles: int) -> int:
    """Cycle number to jump to (at most `cycles` ahead), or the current cycle + 1 or less
    when the next cycle must run on its own (then `Controller.step` runs it)."""
    n0 = ctl._n
    nxt = n0 + 1
    if (cycles < 2 or not ctl.virtual_jumps or ctl._sample_hooks
            or not _queued(ctl.hardware)):
        return nxt
    land = n0 + cycles
    pre_dues = ctl._pre_dues
    for pre in ctl._pre_hooks:  # a pre-advance hook's cycle must run on its own: land before
        due = pre_dues.get(pre)
        if due is None:
            return nxt
        t = due(ctl)
        if t != math.inf:
            land = min(land, first_cycle_at(ctl, t) - 1)
            if land <= nxt:
                return nxt
    for ax in ctl.axes:
        if ax.command_transforms or ax._waiting_inp or ax._gated:
            return nxt
        m = ax._motion
        if m is not None and m.kind != "velocity":
            land = min(land, first_cycle_at(ctl, m.t_end))
            if land <= nxt:
                return nxt
    dues = ctl._cycle_dues
    for hook in ctl._cycle_hooks:
        due = dues.get(hook)
        if due is None:
            return nxt
        t = due(ctl)
        if t != math.inf:
            land = min(land, first_cycle_at(ctl, t))
            if land <= nxt:
                return nxt
    return land


def wake_signals(ctl: Controller) -> frozenset[str] | None:
    """The signals some edge hook acts on (None: a hook may act on any)."""
    sigs: set[str] = set()
    declared = ctl._edge_signals
    for h in ctl._edge_hooks:
        s = declared.get(h)
        if s is None:
            return None
        sigs |= s
    return frozenset(sigs)


def jump(ctl: Controller, land: int) -> None:
    """Run cycles up to `land` (> current + 1) through the back end's piece queue, fed
    ahead in chunks; finish the cycle it stops at (the first with an edge some hook acts
    on, or `land`) as `step` does."""
    hw = ctl.hardware
    origin, period = ctl._t_origin, ctl.period
    movers = [ax for ax in ctl.axes if ax._motion is not None]
    wake = wake_signals(ctl)
    n = ctl._n
    t0 = ctl._time
    chunk = FIRST_CHUNK if _motion._kernel is None else FIRST_CHUNK_COMPILED
    ends: list[np.ndarray] = []
    while True:
        stop = min(land, n + chunk)
        ends = []
        t1 = origin + np.arange(n + 1, stop + 1) * period  # cycle ends, as `step` has them
        for ax in movers:
            m = ax._motion
            assert m is not None
            rows, p1v1 = m.pieces(t0, origin, period, n, stop - n)
            if m.kind != "velocity":  # a move settles at its end: velocity 0 from t_end on
                p1v1[t1 >= m.t_end, 1] = 0.0
            try:
                hw.queue_pieces(ax.index, PieceBlock(rows))
            except BaseException:
                for other in movers:  # nothing half-queued stays behind
                    hw.clear_queue(other.index)
                raise
            ends.append(p1v1)
        rec = ctl.recorder
        run = hw.run_cycles(origin, period, n, stop, wake,
                            trace=rec is not None or bool(ctl._jump_observers))
        last = run.cycle < stop or run.edges or stop >= land
        if rec is not None:  # the landing cycle is recorded by _finish_cycle
            record_trace(ctl, movers, ends, n, run.trace[:run.cycle - n - (1 if last else 0)])
        if ctl._jump_observers:
            _observe(ctl, n, run.cycle - 1 if last else stop, movers, ends, run.trace)
        if last:
            break
        n = stop
        t0 = origin + n * period
        chunk = min(2 * chunk, MAX_CHUNK)
    k = run.cycle
    for ax, p1v1 in zip(movers, ends, strict=True):
        ax._pos, ax._vel = p1v1[k - n - 1].tolist()
        if k < stop:
            hw.clear_queue(ax.index)
    ctl._finish_cycle(k, run.edges)


def record_trace(ctl: Controller, movers: list, ends: list[np.ndarray], n: int,
                 trace: np.ndarray) -> None:
    """Record cycles n+1 .. n+len(trace) that a jump crossed: the rows `Controller._record`
    writes cycle by cycle, from the back end's readback at each cycle end (`trace`) and the
    end states of the movers' pieces (`ends`); nothing else changes in those cycles."""
    from .controller import IO_BITS, STATE_CODES  # the controller imports this module

    m = len(trace)
    if not m:
        return
    axes = ctl.axes
    t = ctl._t_origin + np.arange(n + 1, n + m + 1) * ctl.period
    pos = np.empty((m, len(axes)))
    vel = np.empty((m, len(axes)))
    for ax in axes:
        pos[:, ax.index] = ax.position
        vel[:, ax.index] = ax.velocity
    for ax, p1v1 in zip(movers, ends, strict=True):
        pos[:, ax.index] = p1v1[:m, 0] + ax.counters._cmd_off
        vel[:, ax.index] = p1v1[:m, 1]
    fb = np.stack([ax.counters.feedback_from(trace[:, ax.index, 0], trace[:, ax.index, 1])
                   for ax in axes], axis=1)
    # logical levels: the electrical ones flipped where the contact is normally closed
    nc = np.array([sum(1 << k for k, sig in enumerate(AXIS_INPUTS) if sig in ctl._nc[i])
                   for i in range(len(axes))], dtype=np.int64)
    logical = trace[:, :, 2] ^ nc
    io = np.zeros((m, len(axes)), dtype=np.int64)
    for sig, bit in IO_BITS:
        io |= ((logical >> AXIS_INPUTS.index(sig)) & 1) << bit
    if ctl._estop:
        io |= 1 << 6
    state = np.broadcast_to(np.array([STATE_CODES[ax.state] for ax in axes], dtype=np.int64),
                            (m, len(axes)))
    ctl.recorder.record_block(t, cmd_pos=pos, fb_pos=fb, cmd_vel=vel, state=state, io=io)


def _observe(ctl: Controller, n: int, last: int, movers: list,
             ends: list[np.ndarray], trace: np.ndarray) -> None:
    """Hand the jump observers the command and actual (feedback, `Counters.actual_from`
    of the back end's readback `trace`) positions of the crossed cycles n+1..last."""
    if last <= n:
        return
    rows = [[ax.position] * (last - n) for ax in ctl.axes]
    for ax, p1v1 in zip(movers, ends, strict=True):
        off = ax.counters._cmd_off  # Axis.position = raw position + this offset
        rows[ax.index] = (p1v1[:last - n, 0] + off).tolist()
    positions = [list(r) for r in zip(*rows, strict=True)]
    tr = trace[:last - n]
    act = np.stack([np.asarray(ax.counters.actual_from(tr[:, ax.index, 0], tr[:, ax.index, 1]),
                               dtype=float) for ax in ctl.axes], axis=1)
    actual = act.tolist()
    for obs in tuple(ctl._jump_observers):
        obs(ctl, n + 1, last, positions, actual)
