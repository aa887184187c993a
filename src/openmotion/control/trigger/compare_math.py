"""Exact trigger solvers on piecewise-cubic motion (the compare engine's mathematics).

A *track* is a run of constant-jerk records (ts, p0, v0, a0, j) as in MotionHistory: record
k covers [ts[k], ts[k+1]) and the last one is open-ended. The compare engine cuts the
history of each cycle [t0, t1] into tracks in the compared frame (command counter, or the
feedback model) and asks three questions, each answered between cycles, not at cycle ends:

- `first_crossing`: the first time after `t` the track reaches a level (a compare value),
  with the events of MotionHistory.crossings (the compiled level_events);
- `VectorCycle`: the accumulated path length s(t) (ZMotion VECTOR_MOVED) over the cycle and
  the time it reaches a given distance;
- `first_inside`: the first time all axes are within +-maxerr of a point (2-D/3-D tables).

The solvers themselves are compiled (openmotion._compare, src/openmotion/_compare_*.c):
a job's whole scan of a cycle (every value or point it reaches, in turn) is one call. Their
plain-Python versions, which give the same floats, are the test oracle in
tests/compare_oracle.py; `_ck` is the one handle the engine calls them through.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from ...errors import MotionError
from ...history import MotionHistory

try:
    from ... import _compare as _ck_built
except ImportError:  # pragma: no cover - the package's build compiles it
    _ck_built = None

#: the compiled solvers (a test may swap in the Python oracle, tests/compare_oracle.py)
_ck: Any = _ck_built

Array = NDArray[np.float64]

# Gauss-Legendre nodes on [-1, 1]: exact for polynomials of degree <= 15.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_QUAD_RTOL = 1e-13
_QUAD_DEPTH = 10
if _ck is not None:
    _ck.set_gauss(_GL_X, _GL_W)  # the compiled quadrature uses these very floats


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


def _solvers() -> Any:
    if _ck is None:
        raise MotionError("openmotion._compare is not built: run `pip install .` (or "
                          "`python setup.py build_ext --inplace` in a checkout)")
    return _ck


def crossings_after(tr: Track, level: float, t: float, t1: float,
                    direction: int) -> Array:
    """Times in (t, t1] where the track reaches `level` (direction +1 up, -1 down, 0 both).

    The events of MotionHistory.crossings (an upward event: below the level just before,
    at or above it then; a tangent touch counts as reaching it from the side it came
    from; a dwell on the level counts once, on arrival), each root refined by Newton's
    method inside its sign bracket. An arrival exactly at t belongs to the window that
    ended at t, so it is not repeated.
    """
    return np.array(_solvers().level_events(tr, float(level), t, t1, direction, False))


def first_crossing(tr: Track, level: float, t: float, t1: float,
                   direction: int) -> float | None:
    """The first time in (t, t1] the track reaches `level` in `direction`, or None."""
    times = _solvers().level_events(tr, float(level), t, t1, direction, True)
    return times[0] if times else None


LevelValues = Array | tuple[float, float]  # an array, or (start, step): start + k * step


def level_scan(tr: Track, rng: tuple[float, float], levels: LevelValues, n: int,
               after_final: float | None, index: int, t: float,
               t1: float, direction: int) -> list[tuple[float, float]]:
    """A level table's hits in (t, t1]: from value `index` on, the first crossing of each
    value in turn after the previous hit, until one is not reached (or out of the track's
    (min, max) `rng`). Values: `n` of `levels`, then `after_final` (None: none).
    Returns [(time, value), ...]."""
    return _solvers().level_scan(tr, rng, levels, n, after_final, index, t, t1,  # type: ignore[no-any-return]
                                 direction)


# ---------------------------------------------------------------------------- window
# The set of times an axis is within [c - e, c + e] is a union of closed intervals whose left
# ends are the window start or a crossing of c - e or c + e. So the first time all axes are
# inside is one of these candidates: test them in time order with the evaluated positions.
def first_inside(tracks: list[Track], centre: Array, maxerr: float, t: float,
                 t1: float, ranges: list[tuple[float, float]] | None = None) -> float | None:
    """The first time in [t, t1] every track is within +-maxerr of its centre, or None.
    `ranges`: each track's (min, max) over the window, to skip hopeless solver calls."""
    c = np.ascontiguousarray(centre, dtype=np.float64)
    return _solvers().first_inside(tracks, c, maxerr, t, t1, ranges)  # type: ignore[no-any-return]


