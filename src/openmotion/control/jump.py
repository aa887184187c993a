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
(`Controller.add_jump_observer`) get the command positions of the crossed cycles, so a
per-cycle record (the program runner's trace) stays complete.

Jumping is off, and every cycle runs, while anything needs each cycle: a sample hook (a
servo loop closed in Python), a pre-advance or cycle hook without a due function, the
recorder, a command transform, an axis waiting for INP or a done gate.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..hw.interface import AxisCommand, QueuedHardware

if TYPE_CHECKING:
    from .controller import Controller

#: Pieces are fed ahead in chunks of cycles, doubling from FIRST_CHUNK to MAX_CHUNK, so a
#: jump that an edge ends early wastes little planning and memory stays flat.
FIRST_CHUNK = 32
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


def plan_jump(ctl: Controller, cycles: int) -> int:
    """Cycle number to jump to (at most `cycles` ahead), or the current cycle + 1 or less
    when the next cycle must run on its own (then `Controller.step` runs it)."""
    n0 = ctl._n
    nxt = n0 + 1
    if (cycles < 2 or not ctl.virtual_jumps or ctl.recorder is not None
            or ctl._sample_hooks or not isinstance(ctl.hardware, QueuedHardware)):
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
    chunk = FIRST_CHUNK
    ends: list[list[tuple[float, float]]] = []
    while True:
        stop = min(land, n + chunk)
        ends = []
        for ax in movers:
            m = ax._motion
            assert m is not None
            pieces = []
            p1v1 = []
            t_end = m.t_end
            velocity = m.kind == "velocity"
            ta = t0
            for k in range(n + 1, stop + 1):
                t1 = origin + k * period
                p0, v0, a0, j, p1, v1 = m.piece(ta, t1)
                pieces.append(AxisCommand(ta, t1 - ta, p0, v0, a0, j))
                p1v1.append((p1, v1 if t1 < t_end or velocity else 0.0))
                ta = t1
            try:
                hw.queue_pieces(ax.index, pieces)
            except BaseException:
                for other in movers:  # nothing half-queued stays behind
                    hw.clear_queue(other.index)
                raise
            ends.append(p1v1)
        run = hw.run_cycles(origin, period, n, stop, wake)
        landed = run.cycle < stop or run.edges or stop >= land
        if ctl._jump_observers:
            _observe(ctl, n, run.cycle - 1 if landed else stop, movers, ends)
        if landed:
            break
        n = stop
        t0 = origin + n * period
        chunk = min(2 * chunk, MAX_CHUNK)
    k = run.cycle
    for ax, p1v1 in zip(movers, ends, strict=True):
        ax._pos, ax._vel = p1v1[k - n - 1]
        if k < stop:
            hw.clear_queue(ax.index)
    ctl._finish_cycle(k, run.edges)


def _observe(ctl: Controller, n: int, last: int, movers: list,
             ends: list[list[tuple[float, float]]]) -> None:
    """Hand the jump observers the command positions of the crossed cycles n+1..last."""
    if last <= n:
        return
    rows = [[ax.position] * (last - n) for ax in ctl.axes]
    for ax, p1v1 in zip(movers, ends, strict=True):
        off = ax.counters._cmd_off  # Axis.position = raw position + this offset
        rows[ax.index] = [p + off for p, _ in p1v1[:last - n]]
    positions = [list(r) for r in zip(*rows, strict=True)]
    for obs in tuple(ctl._jump_observers):
        obs(ctl, n + 1, last, positions)
