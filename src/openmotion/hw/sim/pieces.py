"""Motor motion over one stretch of simulated time, as monotone pieces.

Every plant turns the commanded cubic into a list of pieces on which the motor position m
moves in one direction (or not at all). Event finders only ever ask a piece "when does m
first satisfy m >= x (moving up) / m < x (moving down)?", which each piece answers exactly:

- `StepPiece`: a stepper following the pulse train. m is an integer staircase: the pulse
  count minus the steps lost so far. The count reaches integer k when the command cubic
  reaches k (within `EPS_PULSE`), so a crossing time is a root of the cubic.
- `SmoothPiece`: a servo motor (continuous, analytic m(t)); crossing by safeguarded Newton.
- `HoldPiece`: m constant (stall, servo off, or no motion); never crosses anything.
- `JumpPiece`: m jumps at one instant (injected step loss, a command that jumps).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from .cubic import Cubic, cubic_time_at, solve_monotone

#: A count is reached when the command is within this many pulses of the integer, so a
#: planner ending at 999.9999999999 still emits its last pulse.
EPS_PULSE = 1e-9


def count_after(u: float, count: int, direction: int, half: float = 0.0) -> int:
    """Pulse count after the command moves monotonically (in `direction`) to u.

    The count is the last integer reached: floor moving up, ceil moving down (rounding
    toward the previous count), so a pulse is emitted exactly when the command reaches an
    integer, in both directions, and jitter below one pulse emits nothing.
    With `half` = 0.5 (the half-pulse rule, Klipper's step_dist/2) pulse k is emitted when
    the command reaches k - 1/2 going up (k + 1/2 going down): the count is the command
    rounded to the nearest integer, within half a pulse of it at every instant.
    """
    if direction > 0:
        k = math.floor(u + half + EPS_PULSE)
        return k if k > count else count
    if direction < 0:
        k = math.ceil(u - half - EPS_PULSE)
        return k if k < count else count
    return count


class Piece:
    """A monotone stretch [t0, t1] of motor position m. direction: +1, -1 or 0."""

    __slots__ = ("t0", "t1", "m0", "m1", "direction")

    t0: float
    t1: float
    m0: float
    m1: float
    direction: int

    def m_at(self, t: float) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def time_at(self, level: float) -> tuple[float, float]:  # pragma: no cover - overridden
        """(t, m): first time m >= level (direction +1) or m < level (direction -1), and
        the motor position just after it (exact, unlike m_at(t) at a crossing).

        Only called with a level that m reaches inside the piece (m1 satisfies it).
        """
        raise NotImplementedError


class HoldPiece(Piece):
    __slots__ = ()

    def __init__(self, t0: float, t1: float, m: float) -> None:
        self.t0, self.t1, self.m0, self.m1, self.direction = t0, t1, m, m, 0

    def m_at(self, t: float) -> float:
        return self.m0

    def time_at(self, level: float) -> tuple[float, float]:
        return self.t0, self.m0


class JumpPiece(Piece):
    __slots__ = ()

    def __init__(self, t: float, m0: float, m1: float) -> None:
        self.t0 = self.t1 = t
        self.m0, self.m1 = m0, m1
        self.direction = 1 if m1 > m0 else (-1 if m1 < m0 else 0)

    def m_at(self, t: float) -> float:
        return self.m1

    def time_at(self, level: float) -> tuple[float, float]:
        return self.t0, self.m1


class StepPiece(Piece):
    """Stepper following the pulses of `cubic` (local time s = t - tc) on [t0, t1].

    m = count - lost, the count starting at `c0` and moving monotonically in `direction`.
    """

    __slots__ = ("cubic", "tc", "c0", "lost", "half")

    def __init__(self, cubic: Cubic, tc: float, t0: float, t1: float, c0: int, c1: int,
                 lost: int, direction: int, half: float = 0.0) -> None:
        self.cubic, self.tc, self.c0, self.lost = cubic, tc, c0, lost
        self.half = half  # pulse threshold offset, see count_after
        self.t0, self.t1 = t0, t1
        self.m0, self.m1 = c0 - lost, c1 - lost
        self.direction = direction

    def m_at(self, t: float) -> float:
        if t >= self.t1:
            return self.m1
        u = self.cubic.pos(t - self.tc)
        return count_after(u, self.c0, self.direction, self.half) - self.lost

    def time_at(self, level: float) -> tuple[float, float]:
        c = self.cubic
        # moving up: m >= level <=> count >= ceil(level + lost); down: m < level <=>
        # count <= ceil(level + lost) - 1
        k = math.ceil(level + self.lost) - (0 if self.direction > 0 else 1)
        # the exact integer; if the cubic only gets within EPS_PULSE of it, the root is not
        # bracketed and the piece end is returned (where the count was rounded up to k)
        u = k - self.half if self.direction > 0 else k + self.half  # k itself if half == 0
        s = cubic_time_at(c, float(u), self.t0 - self.tc, self.t1 - self.tc)
        return min(max(self.tc + s, self.t0), self.t1), k - self.lost


class SmoothPiece(Piece):
    """Continuous motor motion m(t) = f(t), monotone on [t0, t1]; df is its derivative."""

    __slots__ = ("f", "df")

    def __init__(self, f: Callable[[float], float], df: Callable[[float], float],
                 t0: float, t1: float, direction: int, m0: float | None = None,
                 m1: float | None = None) -> None:
        self.f, self.df = f, df
        self.t0, self.t1 = t0, t1
        self.m0 = f(t0) if m0 is None else m0
        self.m1 = f(t1) if m1 is None else m1
        self.direction = direction

    def m_at(self, t: float) -> float:
        return self.f(min(max(t, self.t0), self.t1))

    def time_at(self, level: float) -> tuple[float, float]:
        return solve_monotone(self.f, self.df, self.t0, self.t1, level), level
