"""Exact trigger solvers on piecewise-cubic motion (the compare engine's mathematics).

A *track* is a run of constant-jerk records (ts, p0, v0, a0, j) as in MotionHistory: record
k covers [ts[k], ts[k+1]) and the last one is open-ended. The compare engine cuts the
history of each cycle [t0, t1] into tracks in the compared frame (command counter, or the
feedback model) and asks three questions, each answered between cycles, not at cycle ends:

- `first_crossing`: the first time after `t` the track reaches a level (a compare value),
  with the events of MotionHistory.crossings (compare_roots.level_events);
- `VectorCycle`: the accumulated path length s(t) (ZMotion VECTOR_MOVED) over the cycle and
  the time it reaches a given distance;
- `first_inside`: the first time all axes are within +-maxerr of a point (2-D/3-D tables).
"""

from __future__ import annotations

import bisect
import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...history import MotionHistory
from .compare_roots import level_events, velocity_roots

Array = NDArray[np.float64]

# Gauss-Legendre nodes on [-1, 1]: exact for polynomials of degree <= 15.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_QUAD_RTOL = 1e-13
_QUAD_DEPTH = 10
_SNAP_RTOL = 1e-10  # distances this close count as reached
_EPS = float(np.finfo(np.float64).eps)
_GL_PAIRS = list(zip(_GL_X.tolist(), _GL_W.tolist(), strict=True))


class Track(NamedTuple):
    """Constant-jerk records in the compared frame (see module docstring)."""

    ts: Array
    p0: Array
    v0: Array
    a0: Array
    j: Array


def history_track(history: MotionHistory, axis: int, t0: float, t1: float) -> Track:
    """The records of `axis` covering [t0, t1], plus the one before (the sign before t0).

    Reads the history's record arrays in place (no copy of the whole window): a per-cycle
    query touches only a few rows.
    """
    return Track(*history.rows(axis, t0, t1))


def affine_track(tr: Track, scale: float, offset: float, e0: float = 0.0, slope: float = 0.0,
                 t_ref: float = 0.0) -> Track:
    """scale * x(t) + offset + e0 + slope * (t - t_ref): still constant-jerk records."""
    p0 = scale * tr.p0 + offset + e0 + slope * (tr.ts - t_ref)
    return Track(tr.ts, p0, scale * tr.v0 + slope, scale * tr.a0, scale * tr.j)


def positions(tr: Track, times: Array) -> Array:
    """Track positions at `times` (vectorized)."""
    t = np.asarray(times, dtype=np.float64)
    k = np.maximum(np.searchsorted(tr.ts, t, side="right") - 1, 0)
    dt = t - tr.ts[k]
    return tr.p0[k] + dt * (tr.v0[k] + dt * (tr.a0[k] / 2.0 + dt * tr.j[k] / 6.0))


def velocities(tr: Track, times: Array) -> Array:
    t = np.asarray(times, dtype=np.float64)
    k = np.maximum(np.searchsorted(tr.ts, t, side="right") - 1, 0)
    dt = t - tr.ts[k]
    return tr.v0[k] + dt * (tr.a0[k] + dt * tr.j[k] / 2.0)


def crossings_after(tr: Track, level: float, t: float, t1: float,
                    direction: int) -> Array:
    """Times in (t, t1] where the track reaches `level` (direction +1 up, -1 down, 0 both).

    An arrival exactly at t belongs to the window that ended at t, so it is not repeated.
    """
    return np.array(level_events(tr.ts, tr.p0, tr.v0, tr.a0, tr.j, level, t, t1, direction))


def first_crossing(tr: Track, level: float, t: float, t1: float,
                   direction: int) -> float | None:
    """The first time in (t, t1] the track reaches `level` in `direction`, or None."""
    times = level_events(tr.ts, tr.p0, tr.v0, tr.a0, tr.j, level, t, t1, direction, first=True)
    return times[0] if times else None


