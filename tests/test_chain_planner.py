"""The compiled chain planner passes (src/openmotion/_chain.c in openmotion._corner) against
their Python oracle (tests/oracle_chain.py): bit for bit on random chains."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import oracle_chain as oc
from openmotion import _corner
from openmotion.control.groups import pathaxes
from openmotion.control.groups import pathexec as px
from openmotion.errors import InfeasibleError
from openmotion.path import Line, plan_speeds
from openmotion.path.lookahead import ElementSpeeds, _curve_knots

pos = st.floats(1e-6, 1e3, allow_nan=False)
lengths = st.lists(st.one_of(pos, st.just(1e-9), st.floats(0.01, 0.1)), min_size=1,
                   max_size=40)


def _same(a, b) -> None:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape
    assert np.array_equal(a, b) or (a.tobytes() == b.tobytes())


@st.composite
def chains(draw):
    length = draw(lengths)
    n = len(length)
    acc = draw(st.lists(pos, min_size=n, max_size=n))
    dec = draw(st.one_of(st.none(), st.lists(pos, min_size=n, max_size=n)))
    jcap = draw(st.lists(st.one_of(st.just(0.0), st.floats(0.0, 1e4), st.just(math.inf)),
                         min_size=n + 1, max_size=n + 1))
    jcap[n] = min(jcap[n], 1e4)
    start2 = draw(st.one_of(st.just(0.0), st.floats(0.0, 1e4)))
    return length, acc, dec, jcap, start2


@settings(max_examples=300, deadline=None)
@given(chains())
def test_passes_and_speeds_bit_for_bit(case) -> None:
    length, acc, dec, jcap2, start2 = case
    back, fwd = _corner.passes(jcap2, acc, length, start2, dec)
    ob, of = oc.passes(jcap2, acc, length, start2, dec)
    _same(back, ob)
    _same(fwd, of)
    d = acc if dec is None else dec
    ccap = [math.sqrt(x) if math.isfinite(x) else 1e3 for x in back[1:]]
    got = _corner.speeds(fwd, acc, d, ccap, length)
    want = oc.speeds(fwd, acc, d, ccap, length)
    for g, w in zip(got, want, strict=True):
        _same(g, w)


@settings(max_examples=300, deadline=None)
@given(chains(), st.floats(-10.0, 10.0), st.lists(st.booleans(), max_size=40))
def test_curve_from_speeds_bit_for_bit(case, s0, zero) -> None:
    length, acc, dec, jcap2, start2 = case
    d = acc if dec is None else dec
    jcap2 = [min(x, 1e4) for x in jcap2]
    back, fwd = oc.passes(jcap2, acc, length, min(start2, jcap2[0]), d)
    ccap = [math.sqrt(x) for x in back[1:]]
    e, c, x = oc.speeds(fwd, acc, d, ccap, length)
    sp = [ElementSpeeds(e[k], c[k], x[k], acc[k], ccap[k], length[k], d[k])
          for k in range(len(length))]
    for k, z in enumerate(zero[:len(sp)]):  # zero-length elements are skipped
        if z:
            sp[k] = ElementSpeeds(e[k], e[k], e[k], acc[k], 1.0, 0.0, d[k])
    curve = px.curve_from_speeds(sp, s0)
    s, v2 = oc.curve_from_speeds(sp, s0)
    _same(curve.s, s)
    _same(curve.v2, v2)


@settings(max_examples=300, deadline=None)
@given(chains(), st.lists(st.floats(0.0, 1.0), max_size=20), st.sampled_from([0.0, 0.004]),
       st.sampled_from([0.0, 0.003]), st.booleans())
def test_s_profile_bit_for_bit(case, brk, dwell, lead, jump) -> None:
    length, acc, dec, jcap2, start2 = case
    d = acc if dec is None else dec
    jcap2 = [min(x, 1e4) for x in jcap2]
    jcap2[-1] = 0.0
    back, fwd = oc.passes(jcap2, acc, length, min(start2, jcap2[0]), d)
    e, c, x = oc.speeds(fwd, acc, d, [math.sqrt(v) for v in back[1:]], length)
    sp = [ElementSpeeds(e[k], c[k], x[k], acc[k], 1.0, length[k], d[k])
          for k in range(len(length))]
    s, v2 = oc.curve_from_speeds(sp)
    curve = px.SpeedCurve(s, v2, jump=jump)
    s_end = float(s[-1])
    breaks = sorted(b * s_end for b in brk)
    try:
        want = oc.s_profile(s, v2, jump, s_end, breaks, dwell=dwell, lead=lead)
    except InfeasibleError:
        with pytest.raises(InfeasibleError):
            px.s_profile(curve, s_end, breaks, dwell=dwell, lead=lead)
        return
    got = px.s_profile(curve, s_end, breaks, dwell=dwell, lead=lead)
    for name in ("t0", "p0", "v0", "a0", "j", "dt"):
        _same(getattr(got, name), getattr(want, name))
    assert got.duration == want.duration
    assert got.start == want.start and got.end == want.end
    assert got.labels == want.labels


def test_s_profile_stall_raises() -> None:
    curve = px.SpeedCurve(np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.0, 0.0]))
    with pytest.raises(InfeasibleError):
        px.s_profile(curve, 2.0, [])


@settings(max_examples=100, deadline=None)
@given(st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5)), min_size=2, max_size=30),
       st.floats(1.0, 100.0), st.floats(10.0, 1e3), st.floats(0.0, 5.0),
       st.floats(0.0, 20.0), st.floats(-3.0, 3.0))
def test_curve_knots_equal_plan_speeds_then_curve(pts, feed, accel, scv, v0, s0) -> None:
    """The join's one-call plan (`_curve_knots`) gives plan_speeds' trapezoids as knots."""
    els = [Line(np.array(a), np.array(b)) for a, b in zip(pts[:-1], pts[1:], strict=True)]
    kw = {"square_corner_velocity": scv, "axis_vmax": np.array([50.0, 80.0]),
          "axis_amax": np.array([500.0, 900.0])}
    try:
        sp = plan_speeds(els, feed, accel, start_speed=v0, **kw)
    except InfeasibleError:  # the fast plan gives up too (None), or raises the same
        with contextlib.suppress(InfeasibleError):
            assert _curve_knots(els, feed, accel, s0, start_speed=v0, **kw) is None
        return
    fast = _curve_knots(els, feed, accel, s0, start_speed=v0, **kw)
    if all(el.length == 0.0 for el in els):
        assert fast is None
        return
    assert fast is not None
    s, v2 = oc.curve_from_speeds(list(sp), s0)
    _same(fast[0], s)
    _same(fast[1], v2)
    assert fast[2] == min(x.decel for x in sp if x.length > 0.0)


def test_bad_arguments_raise() -> None:
    with pytest.raises(ValueError):
        _corner.passes([0.0], [1.0], [1.0], 0.0, None)  # jcap2 needs n + 1 values
    with pytest.raises(TypeError):
        _corner.passes([0.0, 0.0], ["a"], [1.0], 0.0, None)
    with pytest.raises(ValueError):
        _corner.curve([1.0], [1.0], [1.0], [1.0], [1.0], [1.0], 0.0, 1.0, np.empty((2, 1)))
    with pytest.raises(ValueError):
        _corner.s_pieces(np.zeros(0), np.zeros(0), np.zeros(0), 1.0, 0.0, 0.0,
                         np.empty((6, 1)))


def test_random_chains_bit_for_bit() -> None:
    """Long chains of arbitrary doubles (hypothesis favours round numbers; the rounding
    of x ** 2 against x * x, for one, shows only on a few in a thousand)."""
    rng = np.random.default_rng(14)
    for _ in range(5):
        n = 2000
        length = rng.uniform(1e-4, 0.1, n).tolist()
        acc = rng.uniform(10.0, 1e3, n).tolist()
        dec = rng.uniform(10.0, 1e3, n).tolist()
        jcap2 = rng.uniform(0.0, 2e3, n + 1).tolist()
        jcap2[n] = 0.0
        back, fwd = _corner.passes(jcap2, acc, length, 0.0, dec)
        ob, of = oc.passes(jcap2, acc, length, 0.0, dec)
        _same(back, ob)
        _same(fwd, of)
        ccap = rng.uniform(1.0, 60.0, n).tolist()
        e, c, x = _corner.speeds(fwd, acc, dec, ccap, length)
        for g, w in zip((e, c, x), oc.speeds(fwd, acc, dec, ccap, length), strict=True):
            _same(g, w)
        sp = [ElementSpeeds(e[k], c[k], x[k], acc[k], ccap[k], length[k], dec[k])
              for k in range(n)]
        curve = px.curve_from_speeds(sp, 0.25)
        s, v2 = oc.curve_from_speeds(sp, 0.25)
        _same(curve.s, s)
        _same(curve.v2, v2)
        breaks = np.cumsum(length)[:-1] + 0.25
        got = px.s_profile(curve, float(s[-1]), breaks, dwell=0.002)
        want = oc.s_profile(s, v2, False, float(s[-1]), breaks, dwell=0.002)
        for name in ("t0", "p0", "v0", "a0", "dt"):
            _same(getattr(got, name), getattr(want, name))
        assert got.duration == want.duration and got.labels == want.labels


def test_crossings_bit_for_bit() -> None:
    """The instants s(t) crosses element boundaries: a constant-acceleration s(t) and a
    smoothed (jerk) one."""
    from openmotion.path.smoothing import fir_smooth

    rng = np.random.default_rng(3)
    length = rng.uniform(1e-3, 0.2, 300)
    s, v2 = oc.curve_from_speeds([ElementSpeeds(0.0, 0.0, 0.0, 1.0, 1.0, 0.0)] + [
        ElementSpeeds(v, v, v, 500.0, 40.0, float(L)) for v, L in
        zip(rng.uniform(1.0, 40.0, 300), length, strict=True)])
    v2[0] = v2[-1] = 0.0
    raw = px.s_profile(px.SpeedCurve(s, v2), float(s[-1]), [])
    levels = np.cumsum(length)[:-1]
    for sp in (raw, fir_smooth(raw, 0.01)):
        got = pathaxes._crossings(sp, levels)
        assert len(got) == 299
        _same(got, oc.crossings(sp, levels))
    with pytest.raises(ValueError):
        _corner.crossings(np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(3),
                          np.zeros(2))


@settings(max_examples=300, deadline=None)
@given(st.floats(0.0, 1e6), st.lists(st.tuples(st.floats(1e-3, 1e9) | st.just(math.inf),
                                               st.floats(0.0, 2.0) | st.just(5e-324)),
                                     min_size=1, max_size=6))
def test_limit_along_bit_for_bit(limit, pairs) -> None:
    from openmotion.path.lookahead import _limit_along

    axis = np.array([a for a, _ in pairs])
    weight = np.array([w for _, w in pairs])
    assert _limit_along(limit, axis, weight) == oc.limit_along(limit, axis, weight)
    assert _limit_along(limit, None, weight) == limit
    assert _limit_along(limit, axis, weight[::-1][::-1].tolist()) == \
        oc.limit_along(limit, axis, weight)  # (any array-like weight)
    with pytest.raises(ValueError):
        _corner.limit_along(1.0, np.zeros(2), np.zeros(3))


def test_junction_memo_keeps_no_element_alive() -> None:
    """The look-ahead's memo (the compiled prepare's, _chain_prep.c: limits and junction
    caps per element) refers to the elements weakly: a stream's earlier elements go when
    the chain drops them (a strong reference to the element before made every entry keep
    the whole history alive), and it keeps a few plans' records only."""
    import gc
    import weakref

    from openmotion.path.lookahead import _PREP_MEMO

    pts = [np.array([float(k), float(k % 2)]) for k in range(50)]
    els = [Line(a, b) for a, b in zip(pts[:-1], pts[1:], strict=True)]
    plan_speeds(els, 5.0, 50.0, square_corner_velocity=1.0)
    assert _PREP_MEMO  # (the compiled path ran and kept a record)
    first = weakref.ref(els[0])
    del els[:-1]  # only the last element lives on
    gc.collect()
    assert first() is None
    for k in range(10):  # more plans than records
        plan_speeds([Line(np.zeros(2), np.array([1.0, float(k)]))], 5.0, 50.0)
    assert len(_PREP_MEMO) <= 4
