"""The compiled stepper pipeline (`openmotion._kernel.run`, C) behind `SimMachine.run_cycles`.

`run_quiet` hands the kernel a chunk of cycles as flat arrays over all axes: each axis's
command, pulse count, losses, load position, decoder state and switches, and its queued
pieces. The kernel runs the cycles in C with the GIL released and stops before the first
cycle that has an edge to report, a scenario action or timed output due, or anything else
it does not model; `SimMachine` runs that cycle through the Python path (simaxis.py), which
finds the edge's exact time and counts. The state comes back into the `SimAxis` objects,
so both paths always share one state.

The kernel takes a machine whose axes are all steppers (ideal or stalling) without an
armed edge stop or a pitch-error table; for any other machine `usable` is False and every
cycle runs in Python. It is built by the package's own build (setup.py); when the module is
missing (a source tree that was never built) `AVAILABLE` is False and the Python path runs.
Set `SimMachine.native = False` to force the Python path (the equivalence tests do).
"""

from __future__ import annotations

from collections.abc import Collection
from typing import TYPE_CHECKING

import numpy as np

from openmotion.hw.interface import AXIS_INPUTS

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
_ND, _NI, _MAXSW, _NSD, _NSI, _NREC = 13, 26, 8, 4, 3, 12
(D_P0, D_V0, D_A0, D_J, D_TC, D_TE, D_HALF, D_VMAX, D_AMAX, D_BACKLASH, D_Z, D_Y,
 D_UPP) = range(_ND)
(I_COUNT, I_LOST, I_IDEAL, I_ENABLED, I_Q, I_LASTDIR, I_DCOUNT, I_DPERIOD, I_NSW,
 I_TURNF, I_TURNB) = range(11)
I_FWD, I_BWD, I_PBEGIN, I_PEND, I_CURSOR, I_RECORD, I_LEVELS = 11, 16, 21, 22, 23, 24, 25
if _k is not None:
    assert (_k.ND, _k.NI, _k.MAXSW, _k.NSD, _k.NSI, _k.NREC) == (
        _ND, _NI, _MAXSW, _NSD, _NSI, _NREC), "_kernel.c layout differs from kernel.py"


def usable(axes: list[SimAxis]) -> bool:
    """True when the kernel models every axis (steppers, nothing armed, no pitch table, only
    the axis's own input switches: a probe's hidden switches feed a board input through
    the machine's edge filters, which only the Python path applies)."""
    if _k is None:
        return False
    for ax in axes:
        if (type(ax.plant) is not StepperPlant or ax.armed or ax.trans.pitch.e
                or len(ax.switches) > _MAXSW or not _BIT.keys() >= ax.switches.keys()):
            return False
    return True


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


def _wakes(name: str, switches: dict, wake: Collection[str] | None) -> bool:
    if wake is None or name in wake:
        return True
    return name == "sd" and "ltc" not in switches and "ltc" in wake


def level_bits(ax: SimAxis) -> int:
    """The axis's electrical input levels as a bit field, bit i = AXIS_INPUTS[i]."""
    word = 0
    for i, lv in enumerate(ax.levels()):
        if lv:
            word |= 1 << i
    return word


def _switch_bits(name: str, switches: dict) -> int:
    """The input-level bits a switch flips when it toggles (SD is also LTC when no LTC
    switch is placed)."""
    bits = 1 << _BIT[name] if name in _BIT else 0
    if name == "sd" and "ltc" not in switches:
        bits |= 1 << _BIT["ltc"]
    return bits


