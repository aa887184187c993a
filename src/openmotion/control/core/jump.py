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
outputs are identical (tests/test_jump_equivalence.py runs both ways). A motion's pieces
are computed ahead to its end and kept on it (`_ahead`), so a landing re-queues rows
already made for the axes still moving. Jump observers
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
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import MotionError
from ...hw.interface import AXIS_INPUTS, BulkReadback, PieceBlock, QueuedHardware
from . import motion as _motion
from .counters import Counters

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


def end_cycle(ctl: Controller, m: _motion.ActiveMotion) -> int:
    """first_cycle_at(ctl, m.t_end) for a move: the grid cycle is kept on the motion (it
    never changes), so a landing does not search it again for every axis still moving."""
    t = m.t_end
    if t <= ctl._time:
        return ctl._n
    origin, period = ctl._t_origin, ctl.period
    c = m._end_cycle
    if c is None or c[0] != origin or c[1] != period or c[2] < ctl._n:
        k = first_cycle_at(ctl, t)
        if k == ctl._n:  # clamped by the present: not the grid cycle itself, don't keep
            return k
        m._end_cycle = c = (origin, period, k)
    return c[2]


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
    origin, period = ctl._t_origin, ctl.period
    on_grid = ctl._time == origin + n0 * period  # (else end_cycle compares with the time)
    for ax in ctl.axes:
        if ax.command_transforms or ax._waiting_inp or ax._gated:
            return nxt
        m = ax._motion
        if m is not None and m.kind != "velocity":
            c = m._end_cycle  # end_cycle's kept grid cycle, when it is ahead of now
            if on_grid and c is not None and c[2] > n0 and c[0] == origin and c[1] == period:
                e = c[2]
            else:
                e = end_cycle(ctl, m)
            if e < land:
                land = e
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
    on, or `land`) as `step` does.

    A mover's pieces are queued up to the end of those computed ahead (`_ahead`), not only
    to the chunk's end, and stay queued at the landing (`Controller._fed`): the next jump
    of the same motion finds them there and queues nothing (`_feed`). Pieces left for a
    motion that changed are dropped at the next jump, and `Controller.step` drops them
    all before it commands a cycle itself."""
    hw = ctl.hardware
    origin, period = ctl._t_origin, ctl.period
    axes = ctl.axes
    movers = [ax for ax in axes if ax._motion is not None]
    fed = ctl._fed
    if fed:  # pieces left at the last landing for a motion that is over or replaced
        for idx in [i for i, e in fed.items() if axes[i]._motion is not e[0]]:
            del fed[idx]
            hw.clear_queue(idx)
    wake = wake_signals(ctl)
    queued = hw.queued
    n = ctl._n
    t0 = ctl._time
    chunk = FIRST_CHUNK if _motion._kernel is None else FIRST_CHUNK_COMPILED
    ends: list[np.ndarray] = []
    held: tuple | None = None  # record_trace's token of the last chunk's held readback
    while True:
        stop = min(land, n + chunk)
        try:
            ends = []
            for ax in movers:  # (the pieces left queued for the motion serve: `_feed`)
                e = fed.get(ax.index)
                if (e is not None and e[0] is ax._motion and e[1] >= stop and e[2] == origin
                        and e[3] == period and queued(ax.index) == e[1] - n):
                    ends.append(e[5][n - e[4]:stop - e[4]])
                else:
                    ends.append(_feed(ctl, hw, ax, t0, n, stop))
        except BaseException:
            ctl._drop_fed()
            for other in movers:  # nothing half-queued stays behind
                hw.clear_queue(other.index)
            raise
        rec = ctl.recorder
        run = hw.run_cycles(origin, period, n, stop, wake,
                            trace=rec is not None or bool(ctl._jump_observers))
        if run.cycle == ctl._n:  # real time: returned before its first cycle (realtime.py)
            ctl._drop_fed()
            for ax in movers:
                hw.clear_queue(ax.index)
            return
        last = run.cycle < stop or run.edges or stop >= land
        if rec is not None:  # the landing cycle is recorded by _finish_cycle
            held = record_trace(ctl, movers, ends, n,
                                run.trace[:run.cycle - n - (1 if last else 0)], held)
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
    ctl._finish_cycle(k, run.edges)


def _feed(ctl: Controller, hw: Any, ax: Any, t0: float, n: int, stop: int) -> np.ndarray:
    """Queue `ax`'s motion afresh: the pieces of `_ahead` from cycle n+1 to the end of
    those computed ahead (at least up to stop), after clearing what an earlier jump left
    queued; returns the end states (p1, v1) of cycles n+1 .. stop. `jump` keeps the entry
    (`Controller._fed`) and uses the queued pieces again while the queue holds exactly
    those of cycles n+1 .. their end (one piece per cycle: a run started the ones before)
    for the same motion on the same grid."""
    idx = ax.index
    if ctl._fed.pop(idx, None) is not None:
        hw.clear_queue(idx)
    rows, ends = _ahead(ctl, ax._motion, t0, n, stop, tail=True)
    hw.queue_pieces(idx, PieceBlock(rows))
    ctl._fed[idx] = (ax._motion, n + len(rows), ctl._t_origin, ctl.period, n, ends)
    return ends[:stop - n]


def _ahead(ctl: Controller, m: _motion.ActiveMotion, t0: float, n: int, stop: int,
           tail: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The pieces (rows) and end states (p1, v1) of `m` for cycles n+1 .. stop, the first
    starting at t0. With the compiled pieces they are computed ahead, up to the cycle the
    motion ends in (at most MAX_CHUNK cycles on), and kept on the motion, so the next
    jumps reuse them: a landing costs no new pieces for the axes still moving. A motion
    never changes once made, and every cycle's piece depends only on it and the cycle
    grid, so the rows are the very ones computed at the landing. `tail`: every row computed
    ahead from cycle n+1 on (at least up to stop), not only those up to stop."""
    origin, period = ctl._t_origin, ctl.period
    cache = m._ahead
    if cache is not None:
        c_origin, c_period, c_n, rows, ends = cache
        i = n - c_n
        if (c_origin == origin and c_period == period and 0 <= i < len(rows)
                and stop - c_n <= len(rows) and rows[i, 0] == t0):
            j = len(rows) if tail else stop - c_n
            return rows[i:j], ends[i:j]
    upto = stop
    velocity = m.kind == "velocity"
    k_end = 0 if velocity else end_cycle(ctl, m)
    if _motion._kernel is not None:
        upto = max(stop, n + min(FIRST_CHUNK_COMPILED if velocity else k_end - n, MAX_CHUNK))
    rows, ends = m.pieces(t0, origin, period, n, upto - n)
    if not velocity:  # a move settles at its end: velocity 0 from the cycle ending at or
        # after t_end on (the cycle ends rise with k, so that is a tail of the rows)
        ends[max(k_end, n + 1) - n - 1:, 1] = 0.0
    m._ahead = (origin, period, n, rows, ends)
    if tail:
        return rows, ends
    return rows[:stop - n], ends[:stop - n]


