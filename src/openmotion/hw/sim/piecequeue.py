"""The queue of timed cubic pieces of one simulated axis (hw.interface.QueuedHardware).

A piece is an `AxisCommand`; it becomes the axis's pulse-generator command at its t0. The
queue checks a batch as a whole before taking any of it, so a malformed piece leaves the
queue exactly as it was.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand

_FIELDS = ("t0", "dt", "p0", "v0", "a0", "j")
#: Slack on "starts after the piece before ends" (s): t0 + dt of one cycle's piece may be
#: one rounding step past the next cycle's start.
TIME_SLACK = 1e-9


class PieceQueue:
    """Pieces not started yet, in time order, and the end time of the last one queued."""

    __slots__ = ("pieces", "end")

    def __init__(self) -> None:
        self.pieces: deque[AxisCommand] = deque()
        self.end = -math.inf

    def __len__(self) -> int:
        return len(self.pieces)

    def extend(self, pieces: Sequence[AxisCommand], now: float) -> None:
        """Check every piece (MotionError naming it and the rule; nothing queued then),
        then append them all."""
        if isinstance(pieces, AxisCommand) or not isinstance(pieces, Sequence):
            raise MotionError(f"pieces must be a sequence of AxisCommand, got "
                              f"{type(pieces).__name__}")
        end = max(self.end, now)
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
                what = "the hardware time" if end == now else "the end of the piece before"
                raise MotionError(f"pieces[{k}].t0 must be >= {what} ({end!r} s), "
                                  f"got {p.t0!r}")
            end = p.t0 + p.dt
        self.pieces.extend(pieces)
        if pieces:
            self.end = end

    def clear(self) -> None:
        self.pieces.clear()
        self.end = -math.inf

    def next_start(self) -> float:
        """t0 of the next piece, or +inf."""
        return self.pieces[0].t0 if self.pieces else math.inf


def _check_fields(k: int, p: object) -> None:
    if not isinstance(p, AxisCommand):
        raise MotionError(f"pieces[{k}] must be an AxisCommand, got {type(p).__name__}")
    for f in _FIELDS:
        v = getattr(p, f)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise MotionError(f"pieces[{k}].{f} must be a finite number, got {v!r}")
