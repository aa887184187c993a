"""Jerk-limited planning of many moves at once: durations and phase times over arrays.

The same planner as `jerk.py` (see its module notes for the derivation): one compiled
call per chunk of moves (openmotion._profile.phases_many runs the scalar planner's exact
arithmetic over the arrays, so every move's times equal `jerk_limited`'s bit for bit and
the durations `jerk_limited_duration`'s), after the arrays are validated and broadcast here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _profile as _c
from ..errors import COUNTER28_MAX, MotionError
from ..limits import as_array

Array = NDArray[np.float64]

CHUNK = 65536  # moves per compiled call


def _arr(name: str, value: ArrayLike, *, kind: str = "") -> Array:
    return as_array(name, value, kind or None, zero=not kind, signed=not kind)


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

    out = np.empty(length.size if totals else (length.size, 7))
    flat = out.reshape(-1)
    width = 1 if totals else 7
    for k in range(0, length.size, CHUNK):  # chunks: a broadcast input is copied by parts
        sl = slice(k, k + CHUNK)
        _c.phases_many(*(np.ascontiguousarray(x[sl]) for x in (length, v, a, d, j)),
                       flat[k * width:(k + CHUNK) * width], totals)
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
