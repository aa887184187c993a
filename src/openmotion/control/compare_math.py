"""Exact trigger solvers on piecewise-cubic motion (the compare engine's mathematics).

A *track* is a run of constant-jerk records (ts, p0, v0, a0, j) as in MotionHistory: record
k covers [ts[k], ts[k+1]) and the last one is open-ended. The compare engine cuts the
history of each cycle [t0, t1] into tracks in the compared frame (command counter, or the
feedback model) and asks three questions, each answered between cycles, not at cycle ends:

- `first_crossing`: the first time after `t` the track reaches a level (a compare value),
  solved on monotone pieces by the same solver as MotionHistory.crossings;
- `VectorCycle`: the accumulated path length s(t) (ZMotion VECTOR_MOVED) over the cycle and
  the time it reaches a given distance;
- `first_inside`: the first time all axes are within +-maxerr of a point (2-D/3-D tables).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..history import MotionHistory, _find_crossings

Array = NDArray[np.float64]

# Gauss-Legendre nodes on [-1, 1]: exact for polynomials of degree <= 15.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_QUAD_RTOL = 1e-13
_QUAD_DEPTH = 10
_SNAP_RTOL = 1e-10  # distances this close count as reached
_EPS = float(np.finfo(np.float64).eps)


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
    tr = history._axis(axis)  # the store's row arrays; history has no public row slice
    lo = max(tr.index_at(t0) - 1, tr.lo)
    hi = max(tr.index_at(t1), lo) + 1
    return Track(tr.ts[lo:hi], tr.p0[lo:hi], tr.v0[lo:hi], tr.a0[lo:hi], tr.j[lo:hi])


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
    times, dirs = _find_crossings(tr.ts, tr.p0, tr.v0, tr.a0, tr.j, level, t, t1)
    keep = times > t
    if direction:
        keep &= dirs == direction
    return times[keep]


def first_crossing(tr: Track, level: float, t: float, t1: float,
                   direction: int) -> float | None:
    """The first time in (t, t1] the track reaches `level` in `direction`, or None."""
    times = crossings_after(tr, level, t, t1, direction)
    return float(times[0]) if times.size else None


# ---------------------------------------------------------------------------- window
# The set of times an axis is within [c - e, c + e] is a union of closed intervals whose left
# ends are the window start or a crossing of c - e or c + e. So the first time all axes are
# inside is one of these candidates: test them in time order with the evaluated positions.
def first_inside(tracks: list[Track], centre: Array, maxerr: float, t: float,
                 t1: float) -> float | None:
    """The first time in [t, t1] every track is within +-maxerr of its centre, or None."""
    cands = [np.array([t])]
    for tr, c in zip(tracks, centre, strict=True):
        for lvl in (c - maxerr, c + maxerr):
            times, _ = _find_crossings(tr.ts, tr.p0, tr.v0, tr.a0, tr.j, float(lvl), t, t1)
            cands.append(times)
    cand = np.unique(np.concatenate(cands))
    cand = cand[(cand >= t) & (cand <= t1)]
    ok = np.ones(cand.size, dtype=bool)
    for tr, c in zip(tracks, centre, strict=True):
        x = positions(tr, cand)
        tol = 1e-12 * (abs(c) + maxerr + 1.0)  # the crossing solver lands on the level
        ok &= np.abs(x - c) <= maxerr + tol
    idx = np.flatnonzero(ok)
    return float(cand[idx[0]]) if idx.size else None


# ---------------------------------------------------------------------------- vector distance
# s(t) = integral of |W v(t)| dt with W = diag(weights). Each axis's velocity is a quadratic
# per record, so we cut the cycle at every record start and every root of every axis's
# velocity. On each piece the speed is smooth (it only has a kink where all velocities vanish
# together, and those instants are piece ends), and for a single axis or a straight line it
# is a polynomial of degree <= 2, which 8-point Gauss-Legendre integrates exactly. Otherwise
# (curves) the piece is halved adaptively until two levels agree to 1e-13 relative.
def _vel_roots(v: float, a: float, j: float) -> tuple[float, ...]:
    h = 0.5 * j
    if h == 0.0:
        return (-v / a,) if a != 0.0 else ()
    disc = a * a - 4.0 * h * v
    if disc < 0.0:
        return ()
    q = -0.5 * (a + math.copysign(math.sqrt(disc), a))
    return (q / h, v / q) if q != 0.0 else (0.0,)


class VectorCycle:
    """Path length over one window [ta, t1] of several axes' tracks, starting at s0."""

    def __init__(self, tracks: list[Track], weights: Array, ta: float, t1: float,
                 s0: float) -> None:
        self.tracks = tracks
        self.w = np.asarray(weights, dtype=np.float64)
        bps = {ta, t1}
        for tr in tracks:
            n = tr.ts.size
            for k in range(n):
                a_k = float(tr.ts[k])
                b_k = float(tr.ts[k + 1]) if k + 1 < n else math.inf
                if b_k <= ta or a_k >= t1:
                    if ta < a_k < t1:
                        bps.add(a_k)
                    continue
                if ta < a_k:
                    bps.add(a_k)
                for r in _vel_roots(float(tr.v0[k]), float(tr.a0[k]), float(tr.j[k])):
                    tr_ = a_k + r
                    if ta < tr_ < t1 and tr_ < b_k:
                        bps.add(tr_)
        self.B = np.array(sorted(bps))
        pieces = [self.integral(float(u), float(w))
                  for u, w in zip(self.B[:-1], self.B[1:], strict=True)]
        self.S = s0 + np.concatenate([[0.0], np.cumsum(pieces)])

    @property
    def end(self) -> float:
        return float(self.S[-1])

    def speed(self, t: Array) -> Array:
        acc = np.zeros(np.shape(t))
        for tr, w in zip(self.tracks, self.w, strict=True):
            acc += (w * velocities(tr, t)) ** 2
        return np.sqrt(acc)

    def _gl(self, u: float, w: float) -> float:
        h = 0.5 * (w - u)
        x = u + h * (_GL_X + 1.0)
        return float(h * np.dot(_GL_W, self.speed(x)))

    def integral(self, u: float, w: float, depth: int = 0) -> float:
        """Integral of the speed over [u, w] (inside one smooth piece)."""
        if w <= u:
            return 0.0
        whole = self._gl(u, w)
        m = 0.5 * (u + w)
        halves = self._gl(u, m) + self._gl(m, w)
        if abs(halves - whole) <= _QUAD_RTOL * max(abs(halves), 1e-300) or depth >= _QUAD_DEPTH:
            return halves
        return self.integral(u, m, depth + 1) + self.integral(m, w, depth + 1)

    def at(self, t: float) -> float:
        """s(t) for t in the window."""
        i = min(max(int(np.searchsorted(self.B, t, side="right")) - 1, 0), self.B.size - 2)
        return float(self.S[i]) + self.integral(float(self.B[i]), t)

    def time_of(self, d: float, after: float) -> float | None:
        """First time > `after` with s(t) >= d (s is non-decreasing), or None."""
        if d > self.S[-1]:
            # a point exactly at the end of a move: the quadrature sum may land an ulp short
            if d - self.S[-1] > _SNAP_RTOL * max(abs(d), 1.0):
                return None
            d = float(self.S[-1])
        i = int(np.searchsorted(self.S, d, side="left"))  # S[i-1] < d <= S[i]
        i = max(i, 1)
        u, w = float(self.B[i - 1]), float(self.B[i])
        su = float(self.S[i - 1])
        lo, hi = max(u, after), w
        if self.at(lo) >= d:  # already there (d reached at or before `after`)
            return lo if lo > after else None
        # safeguarded Newton on F(t) = s(t) - d, bracketed by [lo, hi]
        t = lo + (hi - lo) * 0.5
        for _ in range(200):
            f = su + self.integral(u, t) - d
            if f >= 0.0:
                hi = t
            else:
                lo = t
            tol = 4.0 * _EPS * max(abs(t), 1.0)
            if hi - lo <= tol:
                return hi
            sp = float(self.speed(np.array([t]))[0])
            tn = t - f / sp if sp > 0.0 else math.nan
            if not lo < tn < hi:
                tn = 0.5 * (lo + hi)
            if abs(tn - t) <= tol:
                return tn
            t = tn
        return hi