# ---------------------------------------------------------------------------- window
# The set of times an axis is within [c - e, c + e] is a union of closed intervals whose left
# ends are the window start or a crossing of c - e or c + e. So the first time all axes are
# inside is one of these candidates: test them in time order with the evaluated positions.
def first_inside(tracks: list[Track], centre: Array, maxerr: float, t: float,
                 t1: float, ranges: list[tuple[float, float]] | None = None) -> float | None:
    """The first time in [t, t1] every track is within +-maxerr of its centre, or None.
    `ranges`: each track's (min, max) over the window, to skip hopeless solver calls.

    Plain floats (a query touches a few records, where numpy's per-call cost dominated),
    candidates tested in time order until the first one inside: the same arithmetic as the
    vectorized version, so the same time (tests/test_compare_roots.py)."""
    cands = {t}
    rows = []
    for k, (tr, c_) in enumerate(zip(tracks, centre, strict=True)):
        c = float(c_)
        lo_k, hi_k = ranges[k] if ranges is not None else (-math.inf, math.inf)
        slack = 1e-9 * (abs(c) + maxerr + 1.0)
        if c + maxerr < lo_k - slack or c - maxerr > hi_k + slack:
            return None  # this axis never gets near its coordinate in the window
        rec = (tr.ts.tolist(), tr.p0.tolist(), tr.v0.tolist(), tr.a0.tolist(), tr.j.tolist())
        rows.append((rec, c, maxerr + 1e-12 * (abs(c) + maxerr + 1.0)))
        for lvl in (c - maxerr, c + maxerr):
            if not lo_k - slack <= lvl <= hi_k + slack:
                continue
            cands.update(level_events(*rec, float(lvl), t, t1))
    for x in sorted(cands):
        if not t <= x <= t1:
            continue
        # the crossing solver lands on the level: tol 1e-12 relative
        if all(abs(_position(rec, x) - c) <= lim for rec, c, lim in rows):
            return float(x)
    return None


def _position(rec: tuple[list[float], ...], x: float) -> float:
    """`positions` at one time, on the records as lists (same arithmetic)."""
    ts, p0, v0, a0, j = rec
    k = max(bisect.bisect_right(ts, x) - 1, 0)
    dt = x - ts[k]
    return p0[k] + dt * (v0[k] + dt * (a0[k] / 2.0 + dt * j[k] / 6.0))


def track_range(tr: Track, ta: float, t1: float) -> tuple[float, float]:
    """(min, max) of the track's position over [ta, t1]: a cheap test that a level cannot
    be reached in this window, so the exact solver is skipped."""
    lo, hi = math.inf, -math.inf
    n = tr.ts.size
    for k in range(n):
        a_k = float(tr.ts[k])
        b_k = float(tr.ts[k + 1]) if k + 1 < n else math.inf
        u, w = max(a_k, ta), min(b_k, t1)
        if w < u:
            continue
        p, v, a, j = float(tr.p0[k]), float(tr.v0[k]), float(tr.a0[k]), float(tr.j[k])
        xs = [u - a_k, w - a_k] + [r for r in velocity_roots(v, a, j) if u - a_k < r < w - a_k]
        for x in xs:
            y = p + x * (v + x * (a / 2.0 + x * j / 6.0))
            lo, hi = min(lo, y), max(hi, y)
    return lo, hi