def record_trace(ctl: Controller, movers: list, ends: list[np.ndarray], n: int,
                 trace: np.ndarray, held: tuple | None = None) -> tuple | None:
    """Record cycles n+1 .. n+len(trace) that a jump crossed: the rows `Controller._record`
    writes cycle by cycle, from the back end's readback at each cycle end (`trace`) and the
    end states of the movers' pieces (`ends`); nothing else changes in those cycles.

    A readback that held through the chunk (`trace` one row broadcast, strides[0] == 0, as
    SimMachine.run_cycles reports an idle stretch) with no mover gives rows that differ
    only in time: the first is written, the rest held (`Recorder.hold`). Returns the token
    `held` of the next chunk of the same jump: the same readback again (nothing else
    changes between a jump's chunks) is held on from the recorder's newest row."""
    m = len(trace)
    if not m:
        return held
    kern = _motion._kernel
    if kern is not None and not movers and m > 1 and isinstance(trace, np.ndarray) \
            and trace.strides[0] == 0:
        rec = ctl.recorder
        key = trace[0].tobytes()
        if held is not None and held[0] == key and held[1] == rec.total \
                and rec.hold(m, ctl._t_origin, ctl.period, n):
            return key, rec.total
        if _first_row(ctl, rec, n + 1, trace[0]):
            rec.hold(m - 1, ctl._t_origin, ctl.period, n + 1)  # it took the row: it holds
            return key, rec.total
    if kern is not None and _block_rows(ctl, ctl.recorder, movers, ends, n, trace):
        return None  # the rows straight into the recorder's ring, in C
    from .controller import STATE_CODES  # the controller imports this module

    axes = ctl.axes
    t = ctl._t_origin + np.arange(n + 1, n + m + 1) * ctl.period
    pos = np.empty((m, len(axes)))
    vel = np.empty((m, len(axes)))
    pos[:] = [ax.position for ax in axes]
    vel[:] = [ax.velocity for ax in axes]
    if movers:
        idx = [ax.index for ax in movers]
        pv = np.stack([e[:m] for e in ends], axis=1)  # (m, movers, 2)
        pos[:, idx] = pv[:, :, 0] + np.array([ax.counters._cmd_off for ax in movers])
        vel[:, idx] = pv[:, :, 1]
    fb = Counters.feedback_of([ax.counters for ax in axes], trace[:, :, 0], trace[:, :, 1])
    # logical levels: the electrical ones flipped where the contact is normally closed
    io = _io_table()[trace[:, :, 2] ^ _nc_words(ctl)]
    if ctl._estop:
        io |= 1 << 6
    state = np.broadcast_to(np.array([STATE_CODES[ax.state] for ax in axes], dtype=np.int64),
                            (m, len(axes)))
    ctl.recorder.record_block(t, cmd_pos=pos, fb_pos=fb, cmd_vel=vel, state=state, io=io)
    return None


