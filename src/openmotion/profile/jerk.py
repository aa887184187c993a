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

import math
from collections.abc import Sequence

import numpy as np

from ..errors import MotionError, check_distance
from ..limits import (
    PPS2_MAX,
    PPS2_MIN,
    PPS3_MAX,
    PPS3_MIN,
    PPS_MAX,
    PPS_MIN,
    check_pulses,
    check_quantity,
)
from .segments import Profile, ProfileBuilder, State

#: State(p, v, a) without the Python frame of the namedtuple's __new__ (the same tuple)
_new_state = tuple.__new__

NEWTON_STEPS = 10  # from within a factor sqrt(3) of the root, 7 reach full double precision

PHASE_LABELS = ("jerk-in", "const-acc", "jerk-out", "cruise", "jerk-in (dec)",
                "const-dec", "jerk-out (dec)")


# ----------------------------------------------------------------- closed-form pieces
def _ramp(v: float, x: float, j: float) -> tuple[float, float]:
    """(jerk time, constant-acceleration time) of the ramp 0 -> v under limit x."""
    if v * j >= x * x:
        return x / j, v / x - x / j
    return math.sqrt(v / j), 0.0


def _ramp_distance(v: float, x: float, j: float) -> float:
    if v * j >= x * x:
        return v * (v / x + x / j) / 2.0
    return v * math.sqrt(v / j)


def _mixed_root(length: float, h: float, j: float, u_hi: float) -> float:
    """Root u = sqrt(V) of g(u) above (only the smaller limit h is reached)."""
    sj = math.sqrt(j)
    u = min(u_hi, (2.0 * h * length) ** 0.25, (length * sj) ** (1.0 / 3.0),
            math.sqrt(2.0 * j * length / h))
    for _ in range(NEWTON_STEPS):
        u2 = u * u
        g = u2 * u2 / (2.0 * h) + u2 * u / sj + u2 * h / (2.0 * j) - length
        dg = 2.0 * u2 * u / h + 3.0 * u2 / sj + u * h / j
        if g <= 0.0 or dg <= 0.0:
            break
        nxt = u - g / dg
        if not nxt < u:
            break
        u = nxt
    return u


def peak_velocity(length: float, v_max: float, a_max: float, d_max: float,
                  j_max: float) -> float:
    """Highest velocity of the time-optimal move of `length` > 0 (see module notes)."""
    if _ramp_distance(v_max, a_max, j_max) + _ramp_distance(v_max, d_max, j_max) <= length:
        return v_max
    lo, hi = min(a_max, d_max), max(a_max, d_max)
    v2 = hi * hi / j_max
    if _ramp_distance(v2, hi, j_max) + _ramp_distance(v2, lo, j_max) <= length:
        k = (1.0 / a_max + 1.0 / d_max) / 2.0
        c = (a_max + d_max) / (2.0 * j_max)
        return 2.0 * length / (c + math.sqrt(c * c + 4.0 * k * length))
    if length <= 2.0 * lo * lo * lo / (j_max * j_max):
        return (length * math.sqrt(j_max) / 2.0) ** (2.0 / 3.0)
    u = _mixed_root(length, lo, j_max, math.sqrt(v2))
    return min(u * u, v_max)


def phase_times(length: float, v_max: float, a_max: float, d_max: float,
                j_max: float, v_cap: float | None = None) -> tuple[float, ...]:
    """The seven phase durations of the fastest move of `length` >= 0 (cruise capped)."""
    if length <= 0.0:
        return (0.0,) * 7
    return _times_at(length, v_max, a_max, d_max, j_max,
                     peak_velocity(length, v_max, a_max, d_max, j_max), v_cap)


