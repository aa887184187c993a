"""Compare outputs and the firing log.

`OutputLine` keeps the exact waveform of one compare-capable general output (`do<n>`) as a
list of timed edges (the accurate record) and drives the physical line:

- on hardware with timed outputs (hw.interface.TimedOutputHardware) `send` runs before the
  hardware advances over a cycle (t0, t1] and hands it every edge of the waveform in that
  cycle with `write_output_at`: the line switches at the exact instants and pulses shorter
  than a cycle keep their true width. Edges added afterwards for times already executed
  ("late": MPOS jobs, found after the cycle) are written by `flush` at the cycle end, as
  below; a stretched pulse holds until the next edge or for one cycle;
- otherwise `flush` writes `Hardware.write_output` once per cycle with the level the
  waveform has at the cycle end. A pulse that starts and ends inside one cycle would vanish
  at cycle granularity, so it is stretched: the line shows it for one cycle. The exact
  widths stay in `edges`.

`EventLog` records every firing: time, job, point index, compared value, output number,
the output state right after the firing, and every axis's command position at that time.
It exports CSV and npz, and `plot_firings` overlays the firings on the XY path.
"""

from __future__ import annotations

import bisect
import csv
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ...errors import MotionError
from . import compare_math as _cm

if TYPE_CHECKING:
    from ...hw.interface import Hardware

Array = NDArray[np.float64]


class OutputLine:
    """Exact waveform of output `do<number>`, starting at `initial` level."""

    def __init__(self, number: int, initial: bool = False) -> None:
        self.number = number
        self.signal = f"do{number}"
        self.initial = initial
        self._t: list[float] = []
        self._lv: list[bool] = []
        self._written = initial  # physical level at the end of what was written
        self.timed = False       # the hardware switches it at exact times (send)
        self._sent_until = -math.inf
        self._late: list[float] = []  # times of edges added at or before _sent_until
        self._sent: tuple[list[float], list[bool]] = ([], [])  # the last send's edges
        self._hold = False       # a late pulse is being shown stretched

    def attach(self, hw: Hardware) -> None:
        """Drive the physical line to the initial level."""
        from ...hw.interface import TimedOutputHardware

        hw.write_output(None, self.signal, bool(self.initial))
        self._written = self.initial
        self.timed = isinstance(hw, TimedOutputHardware)
        self._sent_until = float(hw.time)

    @property
    def edges(self) -> list[tuple[float, bool]]:
        """Every level change (time, new level), time-ordered."""
        return list(zip(self._t, self._lv, strict=True))

    def level_at(self, t: float) -> bool:
        k = bisect.bisect_right(self._t, t) - 1
        return self._lv[k] if k >= 0 else self.initial

    def set(self, t: float, level: bool) -> None:
        """Drive the level from time t on (until the next later edge, if one is scheduled)."""
        self.set_many((t,), (level,))

    def set_many(self, times: Sequence[float], levels: Sequence[bool]) -> None:
        """`set(times[i], levels[i])` for each i in order, in one compiled call: an edge is
        inserted after those at equal times, and an edge that no longer changes the level
        (the one it replaces or repeats) is dropped. A set at or before what was already
        handed to timed hardware is "late" (flush corrects the physical line)."""
        sent = self._sent_until if self.timed else -math.inf
        _cm._solvers().line_set(self._t, self._lv, bool(self.initial), times, levels, sent,
                                self._late)

    def snapshot(self, t: float) -> tuple[bool, list[float], list[bool]]:
        """The waveform from time t on (to undo a cycle's edits with `restore`)."""
        k = bisect.bisect_left(self._t, t)
        return self.initial, self._t[k:], self._lv[k:]

    def restore(self, t: float, snap: tuple[bool, list[float], list[bool]]) -> None:
        k = bisect.bisect_left(self._t, t)
        self.initial = snap[0]
        self._t[k:] = snap[1]
        self._lv[k:] = snap[2]
        self._late.append(t)  # what was sent from t on may be wrong: check at flush

    def cancel_after(self, t: float) -> None:
        """Forget scheduled edges later than t (a stopped timer)."""
        k = bisect.bisect_right(self._t, t)
        del self._t[k:]
        del self._lv[k:]

    def forget_before(self, t: float) -> None:
        """Drop edges before t (bounded memory); the level at t becomes the start level."""
        if not self._t or self._t[0] >= t:
            return
        k = bisect.bisect_left(self._t, t)
        if k:
            self.initial = self._lv[k - 1]
            del self._t[:k]
            del self._lv[:k]

    def pulse_widths(self, active: bool = True) -> Array:
        """Durations of the completed `active`-level intervals (for tests and reports)."""
        t = np.array(self._t)
        lv = np.array(self._lv, dtype=bool)
        starts = np.flatnonzero(lv == active)
        starts = starts[starts + 1 < t.size]
        return t[starts + 1] - t[starts]

    def send(self, hw: Hardware, t0: float, t1: float) -> None:
        """Timed hardware, before it advances over (t0, t1]: schedule every edge of the
        cycle at its exact time (hw at t0; see module docstring)."""
        a = bisect.bisect_right(self._t, t0)
        b = bisect.bisect_right(self._t, t1)
        lvl0 = self.level_at(t0)
        if lvl0 != self._written:  # a late edge, or the end of a stretched pulse
            if self._hold:
                t_r = self._t[a] if a < b else t1
                hw.write_output_at(t_r, None, self.signal, bool(lvl0))  # type: ignore[attr-defined]
            else:
                hw.write_output(None, self.signal, bool(lvl0))
        if b > a:
            bulk = getattr(hw, "write_outputs_at", None)
            if bulk is not None:  # one call for the cycle's edges
                bulk(self._t[a:b], None, self.signal, self._lv[a:b])
            else:
                for k in range(a, b):
                    hw.write_output_at(self._t[k], None, self.signal,  # type: ignore[attr-defined]
                                       bool(self._lv[k]))
        self._sent = (self._t[a:b], self._lv[a:b])
        self._written = self.level_at(t1)
        self._sent_until = t1
        self._late.clear()
        self._hold = False

    def flush(self, hw: Hardware, t0: float, t1: float) -> None:
        """Write the physical line for the cycle (t0, t1] (see module docstring)."""
        if self.timed:
            if not self._late:  # nothing was added for times already handed over
                return
            late = any(t0 <= t <= t1 for t in self._late)
            self._late.clear()
            if not late:
                return
            a = bisect.bisect_right(self._t, t0)
            b = bisect.bisect_right(self._t, t1)
            sent = set(zip(*self._sent, strict=True))
            changed = any(e not in sent for e in zip(self._t[a:b], self._lv[a:b], strict=True))
        else:
            changed = self._changed(t0, t1)
        lvl = self.level_at(t1)
        target = lvl
        if lvl == self._written and changed:
            target = not lvl  # a pulse shorter than the cycle: show it for one cycle
            self._hold = True
        if target != self._written:
            hw.write_output(None, self.signal, bool(target))
            self._written = target

    def _changed(self, t0: float, t1: float) -> bool:
        a = bisect.bisect_right(self._t, t0)
        b = bisect.bisect_right(self._t, t1)
        return b > a


