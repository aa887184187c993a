"""The compiled stepper pipeline (`openmotion._kernel.run`, C) behind `SimMachine.run_cycles`
and `SimMachine.advance`.

`run_quiet` hands the kernel a chunk of cycles as flat arrays over all axes: each axis's
command, pulse count, losses, load position, decoder state and switches, and its queued
pieces. The kernel runs the cycles in C with the GIL released. The first cycle with a
crossing on a `wake` signal is run again in report mode and ends the run: every crossing of
that cycle comes back as an `InputEdge` with its exact time and every axis's decoded count
at that instant. It stops before the cycle of a scenario action (`SimMachine._advance_native`
runs that cycle in parts around the action) and before anything it cannot run exactly;
board outputs at a time touch no axis and are
emitted by SimMachine after the run. The state stays in the kernel's
arrays (`KernelState`) between runs and goes back into the `SimAxis` objects when Python
needs them.

The kernel takes a machine whose axes are all steppers (ideal or stalling, armed edge stops
and pitch-error tables included); for any other machine `usable` is False and every
cycle runs in Python. It is built by the package's own build (setup.py); when the module is
missing (a source tree that was never built) `AVAILABLE` is False and the Python path runs.
Set `SimMachine.native = False` to force the Python path (the equivalence tests do).
"""

from __future__ import annotations

import math
from collections.abc import Collection
from typing import TYPE_CHECKING

import numpy as np

from openmotion.hw.interface import AXIS_INPUTS, InputEdge

from .cubic import Cubic
from .plant import StepperPlant
from .pulses import Stretch
from .switches import IndexSwitch

try:
    from openmotion import _kernel as _k
except ImportError:  # pragma: no cover - depends on the build
    _k = None

if TYPE_CHECKING:
    from .piecequeue import PieceQueue
    from .simaxis import SimAxis

AVAILABLE = _k is not None
# empty buffers for what a call does not want (never written: the kernel sees length 0)
_NONE = np.zeros(0)
_NO_PIECES = np.zeros((0, 6))
_NO_TRACE = np.zeros(0, dtype=np.int64)
_BIT = {sig: i for i, sig in enumerate(AXIS_INPUTS)}

# field indices, kept in step with _kernel.c (checked against its constants below)
_ND, _NI, _MAXSW, _NSD, _NSI, _NREC = 15, 29, 8, 4, 7, 12
(D_P0, D_V0, D_A0, D_J, D_TC, D_TE, D_HALF, D_VMAX, D_AMAX, D_BACKLASH, D_Z, D_Y,
 D_UPP, D_STOP, D_SPACING) = range(_ND)
(I_COUNT, I_LOST, I_IDEAL, I_ENABLED, I_Q, I_LASTDIR, I_DCOUNT, I_DPERIOD, I_NSW,
 I_TURNF, I_TURNB) = range(11)
(I_FWD, I_BWD, I_PBEGIN, I_PEND, I_CURSOR, I_RECORD, I_LEVELS, I_ARMED, I_PITCH,
 I_NPITCH) = (11, 16, 21, 22, 23, 24, 25, 26, 27, 28)
if _k is not None:
    assert (_k.ND, _k.NI, _k.MAXSW, _k.NSD, _k.NSI, _k.NREC) == (
        _ND, _NI, _MAXSW, _NSD, _NSI, _NREC), "_kernel.c layout differs from kernel.py"


def usable(axes: list[SimAxis]) -> bool:
    """True when the kernel models every axis (steppers with at most 8 switches; a probe's
    hidden switches count: their edges come back named and go through the machine's edge
    filters)."""
    if _k is None:
        return False
    return all(type(ax.plant) is StepperPlant and len(ax.switches) <= _MAXSW for ax in axes)


def pacing() -> bool:
    """True inside a real-time pacing context bound to this thread (`_kernel.rt_paced`,
    control/core/realtime.py): every cycle waits for its wall-clock slot."""
    return _k is not None and _k.rt_poll() is not None