def _writable(trace: np.ndarray) -> np.ndarray:
    """`trace` as a C-contiguous, writable int64 array (the kernel's buffers are)."""
    t = np.ascontiguousarray(trace, dtype=np.int64)
    return t if t.flags.writeable else t.copy()


_BULK: dict[type, bool] = {}
_NO_MOVERS = np.zeros(0, dtype=np.int64)
_NO_OFFSETS = np.zeros(0)


_WORDS: dict[tuple, int] = {}


def _level_word(inputs: dict[str, bool]) -> int:
    """The input-level bits (bit k = AXIS_INPUTS[k]) of a readback's inputs dict."""
    key = tuple(inputs.items())
    w = _WORDS.get(key)
    if w is None:
        w = sum(1 << k for k, sig in enumerate(AXIS_INPUTS) if inputs.get(sig))
        if len(_WORDS) < 4096:
            _WORDS[key] = w
    return w


def record_now(ctl: Controller, n: int) -> bool:
    """Record the row of cycle n (its end, now) as `Controller._record` does, in one
    compiled call (the recorder's armed row sink, `Recorder.row_sink`): the back end's
    readback of every axis in one call (BulkReadback), the cached one of an axis already
    read in this cycle (what its counters and inputs show). False (nothing done) without
    the compiled kernel or a bulk readback, or when the recorder takes rows one by one
    (spilling)."""
    rec = ctl.recorder
    sink = rec.sink  # armed by an earlier row, until anything else touches the recorder
    if sink is None:
        sink = _arm(ctl, rec)
        if sink is None:
            return False
    rows = ctl.hardware.read_axes()
    if type(rows) is not np.ndarray or rows.dtype is not _INT64:
        rows = _writable(rows)
    now = ctl._n
    axes = ctl.axes
    if now in ctl._rb_cycle:
        rows = rows.copy()  # not the back end's own array
        for i, c in enumerate(ctl._rb_cycle):
            if c == now:  # read in this cycle: the values the controller holds
                cnt = axes[i].counters
                rows[i] = (cnt._raw_out, cnt._raw_enc, _level_word(ctl._inputs[i]))
    try:  # the usual case in one call; no room or disarmed: _put_row arms it again
        if sink.put(ctl._t_origin + n * ctl.period, axes, rows, _nc_words(ctl), ctl._estop):
            return True
    except (TypeError, ValueError, OverflowError, BufferError) as exc:
        raise MotionError(f"record: {exc}") from None
    return _put_row(ctl, rec, sink, n, rows, "record")


def _put_row(ctl: Controller, rec: Any, sink: Any, n: int, rows: np.ndarray,
             what: str) -> bool:
    """Cycle n's row through the armed `sink`, from the readback `rows` and the axes (the
    sink reads each one's raw position and command offset, velocity, feedback source and
    offset and state, as Axis.position etc. give them). A sink with no room (a
    held run's rows come first: row_sink settles them) or disarmed (another thread read
    the recorder since) is armed again; False when the recorder takes rows one by one."""
    axes = ctl.axes
    t = ctl._t_origin + n * ctl.period
    try:
        if not sink.put(t, axes, rows, _nc_words(ctl), ctl._estop):
            sink = _arm(ctl, rec)
            if sink is None:
                return False
            sink.put(t, axes, rows, _nc_words(ctl), ctl._estop)
    except (TypeError, ValueError, OverflowError, BufferError) as exc:
        raise MotionError(f"{what}: {exc}") from None
    return True


def _first_row(ctl: Controller, rec: Any, n: int, readback: np.ndarray) -> bool:
    """The row of cycle n from the readback row `readback` (int64 [n_axes, 3]) with no
    mover (the first of an idle stretch), through the recorder's row sink; False (nothing
    done) when the recorder takes rows one by one."""
    sink = rec.sink or _arm(ctl, rec)
    if sink is None:
        return False
    return _put_row(ctl, rec, sink, n, readback, "record_block")