def send_lines(lines: Sequence[OutputLine], hw: Hardware, t0: float, t1: float) -> None:
    """`line.send(hw, t0, t1)` for every line. When the hardware has `write_outputs_many`
    (the simulator) and no line has a late or stretched edge pending, the bookkeeping of
    all lines is one compiled call (`lines_send`) and their edges go out in one call
    (three flat lists: times, signals, levels)."""
    bulk = getattr(hw, "write_outputs_many", None)
    writes = None if bulk is None else _cm._solvers().lines_send(lines, t0, t1)
    if writes is None:
        for line in lines:
            line.send(hw, t0, t1)
    elif writes[0]:
        bulk(*writes)


class EventLog:
    """Every firing of every compare job (see module docstring). Kept as blocks of arrays
    as the engine adds them (a cycle's firings at once), joined when read."""

    FIELDS = ("time", "job", "index", "value", "output", "state")

    def __init__(self, n_axes: int) -> None:
        self.n_axes = n_axes
        self._n = 0
        self._f: list[Array] = []  # (k x 2): time, value
        self._k: list[NDArray[np.int64]] = []  # (k x 4): job, index, output, state
        self._pos: list[Array] = []  # (k x n_axes)

    def __len__(self) -> int:
        return self._n

    def add(self, rows: Sequence[tuple[float, int, int, float, int, int]], pos: Array) -> None:
        """Append firings (rows as FIELDS) with their positions (len(rows) x n_axes)."""
        if not rows:
            return
        f = np.array([(r[0], r[3]) for r in rows], dtype=np.float64)
        k = np.array([(r[1], r[2], r[4], r[5]) for r in rows], dtype=np.int64)
        self.add_arrays(f, k, pos)

    def add_arrays(self, f: Array, k: NDArray[np.int64], pos: Array) -> None:
        """Append firings as columns: f (m x 2: time, value), k (m x 4: job, index, output,
        state), pos (m x n_axes)."""
        m = f.shape[0]
        if not m:
            return
        self._f.append(f)
        self._k.append(k)
        self._pos.append(np.asarray(pos, dtype=np.float64).reshape(m, self.n_axes))
        self._n += m

    def clear(self) -> None:
        self._f.clear()
        self._k.clear()
        self._pos.clear()
        self._n = 0

    def _joined(self) -> tuple[Array, NDArray[np.int64], Array]:
        if len(self._f) > 1:  # join the blocks once
            self._f[:] = [np.concatenate(self._f)]
            self._k[:] = [np.concatenate(self._k)]
            self._pos[:] = [np.concatenate(self._pos)]
        if not self._f:
            return (np.empty((0, 2)), np.empty((0, 4), dtype=np.int64),
                    np.empty((0, self.n_axes)))
        return self._f[0], self._k[0], self._pos[0]

    def arrays(self) -> dict[str, NDArray]:
        """Columns: time, job, index, value, output, state (-1 none), positions (n x axes)."""
        f, k, pos = self._joined()
        return {
            "time": f[:, 0].copy(),
            "job": k[:, 0].copy(),
            "index": k[:, 1].copy(),
            "value": f[:, 1].copy(),
            "output": k[:, 2].copy(),
            "state": k[:, 3].copy(),
            "positions": pos.copy(),
        }

    def for_job(self, job: int) -> dict[str, NDArray]:
        a = self.arrays()
        sel = a["job"] == job
        return {k: v[sel] for k, v in a.items()}

    def save_npz(self, path: str | Path) -> Path:
        p = Path(path)
        if p.suffix != ".npz":
            raise MotionError(f"path must end with .npz, got {str(path)!r}")
        p.parent.mkdir(parents=True, exist_ok=True)
        np.savez(p, **self.arrays())
        return p

    def save_csv(self, path: str | Path) -> Path:
        """One row per firing; times and positions with 17 significant digits (round-trip)."""
        p = Path(path)
        if p.suffix != ".csv":
            raise MotionError(f"path must end with .csv, got {str(path)!r}")
        p.parent.mkdir(parents=True, exist_ok=True)
        f, k, pos = self._joined()
        with p.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow([*self.FIELDS, *(f"pos{i}" for i in range(self.n_axes))])
            for (t, val), (job, idx, out, st), ps in zip(f.tolist(), k.tolist(), pos.tolist(),
                                                          strict=True):
                w.writerow([repr(t), job, idx, repr(val), out, st, *(repr(x) for x in ps)])
        return p