def interrupted() -> bool:
    """In a pacing context: the last kernel run returned at a cycle boundary because
    another thread waits for the controller's lock or the executor stops."""
    return bool(_k.rt_poll()) if _k is not None else False


def wait_slot(k: int) -> None:
    """In a pacing context: wait for cycle k's slot before the Python path runs it (a
    no-op when k is already the cycle in progress)."""
    if _k is not None:
        _k.rt_slot(int(k))


#: the signal bit of a hidden switch (a probe's interval bound) in slot s: _HIDDEN + s
_HIDDEN = len(AXIS_INPUTS)


def _wakes(name: str, switches: dict, wake: Collection[str] | None) -> bool:
    if wake is None or name in wake or name not in _BIT:  # hidden: the probe's filter
        return True
    return name == "sd" and "ltc" not in switches and "ltc" in wake


def level_bits(ax: SimAxis) -> int:
    """The axis's electrical input levels as a bit field, bit i = AXIS_INPUTS[i]."""
    word = 0
    for i, lv in enumerate(ax.levels()):
        if lv:
            word |= 1 << i
    return word


_LEVEL_DICTS: dict[int, dict[str, bool]] = {}


def level_dict(bits: int) -> dict[str, bool]:
    """The input levels of a `level_bits` word as AxisReadback.inputs (a new dict)."""
    d = _LEVEL_DICTS.get(bits)
    if d is None:
        d = _LEVEL_DICTS[bits] = {sig: bool(bits >> i & 1) for i, sig in enumerate(AXIS_INPUTS)}
    return d.copy()


def _switch_bits(name: str, switches: dict) -> int:
    """The input-level bits a switch flips when it toggles (SD is also LTC when no LTC
    switch is placed)."""
    bits = 1 << _BIT[name] if name in _BIT else 0
    if name == "sd" and "ltc" not in switches:
        bits |= 1 << _BIT["ltc"]
    return bits


