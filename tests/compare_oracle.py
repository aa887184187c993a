"""The compare engine's solvers in plain Python: the test oracle of openmotion._compare.

These are the Python versions the engine ran before the solvers were compiled
(src/openmotion/_compare_*.c), moved here unchanged in their arithmetic (the
one-implementation rule: src/ holds only the compiled one). The functions have the
compiled module's signatures, so a test can run the whole engine on them by replacing
`compare_math._ck` with this module (`use_oracle`), and compare every fired time, log row
and output waveform with the compiled run (tests/test_compare_compiled.py).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

from openmotion.crossings import velocity_roots

_EPS = 2.220446049250313e-16
_SNAP_RTOL = 1e-10
_GL_PAIRS: list[tuple[float, float]] = []


# ---------------------------------------------------------------------------- level events
def _f(c: float, v: float, a: float, j: float, x: float, level: float, p: float) -> float:
    """Position minus level at local time x, snapped to 0 within rounding of the terms."""
    f = c + x * (v + x * (a / 2.0 + x * j / 6.0))
    scale = abs(level) + abs(p) + abs(x * v) + abs(x * x * a / 2.0) + abs(x * x * x * j / 6.0)
    return 0.0 if abs(f) <= 8.0 * _EPS * scale else f


def _sign(x: float) -> int:
    return 1 if x > 0.0 else -1 if x < 0.0 else 0


def _refine(c: float, v: float, a: float, j: float, lo: float, hi: float, s_lo: int,
            t_base: float) -> float:
    """Root of the monotone cubic in (lo, hi): Newton kept inside the sign bracket."""
    x = 0.5 * (lo + hi)
    tb = abs(t_base)
    a2 = a / 2.0
    up = s_lo > 0
    for _ in range(200):
        f = c + x * (v + x * (a2 + x * j / 6.0))
        if (f > 0.0) if up else (f < 0.0):
            lo = x
        else:
            hi = x
        tol = 2.0 * _EPS * (tb + abs(x))
        if hi - lo <= tol:
            return hi
        d = v + x * (a + x * j / 2.0)
        xn = x - f / d if d != 0.0 else math.nan
        if not lo < xn < hi:
            xn = 0.5 * (lo + hi)
        elif abs(xn - x) <= tol:
            return xn
        x = xn
    return hi


def _events(ts: Sequence[float], p0: Sequence[float], v0: Sequence[float],
            a0: Sequence[float], j0: Sequence[float], level: float, t: float, t1: float,
            direction: int = 0, first: bool = False) -> list[float]:
    n = len(ts)
    out: list[float] = []
    k = 0
    while k + 1 < n and ts[k + 1] <= t:
        k += 1
    s_left: int | None = None
    f_end, ends_at_t1 = 1.0, False
    while k < n:
        tk = float(ts[k])
        if tk > t1:
            break
        end = float(ts[k + 1]) if k + 1 < n else math.inf
        xa, xb = max(t - tk, 0.0), min(end, t1) - tk
        p, v, a, j = float(p0[k]), float(v0[k]), float(a0[k]), float(j0[k])
        c = p - level
        cuts = [xa, *sorted(r for r in velocity_roots(v, a, j) if xa < r < xb), xb]
        for u, w in zip(cuts[:-1], cuts[1:], strict=True):
            if not w > u:
                continue
            fu = _f(c, v, a, j, u, level, p)
            fw = _f(c, v, a, j, w, level, p)
            su, sw = _sign(fu), _sign(fw)
            if s_left is None:
                s_left = su
            elif (s_left < 0 <= fu and direction >= 0) or (s_left > 0 >= fu and direction <= 0):
                out.append(tk + u)
                if first:
                    return out
            if su * sw < 0 and (direction == 0 or direction == -su):
                out.append(tk + _refine(c, v, a, j, u, w, su, tk))
                if first:
                    return out
            s_left = sw if sw != 0 else su
            f_end, ends_at_t1 = fw, end >= t1
        k += 1
    if ends_at_t1 and f_end == 0.0 and s_left and (direction == 0 or direction == -s_left):
        out.append(t1)
    return out


def _lists(track) -> tuple[list[float], ...]:  # noqa: ANN001
    return tuple(list(map(float, c)) for c in track)


def level_events(track, level: float, t: float, t1: float, direction: int = 0,  # noqa: ANN001
                 first: bool = False) -> list[float]:
    return _events(*_lists(track), float(level), t, t1, direction, first)


def track_range(track, ta: float, t1: float) -> tuple[float, float]:  # noqa: ANN001
    ts, p0, v0, a0, j0 = _lists(track)
    lo, hi = math.inf, -math.inf
    n = len(ts)
    for k in range(n):
        a_k = ts[k]
        b_k = ts[k + 1] if k + 1 < n else math.inf
        u, w = max(a_k, ta), min(b_k, t1)
        if w < u:
            continue
        p, v, a, j = p0[k], v0[k], a0[k], j0[k]
        xs = [u - a_k, w - a_k] + [r for r in velocity_roots(v, a, j) if u - a_k < r < w - a_k]
        for x in xs:
            y = p + x * (v + x * (a / 2.0 + x * j / 6.0))
            lo, hi = min(lo, y), max(hi, y)
    return lo, hi


def _level(levels, n: int, after, k: int) -> float:  # noqa: ANN001
    if k < n:
        if isinstance(levels, tuple):
            return levels[0] + k * levels[1]
        return float(levels[k])
    return float(after)


def level_scan(track, rng, levels, n, after_final, index, t, t1, direction):  # noqa: ANN001, ANN201
    """LevelJob.scan's loop on an axis track, as it was in Python."""
    rec = _lists(track)
    lo, hi = rng
    size = n + (after_final is not None)
    out = []
    while index < size:
        lvl = _level(levels, n, after_final, index)
        slack = 1e-9 * (abs(lvl) + 1.0)
        if not lo - slack <= lvl <= hi + slack:
            break
        times = _events(*rec, lvl, t, t1, direction, first=True)
        if not times:
            break
        out.append((times[0], lvl))
        index += 1
        t = times[0]
    return out


