"""The queue of timed cubic pieces of one simulated axis (hw.interface.QueuedHardware).

A piece is a row (t0, dt, p0, v0, a0, j) of a float array; it becomes the axis's
pulse-generator command at its t0. Pieces arrive as a sequence of `AxisCommand` or as a
`PieceBlock` of arrays (a whole chunk of cycles from the planner) and are kept as blocks,
so the compiled kernel takes them without one Python object per piece. The queue checks a
batch as a whole before taking any of it, so a malformed piece leaves the queue exactly as
it was.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand, PieceBlock

try:  # the compiled inner loops (setup.py builds them)
    from openmotion import _kernel
except ImportError:  # pragma: no cover - depends on the build
    _kernel = None

_FIELDS = ("t0", "dt", "p0", "v0", "a0", "j")
_F8 = np.dtype(np.float64)
#: Slack on "starts after the piece before ends" (s): t0 + dt of one cycle's piece may be
#: one rounding step past the next cycle's start.
TIME_SLACK = 1e-9


class PieceQueue:
    """Pieces not started yet, in time order, and the end time of the last one queued."""

    __slots__ = ("_blocks", "_head", "_n", "end", "version")

    def __init__(self) -> None:
        self._blocks: list[np.ndarray] = []  # (m, 6) float arrays, oldest first
        self._head = 0  # rows of _blocks[0] already started
        self._n = 0
        self.end = -math.inf
        #: changes with every change of the queue (the compiled kernel's copy of the rows,
        #: hw/sim/kernel.py, is made again when it differs from the one it was made at)
        self.version = 0

    def __len__(self) -> int:
        return self._n

    def extend(self, pieces: Sequence[AxisCommand] | PieceBlock, now: float) -> None:
        """Check every piece (MotionError naming it and the rule; nothing queued then),
        then append them all."""
        start = self.end if self.end > now else now
        if type(pieces) is PieceBlock:  # the planner's chunks: checked in one C call
            rows = pieces.rows
            if (_kernel is not None and type(rows) is np.ndarray and rows.dtype == _F8
                    and rows.ndim == 2 and rows.shape[1] == 6 and rows.flags.c_contiguous
                    and len(rows) and _kernel.check_rows(rows, start, TIME_SLACK) < 0):
                self._blocks.append(rows)
                self._n += len(rows)
                self.version += 1
                last = rows[-1].tolist()
                self.end = last[0] + last[1]
                return
        if isinstance(pieces, PieceBlock):
            rows = _block_rows(pieces, start, now)
        elif isinstance(pieces, AxisCommand) or not isinstance(pieces, Sequence):
            raise MotionError(f"pieces must be a sequence of AxisCommand or a PieceBlock, "
                              f"got {type(pieces).__name__}")
        else:
            rows = _command_rows(pieces, start, now)
        if not len(rows):
            return
        self._blocks.append(rows)
        self._n += len(rows)
        self.version += 1
        self.end = float(rows[-1, 0] + rows[-1, 1])

    def clear(self) -> None:
        self.version += 1
        self._blocks.clear()
        self._head = 0
        self._n = 0
        self.end = -math.inf

    def next_start(self) -> float:
        """t0 of the next piece, or +inf."""
        return float(self._blocks[0][self._head, 0]) if self._n else math.inf

    def pop(self) -> tuple[float, float, float, float, float, float]:
        """The next piece (t0, dt, p0, v0, a0, j), removed from the queue."""
        row = self._blocks[0][self._head].tolist()
        self.consume(1)
        return tuple(row)  # type: ignore[return-value]

    def remaining(self) -> np.ndarray:
        """Every piece not started yet, as one (n, 6) float array (read only: it may be the
        queue's own block)."""
        if not self._n:
            return np.zeros((0, 6))
        first = self._blocks[0][self._head:]
        if len(self._blocks) == 1:
            return first
        return np.concatenate([first, *self._blocks[1:]])

    def consume(self, n: int) -> None:
        """Drop the next n pieces (they started)."""
        self.version += 1
        self._n -= n
        blocks = self._blocks
        if blocks and n < len(blocks[0]) - self._head:  # (the usual case: in the first block)
            self._head += n
            return
        while n:
            left = len(self._blocks[0]) - self._head
            if n < left:
                self._head += n
                return
            n -= left
            self._blocks.pop(0)
            self._head = 0


def _late(k: int, t0: float, end: float, now: float) -> MotionError:
    what = "the hardware time" if end == now else "the end of the piece before"
    return MotionError(f"pieces[{k}].t0 must be >= {what} ({end!r} s), got {t0!r}")


def _command_rows(pieces: Sequence[AxisCommand], end: float, now: float) -> np.ndarray:
    for k, p in enumerate(pieces):
        # fast path: a float AxisCommand whose fields sum to a finite number has only
        # finite fields; anything else gets the field-by-field check and its message
        try:
            ok = type(p) is AxisCommand and math.isfinite(
                p.t0 + p.dt + p.p0 + p.v0 + p.a0 + p.j)
        except TypeError:
            ok = False
        if not ok:
            _check_fields(k, p)
        if p.dt < 0.0:
            raise MotionError(f"pieces[{k}].dt must be >= 0 s, got {p.dt!r}")
        if p.t0 < end - TIME_SLACK:
            raise _late(k, p.t0, end, now)
        end = p.t0 + p.dt
    return np.array([(p.t0, p.dt, p.p0, p.v0, p.a0, p.j) for p in pieces],
                    dtype=float).reshape(-1, 6)


def _block_rows(block: PieceBlock, end: float, now: float) -> np.ndarray:
    rows = block.rows  # kept as it is when it is float64 and C-contiguous (PieceBlock doc)
    if type(rows) is not np.ndarray or rows.dtype != np.float64 or not rows.flags.c_contiguous:
        try:
            rows = np.array(rows, dtype=float)
        except (TypeError, ValueError) as e:
            raise MotionError(f"pieces.rows must be an (n, 6) array of numbers ({e})"
                              ) from None
    if rows.ndim != 2 or rows.shape[1] != 6:
        raise MotionError(f"pieces.rows must be an (n, 6) array (t0, dt, p0, v0, a0, j), "
                          f"got shape {rows.shape}")
    if not len(rows):
        return rows
    k = _first_bad(rows, end)
    if k >= 0:
        for f, v in zip(_FIELDS, rows[k].tolist(), strict=True):
            if not math.isfinite(v):
                raise MotionError(f"pieces[{k}].{f} must be a finite number, got {v!r}")
        if rows[k, 1] < 0.0:
            raise MotionError(f"pieces[{k}].dt must be >= 0 s, got {rows[k, 1].item()!r}")
        before = (rows[k - 1, 0] + rows[k - 1, 1]).item() if k else end
        raise _late(k, rows[k, 0].item(), before, now)
    return rows


def _first_bad(rows: np.ndarray, end: float) -> int:
    """Index of the first piece with a non-finite field, dt < 0 or a start before the end
    of the piece before (`end` for the first), or -1."""
    if _kernel is not None:
        return _kernel.check_rows(rows, end, TIME_SLACK)
    t0, dt = rows[:, 0], rows[:, 1]
    before = np.concatenate(([end], (t0 + dt)[:-1]))
    bad = ~np.isfinite(rows).all(axis=1) | (dt < 0.0) | (t0 < before - TIME_SLACK)
    return int(np.flatnonzero(bad)[0]) if bad.any() else -1


def _check_fields(k: int, p: object) -> None:
    if not isinstance(p, AxisCommand):
        raise MotionError(f"pieces[{k}] must be an AxisCommand, got {type(p).__name__}")
    for f in _FIELDS:
        v = getattr(p, f)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise MotionError(f"pieces[{k}].{f} must be a finite number, got {v!r}")
