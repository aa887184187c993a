"""The compare engine's solvers (the plain-float _refine of tests/compare_oracle.py, the
compiled compare_math.first_inside) give the very floats of the earlier versions, kept
here as oracles: the speed-ups changed no event time (issue 13, bench/bench_compare.py)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import compare_oracle as cr
from openmotion.control.trigger import compare_math as cm
from openmotion.control.trigger.compare_math import Track
from openmotion.crossings import velocity_roots
from openmotion.history import MotionHistory
from openmotion.profile.segments import ProfileBuilder

_EPS = 2.220446049250313e-16


def refine_oracle(c, v, a, j, lo, hi, s_lo, t_base):  # noqa: ANN001, ANN201
    """compare_roots._refine as it was (one helper call per sign test)."""
    x = 0.5 * (lo + hi)
    for _ in range(200):
        f = c + x * (v + x * (a / 2.0 + x * j / 6.0))
        if (1 if f > 0.0 else -1 if f < 0.0 else 0) == s_lo:
            lo = x
        else:
            hi = x
        tol = 2.0 * _EPS * (abs(t_base) + abs(x))
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


def first_inside_oracle(tracks, centre, maxerr, t, t1, ranges=None):  # noqa: ANN001, ANN201
    """compare_math.first_inside as it was (numpy candidates and positions)."""
    cands = [np.array([t])]
    for k, (tr, c) in enumerate(zip(tracks, centre, strict=True)):
        lo_k, hi_k = ranges[k] if ranges is not None else (-math.inf, math.inf)
        slack = 1e-9 * (abs(c) + maxerr + 1.0)
        if c + maxerr < lo_k - slack or c - maxerr > hi_k + slack:
            return None
        for lvl in (c - maxerr, c + maxerr):
            if not lo_k - slack <= lvl <= hi_k + slack:
                continue
            cands.append(np.array(cr.level_events(tr, float(lvl), t, t1)))
    cand = np.unique(np.concatenate(cands))
    cand = cand[(cand >= t) & (cand <= t1)]
    ok = np.ones(cand.size, dtype=bool)
    for tr, c in zip(tracks, centre, strict=True):
        x = cm.positions(tr, cand)
        tol = 1e-12 * (abs(c) + maxerr + 1.0)
        ok &= np.abs(x - c) <= maxerr + tol
    idx = np.flatnonzero(ok)
    return float(cand[idx[0]]) if idx.size else None


seg = st.tuples(st.floats(1e-4, 0.01), st.floats(-1e7, 1e7), st.floats(-1e4, 1e4))


def _track(segs, v0: float, p0: float) -> tuple[Track, float]:  # noqa: ANN001
    b = ProfileBuilder(p0, v0, v_before=v0)
    for dur, jerk, accel in segs:
        b.segment(dur, jerk, accel=accel)
    h = MotionHistory(1)
    h.append(0, 0.0, b.build())
    r = h.records(0)
    return Track(r["ts"], r["p0"], r["v0"], r["a0"], r["j"]), b.build().duration


@given(c=st.floats(-1e5, 1e5), v=st.floats(-1e5, 1e5), a=st.floats(-1e7, 1e7),
       j=st.floats(-1e9, 1e9), t_base=st.floats(0.0, 1e4), w=st.floats(1e-6, 1e-2))
@settings(max_examples=400, deadline=None)
def test_refine_gives_the_same_float(c, v, a, j, t_base, w):
    # a monotone piece with a sign change: cut at the velocity roots, keep one with a root
    cuts = [0.0, *sorted(r for r in velocity_roots(v, a, j) if 0.0 < r < w), w]
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        flo = c + lo * (v + lo * (a / 2.0 + lo * j / 6.0))
        fhi = c + hi * (v + hi * (a / 2.0 + hi * j / 6.0))
        if flo * fhi < 0.0:
            s = 1 if flo > 0.0 else -1
            assert cr._refine(c, v, a, j, lo, hi, s, t_base) == \
                refine_oracle(c, v, a, j, lo, hi, s, t_base)


@given(sx=st.lists(seg, min_size=1, max_size=4), sy=st.lists(seg, min_size=1, max_size=4),
       vx=st.floats(-5e3, 5e3), vy=st.floats(-5e3, 5e3), px=st.floats(0, 1),
       py=st.one_of(st.none(), st.floats(0, 1)), maxerr=st.floats(0.01, 50.0), w0=st.floats(0, 1),
       w1=st.floats(0, 1), use_ranges=st.booleans())
@settings(max_examples=400, deadline=None)
def test_first_inside_gives_the_same_time(sx, sy, vx, vy, px, py, maxerr, w0, w1,
                                          use_ranges):
    tx, dx = _track(sx, vx, 10.0)
    ty, dy = _track(sy, vy, -3.0)
    T = min(dx, dy)
    py = px if py is None else py  # the same instant on both axes: a hit is possible
    t, t1 = sorted((w0 * T, w1 * T))
    # a centre on the motion (so hits happen), from the positions at fractions of T
    centre = np.array([float(cm.positions(tx, np.array([px * T]))[0]),
                       float(cm.positions(ty, np.array([py * T]))[0])])
    ranges = [cm.track_range(tx, t, t1), cm.track_range(ty, t, t1)] if use_ranges else None
    got = cm.first_inside([tx, ty], centre, maxerr, t, t1, ranges)
    assert got == first_inside_oracle([tx, ty], centre, maxerr, t, t1, ranges)


def test_a_window_hit_on_a_line_is_the_same_time():
    tx, _ = _track([(0.01, 0.0, 2e5)], 1000.0, 0.0)
    ty, _ = _track([(0.01, 0.0, 1e5)], 500.0, 0.0)
    centre = np.array([float(cm.positions(tx, np.array([0.0063]))[0]),
                       float(cm.positions(ty, np.array([0.0063]))[0])])
    for maxerr in (0.01, 1.0, 3.0):
        got = cm.first_inside([tx, ty], centre, maxerr, 0.001, 0.009)
        assert got is not None and 0.001 < got < 0.0063
        assert got == first_inside_oracle([tx, ty], centre, maxerr, 0.001, 0.009)
