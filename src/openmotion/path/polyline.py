"""Blended look-ahead for a polyline in one vectorised pass: corners, limits, speeds.

`plan_polyline(points, ...)` gives what rounding every corner of the lines through `points`
with `blend.blend_corner` (each corner on the line the previous corner trimmed) and then
`lookahead.plan_speeds` on the resulting lines and arcs give, within rounding (1e-9
relative), but computes all corners, element limits and junction caps at once on whole
numpy arrays instead of small arrays per corner, and never re-validates the points it
made itself. Only the trim distances (each corner may use at most `fraction` of what the
previous corner left of the line) and the speed passes are sequential, on plain floats.

The result `PolylinePlan` holds the pieces as arrays (a line or a blend arc each, with its
entry/cruise/exit speed and acceleration); `elements()` and `speeds()` build the Line/Arc3D
and ElementSpeeds objects when a caller needs them. Consecutive equal points are merged
(a zero-length line has no direction to blend).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InfeasibleError, MotionError, check_nonnegative, check_positive
from .arcs import Arc3D
from .blend import BLEND_DIST_FRACTION, REVERSAL_ANGLE, TANGENT_ANGLE
from .geometry import Array, Line, frozen
from .lookahead import ElementSpeeds, _cruise_caps, _passes, check_planner_limits

_SQRT2_M1 = math.sqrt(2.0) - 1.0


@dataclass(frozen=True, eq=False)
class PolylinePlan:
    """The planned pieces of a blended polyline, in path order (M pieces).

    `is_arc[k]` tells a blend arc from a (trimmed) line; `start`/`end` are (M, N) points;
    for arcs, `centre`, `e1`, `e2` (rows), `radius` and `sweep` give the circle as in
    `Arc3D.from_frame` (zeros/0 for lines). The speeds follow `ElementSpeeds`: accelerate
    at `accel` from `entry` to `cruise`, hold, brake to `exit` over `length`.
    `deviation[j]` is how far the path passes from inner point j+1 (0: not blended)."""

    is_arc: np.ndarray
    start: Array
    end: Array
    centre: Array
    e1: Array
    e2: Array
    radius: Array
    sweep: Array
    length: Array
    entry: Array
    cruise: Array
    exit: Array
    accel: Array
    vmax: Array
    deviation: Array

    @property
    def durations(self) -> Array:
        """Time of each piece's trapezoid (ElementSpeeds.duration, vectorised)."""
        a, vc, v0, v1 = self.accel, self.cruise, self.entry, self.exit
        d_acc = (vc * vc - v0 * v0) / (2.0 * a)
        d_dec = (vc * vc - v1 * v1) / (2.0 * a)
        hold = np.maximum(0.0, self.length - d_acc - d_dec)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (vc - v0) / a + (vc - v1) / a + hold / vc
        return np.where((self.length == 0.0) | (vc == 0.0), 0.0, t)

    @property
    def duration(self) -> float:
        """Time along the whole polyline."""
        return float(np.sum(self.durations))

    def elements(self) -> tuple[Line | Arc3D, ...]:
        """The pieces as path elements (Line and Arc3D), joined end to start bit for bit."""
        out: list[Line | Arc3D] = []
        for k in range(self.is_arc.size):
            if self.is_arc[k]:
                out.append(Arc3D.from_frame(self.centre[k], self.e1[k], self.e2[k],
                                            float(self.radius[k]), float(self.sweep[k]),
                                            start=self.start[k], end=self.end[k]))
            else:
                out.append(Line(self.start[k], self.end[k]))
        return tuple(out)

    def speeds(self) -> tuple[ElementSpeeds, ...]:
        """The pieces' speeds as ElementSpeeds (what `plan_speeds` returns)."""
        cols = zip(self.entry.tolist(), self.cruise.tolist(), self.exit.tolist(),
                   self.accel.tolist(), self.vmax.tolist(), self.length.tolist(), strict=True)
        return tuple(ElementSpeeds(*c) for c in cols)