# ---------------------------------------------------------------------------- vector distance
# s(t) = integral of |W v(t)| dt with W = diag(weights). Each axis's velocity is a quadratic
# per record, so we cut the cycle at every record start and every root of every axis's
# velocity. On a piece, with x = t - u, speed^2 = Q(x) = sum_i (c0 + c1 x + c2 x^2)^2 is a
# quartic whose coefficients we form once; the speed sqrt(Q) is smooth inside the piece (a
# kink needs all velocities to vanish together, and those instants are piece ends). For a
# single axis or a straight line sqrt(Q) is a polynomial of degree <= 2, which 8-point
# Gauss-Legendre integrates exactly; otherwise (curves) the piece is halved adaptively until
# two levels agree to 1e-13 relative. s(t) = d is solved by safeguarded Newton (s' = speed).
class VectorCycle:
    """Path length over one window [ta, t1] of several axes' tracks, starting at s0."""

    def __init__(self, tracks: list[Track], weights: Array, ta: float, t1: float,
                 s0: float) -> None:
        w = np.asarray(weights, dtype=np.float64)
        bps = {ta, t1}
        for tr in tracks:
            n = tr.ts.size
            for k in range(n):
                a_k = float(tr.ts[k])
                b_k = float(tr.ts[k + 1]) if k + 1 < n else math.inf
                if ta < a_k < t1:
                    bps.add(a_k)
                if b_k <= ta or a_k >= t1:
                    continue
                for r in velocity_roots(float(tr.v0[k]), float(tr.a0[k]), float(tr.j[k])):
                    tr_ = a_k + r
                    if ta < tr_ < t1 and tr_ < b_k:
                        bps.add(tr_)
        self.B = B = np.array(sorted(bps))
        u = B[:-1]
        mid = 0.5 * (B[:-1] + B[1:])
        Q = np.zeros((u.size, 5))
        for tr, wk in zip(tracks, w, strict=True):
            k = np.maximum(np.searchsorted(tr.ts, mid, side="right") - 1, 0)
            d0 = u - tr.ts[k]
            j = tr.j[k]
            c0 = wk * (tr.v0[k] + d0 * (tr.a0[k] + d0 * j / 2.0))
            c1 = wk * (tr.a0[k] + d0 * j)
            c2 = wk * (j / 2.0)
            Q[:, 0] += c0 * c0
            Q[:, 1] += 2.0 * c0 * c1
            Q[:, 2] += c1 * c1 + 2.0 * c0 * c2
            Q[:, 3] += 2.0 * c1 * c2
            Q[:, 4] += c2 * c2
        self.Q = Q
        self._q = Q.tolist()
        H = B[1:] - u
        # all pieces at once with one and two GL panels; refine only those that disagree
        x1 = (H[:, None] / 2.0) * (_GL_X[None, :] + 1.0)
        one = (H / 2.0) * (self._sq_rows(x1) @ _GL_W)
        xa = (H[:, None] / 4.0) * (_GL_X[None, :] + 1.0)
        two = (H / 4.0) * ((self._sq_rows(xa) + self._sq_rows(xa + H[:, None] / 2.0)) @ _GL_W)
        bad = np.abs(two - one) > _QUAD_RTOL * np.maximum(np.abs(two), 1e-300)
        for i in np.flatnonzero(bad):
            two[i] = self._adaptive(i, 0.0, float(H[i]), 0)
        self.S = s0 + np.concatenate([[0.0], np.cumsum(two)])

    def _sq_rows(self, x: Array) -> Array:
        Q = self.Q
        y = Q[:, 0:1] + x * (Q[:, 1:2] + x * (Q[:, 2:3] + x * (Q[:, 3:4] + x * Q[:, 4:5])))
        return np.sqrt(np.maximum(y, 0.0))

    def _gl(self, i: int, a: float, b: float) -> float:
        # plain floats: ~10x cheaper than numpy on 8 nodes (this runs per Newton step)
        q0, q1, q2, q3, q4 = self._q[i]
        h = 0.5 * (b - a)
        acc = 0.0
        for xg, wg in _GL_PAIRS:
            x = a + h * (xg + 1.0)
            y = q0 + x * (q1 + x * (q2 + x * (q3 + x * q4)))
            acc += wg * math.sqrt(y) if y > 0.0 else 0.0
        return h * acc

    def _adaptive(self, i: int, a: float, b: float, depth: int) -> float:
        m = 0.5 * (a + b)
        whole = self._gl(i, a, b)
        halves = self._gl(i, a, m) + self._gl(i, m, b)
        if abs(halves - whole) <= _QUAD_RTOL * max(abs(halves), 1e-300) or depth >= _QUAD_DEPTH:
            return halves
        return self._adaptive(i, a, m, depth + 1) + self._adaptive(i, m, b, depth + 1)

    @property
    def end(self) -> float:
        return float(self.S[-1])

    def at(self, t: float) -> float:
        """s(t) for t in the window."""
        i = min(max(int(np.searchsorted(self.B, t, side="right")) - 1, 0), self.B.size - 2)
        return float(self.S[i]) + self._gl(i, 0.0, t - float(self.B[i]))

    def time_of(self, d: float, after: float) -> float | None:
        """First time > `after` with s(t) >= d (s is non-decreasing), or None."""
        if d > self.S[-1]:
            # a point exactly at the end of a move: the quadrature sum may land an ulp short
            if d - self.S[-1] > _SNAP_RTOL * max(abs(d), 1.0):
                return None
            d = float(self.S[-1])
        i = max(int(np.searchsorted(self.S, d, side="left")), 1) - 1  # S[i] < d <= S[i+1]
        u = float(self.B[i])
        lo, hi = max(after, u) - u, float(self.B[i + 1]) - u
        su = float(self.S[i])
        if su + self._gl(i, 0.0, lo) >= d:  # already there at `after`
            return u + lo if u + lo > after else None
        q0, q1, q2, q3, q4 = self._q[i]
        x = 0.5 * (lo + hi)
        for _ in range(100):
            f = su + self._gl(i, 0.0, x) - d
            if f >= 0.0:
                hi = x
            else:
                lo = x
            tol = 4.0 * _EPS * max(abs(u + x), 1.0)
            if hi - lo <= tol:
                return u + hi
            sp = math.sqrt(max(q0 + x * (q1 + x * (q2 + x * (q3 + x * q4))), 0.0))
            xn = x - f / sp if sp > 0.0 else math.nan
            if abs(xn - x) <= tol:  # converged (also when the step rounds to nothing)
                return u + max(xn, x) if f < 0.0 else u + x
            if not lo < xn < hi:
                xn = 0.5 * (lo + hi)
            x = xn
        return u + hi