def _times_at(length: float, v_max: float, a_max: float, d_max: float, j_max: float,
              vp: float, v_cap: float | None = None) -> tuple[float, ...]:
    """`phase_times` of a `length` > 0 whose peak velocity `vp` is known."""
    if v_cap is not None and v_cap < vp:
        vp = v_cap
    elif vp < v_max and vp * j_max < min(a_max, d_max) ** 2:
        # pure jerk triangle: tj straight from L = 2*J*tj**3 (no underflow for tiny L)
        tj = (length / (2.0 * j_max)) ** (1.0 / 3.0)
        return (tj, 0.0, tj, 0.0, tj, 0.0, tj)
    tj1, ta = _ramp(vp, a_max, j_max)
    tj2, td = _ramp(vp, d_max, j_max)
    rest = length - _ramp_distance(vp, a_max, j_max) - _ramp_distance(vp, d_max, j_max)
    tv = max(0.0, rest / vp)
    return (tj1, ta, tj1, tv, tj2, td, tj2)


def _synced_cap(length: float, t_target: float, v_max: float, a_max: float,
                d_max: float, j_max: float, hi: float | None = None) -> float:
    """Cruise cap vc whose capped move lasts exactly t_target (>= the optimum); `hi`:
    the move's peak velocity when the caller has it."""

    def dur(vc: float) -> tuple[float, float]:
        # T(vc) and dT/dvc, from T = T_acc/2 + T_dec/2 + L/vc.
        t, dt = length / vc, -length / (vc * vc)
        for x in (a_max, d_max):
            if vc * j_max >= x * x:
                t += (vc / x + x / j_max) / 2.0
                dt += 0.5 / x
            else:
                t += math.sqrt(vc / j_max)
                dt += 0.5 / math.sqrt(vc * j_max)
        return t, dt

    if hi is None:
        hi = peak_velocity(length, v_max, a_max, d_max, j_max)
    lo = length / t_target  # T(lo) >= t_target since T(vc) > L/vc
    # Both limits reached at vc (vc*J >= max(A, D)**2): T*vc = k*vc**2 + c*vc + L, a
    # quadratic with k = (1/A + 1/D)/2, c = (A + D)/(2J); its larger root (T decreasing
    # in vc) in one step, polished by the Newton loop below (one or two steps).
    k = 0.5 * (1.0 / a_max + 1.0 / d_max)
    c = (a_max + d_max) / (2.0 * j_max)
    b = t_target - c
    disc = b * b - 4.0 * k * length
    # Newton from the left end L/T_sync: ~3.6 steps on bench_profile's moves, where the
    # start at the peak velocity took ~26 (its first step overshoots, bisection follows)
    vc = lo
    if b > 0.0 and disc >= 0.0:
        q = (b + math.sqrt(disc)) / (2.0 * k)
        if lo < q < hi and q * j_max >= max(a_max, d_max) ** 2:
            vc = q
    for _ in range(200):
        t, dt = dur(vc)
        err = t - t_target
        if err == 0.0:
            return vc
        if err > 0.0:
            lo = vc
        else:
            hi = vc
        nxt = vc - err / dt if dt < 0.0 else 0.5 * (lo + hi)
        if not lo < nxt < hi:
            nxt = 0.5 * (lo + hi)
        if nxt in (lo, hi) or hi - lo <= 4e-16 * hi:
            break
        vc = nxt
    return vc


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


def _check_times(times: Sequence[float]) -> None:
    # a finite sum of the (non-negative) times means every time is finite: one test
    if not math.isfinite(sum(times)) and not all(math.isfinite(t) for t in times):
        raise MotionError("distance, v_max, a_max, d_max and j_max must be within a numeric "
                          "range where the phase times are finite (magnitudes ~1e-100..1e100)")


def _build(start: float, distance: float, times: Sequence[float], a_max: float,
           d_max: float, j_max: float, duration: float | None = None) -> Profile:
    """The seven-phase profile straight from its phase times: the arithmetic of
    ProfileBuilder (same operations in the same order, so bit for bit the same profile,
    tests/test_jerk.py compares them) without its per-segment calls."""
    rows, labels, t = _rows(start, distance, times, a_max, d_max, j_max)
    # one array for all columns (each column a contiguous row of its transpose)
    cols = np.array(rows, dtype=np.float64).reshape(-1, 6).T.copy()
    return _profile(cols, start, distance, labels, t if duration is None else duration)