def _points(value: ArrayLike) -> Array:
    try:
        pts = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise MotionError(f"points must be a sequence of points of real numbers, got "
                          f"{value!r}") from None
    if pts.ndim != 2 or pts.shape[1] < 2:
        raise MotionError(f"points must be a (count, axes >= 2) array, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise MotionError("points must be finite in every axis")
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)  # merge repeated points
    pts = pts[keep]
    if len(pts) < 2:
        raise MotionError("points must hold at least two different points")
    return pts


def _per_segment(name: str, value: float | Sequence[float], n: int) -> Array:
    if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
        return np.full(n, check_positive(name, value))
    try:
        arr = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be a number > 0 or {n} of them, got {value!r}") from None
    if arr.size != n or not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise MotionError(f"{name} must be a number > 0 or {n} finite numbers > 0 (one per "
                          f"segment after merging repeated points), got {arr.size} values")
    return arr


def _limit_rows(limit: Array, axis: Array | None, weight: Array) -> Array:
    """Row-wise min(limit, axis_i / weight_i) over axes with weight_i > 0."""
    if axis is None:
        return limit
    with np.errstate(divide="ignore", over="ignore"):
        q = np.where(weight > 0.0, axis / np.where(weight > 0.0, weight, 1.0), np.inf)
    return np.minimum(limit, np.min(q, axis=1))


def _max_abs_cos(beta: Array, sweep: Array) -> Array:
    """max |cos(phi + beta)| for phi in [0, sweep] (rows of beta, one sweep per row)."""
    b = beta + sweep[:, None]
    contains = np.floor(b / math.pi) > np.floor(beta / math.pi)
    ends = np.maximum(np.abs(np.cos(beta)), np.abs(np.cos(b)))
    out = np.where(contains, 1.0, ends)
    out[sweep >= math.pi] = 1.0
    return out


def _norm_rows(v: Array) -> Array:
    return np.sqrt(np.einsum("ij,ij->i", v, v))