# ---------------------------------------------------------------------------- window
def _position(rec: tuple[list[float], ...], x: float) -> float:
    ts, p0, v0, a0, j = rec
    k = max(bisect.bisect_right(ts, x) - 1, 0)
    dt = x - ts[k]
    return p0[k] + dt * (v0[k] + dt * (a0[k] / 2.0 + dt * j[k] / 6.0))


def first_inside(tracks, centre, maxerr: float, t: float, t1: float,  # noqa: ANN001
                 ranges=None) -> float | None:  # noqa: ANN001
    """compare_math.first_inside as it was in Python (plain floats, a set of candidates)."""
    cands = {t}
    rows = []
    for k, (tr, c_) in enumerate(zip(tracks, centre, strict=True)):
        c = float(c_)
        lo_k, hi_k = ranges[k] if ranges is not None else (-math.inf, math.inf)
        slack = 1e-9 * (abs(c) + maxerr + 1.0)
        if c + maxerr < lo_k - slack or c - maxerr > hi_k + slack:
            return None
        rec = _lists(tr)
        rows.append((rec, c, maxerr + 1e-12 * (abs(c) + maxerr + 1.0)))
        for lvl in (c - maxerr, c + maxerr):
            if not lo_k - slack <= lvl <= hi_k + slack:
                continue
            cands.update(_events(*rec, float(lvl), t, t1))
    for x in sorted(cands):
        if not t <= x <= t1:
            continue
        if all(abs(_position(rec, x) - c) <= lim for rec, c, lim in rows):
            return float(x)
    return None


def window_scan(tracks, ranges, points, maxerr, index, t, t1):  # noqa: ANN001, ANN201
    """WindowJob.scan's loop, as it was in Python."""
    out = []
    while index < len(points):
        tf = first_inside(tracks, points[index], maxerr, t, t1, ranges)
        if tf is None:
            break
        out.append(tf)
        index += 1
        t = tf
    return out


def positions(tracks, times, out) -> None:  # noqa: ANN001
    """Every track's position at each time into out[i, k] (compare_math.positions)."""
    for i, x in enumerate(times):
        for k, tr in enumerate(tracks):
            out[i, k] = _position(_lists(tr), float(x))


# ---------------------------------------------------------------------------- path length
def set_gauss(x, w) -> None:  # noqa: ANN001
    _GL_PAIRS[:] = list(zip(list(map(float, x)), list(map(float, w)), strict=True))


def gl(q, a: float, b: float) -> float:  # noqa: ANN001
    q0, q1, q2, q3, q4 = q
    h = 0.5 * (b - a)
    acc = 0.0
    for xg, wg in _GL_PAIRS:
        x = a + h * (xg + 1.0)
        y = q0 + x * (q1 + x * (q2 + x * (q3 + x * q4)))
        acc += wg * math.sqrt(y) if y > 0.0 else 0.0
    return h * acc


