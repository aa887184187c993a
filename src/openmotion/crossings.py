"""Level crossings of constant-jerk records: exact times a piecewise-cubic position
reaches a level (MotionHistory.crossings, limits, compare and PSO build on it).

Method: split every record in the query range at its critical points (roots of the
velocity quadratic) and at t0, so each piece is monotone. Then, with f = p - level:
- at each piece start tau an event fires when f was < 0 just before tau and f(tau) >= 0
  (upward), or > 0 and <= 0 (downward): this catches arrivals, tangent touches and
  position jumps between records;
- inside a piece with f(u) and f(w) of strictly opposite sign there is exactly one root,
  found by bisection to adjacent floats (the root is the first float where the sign
  has changed).
The sign "just before" a piece start is the sign at the end of the previous piece, or the
sign of its start value when it ends exactly on the level (monotone in between).
Values within a few ulps of the level are snapped onto it, so a tangent touch computed
with rounding error reads as one touch, not as two crossings or none.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

_EPS = float(np.finfo(np.float64).eps)


def _poly(c: Array, v: Array, a: Array, j: Array, dt: Array) -> Array:
    return c + dt * (v + dt * (a / 2.0 + dt * j / 6.0))


def _snapped(f: Array, level: float, p0: Array, v: Array, a: Array, j: Array,
             dt: Array) -> Array:
    scale = abs(level) + np.abs(p0) + np.abs(dt * v) + np.abs(dt * dt * a / 2.0) \
        + np.abs(dt * dt * dt * j / 6.0)
    return np.where(np.abs(f) <= 8.0 * _EPS * scale, 0.0, f)


# A root beyond this many seconds is outside any record: it is left out (NaN) instead of
# computed, so a quotient by a subnormal jerk or acceleration cannot overflow. The scalar
# velocity_roots computes it (as +-inf) and drops it by the same `0 < x < L` test.
_FAR_S = 1e300


def _quotient(num: Array, den: Array, sel: Array) -> Array:
    """num / den where `sel` and the quotient is below _FAR_S in size, else NaN."""
    out = np.full(num.size, np.nan)
    ok = sel & (np.abs(num) / _FAR_S < np.abs(den))
    out[ok] = num[ok] / den[ok]
    return out


def _critical_points(v: Array, a: Array, j: Array) -> tuple[Array, Array]:
    """Roots of the velocity v + a*dt + j*dt**2/2 (NaN where there is none or it lies
    farther than _FAR_S)."""
    half_j = 0.5 * j
    with np.errstate(invalid="ignore"):  # NaN records compare False: no root
        lin = (half_j == 0.0) & (a != 0.0)
        disc = a * a - 4.0 * half_j * v
        quad = (half_j != 0.0) & (disc >= 0.0)
        q = -0.5 * (a + np.copysign(np.sqrt(np.where(quad, disc, 0.0)), a))
        qn = quad & (q != 0.0)
        c1 = np.where(lin, _quotient(-v, a, lin), _quotient(q, half_j, qn))
        c2 = _quotient(v, q, qn)
        c1[quad & (q == 0.0)] = 0.0  # v == a == 0: double root at dt = 0
    return c1, c2


def find_crossings(ts: Array, p0: Array, v0: Array, a0: Array, j0: Array, level: float,
                   t0: float, t1: float) -> tuple[Array, NDArray[np.int8]]:
    """Times in [t0, t1] where records (ts, p0, v0, a0, j0; the last open-ended, times
    before ts[0] at rest at p0[0]) reach `level`, and each one's direction (+1 up, -1
    down). Records are the MotionHistory layout; see the method above."""
    empty = (np.empty(0), np.empty(0, dtype=np.int8))
    if t1 <= ts[0]:
        return empty  # constant (the oldest record's start) before its start
    # Scan from the last record starting before t0, to know the sign just before t0.
    ks = max(int(np.searchsorted(ts, t0, side="left")) - 1, 0)
    ke = int(np.searchsorted(ts, t1, side="right")) - 1
    kc = int(np.searchsorted(ts, t0, side="right")) - 1  # record holding t0 (-1: before all)
    if ke - ks < _SCALAR_RECORDS:
        return _crossings_scalar(ts, p0, v0, a0, j0, level, t0, t1, ks, ke, kc)
    T = ts[ks:ke + 1]
    m = T.size
    L = np.empty(m)
    L[:-1] = np.diff(T)
    L[-1] = t1 - T[-1]
    P, V, A, J = p0[ks:ke + 1], v0[ks:ke + 1], a0[ks:ke + 1], j0[ks:ke + 1]
    C = P - level
    x0 = np.full(m, np.nan)
    r0 = kc - ks
    x0v = t0 - ts[kc] if kc >= 0 else 0.0
    if kc >= ks:
        x0[r0] = x0v
    c1, c2 = _critical_points(V, A, J)
    B = np.column_stack([np.zeros(m), c1, c2, x0, L])
    inner = (B > 0.0) & (L[:, None] > B)
    inner[:, 0] = True
    inner[:, -1] = True
    B = np.where(inner, B, np.nan)
    B.sort(axis=1)
    U, W = B[:, :-1], B[:, 1:]
    ok = W > U  # NaN compares False
    rec = np.broadcast_to(np.arange(m)[:, None], U.shape)[ok]
    u, w = U[ok], W[ok]
    n = u.size
    if n == 0:
        return empty
    c, v, a, j, pr = C[rec], V[rec], A[rec], J[rec], P[rec]
    fu = _snapped(_poly(c, v, a, j, u), level, pr, v, a, j, u)
    fw = _snapped(_poly(c, v, a, j, w), level, pr, v, a, j, w)
    su, sw = np.sign(fu), np.sign(fw)
    s_end = np.where(sw != 0.0, sw, su)  # sign just before each piece's end
    s_left = np.empty(n)
    s_left[0] = su[0]
    s_left[1:] = s_end[:-1]
    in_range = (rec > r0) | ((rec == r0) & (u >= x0v))  # all pieces when t0 < ts[0]
    tau = T[rec] + u
    tau[(rec == r0) & (u == x0v)] = t0

    times = np.zeros((n, 2))
    dirs = np.zeros((n, 2), dtype=np.int8)
    up = in_range & (s_left < 0) & (fu >= 0.0)
    down = in_range & (s_left > 0) & (fu <= 0.0)
    times[:, 0] = tau
    dirs[up, 0] = 1
    dirs[down, 0] = -1

    sel = np.flatnonzero(in_range & (su * sw < 0.0))
    if sel.size:
        lo, hi = u[sel].copy(), w[sel].copy()
        s = su[sel]
        cs, vs, as_, js = c[sel], v[sel], a[sel], j[sel]
        for _ in range(2200):  # enough to reach adjacent floats from any bracket
            mid = 0.5 * (lo + hi)
            active = (mid > lo) & (mid < hi)
            if not active.any():
                break
            same = np.sign(_poly(cs, vs, as_, js, mid)) == s
            lo = np.where(active & same, mid, lo)
            hi = np.where(active & ~same, mid, hi)
        times[sel, 1] = T[rec[sel]] + hi
        dirs[sel, 1] = np.where(s < 0, 1, -1)

    dt1 = L[-1:]
    f1 = _snapped(_poly(C[-1:], V[-1:], A[-1:], J[-1:], dt1), level, P[-1:], V[-1:], A[-1:],
                  J[-1:], dt1)[0]
    d1 = 1 if (s_end[-1] < 0 and f1 >= 0.0) else -1 if (s_end[-1] > 0 and f1 <= 0.0) else 0
    flat_t, flat_d = times.reshape(-1), dirs.reshape(-1)
    keep = flat_d != 0
    out_t, out_d = flat_t[keep], flat_d[keep]
    if d1:
        out_t = np.append(out_t, t1)
        out_d = np.append(out_d, np.int8(d1))
    return out_t, out_d


# Few records (the per-cycle case): the same algorithm in plain floats, which is ~50x
# cheaper than numpy on tiny arrays. Same formulas in the same order, so both paths give
# bit-identical results (tested).
_SCALAR_RECORDS = 8


def _sign(x: float) -> float:
    return 1.0 if x > 0.0 else -1.0 if x < 0.0 else 0.0


def _crossings_scalar(ts: Array, p0: Array, v0: Array, a0: Array, j0: Array, level: float,
                      t0: float, t1: float, ks: int, ke: int,
                      kc: int) -> tuple[Array, NDArray[np.int8]]:
    out_t: list[float] = []
    out_d: list[int] = []
    x0v = t0 - float(ts[kc]) if kc >= 0 else 0.0
    s_left: float | None = None
    last = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for k in range(ks, ke + 1):
        T = float(ts[k])
        L = float(ts[k + 1]) - T if k < ke else t1 - T
        p, v, a, j = float(p0[k]), float(v0[k]), float(a0[k]), float(j0[k])
        c = p - level
        last = (c, v, a, j, p, L)
        bps = [0.0, L]
        bps[1:1] = sorted(x for x in (*velocity_roots(v, a, j), x0v if k == kc else math.nan)
                          if 0.0 < x < L)
        for u, w in zip(bps[:-1], bps[1:], strict=True):
            if not w > u:
                continue
            fu = _snap_scalar(c + u * (v + u * (a / 2.0 + u * j / 6.0)), level, p, v, a, j, u)
            fw = _snap_scalar(c + w * (v + w * (a / 2.0 + w * j / 6.0)), level, p, v, a, j, w)
            su, sw = _sign(fu), _sign(fw)
            if s_left is None:
                s_left = su
            if k > kc or (k == kc and u >= x0v):
                tau = t0 if (k == kc and u == x0v) else T + u
                if s_left < 0 and fu >= 0.0:
                    out_t.append(tau)
                    out_d.append(1)
                elif s_left > 0 and fu <= 0.0:
                    out_t.append(tau)
                    out_d.append(-1)
                if su * sw < 0.0:
                    lo, hi = u, w
                    while True:
                        mid = 0.5 * (lo + hi)
                        if not lo < mid < hi:
                            break
                        if _sign(c + mid * (v + mid * (a / 2.0 + mid * j / 6.0))) == su:
                            lo = mid
                        else:
                            hi = mid
                    out_t.append(T + hi)
                    out_d.append(1 if su < 0 else -1)
            s_left = sw if sw != 0.0 else su
    if s_left is not None:
        c, v, a, j, p, L = last
        f1 = _snap_scalar(c + L * (v + L * (a / 2.0 + L * j / 6.0)), level, p, v, a, j, L)
        if s_left < 0 and f1 >= 0.0:
            out_t.append(t1)
            out_d.append(1)
        elif s_left > 0 and f1 <= 0.0:
            out_t.append(t1)
            out_d.append(-1)
    return np.array(out_t, dtype=np.float64), np.array(out_d, dtype=np.int8)


def _snap_scalar(f: float, level: float, p0: float, v: float, a: float, j: float,
                 dt: float) -> float:
    scale = abs(level) + abs(p0) + abs(dt * v) + abs(dt * dt * a / 2.0) \
        + abs(dt * dt * dt * j / 6.0)
    return 0.0 if abs(f) <= 8.0 * _EPS * scale else f


def velocity_roots(v: float, a: float, j: float) -> tuple[float, ...]:
    """Roots of the velocity v + a*x + j*x**2/2 (the cuts that make a record monotone)."""
    h = 0.5 * j
    if h == 0.0:
        return (-v / a,) if a != 0.0 else ()
    disc = a * a - 4.0 * h * v
    if disc < 0.0:
        return ()
    q = -0.5 * (a + math.copysign(math.sqrt(disc), a))
    return (q / h, v / q) if q != 0.0 else (0.0,)
