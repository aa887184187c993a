"""The jerk-limited profile builder in plain Python: the test oracle of openmotion._profile.

These are the Python versions profile/jerk.py ran before the builder was compiled
(src/openmotion/_profile.c), moved here unchanged in their arithmetic (the
one-implementation rule: src/ holds only the compiled one). `phase_times`, `duration`,
`rest_to_rest`, `synced` and `phases_many` have the compiled module's signatures, so
tests compare the two call for call (tests/test_profile_compiled.py); `build_with_builder`
makes the same profile through ProfileBuilder segment by segment.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence

from openmotion.profile.jerk import PHASE_LABELS
from openmotion.profile.segments import Profile, ProfileBuilder

NEWTON_STEPS = 10  # from within a factor sqrt(3) of the root, 7 reach full double precision


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


# ------------------------------------------------- the compiled module's signatures
def _finite(times: Sequence[float]) -> bool:
    return all(math.isfinite(t) for t in times)


def _pack(rows: list[float]) -> bytes:
    """(t0, p0, v0, a0, j, dt) rows end to end -> the field-major columns as bytes."""
    n = len(rows) // 6
    return struct.pack(f"{6 * n}d", *(rows[6 * k + f] for f in range(6) for k in range(n)))


def _mask(labels: list[str]) -> int:
    return sum(1 << PHASE_LABELS.index(lb) for lb in labels)


def duration(length: float, v_max: float, a_max: float, d_max: float,
             j_max: float) -> float | None:
    times = phase_times(length, v_max, a_max, d_max, j_max)
    return math.fsum(times) if _finite(times) else None


def rest_to_rest(start: float, distance: float, v_max: float, a_max: float, d_max: float,
                 j_max: float) -> tuple[bytes, int, float] | None:
    times = phase_times(abs(distance), v_max, a_max, d_max, j_max)
    if not _finite(times):
        return None
    rows, labels, t = _rows(start, distance, times, a_max, d_max, j_max)
    return _pack(rows), _mask(labels), t


def synced(dists: Sequence[float], starts: Sequence[float], vs: Sequence[float],
           as_: Sequence[float], ds: Sequence[float], js: Sequence[float]
           ) -> tuple[float, bytes, tuple[int, ...]] | None:
    n = len(dists)
    lims = list(zip(vs, as_, ds, js, strict=True))
    peaks = [peak_velocity(abs(x), *lim) if x != 0.0 else 0.0
             for x, lim in zip(dists, lims, strict=True)]
    times = [_times_at(abs(x), *lim, vp) if x != 0.0 else (0.0,) * 7
             for x, lim, vp in zip(dists, lims, peaks, strict=True)]
    if not all(_finite(t) for t in times):
        return None
    durs = [math.fsum(t) for t in times]
    t_sync = max(durs)
    if t_sync <= 0.0:
        return t_sync, b"", (0,) * n
    rows: list[float] = []
    masks = []
    for i in range(n):
        v, a, d, j = lims[i]
        if dists[i] == 0.0:
            masks.append(-1)
            continue
        tm = times[i]
        if durs[i] < t_sync:
            cap = _synced_cap(abs(dists[i]), t_sync, v, a, d, j, peaks[i])
            tm = _times_at(abs(dists[i]), v, a, d, j, peaks[i], v_cap=cap)
        r, labels, _ = _rows(starts[i], dists[i], tm, a, d, j)
        rows += r
        masks.append(_mask(labels))
    return t_sync, _pack(rows), tuple(masks)


def phases_many(length, v_max, a_max, d_max, j_max, out, totals: bool) -> None:
    """The batch, one move at a time (float64 arrays in, `out` filled)."""
    for i in range(len(length)):
        t = phase_times(float(length[i]), float(v_max[i]), float(a_max[i]),
                        float(d_max[i]), float(j_max[i]))
        if totals:
            out[i] = math.fsum(t) if _finite(t) else math.nan
        else:
            out[7 * i:7 * i + 7] = t


def build_with_builder(start: float, distance: float, times: Sequence[float],
                       a_max: float, d_max: float, j_max: float) -> Profile:
    """The same profile through ProfileBuilder, one segment call per phase."""
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