def adaptive(q, a: float, b: float, rtol: float, max_depth: int, depth: int = 0) -> float:  # noqa: ANN001
    m = 0.5 * (a + b)
    whole = gl(q, a, b)
    halves = gl(q, a, m) + gl(q, m, b)
    if abs(halves - whole) <= rtol * max(abs(halves), 1e-300) or depth >= max_depth:
        return halves
    return (adaptive(q, a, m, rtol, max_depth, depth + 1)
            + adaptive(q, m, b, rtol, max_depth, depth + 1))


def _row(Q, i: int) -> tuple[float, ...]:  # noqa: ANN001
    return tuple(float(x) for x in Q[i])


def vector_at(B, S, Q, t: float) -> float:  # noqa: ANN001
    i = min(max(bisect.bisect_right(list(B), t) - 1, 0), len(B) - 2)
    return float(S[i]) + gl(_row(Q, i), 0.0, t - float(B[i]))


def time_of(B, S, Q, d: float, after: float) -> float | None:  # noqa: ANN001
    """VectorCycle.time_of as it was in Python."""
    if d > S[-1]:
        if d - S[-1] > _SNAP_RTOL * max(abs(d), 1.0):
            return None
        d = float(S[-1])
    i = max(bisect.bisect_left(list(S), d), 1) - 1
    u = float(B[i])
    lo, hi = max(after, u) - u, float(B[i + 1]) - u
    su = float(S[i])
    q = _row(Q, i)
    if su + gl(q, 0.0, lo) >= d:
        return u + lo if u + lo > after else None
    q0, q1, q2, q3, q4 = q
    x = 0.5 * (lo + hi)
    for _ in range(100):
        f = su + gl(q, 0.0, x) - d
        if f >= 0.0:
            hi = x
        else:
            lo = x
        tol = 4.0 * _EPS * max(abs(u + x), 1.0)
        if hi - lo <= tol:
            return u + hi
        sp = math.sqrt(max(q0 + x * (q1 + x * (q2 + x * (q3 + x * q4))), 0.0))
        xn = x - f / sp if sp > 0.0 else math.nan
        if abs(xn - x) <= tol:
            return u + max(xn, x) if f < 0.0 else u + x
        if not lo < xn < hi:
            xn = 0.5 * (lo + hi)
        x = xn
    return u + hi


def vector_scan(B, S, Q, levels, n, after_final, index, t, first_only):  # noqa: ANN001, ANN201
    """LevelJob.scan's loop on a path length, as it was in Python."""
    size = n + (after_final is not None)
    out = []
    while index < size:
        lvl = _level(levels, n, after_final, index)
        tf = time_of(B, S, Q, lvl, t)
        if tf is None:
            break
        out.append((tf, lvl))
        if first_only:
            break
        index += 1
        t = tf
    return out


def vector_cycle_numpy(tracks, weights, ta: float, t1: float, s0: float):  # noqa: ANN001, ANN201
    """VectorCycle.__init__ as it was in numpy, whole: (B, Q, S) (tracks: Track rows)."""
    import numpy as np

    B, Q, R = (np.frombuffer(x) for x in vector_pieces(tracks, weights, ta, t1))
    n = B.size - 1
    Q, R = Q.reshape(n, 5), R.reshape(2, n, 8)
    w = np.array([wg for _, wg in _GL_PAIRS])
    d1 = np.ascontiguousarray(R[0]) @ w  # (the old code's two fresh (n, 8) @ w products)
    d2 = np.ascontiguousarray(R[1]) @ w
    return B, Q, np.frombuffer(vector_sums(B, Q, d1, d2, s0, 1e-13, 10))


def vector_pieces(tracks, weights, ta: float, t1: float):  # noqa: ANN001, ANN201
    """VectorCycle.__init__'s pieces as it was in numpy: B, Q and the node speeds R
    (bytes, the compiled module's form; the products with the weights stay numpy's)."""
    import numpy as np

    tracks = [spec_track(s, ta, t1) for s in tracks]
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
    B = np.array(sorted(bps))
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
    H = B[1:] - u
    gx = np.array([x for x, _ in _GL_PAIRS])

    def sq_rows(x):  # noqa: ANN001, ANN202
        y = Q[:, 0:1] + x * (Q[:, 1:2] + x * (Q[:, 2:3] + x * (Q[:, 3:4] + x * Q[:, 4:5])))
        return np.sqrt(np.maximum(y, 0.0))

    x1 = (H[:, None] / 2.0) * (gx[None, :] + 1.0)
    xa = (H[:, None] / 4.0) * (gx[None, :] + 1.0)
    r1 = sq_rows(x1)
    r2 = sq_rows(xa) + sq_rows(xa + H[:, None] / 2.0)
    return B.tobytes(), Q.tobytes(), r1.tobytes() + r2.tobytes()