def run_quiet(axes: list[SimAxis], queues: list[PieceQueue], origin: float, period: float,
              start: int, stop: int, now: float, limit: float,
              wake: Collection[str] | None, trace: bool = False
              ) -> tuple[int, float, np.ndarray | None]:
    """Run cycles start+1 .. at most stop in the kernel; returns (cycle reached, time,
    trace): with `trace`, an int64 array [cycles run, axis, 3] of the pulse count, decoded
    count and input levels (`level_bits`) at the end of each cycle.

    Stops before the first cycle ending at or after `limit` or with an edge on a `wake`
    signal; the state of every axis (and the pieces started) is written back."""
    n = len(axes)
    adl: list[tuple] = []
    ail: list[list] = []
    sdl: list[list[tuple]] = []
    sil: list[list[tuple]] = []
    blocks: list[np.ndarray] = []
    total = 0
    names: list[list[str]] = []
    recording = False
    pad_d = [(0.0, 0.0, 0.0, 0.0)] * _MAXSW
    pad_i = [(0, 0, 0)] * _MAXSW
    for x, ax in enumerate(axes):
        g, plant, dec, tr = ax.gen, ax.plant, ax.decoder, ax.trans
        c = g.cubic
        adl.append((c.p0, c.v0, c.a0, c.j, g.tc, g.te, g.half, plant.vmax, plant.amax,
                    tr.backlash, tr.z, ax.y, dec.upp))
        block = queues[x].remaining()
        begin = total
        total += len(block)
        blocks.append(block)
        fwd = [*dec.fwd_pre, 0, 0, 0, 0][:5]
        bwd = [*dec.bwd_pre, 0, 0, 0, 0][:5]
        rec = g.record is not None
        recording = recording or rec
        ail.append([g.count, plant.lost, plant.ideal, plant.enabled, dec.q, dec.last_dir,
                    dec.count, dec.period, len(ax.switches), dec.turn[1], dec.turn[-1],
                    *fwd, *bwd, begin, total, begin, rec])
        sws = ax.switches
        nm = list(sws)
        names.append(nm)
        rd, ri = [], []
        base = level_bits(ax) if trace else 0
        for name in nm:
            sw = sws[name]
            if type(sw) is IndexSwitch:
                rd.append((1.0, sw.period, sw.width, 0.0))
            else:
                rd.append((0.0, sw.lo, sw.hi, sw.hyst))
            bits = _switch_bits(name, sws)
            if sw.active:
                base ^= bits
            ri.append((sw.active, _wakes(name, sws, wake), bits))
        ail[-1].append(base)
        sdl.append(rd + pad_d[len(rd):])
        sil.append(ri + pad_i[len(ri):])
    ad = np.array(adl, dtype=float)
    ai = np.array(ail, dtype=np.int64)
    sd = np.array(sdl, dtype=float)
    si = np.array(sil, dtype=np.int64)
    pieces = np.concatenate(blocks) if total else _NO_PIECES
    popt = np.zeros(len(pieces)) if recording else _NONE
    cap = (stop - start) * n * 8 + 16 if recording else 0
    rows = np.zeros((cap, _NREC)) if cap else _NONE
    tr = np.zeros((stop - start, n, 3), dtype=np.int64) if trace else _NO_TRACE
    k, t, used = _k.run(ad, ai, sd, si, pieces, popt, rows, tr, float(origin), float(period),
                        int(start), int(stop), float(now), float(limit))
    if k == start:
        return k, now, tr[:0] if trace else None
    _write_back(axes, queues, ad, ai, si, pieces, popt, rows[:used], names)
    return k, t, tr[:k - start] if trace else None


def _write_back(axes: list[SimAxis], queues: list[PieceQueue], ad: np.ndarray,
                ai: np.ndarray, si: np.ndarray, pieces: np.ndarray, popt: np.ndarray,
                rows: np.ndarray, names: list[list[str]]) -> None:
    adl, ail, sil = ad.tolist(), ai.tolist(), si.tolist()
    recording = any(ax.gen.record is not None for ax in axes)
    pcl = pieces.tolist() if recording else []
    ptl = popt.tolist() if recording else []
    per_axis: list[list[list[float]]] = [[] for _ in axes]
    for r in rows.tolist():
        per_axis[int(r[0])].append(r)
    for x, ax in enumerate(axes):
        d, i = adl[x], ail[x]
        g, plant, dec, tr = ax.gen, ax.plant, ax.decoder, ax.trans
        begin, cursor = i[I_PBEGIN], i[I_CURSOR]
        rec = g.record
        if cursor > begin:
            queues[x].consume(cursor - begin)
            if rec is not None:
                for m in range(begin, cursor):
                    t0, dt, p0, v0, a0, j = pcl[m]
                    rec.command(ptl[m], Cubic(p0, v0, a0, j), t0, t0 + dt)
            g.cubic = Cubic(d[D_P0], d[D_V0], d[D_A0], d[D_J])
            g.tc, g.te = d[D_TC], d[D_TE]
        g.count = i[I_COUNT]
        plant.lost = i[I_LOST]
        tr.z = d[D_Z]
        ax.y = d[D_Y]
        dec.q, dec.last_dir, dec.count = i[I_Q], i[I_LASTDIR], i[I_DCOUNT]
        for s, name in enumerate(names[x]):
            ax.switches[name].active = bool(sil[x][s][0])
        if rec is not None:
            half = g.half
            for r in per_axis[x]:
                _, kind, t0, t1, tc, p0, v0, a0, j, dr, c0, c1 = r
                cub = Cubic(p0, v0, a0, j) if kind else None
                rec.add(Stretch(t0, t1, cub, tc, int(dr), int(c0), int(c1)), half)
        ax.stop_time = None
        ax.record = []
        ax.run_start = (tr.z, (dec.q, dec.last_dir, dec.count))