def _profile(cols: np.ndarray, start: float, distance: float, labels: list[str],
             duration: float) -> Profile:
    """The Profile of the columns (t0, p0, v0, a0, j, dt) as rows of `cols`."""
    dr = 1.0 if distance >= 0.0 else -1.0
    # Profile's own fields set at once (it is a frozen dataclass without __post_init__:
    # the same object Profile(...) makes, without its per-field frozen setattr)
    prof = object.__new__(Profile)
    z = 0.0 * dr
    prof.__dict__.update(t0=cols[0], p0=cols[1], v0=cols[2], a0=cols[3], j=cols[4],
                         duration=duration,
                         start=_new_state(State, (float(start), z, 0.0)),
                         end=_new_state(State, (float(start + distance), z, 0.0)),
                         labels=tuple(labels), dt=cols[5])
    return prof


def _rows(start: float, distance: float, times: Sequence[float], a_max: float,
          d_max: float, j_max: float) -> tuple[list[float], list[str], float]:
    """The phases that last, (t0, p0, v0, a0, j, dt) end to end, their labels and the end
    time. The seven phases are written out one after the other (a loop over them cost
    half of the build)."""
    dr = 1.0 if distance >= 0.0 else -1.0
    tj1, ta, _, tv, tj2, td, _ = times
    a_pk = min(a_max, j_max * tj1)
    d_pk = min(d_max, j_max * tj2)
    # each phase's acceleration at its start and jerk, signed by the direction
    z, ap, dn = 0.0 * dr, a_pk * dr, -d_pk * dr
    jp, jn = j_max * dr, -j_max * dr
    p, v = float(start), 0.0 * dr
    t = 0.0
    rows: list[float] = []  # (t0, p0, v0, a0, j, dt) of each phase that lasts, end to end
    labels: list[str] = []
    if tj1 > 0.0:
        rows += (t, p, v, z, jp, tj1)
        labels.append(PHASE_LABELS[0])
        p = p + tj1 * (v + tj1 * (z / 2.0 + tj1 * jp / 6.0))
        v = v + tj1 * (z + tj1 * jp / 2.0)
        t += tj1
    if ta > 0.0:
        rows += (t, p, v, ap, z, ta)
        labels.append(PHASE_LABELS[1])
        p = p + ta * (v + ta * (ap / 2.0 + ta * z / 6.0))
        v = v + ta * (ap + ta * z / 2.0)
        t += ta
    if tj1 > 0.0:
        rows += (t, p, v, ap, jn, tj1)
        labels.append(PHASE_LABELS[2])
        p = p + tj1 * (v + tj1 * (ap / 2.0 + tj1 * jn / 6.0))
        v = v + tj1 * (ap + tj1 * jn / 2.0)
        t += tj1
    if tv > 0.0:
        rows += (t, p, v, z, z, tv)
        labels.append(PHASE_LABELS[3])
        p = p + tv * (v + tv * (z / 2.0 + tv * z / 6.0))
        v = v + tv * (z + tv * z / 2.0)
        t += tv
    if tj2 > 0.0:
        rows += (t, p, v, z, jn, tj2)
        labels.append(PHASE_LABELS[4])
        p = p + tj2 * (v + tj2 * (z / 2.0 + tj2 * jn / 6.0))
        v = v + tj2 * (z + tj2 * jn / 2.0)
        t += tj2
    if td > 0.0:
        rows += (t, p, v, dn, z, td)
        labels.append(PHASE_LABELS[5])
        p = p + td * (v + td * (dn / 2.0 + td * z / 6.0))
        v = v + td * (dn + td * z / 2.0)
        t += td
    if tj2 > 0.0:
        rows += (t, p, v, dn, jp, tj2)
        labels.append(PHASE_LABELS[6])
        p = p + tj2 * (v + tj2 * (dn / 2.0 + tj2 * jp / 6.0))
        v = v + tj2 * (dn + tj2 * jp / 2.0)
        t += tj2

    return rows, labels, t


