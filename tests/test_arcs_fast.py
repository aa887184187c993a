"""The planner's fast element arithmetic is bit for bit the general one.

`_Frame._tangent_one` (the end tangents every arc and blend computes when it is made)
against `_Frame._tangent_at` (the general, broadcasting evaluation), and `Line.between`
against `Line(...)`, on random circles, helices and lines in 2 to 4 axes.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.path.arcs import Arc3D, _Frame
from openmotion.path.geometry import Line

coord = st.floats(-1e4, 1e4, allow_nan=False)


def _frame(centre, angle, radius, sweep, helix, tilt) -> _Frame:
    n = len(centre)
    c = np.array(centre, dtype=float)
    e1 = np.zeros(n)
    e2 = np.zeros(n)
    e1[0], e1[1] = np.cos(angle), np.sin(angle)
    e2[0], e2[1] = -np.sin(angle), np.cos(angle)
    if n > 2:  # tilt the plane out of the first two axes
        e2 = np.cos(tilt) * e2
        e2[2] = np.sin(tilt)
        e2 = e2 / np.linalg.norm(e2)
    h = np.zeros(n)
    if n > 2:
        h[-1] = helix  # along the last axis (orthogonal enough for the evaluator)
    start = c + radius * e1
    end = c + radius * (np.cos(sweep) * e1 + np.sin(sweep) * e2) + h
    return _Frame(c, e1, e2, radius, sweep, h, start, end)


@settings(max_examples=300, deadline=None)
@given(st.integers(2, 4).flatmap(lambda n: st.lists(coord, min_size=n, max_size=n)),
       st.floats(-7.0, 7.0), st.floats(1e-6, 1e4), st.floats(1e-6, 2 * np.pi),
       st.floats(-10.0, 10.0), st.floats(-1.5, 1.5), st.floats(0.0, 1.0))
def test_tangent_one_is_tangent_at(centre, angle, radius, sweep, helix, tilt, frac):
    f = _frame(centre, angle, radius, sweep, helix, tilt)
    for s in (0.0, f.length, frac * f.length):
        fast = f._tangent_one(s)
        ref = f._tangent_at(np.asarray(s))
        assert fast.shape == ref.shape
        assert np.array_equal(fast, ref), (s, fast, ref)
    assert np.array_equal(f.t_start, f._tangent_at(np.asarray(0.0)))
    assert np.array_equal(f.t_end, f._tangent_at(np.asarray(f.length)))


@settings(max_examples=200, deadline=None)
@given(st.integers(2, 4).flatmap(lambda n: st.tuples(
    st.lists(coord, min_size=n, max_size=n), st.lists(coord, min_size=n, max_size=n))))
def test_line_between_is_line(pts):
    a, b = (np.array(p, dtype=float) for p in pts)
    for x in (a, b):
        x.flags.writeable = False
    fast, ref = Line.between(a, b), Line(a, b)
    assert fast.length == ref.length
    assert np.array_equal(fast.direction, ref.direction)


def test_arc_through_points_keeps_its_end_tangents():
    arc = Arc3D([0.0, 0.0, 0.0], [1.0, 1.0, 0.2], [2.0, 0.0, 0.4])
    f = arc._frame
    assert np.array_equal(arc.start_tangent, f._tangent_at(np.asarray(0.0)))
    assert np.array_equal(arc.end_tangent, f._tangent_at(np.asarray(f.length)))
