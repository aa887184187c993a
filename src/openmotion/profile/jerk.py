"""Time-optimal jerk-limited (seven-phase) rest-to-rest moves, single axis and time-synced.

A rest-to-rest move under |v| <= V, acceleration <= A (accelerating), <= D (decelerating)
and |jerk| <= J is, at its fastest, an acceleration ramp 0 -> Vp, a cruise at Vp and a
deceleration ramp Vp -> 0, each ramp the three-phase "S" (jerk +J, 0, -J). The only
unknown is the peak velocity Vp; the phase times follow from it in closed form.

Derivation (one ramp 0 -> V with limit X, zero acceleration at both ends):
    V >= X**2/J (X reached):  T = V/X + X/J,   d = V*T/2 = V**2/(2X) + V*X/(2J)
    V <  X**2/J (triangle):   T = 2*sqrt(V/J), d = V*T/2 = V**1.5/sqrt(J)
(d = V*T/2 because the ramp's velocity is point-symmetric about its midpoint.)
With f(V) = d_acc(V) + d_dec(V) (continuous, increasing), Vp = v_max if f(v_max) <= L,
otherwise the root of f(V) = L:
    both limits reached:  k*V**2 + c*V - L = 0, k = (1/A + 1/D)/2, c = (A + D)/(2J)
    neither reached:      2*V**1.5/sqrt(J) = L  ->  V = (L*sqrt(J)/2)**(2/3)
    only the smaller H reached, u = sqrt(V):
                          g(u) = u**4/(2H) + u**3/sqrt(J) + u**2*H/(2J) - L = 0
g is convex and increasing for u > 0 (it is C1 across the regime borders, and its second
derivative only jumps up there), so Newton started above the root falls monotonically onto
it. Each term alone is <= L at the root and one term is >= L/3, so the root lies within
[m/sqrt(3), m], m = smallest single-term root: ~7 Newton steps reach full precision.

Time sync: with a cruise cap vc <= Vp the duration is T(vc) = T_acc(vc)/2 + T_dec(vc)/2
+ L/vc, decreasing in vc; a slower axis gets the vc with T(vc) = T_sync (bracketed Newton).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import _profile as _c
from ..errors import COUNTER28_MAX, MotionError, check_distance
from ..limits import (
    PPS2_MAX,
    PPS2_MIN,
    PPS3_MAX,
    PPS3_MIN,
    PPS_MAX,
    PPS_MIN,
    PULSES_MAX,
    check_pulses,
    check_quantity,
)
from .segments import Profile, ProfileBuilder, State

#: State(p, v, a) without the Python frame of the namedtuple's __new__ (the same tuple)
_new_state = tuple.__new__

PHASE_LABELS = ("jerk-in", "const-acc", "jerk-out", "cruise", "jerk-in (dec)",
                "const-dec", "jerk-out (dec)")


# ---------------------------------------------------------- the compiled builder
# openmotion._profile (src/openmotion/_profile.c) does the arithmetic above: phase times
# and the pieces (t0, p0, v0, a0, j, dt) of the phases that last, as field-major columns
# in a bytearray, with a mask of the phases that have a piece. Its plain-Python version is
# the test oracle, tests/jerk_oracle.py (bit for bit the same floats).

#: the labels of the phases that last, by the compiled builder's mask (bit k: phase k)
_LABELS = tuple(tuple(lb for k, lb in enumerate(PHASE_LABELS) if m >> k & 1)
                for m in range(128))


def phase_times(length: float, v_max: float, a_max: float, d_max: float,
                j_max: float) -> tuple[float, ...]:
    """The seven phase durations of the fastest move of `length` >= 0 (validated limits)."""
    return _c.phase_times(length, v_max, a_max, d_max, j_max)


# ------------------------------------------------------------------ validation
def _limits(v_max: float, a_max: float, j_max: float,
            d_max: float | None) -> tuple[float, float, float, float]:
    if type(v_max) is float and type(a_max) is float and type(j_max) is float and \
            PPS_MIN <= v_max <= PPS_MAX and PPS2_MIN <= a_max <= PPS2_MAX and \
            PPS3_MIN <= j_max <= PPS3_MAX and (d_max is None or (
                type(d_max) is float and PPS2_MIN <= d_max <= PPS2_MAX)):
        # every value a float within its range: what check_quantity would return
        return v_max, a_max, a_max if d_max is None else d_max, j_max
    v = check_quantity("v_max", v_max, "pps")
    a = check_quantity("a_max", a_max, "pps2")
    j = check_quantity("j_max", j_max, "pps3")
    d = a if d_max is None else check_quantity("d_max", d_max, "pps2")
    return v, a, d, j


def _profile(buf: bytearray, mask: int, start: float, distance: float,
             duration: float) -> Profile:
    """The Profile of the compiled builder's pieces (`buf`, `mask`) from `start`."""
    labels = _LABELS[mask]
    t0, p0, v0, a0, j, dt = np.frombuffer(buf).reshape(6, len(labels))
    z = 0.0 if distance >= 0.0 else -0.0
    # Profile's own fields set at once (it is a frozen dataclass without __post_init__:
    # the same object Profile(...) makes, without its per-field frozen setattr)
    prof = object.__new__(Profile)
    prof.__dict__.update(t0=t0, p0=p0, v0=v0, a0=a0, j=j, duration=duration,
                         start=_new_state(State, (start, z, 0.0)),
                         end=_new_state(State, (start + distance, z, 0.0)),
                         labels=labels, dt=dt)
    return prof