def vector_sums(B, Q, d1, d2, s0: float, rtol: float, max_depth: int):  # noqa: ANN001, ANN201
    """VectorCycle.__init__'s sums as it was in numpy (d1, d2: the weight products)."""
    import numpy as np

    H = B[1:] - B[:-1]
    one = (H / 2.0) * d1
    two = (H / 4.0) * d2
    bad = np.abs(two - one) > rtol * np.maximum(np.abs(two), 1e-300)
    for i in np.flatnonzero(bad):
        two[i] = adaptive(_row(Q, i), 0.0, float(H[i]), rtol, max_depth)
    return (s0 + np.concatenate([[0.0], np.cumsum(two)])).tobytes()


# ---------------------------------------------------------------------------- output lines
def line_set(t_list: list[float], lv_list: list[bool], initial: bool, times, levels,  # noqa: ANN001
             sent_until: float, late: list[float]) -> None:
    """OutputLine.set, one call after the other, as it was in Python."""
    for t, level in zip(list(map(float, times)), levels, strict=True):
        k = bisect.bisect_right(t_list, t)
        before = lv_list[k - 1] if k else initial
        after_same = k < len(t_list) and lv_list[k] == level
        if before == level and not after_same:
            continue
        if t <= sent_until:
            late.append(t)
        t_list.insert(k, t)
        lv_list.insert(k, bool(level))
        for i in (k + 1, k):
            if 0 <= i < len(t_list):
                prev = lv_list[i - 1] if i else initial
                if lv_list[i] == prev:
                    del t_list[i]
                    del lv_list[i]


# ---------------------------------------------------------------------------- scan driver
def solver_checks(on: bool) -> tuple[int, int]:  # noqa: ARG001
    """(The compiled module's test switch; the oracle refines every candidate.)"""
    return (0, 0)


def bank_new(specs):  # noqa: ANN001, ANN201
    """The jobs of a scan group, as given (see bank_scan)."""
    return [tuple(s) for s in specs]


def spec_track(spec, ta: float, t1: float):  # noqa: ANN001, ANN201
    """A track spec (hist, scale, offset, e0, slope, t_ref) as CompareEngine.track builds
    it in Python: MotionHistory.rows of the window, then affine_track ((hist,): the rows;
    a 5-tuple: as is)."""
    if len(spec) not in (1, 6):
        return spec
    from openmotion.control.trigger.compare_math import Track, affine_track

    h = spec[0]
    lo = max(h.index_at(ta) - 1, h.lo)
    hi = max(h.index_at(t1), lo) + 1
    tr = Track(*(c[lo:hi] for c in (h.ts, h.p0, h.v0, h.a0, h.j)))
    if len(spec) == 1:  # (hist,): the rows as stored (MotionHistory.rows)
        return tr
    return affine_track(tr, *spec[1:])


