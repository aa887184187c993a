"""Level events on a track, fast: the compare engine's per-firing solver.

Same events as MotionHistory.crossings (an upward event is a time where the position was
below the level just before and is at or above it then; downward mirrored; a tangent touch
counts as reaching the level from the side it came from; a dwell on the level counts once,
on arrival), found the same way on monotone pieces (records cut at the velocity roots),
but each root is refined by Newton's method inside the sign bracket instead of bisection
to adjacent floats: 4-6 steps instead of ~50, the same time to a few ulps. Plain floats:
a compare query touches one to three records, where numpy's per-call overhead dominates.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ...crossings import velocity_roots

__all__ = ["level_events", "velocity_roots"]

_EPS = 2.220446049250313e-16


def _f(c: float, v: float, a: float, j: float, x: float, level: float, p: float) -> float:
    """Position minus level at local time x, snapped to 0 within rounding of the terms."""
    f = c + x * (v + x * (a / 2.0 + x * j / 6.0))
    scale = abs(level) + abs(p) + abs(x * v) + abs(x * x * a / 2.0) + abs(x * x * x * j / 6.0)
    return 0.0 if abs(f) <= 8.0 * _EPS * scale else f


def _sign(x: float) -> int:
    return 1 if x > 0.0 else -1 if x < 0.0 else 0


def _refine(c: float, v: float, a: float, j: float, lo: float, hi: float, s_lo: int,
            t_base: float) -> float:
    """Root of the monotone cubic in (lo, hi), whose sign is s_lo at lo and -s_lo at hi:
    Newton's method kept inside the sign bracket, to the absolute time resolution.
    (The arithmetic is written out once per step, in a fixed order: the result is the
    same float whatever the caller; tests/test_compare_roots.py checks it against the
    plain version.)"""
    x = 0.5 * (lo + hi)
    tb = abs(t_base)
    a2 = a / 2.0
    up = s_lo > 0
    for _ in range(200):
        f = c + x * (v + x * (a2 + x * j / 6.0))
        if (f > 0.0) if up else (f < 0.0):
            lo = x
        else:
            hi = x
        tol = 2.0 * _EPS * (tb + abs(x))
        if hi - lo <= tol:
            return hi
        d = v + x * (a + x * j / 2.0)
        xn = x - f / d if d != 0.0 else math.nan
        if not lo < xn < hi:
            xn = 0.5 * (lo + hi)
        elif abs(xn - x) <= tol:
            return xn
        x = xn
    return hi


def level_events(ts: Sequence[float], p0: Sequence[float], v0: Sequence[float],
                 a0: Sequence[float], j0: Sequence[float], level: float, t: float, t1: float,
                 direction: int = 0, first: bool = False) -> list[float]:
    """Times in (t, t1] where the records reach `level` (direction +1, -1 or 0 = both).

    An event exactly at t belongs to the window that ended at t and is not returned; the
    sign at t starts the scan. `first`: stop at the first event.
    """
    n = len(ts)
    out: list[float] = []
    k = 0
    while k + 1 < n and ts[k + 1] <= t:
        k += 1
    s_left: int | None = None
    f_end, ends_at_t1 = 1.0, False
    while k < n:
        tk = float(ts[k])
        if tk > t1:
            break
        end = float(ts[k + 1]) if k + 1 < n else math.inf
        xa, xb = max(t - tk, 0.0), min(end, t1) - tk
        p, v, a, j = float(p0[k]), float(v0[k]), float(a0[k]), float(j0[k])
        c = p - level
        cuts = [xa, *sorted(r for r in velocity_roots(v, a, j) if xa < r < xb), xb]
        for u, w in zip(cuts[:-1], cuts[1:], strict=True):
            if not w > u:
                continue
            fu = _f(c, v, a, j, u, level, p)
            fw = _f(c, v, a, j, w, level, p)
            su, sw = _sign(fu), _sign(fw)
            if s_left is None:
                s_left = su  # the scan starts at t: no event there
            elif (s_left < 0 <= fu and direction >= 0) or (s_left > 0 >= fu and direction <= 0):
                out.append(tk + u)  # arrival at a piece start (or a jump between records)
                if first:
                    return out
            if su * sw < 0 and (direction == 0 or direction == -su):
                out.append(tk + _refine(c, v, a, j, u, w, su, tk))
                if first:
                    return out
            s_left = sw if sw != 0 else su
            f_end, ends_at_t1 = fw, end >= t1
        k += 1
    if ends_at_t1 and f_end == 0.0 and s_left and (direction == 0 or direction == -s_left):
        out.append(t1)  # arrival exactly at the window end
    return out