_TIMES_RANGE = ("distance, v_max, a_max, d_max and j_max must be within a numeric range "
                "where the phase times are finite (magnitudes ~1e-100..1e100)")


# ------------------------------------------------------------------- public API
def jerk_limited(distance: float, v_max: float, a_max: float, j_max: float, *,
                 d_max: float | None = None, start: float = 0.0) -> Profile:
    """Time-optimal rest-to-rest jerk-limited move of `distance` pulses from `start`.

    `d_max` limits deceleration separately (None: same as `a_max`). Negative distances move
    backwards; zero gives an empty profile. The profile ends exactly on start + distance.
    """
    dist = check_distance("distance", distance)
    st = check_pulses("start", start)
    v, a, d, j = _limits(v_max, a_max, j_max, d_max)
    built = _c.rest_to_rest(st, dist, v, a, d, j)
    if built is None:
        raise MotionError(_TIMES_RANGE)
    buf, mask, t = built
    return _profile(buf, mask, st, dist, t)


def jerk_limited_duration(distance: float, v_max: float, a_max: float, j_max: float, *,
                          d_max: float | None = None) -> float:
    """Duration of `jerk_limited` without building the profile."""
    dist = check_distance("distance", distance)
    v, a, d, j = _limits(v_max, a_max, j_max, d_max)
    t = _c.duration(abs(dist), v, a, d, j)
    if t is None:
        raise MotionError(_TIMES_RANGE)
    return t


def _per_axis(name: str, value: float | Sequence[float] | None, n: int) -> list:
    if value is None or isinstance(value, (int, float)) or not hasattr(value, "__len__"):
        return [value] * n  # a scalar (or a non-number, refused by its own check)
    try:
        vals = list(value)
    except TypeError:
        raise MotionError(f"{name} must be a number or a sequence of {n} numbers") from None
    if len(vals) != n:
        raise MotionError(f"{name} must have one value per axis ({n} distances), "
                          f"got {len(vals)}")
    return vals


def _plain(vals: object, n: int, lo: float, hi: float) -> Sequence[float] | None:
    """`vals` when it is n floats within [lo, hi] (a float: repeated n times), else None:
    what the per-value checks would return, decided without them (the common case)."""
    if type(vals) is float:
        return (vals,) * n if lo <= vals <= hi else None
    if (type(vals) is not list and type(vals) is not tuple) or len(vals) != n:
        return None
    for x in vals:
        if type(x) is not float or not lo <= x <= hi:
            return None
    return vals