def _block_rows(ctl: Controller, rec: Any, movers: list, ends: list[np.ndarray], n: int,
                trace: np.ndarray) -> bool:
    """The rows of cycles n+1 .. n+len(trace) a jump crossed through the recorder's row
    sink (`put_block`: the rows `_kernel.record_rows` writes): the movers' positions and velocities
    from their piece ends, every other axis's held values. False (nothing done) when the
    recorder takes rows one by one."""
    m = len(trace)
    sink = rec.sink or _arm(ctl, rec, m)
    if sink is None:
        return False
    args = (n, ctl._t_origin, ctl.period, _writable(trace), ctl.axes,
            [ax.index for ax in movers],
            tuple(e if e.flags.c_contiguous else np.ascontiguousarray(e) for e in ends),
            [float(ax.counters._cmd_off) for ax in movers], _nc_words(ctl), ctl._estop)
    try:
        if not sink.put_block(*args):
            sink = _arm(ctl, rec, m)  # no room or disarmed (see record_now)
            if sink is None:
                return False
            sink.put_block(*args)
    except (TypeError, ValueError, OverflowError, BufferError) as exc:
        raise MotionError(f"record_block: {exc}") from None
    return True


def _arm(ctl: Controller, rec: Any, rows: int = 1) -> Any:
    """The recorder's row sink armed at its head (`Recorder.row_sink`), or None when the
    row goes through `Recorder.record` (no compiled kernel, no bulk readback, spilling)."""
    hw = ctl.hardware
    t = type(hw)
    bulk = _BULK.get(t)
    if bulk is None:
        bulk = _BULK[t] = isinstance(hw, BulkReadback)
    if _motion._kernel is None or not bulk:
        return None
    return rec.row_sink(_IO_TABLE[0] if _IO_TABLE else _io_table(), *_state_table(), rows)


def _state_table() -> tuple[tuple, tuple[int, ...]]:
    """Controller.STATE_CODES as (states, codes) tuples (the recorder's row sink)."""
    if not _STATE_TABLE:
        from .controller import STATE_CODES  # the controller imports this module
        _STATE_TABLE.append((tuple(STATE_CODES), tuple(STATE_CODES.values())))
    return _STATE_TABLE[0]


_STATE_TABLE: list[tuple[tuple, tuple[int, ...]]] = []
_INT64 = np.dtype(np.int64)


_IO_TABLE: list[np.ndarray] = []


def _io_table() -> np.ndarray:
    """The io word (Controller._record's, IO_BITS) of every logical input-level word
    (bit k = AXIS_INPUTS[k]), so a block of levels converts in one lookup."""
    if not _IO_TABLE:
        from .controller import IO_BITS  # the controller imports this module
        words = np.arange(1 << len(AXIS_INPUTS), dtype=np.int64)
        io = np.zeros_like(words)
        for sig, bit in IO_BITS:
            io |= ((words >> AXIS_INPUTS.index(sig)) & 1) << bit
        _IO_TABLE.append(io)
    return _IO_TABLE[0]


def _nc_words(ctl: Controller) -> np.ndarray:
    """Per axis, the input-level bits (bit k = AXIS_INPUTS[k]) whose contact is normally
    closed. `Controller.reconfigure_axis` (logic) puts a new set in the axis's place of the
    contact table, so the words are kept with the sets they came from (held, so compared
    by identity first, by value otherwise) and made again when one differs."""
    cached = getattr(ctl, "_jump_nc_words", None)
    sets = tuple(ctl._nc)
    if cached is None or cached[0] != sets:
        words = np.array([sum(1 << k for k, sig in enumerate(AXIS_INPUTS) if sig in nc)
                          for nc in sets], dtype=np.int64)
        cached = ctl._jump_nc_words = (sets, words)
    return cached[1]


def _observe(ctl: Controller, n: int, last: int, movers: list,
             ends: list[np.ndarray], trace: np.ndarray) -> None:
    """Hand the jump observers the command and actual (feedback, `Counters.actual_from`
    of the back end's readback `trace`) positions of the crossed cycles n+1..last, as
    arrays (rows = cycles, columns = axes)."""
    if last <= n:
        return
    m = last - n
    positions = np.empty((m, len(ctl.axes)))
    positions[:] = [ax.position for ax in ctl.axes]
    for ax, p1v1 in zip(movers, ends, strict=True):
        # Axis.position = raw position + this offset
        positions[:, ax.index] = p1v1[:m, 0] + ax.counters._cmd_off
    tr = trace[:m]
    actual = np.stack([np.asarray(ax.counters.actual_from(tr[:, ax.index, 0], tr[:, ax.index, 1]),
                                  dtype=float) for ax in ctl.axes], axis=1)
    for obs in tuple(ctl._jump_observers):
        obs(ctl, n + 1, last, positions, actual)