def plot_firings(log: EventLog, path: str | Path, *, path_xy: Array | None = None,
                 axes: tuple[int, int] = (0, 1), title: str = "compare firings") -> Path:
    """Draw the XY path (optional (n, 2) array) with every firing marked; returns the file."""
    from matplotlib.figure import Figure  # optional heavy import, only when plotting

    p = Path(path)
    if p.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise MotionError(f"path must end with .png, .svg or .pdf, got {str(path)!r}")
    a = log.arrays()
    fig = Figure(figsize=(7, 6))
    ax = fig.add_subplot(1, 1, 1)
    if path_xy is not None:
        xy = np.asarray(path_xy, dtype=np.float64)
        ax.plot(xy[:, 0], xy[:, 1], lw=0.8, color="0.5", label="path")
    pos = a["positions"]
    if pos.shape[0]:
        on = a["state"] != 0
        ax.plot(pos[on, axes[0]], pos[on, axes[1]], "o", ms=3, color="tab:red",
                label="firing (output on)")
        ax.plot(pos[~on, axes[0]], pos[~on, axes[1]], "x", ms=4, color="tab:blue",
                label="firing (output off)")
    ax.set_xlabel(f"axis {axes[0]}")
    ax.set_ylabel(f"axis {axes[1]}")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"{title} ({len(log)} firings)")
    ax.legend(loc="best", fontsize=8)
    p.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(p, dpi=100)
    return p
