"""The compiled axis knots (openmotion._profile.axis_knots, _profile_knots.c) give the
floats of their numpy oracle (control/groups/pathaxes.py `_knots_numpy`, the code
axis_profiles ran before) for chains of lines, arcs, helices, 3-D arcs and trimmed
elements, from rest and from a speed, over a whole plan and over windows of it; chains
with an element type the table does not know fall back to the numpy version."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion import _profile as C
from openmotion.control.groups import pathaxes as pa
from openmotion.control.groups import pathexec as px
from openmotion.control.groups.groupexec import _section
from openmotion.path import Arc, Line
from test_pathpoints import _elements


def _same(x: np.ndarray, y: np.ndarray) -> bool:
    return x.shape == y.shape and np.array_equal(x.view(np.int64), y.view(np.int64))


def _both(chain: px.Chain, sp, period: float, starts) -> tuple[list, list]:  # noqa: ANN001
    got = pa.axis_profiles(chain, sp, period, starts)
    saved = pa._knots_compiled
    pa._knots_compiled = lambda *a: None  # the numpy version alone
    try:
        ref = pa.axis_profiles(chain, sp, period, starts)
    finally:
        pa._knots_compiled = saved
    return got, ref


def _check(chain: px.Chain, sp, period: float, starts, *, exact: bool = True) -> None:  # noqa: ANN001
    got, ref = _both(chain, sp, period, starts)
    assert len(got) == len(ref)
    for g, r in zip(got, ref, strict=True):
        for name in ("t0", "p0", "v0", "a0", "j", "dt"):
            x, y = getattr(g, name), getattr(r, name)
            if exact:
                assert _same(x, y), name
            else:  # an arc's cos/sin may be numpy's own SIMD ones: an ulp apart
                assert np.allclose(x, y, rtol=1e-12, atol=1e-9), name
        assert (g.start, g.end, g.duration, g.labels) == (r.start, r.end, r.duration, r.labels)


def _plan(els: list, scv: float = 0.0):  # noqa: ANN202
    chain = px.Chain(els, range(len(els)))
    dim = els[0].dim
    lim = px.Limits(200.0, 2000.0, np.full(dim, 150.0), np.full(dim, 1500.0), scv)
    curve = px.plan_curve(chain, 0.0, 0.0, lim)
    return chain, px.s_profile(curve, chain.length, chain.cum[1:-1].tolist())


def _cos_is_libm() -> bool:
    import math

    x = np.linspace(-7.0, 7.0, 4001)
    return bool(np.all(np.cos(x) == [math.cos(v) for v in x.tolist()]))


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0)), min_size=1,
                max_size=8), st.sampled_from([0.0, 20.0]), st.sampled_from([0.001, 0.004]),
       st.booleans())
def test_lines_and_arcs_as_numpy(pts, scv, period, arc_end):
    verts = [np.zeros(2)]
    for p in pts:
        q = verts[-1] + np.array(p)
        if np.linalg.norm(q - verts[-1]) > 0.5:
            verts.append(q)
    if len(verts) < 2:
        return
    els: list = [Line(a, b) for a, b in zip(verts[:-1], verts[1:], strict=True)]
    if arc_end:
        c = verts[-1] + np.array([5.0, 0.0])
        els.append(Arc(verts[-1], c, verts[-1] + np.array([10.0, 0.0])))
    chain, sp = _plan(els, scv)
    assert chain.table.packed is not None
    _check(chain, sp, period, [0.0, 0.0], exact=not arc_end or _cos_is_libm())
    # a window from part-way (a moving start) and the rest of the plan
    for u in (0.3 * sp.duration, 0.71 * sp.duration):
        w = _section(sp, u, 0.25)
        start = chain.point(float(sp.state_at(u).p))
        _check(chain, w, period, start, exact=not arc_end or _cos_is_libm())


def test_every_element_kind_as_numpy():
    from openmotion.control.groups.pathpoints import ElementTable

    els = _elements()
    els = [el for el, kind in zip(els, ElementTable(els).kind, strict=True) if kind]
    assert len(els) == len(_elements()) - 3  # all but the wrapped and the trimmed trimmed
    chain, sp = _plan(els)
    assert chain.table.packed is not None
    _check(chain, sp, 0.001, np.asarray(els[0].start, dtype=float), exact=_cos_is_libm())


def test_unknown_element_types_use_the_numpy_version():
    els = [el for el in _elements() if type(el).__name__ != "_Wrapped"]  # a trimmed
    chain, sp = _plan(els)  # trimmed element is one the table asks itself
    assert chain.table.packed is None
    got, ref = _both(chain, sp, 0.002, np.asarray(els[0].start, dtype=float))
    for g, r in zip(got, ref, strict=True):
        assert _same(g.p0, r.p0) and _same(g.a0, r.a0)


def test_compiled_refuses_bad_arguments():
    chain, sp = _plan([Line([0.0, 0.0], [3.0, 0.0]), Line([3.0, 0.0], [3.0, 4.0])])
    packed = chain.table.packed
    n = 5
    z = np.zeros(n)
    args = [packed, chain.cum, np.linspace(0.0, 1.0, n), z, z, z[:-1], z[:-1], z[:-1],
            np.zeros(2), np.zeros(0), np.empty((n, 2)), np.empty((n - 1, 2)),
            np.empty((n - 1, 2)), np.empty((n - 1, 2))]
    assert C.axis_knots(*args) is True
    with pytest.raises(ValueError, match="matching sizes"):
        C.axis_knots(*args[:4], np.zeros(n + 1), *args[5:])
    with pytest.raises(ValueError, match="matching sizes"):
        C.axis_knots(*args[:9], np.zeros(1), *args[10:])
    with pytest.raises(TypeError, match="float64"):
        C.axis_knots(*args[:3], np.zeros(n, dtype=np.int64), *args[4:])
    with pytest.raises(TypeError, match="14 arguments"):
        C.axis_knots(*args[:3])
    bad = packed.copy()
    bad[0, 0] = 0.0  # an element kind it does not evaluate
    assert C.axis_knots(bad, *args[1:]) is False