def _build_with_builder(start: float, distance: float, times: Sequence[float],
                        a_max: float, d_max: float, j_max: float) -> Profile:
    """The same profile through ProfileBuilder (the reference `_build` is tested against)."""
    b = ProfileBuilder(start, direction=1.0 if distance >= 0.0 else -1.0)
    tj1, ta, _, tv, tj2, td, _ = times
    a_pk = min(a_max, j_max * tj1)
    d_pk = min(d_max, j_max * tj2)
    b.segment(tj1, j_max, accel=0.0, label=PHASE_LABELS[0])
    b.segment(ta, 0.0, accel=a_pk, label=PHASE_LABELS[1])
    b.segment(tj1, -j_max, accel=a_pk, label=PHASE_LABELS[2])
    b.segment(tv, 0.0, accel=0.0, label=PHASE_LABELS[3])
    b.segment(tj2, -j_max, accel=0.0, label=PHASE_LABELS[4])
    b.segment(td, 0.0, accel=-d_pk, label=PHASE_LABELS[5])
    b.segment(tj2, j_max, accel=-d_pk, label=PHASE_LABELS[6])
    b.set_acceleration(0.0)
    return b.build(end_p=start + distance)


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
    times = phase_times(abs(dist), v, a, d, j)
    _check_times(times)
    return _build(st, dist, times, a, d, j)


def jerk_limited_duration(distance: float, v_max: float, a_max: float, j_max: float, *,
                          d_max: float | None = None) -> float:
    """Duration of `jerk_limited` without building the profile."""
    dist = check_distance("distance", distance)
    v, a, d, j = _limits(v_max, a_max, j_max, d_max)
    times = phase_times(abs(dist), v, a, d, j)
    _check_times(times)
    return math.fsum(times)


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


def jerk_limited_sync(distances: Sequence[float], v_max: float | Sequence[float],
                      a_max: float | Sequence[float], j_max: float | Sequence[float], *,
                      d_max: float | Sequence[float] | None = None,
                      starts: Sequence[float] | None = None) -> list[Profile]:
    """Jerk-limited moves of several axes that start together and all last T.

    T is the longest per-axis optimum; every other axis cruises slower so that its profile
    lasts exactly T (within its own limits). A zero-distance axis dwells for T.
    Limits are scalars or one value per axis.
    """
    try:
        dists = list(distances)
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
    peaks = [peak_velocity(abs(x), *lim) if x != 0.0 else 0.0
             for x, lim in zip(dists, lims, strict=True)]
    times = [_times_at(abs(x), *lim, vp) if x != 0.0 else (0.0,) * 7
             for x, lim, vp in zip(dists, lims, peaks, strict=True)]
    for t in times:
        _check_times(t)
    durs = [math.fsum(t) for t in times]
    t_sync = max(durs)
    out: list[Profile | None] = []
    rows: list[float] = []   # every moving axis's phases, one array for all of them
    parts: list[tuple[int, int, list[str]]] = []
    for i in range(n):
        v, a, d, j = lims[i]
        if t_sync <= 0.0:
            out.append(_build(st[i], 0.0, times[i], a, d, j))
            continue
        if dists[i] == 0.0:
            b = ProfileBuilder(st[i])
            b.segment(t_sync, 0.0, label="dwell")
            out.append(b.build(end_p=st[i]))
            continue
        tm = times[i]
        if durs[i] < t_sync:
            cap = _synced_cap(abs(dists[i]), t_sync, v, a, d, j, peaks[i])
            tm = _times_at(abs(dists[i]), v, a, d, j, peaks[i], v_cap=cap)
        r, labels, _ = _rows(st[i], dists[i], tm, a, d, j)
        parts.append((i, len(rows) // 6, labels))
        rows += r
        out.append(None)
    if parts:
        cols = np.array(rows, dtype=np.float64).reshape(-1, 6).T.copy()
        for i, k, labels in parts:
            # Float sums of phase times differ from T in the last ulp; pin every axis to T.
            out[i] = _profile(cols[:, k:k + len(labels)], st[i], dists[i], labels, t_sync)
    return out  # type: ignore[return-value]