class KernelState:
    """The kernel's arrays over all axes, kept between calls: built from the `SimAxis`
    objects once (`__init__`), run by `run_quiet` call after call, and written back into
    the objects only when Python needs them (`write_back`; SimMachine decides when). So a
    landing of a virtual-time jump costs no per-axis packing or copying."""

    __slots__ = ("ad", "ai", "sd", "si", "pitch", "names", "recording", "_wake", "_wake_key",
                 "_readback", "_edges", "_arena", "_fill", "_vers", "_cur")

    def __init__(self, axes: list[SimAxis]) -> None:
        n = len(axes)
        ad = np.zeros((n, _ND))
        ai = np.zeros((n, _NI), dtype=np.int64)
        sd = np.zeros((n, _MAXSW, _NSD))
        si = np.zeros((n, _MAXSW, _NSI), dtype=np.int64)
        adl: list[tuple] = []
        ail: list[list] = []
        tables: list[float] = []  # the pitch tables: z, e, y of each axis that has one
        self.names: list[list[str]] = []
        for x, ax in enumerate(axes):
            g, plant, dec, tr = ax.gen, ax.plant, ax.decoder, ax.trans
            c = g.cubic
            pt = tr.pitch
            at = len(tables)
            if pt.e:
                tables += map(float, [*pt.z, *pt.e, *pt.y])
            adl.append((c.p0, c.v0, c.a0, c.j, g.tc, g.te, g.half, plant.vmax, plant.amax,
                        tr.backlash, tr.z, ax.y, dec.upp,
                        math.nan if ax.stop_time is None else ax.stop_time,
                        float(pt.spacing)))
            fwd = [*dec.fwd_pre, 0, 0, 0, 0][:5]
            bwd = [*dec.bwd_pre, 0, 0, 0, 0][:5]
            sws = ax.switches
            nm = list(sws)
            self.names.append(nm)
            base = level_bits(ax)
            for s, name in enumerate(nm):
                sw = sws[name]
                if type(sw) is IndexSwitch:
                    sd[x, s] = (1.0, sw.period, sw.width, 0.0)
                else:
                    sd[x, s] = (0.0, sw.lo, sw.hi, sw.hyst)
                bits = _switch_bits(name, sws)
                if sw.active:
                    base ^= bits
                arm = ax.armed.get(name) if name != "ez" else None
                rank = list(ax.armed).index(name) + 1 if arm is not None else 0
                si[x, s] = (sw.active, 0, bits, _BIT.get(name, _HIDDEN + s), rank,
                            arm[0] if arm else 0, arm[1] if arm else 0)
            ail.append([g.count, plant.lost, plant.ideal, plant.enabled, dec.q, dec.last_dir,
                        dec.count, dec.period, len(sws), dec.turn[1], dec.turn[-1],
                        *fwd, *bwd, 0, 0, 0, g.record is not None, base,
                        any(name in sws and name != "ez" for name in ax.armed),
                        at, len(pt.e)])
        if n:
            ad[:] = adl
            ai[:] = ail
        self.ad, self.ai, self.sd, self.si = ad, ai, sd, si
        self.pitch = np.array(tables, dtype=float)
        self.recording = any(ax.gen.record is not None for ax in axes)  # pulse records
        self._wake_key: object = ()  # no wake set computed yet
        self._wake = np.zeros((n, _MAXSW), dtype=np.int64)
        self._readback: list[list[int]] | None = None
        self._edges = _edge_room(64, n)
        # the queued pieces of every axis, kept between runs (`_sync_pieces`): rows
        # [I_PBEGIN, I_PEND) of the arena are axis x's pieces as its queue held them at
        # version _vers[x], the kernel's cursor (I_CURSOR) at _cur[x] its queue's head
        self._arena = _NO_PIECES
        self._fill = 0
        self._vers = [-1] * n
        self._cur = [0] * n

    def grow_edges(self) -> None:
        """Room for twice as many edges in one cycle (the kernel asked for more)."""
        self._edges = _edge_room(2 * len(self._edges[0]), len(self.ad))

    def set_wake(self, axes: list[SimAxis], wake: Collection[str] | None) -> None:
        """Mark the switches whose edges end a kernel run (computed once per wake set)."""
        key = None if wake is None else frozenset(wake)
        if key != self._wake_key or (key is None) != (self._wake_key is None):
            for x, nm in enumerate(self.names):
                sws = axes[x].switches
                for s, name in enumerate(nm):
                    self._wake[x, s] = _wakes(name, sws, key)
            self._wake_key = key
            self.si[:, :, 1] = self._wake  # (only set here: kept between runs)

    def set_command(self, x: int, p0: float, v0: float, a0: float, j: float, tc: float,
                    te: float) -> None:
        """Axis x's generator follows the cubic (p0, v0, a0, j) over [tc, te] from now
        (SimAxis.set_command without a pulse record)."""
        self.ad[x, D_P0:D_TE + 1] = (p0, v0, a0, j, tc, te)

    def readback(self, x: int) -> tuple[int, int, int]:
        """(pulse count, decoded count, input level bits) of axis x now."""
        rb = self._readback
        if rb is None:
            rb = self._readback = self.readback_rows().tolist()
        return tuple(rb[x])  # type: ignore[return-value]

    def readback_row(self) -> np.ndarray:
        """int64 [1, n, 3]: `readback_rows` as one trace row."""
        out = np.empty((1, len(self.ai), 3), dtype=np.int64)
        _k.readback(self.ai, self.si, out)
        return out

    def readback_rows(self) -> np.ndarray:
        """int64 [n, 3]: (pulse count, decoded count, input level bits) of every axis now."""
        out = np.empty((len(self.ai), 3), dtype=np.int64)
        _k.readback(self.ai, self.si, out)
        return out

    def stop_time(self, x: int) -> float | None:
        """When an armed stop cut axis x's pulses in the last stretch run, else None."""
        t = float(self.ad[x, D_STOP])
        return None if math.isnan(t) else t

    def stopped(self) -> bool:
        """An armed stop cut some axis's pulses in the last stretch run."""
        return not bool(np.isnan(self.ad[:, D_STOP]).all())

    def at_rest(self, t: float) -> bool:
        """Every generator holds its command's end at time t (te <= t)."""
        return bool((self.ad[:, D_TE] <= t).all())

    def write_back(self, axes: list[SimAxis]) -> None:
        """Put the arrays' state into the axis objects (the kernel's arrays stay valid)."""
        adl, ail, sil = self.ad.tolist(), self.ai.tolist(), self.si.tolist()
        for x, ax in enumerate(axes):
            d, i = adl[x], ail[x]
            g, plant, dec, tr = ax.gen, ax.plant, ax.decoder, ax.trans
            g.cubic = Cubic(d[D_P0], d[D_V0], d[D_A0], d[D_J])
            g.tc, g.te = d[D_TC], d[D_TE]
            g.count = i[I_COUNT]
            plant.lost = i[I_LOST]
            tr.z = d[D_Z]
            ax.y = d[D_Y]
            dec.q, dec.last_dir, dec.count = i[I_Q], i[I_LASTDIR], i[I_DCOUNT]
            for s, name in enumerate(self.names[x]):
                ax.switches[name].active = bool(sil[x][s][0])
            ax.stop_time = None if math.isnan(d[D_STOP]) else d[D_STOP]
            ax.record = []
            ax.run_start = (tr.z, (dec.q, dec.last_dir, dec.count))