def plan_polyline(points: ArrayLike, feed: float | Sequence[float],
                  accel: float | Sequence[float], *, tolerance: float,
                  fraction: float = BLEND_DIST_FRACTION, square_corner_velocity: float = 0.0,
                  start_speed: float = 0.0, end_speed: float = 0.0,
                  axis_vmax: ArrayLike | None = None, axis_amax: ArrayLike | None = None,
                  axis_vjump: ArrayLike | None = None, arc_tangential_ratio: float = 0.5,
                  min_cruise_ratio: float = 0.0) -> PolylinePlan:
    """Round every corner of the polyline through `points` within `tolerance` and plan the
    speeds along it (module docstring): blend_corner at each corner, then plan_speeds.

    `feed`/`accel`: one value or one per segment (a blend arc takes the values of the
    segment it leads into, like a program's command). The other arguments are those of
    `blend_corner` and `plan_speeds`. Corners that are not rounded (tolerance 0, tangent,
    a reversal) are crossed at the junction speed of `square_corner_velocity`.
    """
    pts = _points(points)
    n_seg = len(pts) - 1
    dim = pts.shape[1]
    feeds = _per_segment("feed", feed, n_seg)
    accels = _per_segment("accel", accel, n_seg)
    tol = check_nonnegative("tolerance", tolerance)
    frac = check_positive("fraction", fraction)
    if frac > 0.5:
        raise MotionError(f"fraction must be in (0, 0.5], got {fraction!r}")
    scv, v_start, v_end, vmax_ax, amax_ax, vjump_ax, ratio, mcr = check_planner_limits(
        dim, square_corner_velocity, start_speed, end_speed, axis_vmax, axis_amax, axis_vjump,
        arc_tangential_ratio, min_cruise_ratio)

    # --- segments: lengths and directions (as Line computes them)
    delta = pts[1:] - pts[:-1]
    big = np.max(np.abs(delta), axis=1)
    seg_len = big * _norm_rows(delta / big[:, None])
    u = delta / seg_len[:, None]

    # --- corners j = 0 .. n_seg-2 at pts[j+1], from segment j to j+1
    u1, u2 = u[:-1], u[1:]
    dm = u1 - u2
    dp = u1 + u2
    cos_t = _norm_rows(dm) / 2.0
    sin_t = _norm_rows(dp) / 2.0
    turn = 2.0 * np.arctan2(cos_t, sin_t)
    sharp = turn >= TANGENT_ANGLE
    blend = sharp & (math.pi - turn >= REVERSAL_ANGLE) if tol > 0.0 else \
        np.zeros(n_seg - 1, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_tol = tol * (1.0 + sin_t) / cos_t
    # sequential: a corner may use `frac` of what the previous corner left of its line
    d_list = [0.0] * (n_seg + 1)  # d_list[j]: trim at pts[j] (0 and n_seg: the ends)
    lens = seg_len.tolist()
    dt = d_tol.tolist()
    for j in np.flatnonzero(blend).tolist():  # min() of three, spelled out (hot loop)
        x = frac * (lens[j] - d_list[j])
        y = frac * lens[j + 1]
        x = x if x <= y else y
        y = dt[j]
        d_list[j + 1] = x if x <= y else y
    d_all = np.array(d_list)
    d = d_all[1:-1]

    # --- pieces: line k, then the arc of corner k when blended
    nb = np.flatnonzero(blend)
    n_arc = nb.size
    m = n_seg + n_arc
    line_pos = np.arange(n_seg) + np.concatenate(([0], np.cumsum(blend)))
    arc_pos = line_pos[nb] + 1
    is_arc = np.zeros(m, dtype=bool)
    is_arc[arc_pos] = True
    corner = pts[1:-1]
    a_start = corner[nb] - u1[nb] * d[nb, None]
    a_end = corner[nb] + u2[nb] * d[nb, None]
    l_start = pts[:-1].copy()
    l_end = pts[1:].copy()
    l_end[nb] = a_start
    l_start[nb + 1] = a_end
    start = np.empty((m, dim))
    end = np.empty((m, dim))
    start[line_pos], end[line_pos] = l_start, l_end
    start[arc_pos], end[arc_pos] = a_start, a_end
    ld = l_end - l_start
    lbig = np.max(np.abs(ld), axis=1)
    l_len = lbig * _norm_rows(ld / lbig[:, None])

    # --- blend arcs (blend.blend_corner's closed form, all corners at once)
    cb, sb, db = cos_t[nb], sin_t[nb], d[nb]
    ub1 = u1[nb]
    radius = db * sb / cb
    normal = -dm[nb] / _norm_rows(dm[nb])[:, None]
    centre = corner[nb] + normal * (db / cb)[:, None]
    e1 = -(ub1 * cb[:, None] + normal)
    e1 = e1 - np.einsum("ij,ij->i", e1, ub1)[:, None] * ub1
    e1 = e1 / _norm_rows(e1)[:, None]
    e2 = ub1 - np.einsum("ij,ij->i", ub1, e1)[:, None] * e1
    e2 = e2 / _norm_rows(e2)[:, None]
    sweep = turn[nb]
    arc_len = np.abs(radius * sweep)
    kappa = radius / (radius * radius)

    # --- element limits (lookahead._limits_of)
    lu = np.abs(ld / l_len[:, None])
    l_vmax = _limit_rows(feeds, vmax_ax, lu)
    l_acc = _limit_rows(accels, amax_ax, lu)
    af, aa = feeds[nb + 1], accels[nb + 1]
    k_t = radius * sweep / arc_len
    amp = np.hypot(e1, e2)
    mat = k_t[:, None] * amp * _max_abs_cos(np.arctan2(e1, e2), sweep)
    a_vmax = _limit_rows(af, vmax_ax, mat)
    total = _limit_rows(aa, amax_ax, amp)
    a_acc = ratio * total
    a_vmax = np.minimum(a_vmax, np.sqrt(math.sqrt(1.0 - ratio * ratio) * total / kappa))

    length = np.empty(m)
    acc = np.empty(m)
    cap = np.empty(m)
    length[line_pos], length[arc_pos] = l_len, arc_len
    acc[line_pos], acc[arc_pos] = l_acc, a_acc
    cap[line_pos], cap[arc_pos] = l_vmax, a_vmax
    own_acc = np.empty(m)  # the path acceleration of each piece's segment (junction a_j)
    own_acc[line_pos], own_acc[arc_pos] = accels, aa

    # --- junction caps (v**2), jc[k] at the start of piece k
    jv = np.minimum(cap[:-1], cap[1:])  # tangent joints: the neighbours' caps
    sharp_stop = np.flatnonzero(sharp & ~blend)  # corners crossed unrounded
    if sharp_stop.size:
        k_next = line_pos[sharp_stop + 1]
        jv[k_next - 1] = np.minimum(jv[k_next - 1], _corner_caps(
            u1[sharp_stop], u2[sharp_stop], dm[sharp_stop], dp[sharp_stop],
            np.minimum(own_acc[k_next - 1], own_acc[k_next]), scv, amax_ax, vjump_ax,
            length[k_next - 1], length[k_next]))
    jcap2 = [0.0] * (m + 1)
    jcap2[1:m] = (jv * jv).tolist()
    capl = cap.tolist()
    jcap2[0] = capl[0] ** 2
    jcap2[m] = min(v_end, capl[m - 1]) ** 2

    accl = acc.tolist()
    lenl = length.tolist()
    start2 = v_start * v_start
    back, fwd = _passes(jcap2, accl, lenl, start2)
    if start2 > back[0] * (1.0 + 1e-12):
        raise InfeasibleError(f"start_speed {v_start:g} exceeds the highest speed the path "
                              f"allows at its start, {math.sqrt(back[0]):.6g}")
    ccap = cap
    if mcr > 0.0:
        cap2, jcap2 = _cruise_caps(jcap2, [c * c for c in capl], accl, lenl, mcr, start2)
        ccap = np.sqrt(np.array(cap2))
        back, fwd = _passes(jcap2, accl, lenl, start2)
    f = np.array(fwd)
    vin, vout = np.sqrt(f[:-1]), np.sqrt(f[1:])
    peak2 = 0.5 * (f[:-1] + f[1:]) + acc * length
    cruise = np.maximum(np.maximum(vin, vout), np.minimum(ccap, np.sqrt(peak2)))

    cen, ee1, ee2 = np.zeros((m, dim)), np.zeros((m, dim)), np.zeros((m, dim))
    cen[arc_pos], ee1[arc_pos], ee2[arc_pos] = centre, e1, e2
    rad = np.zeros(m)
    swp = np.zeros(m)
    rad[arc_pos], swp[arc_pos] = radius, sweep
    dev = np.zeros(n_seg - 1)
    dev[nb] = db * (1.0 - sb) / cb
    return PolylinePlan(frozen(is_arc), frozen(start), frozen(end), frozen(cen), frozen(ee1),
                        frozen(ee2), frozen(rad), frozen(swp), frozen(length), frozen(vin),
                        frozen(cruise), frozen(vout), frozen(acc), frozen(cap), frozen(dev))


def _corner_caps(u1: Array, u2: Array, dm: Array, dp: Array, accel: Array, scv: float,
                 amax_ax: Array | None, vjump_ax: Array | None, len1: Array,
                 len2: Array) -> Array:
    """lookahead._junction_cap for rows of corners crossed unrounded (the turn is at least
    TANGENT_ANGLE): junction deviation with the axis-limited acceleration along u2 - u1,
    the half-length caps and the axis velocity steps."""
    diff = -dm
    chord = _norm_rows(diff)
    a_j = _limit_rows(accel, amax_ax, np.abs(diff) / chord[:, None])
    s = scv * np.sqrt(a_j / accel)
    sin_h = _norm_rows(dp) / 2.0
    cos_h = chord / 2.0
    with np.errstate(divide="ignore", invalid="ignore"):
        v2 = s * s * _SQRT2_M1 * sin_h * (1.0 + sin_h) / (cos_h * cos_h)
        tan_h = sin_h / cos_h
    v2 = np.minimum(v2, np.minimum(0.5 * len1 * a_j * tan_h, 0.5 * len2 * a_j * tan_h))
    return _limit_rows(np.sqrt(v2), vjump_ax, np.abs(diff))
