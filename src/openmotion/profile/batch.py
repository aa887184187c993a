"""Vectorized jerk-limited planning: durations and phase times of many moves at once.

The same closed forms as `jerk.py` (see its module notes for the derivation), evaluated
with numpy over whole arrays: regimes are selected with masks and the mixed-regime root
is found with a fixed number of monotone Newton steps, so there is no Python loop over
moves. Results equal the scalar planner's to ~1e-15 relative.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import COUNTER28_MAX, MotionError
from ..limits import as_array
from .jerk import NEWTON_STEPS

Array = NDArray[np.float64]

CHUNK = 16384  # moves per vectorized pass


def _arr(name: str, value: ArrayLike, *, kind: str = "") -> Array:
    return as_array(name, value, kind or None, zero=not kind, signed=not kind)


def _ramp_distance(v: Array, x: Array, j: Array) -> Array:
    sat = v * j >= x * x
    return np.where(sat, v * (v / x + x / j) / 2.0, v * np.sqrt(v / j))


def _peak_velocity(length: Array, v_max: Array, a_max: Array, d_max: Array,
                   j_max: Array) -> Array:
    """Vectorized `jerk.peak_velocity` (length > 0 everywhere)."""
    lo = np.minimum(a_max, d_max)
    hi = np.maximum(a_max, d_max)
    v2 = hi * hi / j_max
    cruise = _ramp_distance(v_max, a_max, j_max) + _ramp_distance(v_max, d_max, j_max) <= length
    both = _ramp_distance(v2, hi, j_max) + _ramp_distance(v2, lo, j_max) <= length
    neither = length <= 2.0 * lo * lo * lo / (j_max * j_max)

    k = (1.0 / a_max + 1.0 / d_max) / 2.0
    c = (a_max + d_max) / (2.0 * j_max)
    v_both = 2.0 * length / (c + np.sqrt(c * c + 4.0 * k * length))
    v_neither = (length * np.sqrt(j_max) / 2.0) ** (2.0 / 3.0)

    vp = np.where(cruise, v_max, np.where(both, v_both, v_neither))
    mixed = np.flatnonzero(~(cruise | both | neither))
    if mixed.size:  # only these need the Newton iteration
        L, h, jm = length[mixed], lo[mixed], j_max[mixed]
        sj = np.sqrt(jm)
        u = np.minimum.reduce([np.sqrt(v2[mixed]), (2.0 * h * L) ** 0.25, np.cbrt(L * sj),
                               np.sqrt(2.0 * jm * L / h)])
        for _ in range(NEWTON_STEPS):
            u2 = u * u
            g = u2 * u2 / (2.0 * h) + u2 * u / sj + u2 * h / (2.0 * jm) - L
            dg = 2.0 * u2 * u / h + 3.0 * u2 / sj + u * h / jm
            step = np.where((g > 0.0) & (dg > 0.0), g / np.where(dg > 0.0, dg, 1.0), 0.0)
            u = np.minimum(u, u - step)  # monotone from above, as in the scalar code
        vp[mixed] = np.minimum(u * u, v_max[mixed])
    return vp


def _chunk_phases(length: Array, v: Array, a: Array, d: Array, j: Array) -> Array:
    moving = length > 0.0
    safe_len = np.where(moving, length, 1.0)
    vp = _peak_velocity(safe_len, v, a, d, j)
    out = np.empty((length.size, 7))
    for col_j, col_c, x in ((0, 1, a), (4, 5, d)):
        sat = vp * j >= x * x
        tj = np.where(sat, x / j, np.sqrt(vp / j))
        out[:, col_j] = tj
        out[:, col_j + 2] = tj
        out[:, col_c] = np.where(sat, vp / x - x / j, 0.0)
    rest = safe_len - _ramp_distance(vp, a, j) - _ramp_distance(vp, d, j)
    out[:, 3] = np.maximum(rest / vp, 0.0)
    # pure jerk triangle: tj straight from L = 2*J*tj**3, as the scalar code does
    tri = (vp < v) & (vp * j < np.minimum(a, d) ** 2)
    if tri.any():
        tj = (safe_len[tri] / (2.0 * j[tri])) ** (1.0 / 3.0)
        out[tri] = 0.0
        out[tri, 0] = out[tri, 2] = out[tri, 4] = out[tri, 6] = tj
    out[~moving] = 0.0
    return out


def _total(ph: Array) -> Array:
    tj1, ta, _, tv, tj2, td, _ = ph.T
    # The scalar code sums with math.fsum; this plain sum differs by a few ulps at most.
    return 2.0 * tj1 + ta + tv + 2.0 * tj2 + td


def _phases(distance: ArrayLike, v_max: ArrayLike, a_max: ArrayLike, j_max: ArrayLike,
            d_max: ArrayLike | None, *, totals: bool = False) -> tuple[Array, tuple[int, ...]]:
    """(N, 7) phase times, or with `totals` only the (N,) durations (8 bytes per move)."""
    dist = _arr("distance", distance)
    if (np.abs(dist) > COUNTER28_MAX).any():
        raise MotionError(f"distance must satisfy |distance| <= {COUNTER28_MAX} everywhere")
    v = _arr("v_max", v_max, kind="pps")
    a = _arr("a_max", a_max, kind="pps2")
    j = _arr("j_max", j_max, kind="pps3")
    d = a if d_max is None else _arr("d_max", d_max, kind="pps2")
    try:
        length, v, a, d, j = np.broadcast_arrays(np.abs(dist), v, a, d, j)
    except ValueError:
        shape = dist.shape
        for name, x in (("v_max", v), ("a_max", a), ("d_max", d), ("j_max", j)):
            try:
                shape = np.broadcast_shapes(shape, x.shape)
            except ValueError:
                raise MotionError(f"{name} has shape {x.shape}, which does not broadcast "
                                  f"with distance and the limits before it "
                                  f"{shape}") from None
        raise MotionError("distance and limits must have broadcastable shapes") from None
    shape = length.shape
    length, v, a, d, j = (x.reshape(-1) for x in (length, v, a, d, j))

    out = np.zeros(length.size if totals else (length.size, 7))
    for k in range(0, length.size, CHUNK):  # chunks keep the temporaries in cache
        sl = slice(k, k + CHUNK)
        # np.where evaluates every branch; overflow in an unselected one is harmless
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            ph = _chunk_phases(length[sl], v[sl], a[sl], d[sl], j[sl])
        out[sl] = _total(ph) if totals else ph
    if not np.isfinite(out).all():
        raise MotionError("distance, v_max, a_max, d_max and j_max must be within a numeric "
                          "range where the phase times are finite (magnitudes ~1e-100..1e100)")
    return out, shape


def jerk_limited_phases(distance: ArrayLike, v_max: ArrayLike, a_max: ArrayLike,
                        j_max: ArrayLike, d_max: ArrayLike | None = None) -> Array:
    """Phase durations, shape (N, 7), of the time-optimal moves (arguments broadcast).

    Column order as in `jerk.PHASE_LABELS`: jerk-in, const-acc, jerk-out, cruise,
    jerk-in (dec), const-dec, jerk-out (dec). Zero distances give zero rows.
    """
    return _phases(distance, v_max, a_max, j_max, d_max)[0]


def jerk_limited_durations(distance: ArrayLike, v_max: ArrayLike, a_max: ArrayLike,
                           j_max: ArrayLike, d_max: ArrayLike | None = None) -> Array:
    """Durations of the time-optimal rest-to-rest moves, shaped like the broadcast inputs."""
    total, shape = _phases(distance, v_max, a_max, j_max, d_max, totals=True)
    return total.reshape(shape)
