"""Scalar cubic helpers for the simulator's hot path: evaluate, split into monotone pieces,
and find the exact time a monotone stretch reaches a level.

Plain float math on purpose: per axis and cycle these run a handful of times, where numpy's
call overhead would cost more than the arithmetic.
"""

from __future__ import annotations

import math
from typing import NamedTuple

#: Root tolerance in time (s); a bracketed Newton stops once the bracket is below this.
TIME_TOL = 1e-13


class Cubic(NamedTuple):
    """p(s) = p0 + v0*s + a0*s**2/2 + j*s**3/6 for local time s."""

    p0: float
    v0: float = 0.0
    a0: float = 0.0
    j: float = 0.0

    def pos(self, s: float) -> float:
        return self.p0 + s * (self.v0 + s * (self.a0 / 2.0 + s * self.j / 6.0))

    def vel(self, s: float) -> float:
        return self.v0 + s * (self.a0 + s * self.j / 2.0)

    def acc(self, s: float) -> float:
        return self.a0 + s * self.j


def quadratic_roots(c2: float, c1: float, c0: float, lo: float, hi: float) -> list[float]:
    """Real roots of c2*s**2 + c1*s + c0 strictly inside (lo, hi), ascending."""
    if c2 == 0.0:
        if c1 == 0.0:
            return []
        r = -c0 / c1
        return [r] if lo < r < hi else []
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        return []
    # numerically stable pair: q = -(c1 + sign(c1) sqrt(disc)) / 2
    sq = math.sqrt(disc)
    q = -0.5 * (c1 + math.copysign(sq, c1))
    roots = []
    if q != 0.0:
        roots.append(q / c2)
        roots.append(c0 / q)
    else:
        roots.append(0.0)
    return sorted(r for r in set(roots) if lo < r < hi)


def velocity_zeros(c: Cubic, lo: float, hi: float) -> list[float]:
    """Local times in (lo, hi) where the cubic's velocity is zero (direction may change)."""
    return quadratic_roots(c.j / 2.0, c.a0, c.v0, lo, hi)


def solve_monotone(f, df, lo: float, hi: float, target: float) -> float:
    """Time s in [lo, hi] with f(s) == target for f monotone on [lo, hi] (safeguarded Newton).

    Returns the bracket end nearest the target if it is not strictly bracketed (the caller
    only asks for levels that lie between f(lo) and f(hi)).
    """
    flo = f(lo) - target
    fhi = f(hi) - target
    if flo == 0.0:
        return lo
    if fhi == 0.0:
        return hi
    if (flo > 0.0) == (fhi > 0.0):
        return lo if abs(flo) <= abs(fhi) else hi
    if flo > 0.0:  # orient so that f - target rises from lo to hi
        lo_neg, hi_pos = hi, lo
    else:
        lo_neg, hi_pos = lo, hi
    # start from the secant point
    s = lo - flo * (hi - lo) / (fhi - flo)
    for _ in range(100):
        fs = f(s) - target
        if fs == 0.0:
            return s
        if fs < 0.0:
            lo_neg = s
        else:
            hi_pos = s
        width = abs(hi_pos - lo_neg)
        if width <= TIME_TOL * max(1.0, abs(s)):
            return 0.5 * (lo_neg + hi_pos)
        d = df(s)
        step_ok = False
        if d != 0.0:
            s_new = s - fs / d
            # accept Newton only inside the bracket and if it shrinks fast; else bisect
            if (min(lo_neg, hi_pos) < s_new < max(lo_neg, hi_pos)
                    and abs(s_new - s) < 0.5 * width):
                s = s_new
                step_ok = True
        if not step_ok:
            s = 0.5 * (lo_neg + hi_pos)
    return s


def cubic_time_at(c: Cubic, level: float, lo: float, hi: float) -> float:
    """Local time in [lo, hi] where a cubic, monotone there, reaches `level`."""
    if c.j == 0.0 and c.a0 == 0.0 and c.v0 != 0.0:
        s = (level - c.p0) / c.v0
        return min(max(s, lo), hi)
    return solve_monotone(c.pos, c.vel, lo, hi, level)