def _plain_axes(distances: object, v_max: object, a_max: object, j_max: object,
                d_max: object, starts: object) -> tuple[Sequence[float], ...] | None:
    """(distances, starts, v, a, d, j) per axis when every value is a float within its
    range, else None (then `_checked_axes` checks one by one and names the bad value)."""
    if (type(distances) is not list and type(distances) is not tuple) or not distances:
        return None
    n = len(distances)
    dists = _plain(distances, n, -float(COUNTER28_MAX), float(COUNTER28_MAX))
    st = (0.0,) * n if starts is None else _plain(starts, n, -PULSES_MAX, PULSES_MAX)
    vs = _plain(v_max, n, PPS_MIN, PPS_MAX)
    as_ = _plain(a_max, n, PPS2_MIN, PPS2_MAX)
    js = _plain(j_max, n, PPS3_MIN, PPS3_MAX)
    ds = as_ if d_max is None else _plain(d_max, n, PPS2_MIN, PPS2_MAX)
    if dists is None or st is None or vs is None or as_ is None or js is None or ds is None:
        return None
    return dists, st, vs, as_, ds, js


def _checked_axes(distances: object, v_max: object, a_max: object, j_max: object,
                  d_max: object, starts: object) -> tuple[Sequence[float], ...]:
    """(distances, starts, v, a, d, j) per axis, every value checked by name."""
    try:
        dists = list(distances)  # type: ignore[call-overload]
    except TypeError:
        raise MotionError("distances must be a sequence of numbers") from None
    n = len(dists)
    if n == 0:
        raise MotionError("distances must hold at least one axis")
    dists = [check_distance(f"distances[{i}]", x) for i, x in enumerate(dists)]
    st = [0.0] * n if starts is None else [
        check_pulses(f"starts[{i}]", x) for i, x in enumerate(_per_axis("starts", starts, n))
    ]
    vs, as_, js, ds = (_per_axis(nm, val, n) for nm, val in
                       (("v_max", v_max), ("a_max", a_max), ("j_max", j_max),
                        ("d_max", d_max)))
    lims = []
    for i in range(n):
        try:
            lims.append(_limits(vs[i], as_[i], js[i], ds[i]))
        except MotionError as e:
            raise MotionError(f"axis {i}: {e}") from None
    vs, as_, ds, js = zip(*lims, strict=True)
    return dists, st, vs, as_, ds, js


def jerk_limited_sync(distances: Sequence[float], v_max: float | Sequence[float],
                      a_max: float | Sequence[float], j_max: float | Sequence[float], *,
                      d_max: float | Sequence[float] | None = None,
                      starts: Sequence[float] | None = None) -> list[Profile]:
    """Jerk-limited moves of several axes that start together and all last T.

    T is the longest per-axis optimum; every other axis cruises slower so that its profile
    lasts exactly T (within its own limits). A zero-distance axis dwells for T.
    Limits are scalars or one value per axis.
    """
    axes = _plain_axes(distances, v_max, a_max, j_max, d_max, starts)
    if axes is None:
        axes = _checked_axes(distances, v_max, a_max, j_max, d_max, starts)
    dists, st, vs, as_, ds, js = axes
    solved = _c.synced(dists, st, vs, as_, ds, js)
    if solved is None:
        raise MotionError(_TIMES_RANGE)
    t_sync, buf, masks = solved
    if t_sync <= 0.0:  # nothing moves (or only by amounts below the times' resolution)
        return [_profile(bytearray(), 0, x, 0.0, 0.0) for x in st]
    out: list[Profile] = []
    flat = np.frombuffer(buf)  # every moving axis's pieces end to end, field by field
    m = len(flat) // 6
    k = 0
    for i, mask in enumerate(masks):
        if mask < 0:  # not moving: a dwell of T
            b = ProfileBuilder(st[i])
            b.segment(t_sync, 0.0, label="dwell")
            out.append(b.build(end_p=st[i]))
            continue
        labels = _LABELS[mask]
        e = k + len(labels)
        t0, p0, v0, a0 = flat[k:e], flat[m + k:m + e], flat[2 * m + k:2 * m + e], \
            flat[3 * m + k:3 * m + e]
        jk, dt = flat[4 * m + k:4 * m + e], flat[5 * m + k:5 * m + e]
        k = e
        z = 0.0 if dists[i] >= 0.0 else -0.0
        prof = object.__new__(Profile)
        # every axis pinned to T (float sums of phase times differ from T in the last ulp)
        prof.__dict__.update(t0=t0, p0=p0, v0=v0, a0=a0, j=jk, duration=t_sync,
                             start=_new_state(State, (st[i], z, 0.0)),
                             end=_new_state(State, (st[i] + dists[i], z, 0.0)),
                             labels=labels, dt=dt)
        out.append(prof)
    return out
