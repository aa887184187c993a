"""The geometry of a program's coming lines, made a stretch at a time (the runner's feed).

A program is mostly runs of straight lines (G1, G0, arcs sent as chords). The runner's feed
pushes them one by one (`Group._queue_line`); the line from one end point to the next
depends on nothing but the two points, so `LinesAhead` makes the lines of up to `STRETCH`
consecutive line ops at once (`Line.chain_of`: one vectorised pass, bit for bit the lines
the group would make). The group takes a prepared line only when its queue's tail is that
line's start, the very array of the line pushed before it; anything else (the first line
of a stretch, a line after an arc, after a probe or a restart) it makes itself. Entries are
dropped as they are taken, so the memory held is one stretch whatever the program length.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..path.geometry import Line

if TYPE_CHECKING:
    from .convert import Op

#: Line ops prepared at once.
STRETCH = 256


class LinesAhead:
    """Prepared (end row, line from the op before it) of the coming line ops of one pass."""

    def __init__(self) -> None:
        self._ops: list[Op] | None = None
        self._at: dict[int, tuple[Op, np.ndarray, Line | None]] = {}

    def take(self, ops: list[Op], pc: int) -> tuple[np.ndarray, Line | None] | None:
        """(end, line) for the line op ops[pc]: its end point as a read-only row and the
        line to it from the op before it (None for the first op of a stretch), or None
        when the op cannot be prepared (the group then makes the line from op.end)."""
        if ops is not self._ops:
            self._ops, self._at = ops, {}
        got = self._at.pop(pc, None)
        if got is None or got[0] is not ops[pc]:
            got = self._prepare(ops, pc)
            if got is None:
                return None
        return got[1], got[2]

    def _prepare(self, ops: list[Op], pc: int) -> tuple[Op, np.ndarray, Line | None] | None:
        self._at.clear()
        stretch: list[Op] = []
        n = -1
        for op in ops[pc:pc + STRETCH]:
            end = op.end
            if op.kind != "line" or end is None or end.ndim != 1 or end.dtype != np.float64:
                break
            if n < 0:
                n = end.size
            elif end.size != n:
                break
            stretch.append(op)
        if len(stretch) < 2 or n < 2:
            return None
        pts = np.array([op.end for op in stretch])
        if not np.isfinite(pts).all():
            return None
        lines = Line.chain_of(pts)
        first = (stretch[0], lines[0].start, None)
        for k in range(1, len(stretch)):
            self._at[pc + k] = (stretch[k], lines[k - 1].end, lines[k - 1])
        return first