def bank_scan(bank, jobs, tracks, lines, pos_tracks, ta: float, t1: float,  # noqa: ANN001, ANN201
              vectors=()):  # noqa: ANN001
    """CompareEngine's job loop for LevelJob (axis or path length) / WindowJob with Toggle,
    SetLevel or Pulse, as it was in Python: each job's scan, its action on its line, its
    row. vectors: (B, S, Q) of each path-length source."""
    tracks = [spec_track(s, ta, t1) for s in tracks]
    pos_tracks = [spec_track(s, ta, t1) for s in pos_tracks]
    ranges: dict[int, tuple[float, float]] = {}
    f: list[tuple[float, float]] = []
    k: list[tuple[int, int, int, int]] = []
    done: list[int] = []
    for i, (spec, job) in enumerate(zip(bank, jobs, strict=True)):
        (code, slots, direction, repeat, vals, n, after, maxerr, t_armed, jid, act, flag,
         width, ln, output) = spec
        rng = [] if code == 2 else [ranges.setdefault(s, track_range(tracks[s], ta, t1))
                                    for s in slots]
        a = max(ta, t_armed)
        hits: list[tuple[float, float, int]] = []
        if code == 2:  # LevelJob.scan on a VectorSource
            size = n + (after is not None)
            B, S, Q = vectors[slots[0]]
            if a < t1:
                if repeat:
                    hits = [(tf, v, 0) for tf, v in vector_scan(B, S, Q, vals, n, after, 0, a,
                                                                True)]
                elif job.index < size:
                    found = vector_scan(B, S, Q, vals, n, after, job.index, a, False)
                    hits = [(tf, v, job.index + q) for q, (tf, v) in enumerate(found)]
                    job.index += len(found)
            finished = not repeat and job.index >= size
        elif code == 0:
            size = n + (after is not None)
            if a < t1:
                if repeat:
                    lvl = _level(vals, n, after, 0)
                    slack = 1e-9 * (abs(lvl) + 1.0)
                    if rng[0][0] - slack <= lvl <= rng[0][1] + slack:
                        hits = [(tf, lvl, 0) for tf in
                                level_events(tracks[slots[0]], lvl, a, t1, direction, False)]
                elif job.index < size:
                    found = level_scan(tracks[slots[0]], rng[0], vals, n, after, job.index, a,
                                       t1, direction)
                    hits = [(tf, v, job.index + q) for q, (tf, v) in enumerate(found)]
                    job.index += len(found)
            finished = not repeat and job.index >= size
        else:
            if a <= t1 and job.index < n:
                found = window_scan([tracks[s] for s in slots], rng, vals, maxerr, job.index,
                                    a, t1)
                hits = [(tf, float(job.index + q), job.index + q) for q, tf in enumerate(found)]
                job.index += len(found)
            finished = job.index >= n
        if hits:
            line = lines[ln]
            sent = line._sent_until if line.timed else -math.inf
            times, levels, states = [], [], []
            for q, (tf, _, _) in enumerate(hits):
                st = (bool(flag) if (job.hits + q) % 2 == 0 else not flag) if act == 0 \
                    else bool(flag)
                states.append(st)
                times.append(tf)
                levels.append(st)
                if act == 2:
                    times.append(tf + width)
                    levels.append(not st)
            line_set(line._t, line._lv, bool(line.initial), times, levels, sent, line._late)
            job.hits += len(hits)
            f.extend((tf, v) for tf, v, _ in hits)
            k.extend((jid, idx, output, int(st)) for (_, _, idx), st in zip(hits, states,
                                                                           strict=True))
        if finished:
            done.append(i)
    if not f and not done:
        return None
    import numpy as np

    by_time = sorted(range(len(f)), key=lambda q: f[q][0])  # (stable: job, hit order)
    f, k = [f[q] for q in by_time], [k[q] for q in by_time]

    pos = np.empty((len(f), len(pos_tracks)))
    positions(pos_tracks, [x[0] for x in f], pos)
    return (np.array(f, dtype=np.float64).reshape(-1, 2).tobytes(),
            np.array(k, dtype=np.int64).reshape(-1, 4).tobytes(), pos.tobytes(), done)


def lines_send(lines, t0: float, t1: float):  # noqa: ANN001, ANN201
    """OutputLine.send's bookkeeping for all lines (None when a line needs send itself)."""
    cuts = []
    for line in lines:
        a = bisect.bisect_right(line._t, t0)
        if (line._lv[a - 1] if a else line.initial) != line._written:
            return None
        cuts.append((a, bisect.bisect_right(line._t, t1)))
    times, signals, levels = [], [], []
    for line, (a, b) in zip(lines, cuts, strict=True):
        line._sent = (line._t[a:b], line._lv[a:b])
        line._written = line._lv[b - 1] if b else line.initial
        line._sent_until = t1
        line._late.clear()
        line._hold = False
        times += line._t[a:b]
        signals += [line.signal] * (b - a)
        levels += line._lv[a:b]
    return times, signals, levels


def plan_records(hists, t1: float, old=None):  # noqa: ANN001, ANN201
    """The record in force just before t1 of each record store (MotionHistory.record_at),
    as CompareEngine compared them in Python (old given: are they all the same?)."""
    recs = []
    for h in hists:
        k = h.index_at(math.nextafter(t1, -math.inf))
        recs.append(() if k < h.lo else (float(h.ts[k]), float(h.p0[k]), float(h.v0[k]),
                                         float(h.a0[k]), float(h.j[k])))
    return recs if old is None else recs == old


def lines_snapshot(lines, t: float):  # noqa: ANN001, ANN201
    return [line.snapshot(t) for line in lines]


def lines_end(lines, hw, t0: float, t1: float, keep: float) -> None:  # noqa: ANN001
    for line in lines:
        line.flush(hw, t0, t1)
        line.forget_before(keep)
