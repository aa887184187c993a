"""Per-cycle trace recording into preallocated numpy ring buffers.

The controller calls `Recorder.record` once per cycle with one value per axis for each
channel; the recorder keeps the newest `capacity` cycles (architecture.md "Memory is
bounded"). `arrays()` returns them in time order for plots (plot.plot_trace) and tests;
`save()` writes .npz or .csv. With `spill_path` set, every row that would be overwritten is
first appended to a raw file, so a 10-hour recording runs in flat memory and nothing is lost
(`load_spill` reads it back).

A stretch of rows in which every channel holds its value (an idle virtual-time jump,
`hold`) is kept as one run (the values once, the times by their grid formula) and written
into the ring only when something reads the rows or a later row would overwrite them, so
recording an idle hour costs next to nothing until the trace is read; the rows are the
same either way.

Channels, per axis:
  cmd_pos  command position (pulses, float64: counts are exact up to 2**53)
  fb_pos   feedback (encoder) position
  cmd_vel  command velocity (pulses/s)
  state    axis state code (int32; the controller's numbering)
  io       I/O word (int64 bit field of the axis's input/output levels)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import MotionError, check_int

try:  # the compiled row writer of a cycle-by-cycle step (put_row); absent: record
    from ._kernel import RowSink as _RowSink
except ImportError:  # pragma: no cover - depends on the build
    _RowSink = None

FLOAT_CHANNELS = ("cmd_pos", "fb_pos", "cmd_vel")
INT_CHANNELS = ("state", "io")
CHANNELS = FLOAT_CHANNELS + INT_CHANNELS
_INT_DTYPES = {"state": np.int32, "io": np.int64}
_NO_STATE = np.zeros(0, dtype=np.int32)
_NO_IO = np.zeros(0, dtype=np.int64)
_MAX_HELD = 64  # held runs kept unwritten at most (then they are written into the ring)


class Recorder:
    """Ring buffer of per-cycle traces: time plus per-axis channels."""

    def __init__(self, n_axes: int, capacity: int, channels: Iterable[str] = CHANNELS, *,
                 spill_path: str | Path | None = None) -> None:
        check_int("n_axes", n_axes, 1)
        check_int("capacity", capacity, 1)
        if isinstance(channels, str):
            raise MotionError("channels must be a sequence of channel names, not a string")
        chans = tuple(channels)
        for c in chans:
            if c not in CHANNELS:
                raise MotionError(f"channels must be among {CHANNELS}, got {c!r}")
        if not chans or len(set(chans)) != len(chans):
            raise MotionError(f"channels must be non-empty and without repeats, got {chans!r}")
        self.n_axes = n_axes
        self.capacity = capacity
        # Keep the canonical order whatever order the caller gave.
        self.channels = tuple(c for c in CHANNELS if c in chans)
        self._fchans = tuple(c for c in FLOAT_CHANNELS if c in chans)
        self._ichans = tuple(c for c in INT_CHANNELS if c in chans)
        rows = capacity + 1  # one scratch row: a failed write never touches a live row
        self._t = np.zeros(rows)
        self._f = np.zeros((rows, len(self._fchans), n_axes))
        self._i = {c: np.zeros((rows, n_axes), dtype=_INT_DTYPES[c]) for c in self._ichans}
        # (np.zeros maps the pages lazily: a row's first write into a page costs a page
        # fault, about a microsecond per 4 KiB, against touching the whole ring here, which
        # costs its size in time and pushes the caller's working set out of the caches)
        self._fslot = {c: k for k, c in enumerate(self._fchans)}
        self._slots: np.ndarray | None = None  # record_into's float slots
        self._bound: tuple[Any, Any] | None = None  # row_sink's (table, RowSink)
        #: the compiled row writer armed at the ring's head (`row_sink`), or None; the rows
        #: it put are taken back (`_sync`) before anything else reads or writes the ring
        self.sink: Any = None
        self._head = 0   # next row to write
        self._count = 0  # live rows (<= capacity)
        self._total = 0   # rows ever recorded since the last clear (`total`)
        self._last_t = -math.inf
        # held runs not yet in the ring, oldest first: [abs start, m, origin, period, n0,
        # float values (F, n), {int channel: values (n,)}]; abs row j lives at ring row
        # j % (capacity + 1) (head == total mod rows); _floor: the oldest run's first kept
        # abs row (a write reaching its ring row, abs floor + capacity + 1, settles first)
        self._held: list[list[Any]] = []
        self._floor = math.inf
        self._spill: Path | None = None
        self.spilled = 0
        if spill_path is not None:
            self._spill = Path(spill_path)
            self._spill.parent.mkdir(parents=True, exist_ok=True)
            self._spill.write_bytes(b"")

    # ------------------------------------------------------------------ hot path
    def record(self, t: float, cmd_pos: ArrayLike | None = None,
               fb_pos: ArrayLike | None = None, cmd_vel: ArrayLike | None = None,
               state: ArrayLike | None = None, io: ArrayLike | None = None) -> None:
        """Store one cycle. Each channel takes one value per axis; disabled ones are ignored.

        `t` must be finite and not earlier than the previous record. On a bad argument a
        MotionError is raised and the recording is unchanged.
        """
        self._sync()
        try:
            t = float(t)
        except (TypeError, ValueError):
            raise MotionError(f"t must be a real number, got {t!r}") from None
        if not (math.isfinite(t) and t >= self._last_t):
            raise MotionError(
                f"t must be finite and >= the previous time {self._last_t!r}, got {t!r}"
            )
        if self._total + 1 > self._floor + self.capacity + 1:
            self._settle()
        i = self._head
        vals = {"cmd_pos": cmd_pos, "fb_pos": fb_pos, "cmd_vel": cmd_vel, "state": state,
                "io": io}
        n = self.n_axes
        try:
            row = self._f[i]
            for k, c in enumerate(self._fchans):
                v = vals[c]
                if len(v) != n:  # type: ignore[arg-type]
                    raise ValueError(f"{c} has {len(v)} values")  # type: ignore[arg-type]
                row[k] = v
            for c in self._ichans:
                v = vals[c]
                if len(v) != n:  # type: ignore[arg-type]
                    raise ValueError(f"{c} has {len(v)} values")  # type: ignore[arg-type]
                self._i[c][i] = v
        except (TypeError, ValueError, OverflowError) as exc:
            raise MotionError(
                f"each recorded channel must hold {self.n_axes} numbers (one per axis): {exc}"
            ) from None
        if self._fchans and not np.isfinite(row).all():
            raise MotionError(f"recorded positions/velocities must be finite at t={t!r}")
        self._t[i] = t
        self._last_t = t
        if self._count == self.capacity:
            if self._spill is not None:
                self._spill_oldest()
        else:
            self._count += 1
        self._head = i + 1 if i + 1 <= self.capacity else 0
        self._total += 1

    def record_block(self, t: ArrayLike, **channels: ArrayLike) -> None:
        """Store m cycles at once: `t` (m,) and each enabled channel (m, n_axes), as m
        `record` calls would (the same rows, the same checks; MotionError and nothing
        stored on a bad argument). Virtual-time jumps record the cycles they cross so."""
        self._sync()
        try:
            tt = np.asarray(t, dtype=float)
            vals = {c: np.asarray(channels[c]) for c in self.channels}
        except (KeyError, TypeError, ValueError) as exc:
            raise MotionError(f"record_block needs t and every recorded channel "
                              f"{self.channels}: {exc}") from None
        m = len(tt)
        if tt.ndim != 1 or any(v.shape != (m, self.n_axes) for v in vals.values()):
            raise MotionError(f"record_block: t must be (m,) and each channel (m, "
                              f"{self.n_axes}), got {tt.shape} and "
                              f"{[v.shape for v in vals.values()]}")
        if not m:
            return
        if not (np.isfinite(tt).all() and tt[0] >= self._last_t
                and (np.diff(tt) >= 0.0).all()):
            raise MotionError(f"t must be finite and non-decreasing from the previous time "
                              f"{self._last_t!r}")
        if any(not np.isfinite(vals[c]).all() for c in self._fchans):
            raise MotionError("recorded positions/velocities must be finite")
        if self._spill is not None:  # spilling works row by row
            for r in range(m):
                self.record(tt[r], **{c: v[r] for c, v in vals.items()})
            return
        if self._total + m > self._floor + self.capacity + 1:
            self._settle()
        rows = self.capacity + 1
        keep = min(m, self.capacity)  # older rows of the block would be overwritten anyway
        idx = (self._head + (m - keep) + np.arange(keep)) % rows
        self._t[idx] = tt[m - keep:]
        for c in self._fchans:
            self._f[idx, self._fslot[c]] = vals[c][m - keep:]
        for c in self._ichans:
            self._i[c][idx] = vals[c][m - keep:]
        self._last_t = float(tt[-1])
        self._count = min(self.capacity, self._count + m)
        self._head = (self._head + m) % rows
        self._total += m

    def record_into(self, m: int, t_first: float, t_last: float,
                    fill: Callable[..., None]) -> bool:
        """Store m rows that `fill(t, f, state, io, head, slots)` writes straight into the
        ring (the compiled recorder of a jump's crossed cycles, control/core/jump.py):
        `t`, `f` (rows, float channels, n_axes), int32 `state` and int64 `io` (rows,
        n_axes; empty arrays when the channel is off) are the ring arrays, `head` the row
        the first of the m goes to (mod rows: only the last min(m, capacity) are kept),
        `slots` the float slot of cmd_pos, fb_pos, cmd_vel (-1: off). Returns False and
        stores nothing when the rows must go through `record_block` (a spilling recorder).
        `fill` raises MotionError before writing anything if a value is bad."""
        self._sync()
        if self._spill is not None:
            return False
        if not (math.isfinite(t_first) and t_first >= self._last_t and t_last >= t_first):
            raise MotionError(f"t must be finite and non-decreasing from the previous time "
                              f"{self._last_t!r}")
        if not m:
            return True
        if self._total + m > self._floor + self.capacity + 1:
            self._settle()
        slots = self._slots
        if slots is None:
            slots = self._slots = np.array([self._fslot.get(c, -1) for c in FLOAT_CHANNELS],
                                           dtype=np.int64)
        fill(self._t, self._f, self._i.get("state", _NO_STATE), self._i.get("io", _NO_IO),
             self._head, slots)
        self._last_t = float(t_last)
        self._count = min(self.capacity, self._count + m)
        self._head = (self._head + m) % (self.capacity + 1)
        self._total += m
        return True

    def row_sink(self, table: NDArray[np.int64], states: tuple[Any, ...],
                 codes: tuple[int, ...], rows: int = 1) -> Any:
        """The compiled row writer (`_kernel.RowSink`) bound to the ring and armed at its
        head, for the rows of a cycle-by-cycle step (control/core/jump.record_now): each
        `put(t, values, readback, nc, estop)` writes one row, the one `record` stores for
        it (the io word `table[levels ^ nc]`, the state code `codes[k]` of `states[k]`);
        `put_block(...)` the rows of a jump's crossed cycles, those `record_into` of
        `_kernel.record_rows` stores (`rows`: the held runs the next `rows` rows would
        overwrite are settled first).
        Also `self.sink` until anything else reads or writes the recorder, which first
        takes the rows put back (`_sync`). None when the rows must go through `record` (a
        spilling recorder, no compiled kernel)."""
        self._sync()
        if self._spill is not None or _RowSink is None:
            return None
        bound = self._bound
        if bound is None or bound[0] is not table:
            if not (isinstance(table, np.ndarray) and table.dtype == np.int64
                    and table.ndim == 1):
                raise MotionError(f"record: table must be a 1-D int64 array, got {table!r}")
            slots = self._slots
            if slots is None:
                slots = self._slots = np.array([self._fslot.get(c, -1)
                                                for c in FLOAT_CHANNELS], dtype=np.int64)
            try:
                bound = self._bound = (table, _RowSink(
                    self._t, self._f, self._i.get("state", _NO_STATE),
                    self._i.get("io", _NO_IO), slots, table, self.n_axes, states, codes))
            except (TypeError, ValueError, BufferError) as exc:
                raise MotionError(f"record: {exc}") from None
        if self._total + rows > self._floor + self.capacity + 1:  # they would overwrite
            self._settle()  # a held row
        # rows it may put before one would overwrite a held run's row (then it settles)
        room = int(self._floor + self.capacity + 1 - self._total) if self._held else 1 << 62
        sink = bound[1]
        sink.arm(self._head, self._last_t, room)
        self.sink = sink
        return sink

    def _sync(self) -> None:
        """Take back the rows the armed sink put (head, count, total, newest time)."""
        s = self.sink
        if s is not None:
            self.sink = None
            k, last = s.take()
            if k:
                self._head = (self._head + k) % (self.capacity + 1)
                self._count = min(self.capacity, self._count + k)
                self._total += k
                self._last_t = last

    def hold(self, m: int, origin: float, period: float, n0: int) -> bool:
        """Store m rows that repeat the newest row's channel values at the times
        origin + (n0 + 1 + r) * period, r = 0 .. m-1 (an idle jump's crossed cycles, whose
        first row was recorded). Kept as one run until read (`arrays`) or about to be
        overwritten; the rows are those m `record` calls would store. Returns False and
        stores nothing for a spilling recorder (the caller records the rows). MotionError
        (nothing stored) without a newest row or on times out of order."""
        held = self._held
        if held and self.sink is None and type(m) is int and m > 0:  # the usual case: an
            last = held[-1]  # idle jump's next chunk goes on from the newest held run
            if last[0] + last[1] == self._total and last[2] == origin and last[3] == period \
                    and last[4] + last[1] == n0 and len(held) == 1:
                t1, t2 = origin + (n0 + 1) * period, origin + (n0 + m) * period
                if math.isfinite(t1) and math.isfinite(t2) and t1 >= self._last_t \
                        and t2 >= t1:
                    last[1] += m
                    self._floor = last[0] + last[1] - min(last[1], self.capacity)
                    self._last_t = float(t2)
                    self._count = min(self.capacity, self._count + m)
                    self._head = (self._head + m) % (self.capacity + 1)
                    self._total += m
                    return True
        self._sync()
        if type(m) is not int or m < 0:
            check_int("m", m, 0)
        if not self._count:
            raise MotionError("hold needs a recorded row to repeat")
        if self._spill is not None:
            return False
        if not m:
            return True
        t1 = origin + (n0 + 1) * period
        t2 = origin + (n0 + m) * period
        if not (math.isfinite(t1) and math.isfinite(t2) and t1 >= self._last_t
                and t2 >= t1):
            raise MotionError(f"t must be finite and non-decreasing from the previous time "
                              f"{self._last_t!r}")
        total = self._total
        held = self._held
        if len(held) >= _MAX_HELD:  # (overlaps need nothing: runs settle oldest first)
            self._settle()
            held = self._held
        last = held[-1] if held else None
        if last is not None and last[0] + last[1] == total:  # the newest row is this run's
            if last[2] == origin and last[3] == period and last[4] + last[1] == n0:
                last[1] += m
            else:
                held.append([total, m, origin, period, n0, last[5], last[6]])
        else:
            r = (self._head - 1) % (self.capacity + 1)
            held.append([total, m, origin, period, n0, self._f[r].copy(),
                         {c: a[r].copy() for c, a in self._i.items()}])
        first = held[0]
        self._floor = first[0] + first[1] - min(first[1], self.capacity)
        self._last_t = float(t2)
        self._count = min(self.capacity, self._count + m)
        self._head = (self._head + m) % (self.capacity + 1)
        self._total = total + m
        return True

    def _settle(self) -> None:
        """Write the held runs into the ring (oldest first; only the rows still kept)."""
        rows = self.capacity + 1
        for start, m, origin, period, n0, fv, iv in self._held:
            keep = min(m, self.capacity)
            r0 = m - keep  # the first row of the run still kept
            at = (start + r0) % rows
            while keep:
                k = min(keep, rows - at)
                self._t[at:at + k] = origin + np.arange(n0 + 1 + r0, n0 + 1 + r0 + k,
                                                        dtype=np.int64) * period
                self._f[at:at + k] = fv
                for c, a in self._i.items():
                    a[at:at + k] = iv[c]
                keep -= k
                r0 += k
                at = 0
        self._held = []
        self._floor = math.inf

    # ------------------------------------------------------------------ reading
    def __len__(self) -> int:
        self._sync()
        return self._count

    @property
    def total(self) -> int:
        """Rows ever recorded since the last clear."""
        self._sync()
        return self._total

    @property
    def dropped(self) -> int:
        """Rows that left the window without being spilled to a file."""
        self._sync()
        return self._total - self._count - self.spilled

    def _order(self) -> NDArray[np.intp]:
        rows = self.capacity + 1
        start = (self._head - self._count) % rows
        return (start + np.arange(self._count)) % rows

    def arrays(self) -> dict[str, NDArray[Any]]:
        """Copies of the retained rows in time order: 't' (n,) and each channel (n, n_axes)."""
        self._sync()
        if self._held:
            self._settle()
        idx = self._order()
        out: dict[str, NDArray[Any]] = {"t": self._t[idx]}
        for c in self.channels:
            out[c] = self._f[idx, self._fslot[c]] if c in self._fslot else self._i[c][idx]
        return out

    def clear(self) -> None:
        """Forget every row (the spill file, if any, is restarted empty)."""
        self._sync()
        self._head = 0
        self._count = 0
        self._total = 0
        self.spilled = 0
        self._last_t = -math.inf
        self._held = []
        self._floor = math.inf
        if self._spill is not None:
            self._spill.write_bytes(b"")

    # ------------------------------------------------------------------ files
    def save(self, path: str | Path) -> Path:
        """Write the retained rows to `path` (.npz, or .csv with one column per axis)."""
        p = Path(path)
        suffix = p.suffix.lower()
        if suffix not in (".npz", ".csv"):
            raise MotionError(f"path must end with .npz or .csv, got {str(path)!r}")
        save_arrays(self.arrays(), p)
        return p

    def _row_dtype(self) -> np.dtype:
        fields: list[tuple[str, Any, tuple[int, ...]]] = [("t", np.float64, ())]
        fields += [(c, np.float64, (self.n_axes,)) for c in self._fchans]
        fields += [(c, _INT_DTYPES[c], (self.n_axes,)) for c in self._ichans]
        return np.dtype(fields)

    def _spill_oldest(self) -> None:
        """Append the oldest half of the window to the spill file and drop it from the ring.

        Called when the row just written would push the oldest one out; spilling half the
        window at once makes the file write rare (amortised O(1) per cycle).
        """
        assert self._spill is not None
        k = max(1, self.capacity // 2)
        rows = self.capacity + 1
        idx = (self._head - self._count + rows + np.arange(k)) % rows
        rec = np.zeros(k, dtype=self._row_dtype())
        rec["t"] = self._t[idx]
        for n, c in enumerate(self._fchans):
            rec[c] = self._f[idx, n]
        for c in self._ichans:
            rec[c] = self._i[c][idx]
        with self._spill.open("ab") as fh:
            fh.write(rec.tobytes())
        self.spilled += k
        # The row just written (at head) becomes live; k old rows left.
        self._count += 1 - k

    def load_spill(self) -> dict[str, NDArray[Any]]:
        """The spilled rows (oldest first), read from the spill file as arrays."""
        if self._spill is None:
            raise MotionError("load_spill needs a Recorder created with spill_path")
        data = np.fromfile(self._spill, dtype=self._row_dtype())
        return {name: np.ascontiguousarray(data[name]) for name in data.dtype.names or ()}

    def all_arrays(self) -> dict[str, NDArray[Any]]:
        """Spilled rows followed by the retained rows (everything since the last clear)."""
        ring = self.arrays()
        if self._spill is None:
            return ring
        old = self.load_spill()
        return {k: np.concatenate([old[k], ring[k]]) for k in ring}


# ---------------------------------------------------------------------------- file helpers
def _csv_columns(arrays: dict[str, NDArray[Any]]) -> tuple[list[str], list[NDArray[Any]]]:
    names, cols = ["t"], [np.asarray(arrays["t"], dtype=np.float64)]
    for c in CHANNELS:
        if c in arrays:
            a = np.asarray(arrays[c])
            for ax in range(a.shape[1]):
                names.append(f"{c}[{ax}]")
                cols.append(a[:, ax])
    return names, cols


def save_arrays(arrays: dict[str, NDArray[Any]], path: str | Path) -> Path:
    """Write recorder arrays to .npz (exact) or .csv (floats as %.17g, ints as integers)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".npz":
        np.savez_compressed(p, **arrays)
        return p
    if suffix != ".csv":
        raise MotionError(f"path must end with .npz or .csv, got {str(path)!r}")
    names, cols = _csv_columns(arrays)
    fmts = ["%d" if np.issubdtype(c.dtype, np.integer) else "%.17g" for c in cols]
    table = np.empty((cols[0].size, len(cols)), dtype=object)
    for k, c in enumerate(cols):
        table[:, k] = c
    np.savetxt(p, table, fmt=fmts, delimiter=",", header=",".join(names), comments="")
    return p


def load_trace(path: str | Path) -> dict[str, NDArray[Any]]:
    """Read a trace written by `Recorder.save` back into the `arrays()` layout."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".npz":
        with np.load(p) as z:
            return {k: z[k] for k in z.files}
    if suffix != ".csv":
        raise MotionError(f"path must end with .npz or .csv, got {str(path)!r}")
    with p.open() as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2)
    out: dict[str, NDArray[Any]] = {"t": data[:, 0].copy()}
    for c in CHANNELS:
        cols = [k for k, name in enumerate(header) if name.startswith(c + "[")]
        if cols:
            block = data[:, cols]
            out[c] = block.astype(_INT_DTYPES[c]) if c in _INT_DTYPES else block
    return out