def _edge_room(cap: int, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (np.zeros(cap), np.zeros((cap, 4), dtype=np.int64),
            np.zeros((cap, n), dtype=np.int64))


def run_quiet(ks: KernelState, axes: list[SimAxis], queues: list[PieceQueue], origin: float,
              period: float, start: int, stop: int, now: float, limit: float,
              wake: Collection[str] | None, trace: bool = False, report: bool = False,
              paced: bool = True
              ) -> tuple[int, float, np.ndarray | None, list[InputEdge]]:
    """Run cycles start+1 .. at most stop in the kernel on the arrays of `ks`; returns
    (cycle reached, time, trace, edges): with `trace`, an int64 array [cycles run, axis, 3]
    of the pulse count, decoded count and input levels (`level_bits`) at the end of each
    cycle; `edges`, the input edges of the last cycle run when it crossed a switch on a
    `wake` signal (then it is the last cycle run), every axis's decoded count at each.
    `report`: every cycle reports its edges (the first cycle with any ends the run).

    Stops before the first cycle ending at or after `limit` or one the kernel cannot run
    exactly (a count beyond its integer range: the caller runs it). The pieces started
    leave their queues; the axis state stays in `ks` (with pulse recording on, it and the
    record are written back into the axes at once)."""
    parts: list[np.ndarray] = []
    while True:
        k, now, tr, edges, full = _run(ks, axes, queues, origin, period, start, stop, now,
                                       limit, wake, trace, report, paced)
        if tr is not None:
            parts.append(tr)
        if not full:
            break
        ks.grow_edges()
        start = k
    if trace and len(parts) > 1:
        return k, now, np.concatenate(parts), edges
    return k, now, parts[0] if trace else None, edges


def _run(ks: KernelState, axes: list[SimAxis], queues: list[PieceQueue], origin: float,
         period: float, start: int, stop: int, now: float, limit: float,
         wake: Collection[str] | None, trace: bool, report: bool, paced: bool
         ) -> tuple[int, float, np.ndarray | None, list[InputEdge], bool]:
    n = len(axes)
    if not report:  # in report mode every crossing is an edge anyway
        ks.set_wake(axes, wake)
    ai = ks.ai
    recording = ks.recording
    if recording:
        used, begin, pieces, popt, rows = _gather_pieces(ks, queues, start, stop)
    else:  # the arena kept between runs: only the queues changed since are copied in
        pieces, popt, rows = _sync_pieces(ks, queues), _NONE, _NONE
    tr = np.zeros((stop - start, n, 3), dtype=np.int64) if trace else _NO_TRACE
    et, ei, enc = ks._edges
    k, t, nrows, nedges, full = _k.run(ks.ad, ai, ks.sd, ks.si, pieces, popt, rows, tr, et,
                                       ei, enc, ks.pitch, float(origin), float(period),
                                       int(start), int(stop), float(now), float(limit),
                                       report, paced)
    if k == start:
        return k, now, tr[:0] if trace else None, [], bool(full)
    ks._readback = None
    if not recording:
        cur, vers = ks._cur, ks._vers
        after = ai[:, I_CURSOR].tolist()
        if after != cur:
            for x, c in enumerate(after):
                if c != cur[x]:
                    q = queues[x]
                    q.consume(c - cur[x])
                    vers[x] = q.version
            ks._cur = after
    elif used:
        cursor = ai[used, I_CURSOR].tolist()
        for x, b, c in zip(used, begin, cursor, strict=True):
            if c > b:
                queues[x].consume(c - b)
        _record_commands(axes, used, begin, cursor, pieces, popt)
    if recording:
        ks.write_back(axes)
        _record_stretches(axes, rows[:nrows])
    edges: list[InputEdge] = []
    if nedges:
        names = AXIS_INPUTS
        for tm, (axis, bit, level, _), counts in zip(et[:nedges].tolist(),
                                                     ei[:nedges].tolist(),
                                                     enc[:nedges].tolist(), strict=True):
            name = names[bit] if bit < _HIDDEN else ks.names[axis][bit - _HIDDEN]
            edges.append(InputEdge(tm, axis, name, level == 1, tuple(counts)))
    return k, t, tr[:k - start] if trace else None, edges, bool(full)


def _gather_pieces(ks: KernelState, queues: list[PieceQueue], start: int, stop: int
                   ) -> tuple[list[int], list[int], np.ndarray, np.ndarray, np.ndarray]:
    """With pulse recording: every queue's pieces in one array made for this run (used
    axes, their first rows, the pieces, their start times and the record rows to fill)."""
    ai = ks.ai
    ai[:, I_PBEGIN:I_CURSOR + 1] = 0
    blocks: list[np.ndarray] = []
    used: list[int] = []
    begin: list[int] = []
    total = 0
    for x, q in enumerate(queues):
        if len(q):
            block = q.remaining()
            used.append(x)
            begin.append(total)
            total += len(block)
            blocks.append(block)
    if used:  # each axis's rows: [begin, end) of the pieces array, cursor at begin
        ai[used, I_PBEGIN] = begin
        ai[used, I_CURSOR] = begin
        ai[used, I_PEND] = [*begin[1:], total]
    if not total:
        pieces = _NO_PIECES
    elif len(blocks) == 1 and blocks[0].flags.writeable:
        pieces = blocks[0]  # the queue's own block (the kernel only reads it)
    else:
        pieces = np.concatenate(blocks)
    popt = np.zeros(len(pieces))
    cap = (stop - start) * len(queues) * 8 + 16
    return used, begin, pieces, popt, np.zeros((cap, _NREC))


def _sync_pieces(ks: KernelState, queues: list[PieceQueue]) -> np.ndarray:
    """The arena of every axis's queued pieces (`KernelState._arena`), brought up to date:
    the pieces of a queue that changed since the kernel last saw it (new pieces, cleared,
    or started in Python) are copied in after the rows in use and the axis's [I_PBEGIN,
    I_PEND) and cursor point at them; an axis whose queue did not change keeps its rows
    and the cursor where the last run left it. A full arena is made again, larger."""
    vers = ks._vers
    changed = [x for x, q in enumerate(queues) if q.version != vers[x]]
    if not changed:
        return ks._arena
    blocks = [queues[x].remaining() for x in changed]
    need = sum(len(b) for b in blocks)
    if ks._fill + need > len(ks._arena):  # compact: every axis's rows again, from row 0
        changed = list(range(len(queues)))
        blocks = [q.remaining() for q in queues]
        need = sum(len(b) for b in blocks)
        ks._arena = np.empty((max(2 * need, 4096), 6))
        ks._fill = 0
    arena, pos, cur, ai = ks._arena, ks._fill, ks._cur, ks.ai
    for x, b in zip(changed, blocks, strict=True):
        m = len(b)
        if m:
            arena[pos:pos + m] = b
        ai[x, I_PBEGIN:I_CURSOR + 1] = (pos, pos + m, pos)  # begin, end, cursor
        cur[x] = pos
        pos += m
        vers[x] = queues[x].version
    ks._fill = pos
    return arena


def _record_commands(axes: list[SimAxis], used: list[int], begin: list[int],
                     cursor: list[int], pieces: np.ndarray, popt: np.ndarray) -> None:
    """The pieces the kernel started, into the pulse records (as `set_command` does)."""
    pcl, ptl = pieces.tolist(), popt.tolist()
    for x, b, c in zip(used, begin, cursor, strict=True):
        rec = axes[x].gen.record
        if rec is not None:
            for m in range(b, c):
                t0, dt, p0, v0, a0, j = pcl[m]
                rec.command(ptl[m], Cubic(p0, v0, a0, j), t0, t0 + dt)


def _record_stretches(axes: list[SimAxis], rows: np.ndarray) -> None:
    """The kernel's pulse-record rows, into the axes' pulse records."""
    for r in rows.tolist():
        _, kind, t0, t1, tc, p0, v0, a0, j, dr, c0, c1 = r
        g = axes[int(r[0])].gen
        if g.record is not None:
            cub = Cubic(p0, v0, a0, j) if kind else None
            g.record.add(Stretch(t0, t1, cub, tc, int(dr), int(c0), int(c1)), g.half)


def joined_trace(rows: list[np.ndarray | tuple[np.ndarray, int]], n: int) -> np.ndarray:
    """The trace parts of a run ([cycles, n, 3] arrays, or (row [1, n, 3], cycles) for a
    readback held over cycles) as one array; a readback that held through the whole run
    (an idle stretch) comes back as its row over the cycles with strides[0] == 0 (a
    read-only view), so its rows cost nothing to make or to record."""
    if not rows:
        return np.zeros((0, n, 3), dtype=np.int64)
    if len(rows) == 1 and type(rows[0]) is not tuple:
        return rows[0]
    if len(rows) == 2:  # the usual idle chunk: one cycle run, then the held stretch
        a, b = rows
        if type(b) is tuple and type(a) is not tuple and len(a) == 1 \
                and a.tobytes() == b[0].tobytes():
            return _held_rows(a, 1 + b[1])
    key = None
    total = 0
    for r in rows:
        if type(r) is tuple:
            row, c = r
        elif len(r) == 1:
            row, c = r, 1
        else:
            break
        b = row.tobytes()
        if key is None:
            key = b
        elif b != key:
            break
        total += c
    else:
        first = rows[0]
        first = first[0] if type(first) is tuple else first
        return first if total == 1 else _held_rows(first, total)
    return np.concatenate([np.broadcast_to(r[0], (r[1], n, 3)) if type(r) is tuple else r
                           for r in rows])


def _held_rows(row: np.ndarray, m: int) -> np.ndarray:
    """The row [1, n, 3] seen m times: a read-only view with strides[0] == 0, cut from one
    long view kept per distinct row (an idle machine shows the same row chunk after
    chunk, and a view costs microseconds to build; the kept copy is never written)."""
    key = row.tobytes()
    view = _HELD.get(key)
    if view is None or len(view) < m:
        if len(_HELD) >= 64:
            _HELD.clear()
        base = np.array(row, dtype=np.int64)
        view = np.ndarray((max(m, 1 << 20), *base.shape[1:]), dtype=np.int64, buffer=base,
                          strides=(0, *base.strides[1:]))
        view.flags.writeable = False
        _HELD[key] = view
    return view[:m]


_HELD: dict[bytes, np.ndarray] = {}