def window_scan(tracks: list[Track], ranges: list[tuple[float, float]] | None,
                points: Array, maxerr: float, index: int, t: float,
                t1: float) -> list[float]:
    """A point table's hits in [t, t1]: `first_inside` of point `index`, then of the next
    point from that time on, until one is not reached. points: C-contiguous (n, k)."""
    return _solvers().window_scan(tracks, ranges, points, maxerr, index, t, t1)  # type: ignore[no-any-return]


def track_range(tr: Track, ta: float, t1: float) -> tuple[float, float]:
    """(min, max) of the track's position over [ta, t1]: a cheap test that a level cannot
    be reached in this window, so the exact solver is skipped."""
    return _solvers().track_range(tr, ta, t1)  # type: ignore[no-any-return]


# ---------------------------------------------------------------------------- vector distance
# s(t) = integral of |W v(t)| dt with W = diag(weights). Each axis's velocity is a quadratic
# per record, so we cut the cycle at every record start and every root of every axis's
# velocity. On a piece, with x = t - u, speed^2 = Q(x) = sum_i (c0 + c1 x + c2 x^2)^2 is a
# quartic whose coefficients we form once; the speed sqrt(Q) is smooth inside the piece (a
# kink needs all velocities to vanish together, and those instants are piece ends). For a
# single axis or a straight line sqrt(Q) is a polynomial of degree <= 2, which 8-point
# Gauss-Legendre integrates exactly; otherwise (curves) the piece is halved adaptively until
# two levels agree to 1e-13 relative. s(t) = d is solved by safeguarded Newton (s' = speed).
# (Compiled: _compare.vector_pieces / vector_sums; the numpy version is the oracle,
# tests/compare_oracle.vector_cycle_numpy.)
class VectorCycle:
    """Path length over one window [ta, t1] of several axes' tracks, starting at s0.

    tracks: Track rows, or history specs as the scan driver takes them ((hist,) for the
    rows as stored). The pieces and their node speeds are compiled (vector_pieces); the
    two 8-point weight products stay numpy products `(n, 8) @ w`, as they always were
    (their BLAS rounding depends on the kernel and on n; one stacked product makes the
    same two calls), then vector_sums refines the pieces that disagree and sums them."""

    def __init__(self, tracks: list[Any], weights: Array, ta: float, t1: float,
                 s0: float) -> None:
        ck = _solvers()
        w = np.ascontiguousarray(weights, dtype=np.float64)
        b, q, r = ck.vector_pieces(tracks, w, float(ta), float(t1))
        self.B = B = np.frombuffer(b, dtype=np.float64)
        n = B.size - 1
        self.Q = Q = np.frombuffer(q, dtype=np.float64).reshape(n, 5)
        d = np.frombuffer(r, dtype=np.float64).reshape(2, n, 8) @ _GL_W  # (each (n, 8) @ w)
        self.S = np.frombuffer(ck.vector_sums(B, Q, d[0], d[1], float(s0), _QUAD_RTOL,
                                              _QUAD_DEPTH), dtype=np.float64)

    @property
    def end(self) -> float:
        return float(self.S[-1])

    def at(self, t: float) -> float:
        """s(t) for t in the window."""
        return _solvers().vector_at(self.B, self.S, self.Q, t)  # type: ignore[no-any-return]

    def time_of(self, d: float, after: float) -> float | None:
        """First time > `after` with s(t) >= d (s is non-decreasing), or None: safeguarded
        Newton on the piece holding d (s' = speed)."""
        return _solvers().time_of(self.B, self.S, self.Q, d, after)  # type: ignore[no-any-return]

    def scan(self, levels: LevelValues, n: int, after_final: float | None, index: int,
             t: float, first_only: bool) -> list[tuple[float, float]]:
        """A distance table's hits: `time_of` each value from `index` on in turn (see
        level_scan; first_only: the value at `index` only)."""
        return _solvers().vector_scan(self.B, self.S, self.Q, levels, n, after_final,  # type: ignore[no-any-return]
                                      index, t, first_only)
