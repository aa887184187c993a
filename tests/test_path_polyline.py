"""plan_polyline: the vectorised blended look-ahead equals blend_corner + plan_speeds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import InfeasibleError, MotionError
from openmotion.path import Arc3D, Line, blend_corner, plan_polyline, plan_speeds

REL = 1e-9


def oracle(pts, feeds, accels, tol, **kw):
    """The per-corner object path plan_polyline replaces: Line per segment, blend_corner at
    every corner on the line the previous corner trimmed, plan_speeds on the pieces (an
    arc takes the feed and acceleration of the segment it leads into)."""
    lines = [Line(pts[k], pts[k + 1]) for k in range(len(pts) - 1)]
    els, fe, ac = [], [], []
    prev = lines[0]
    for k, nxt in enumerate(lines[1:], start=1):
        b = blend_corner(prev, nxt, tol)
        if b is None:
            els.append(prev)
            fe.append(feeds[k - 1])
            ac.append(accels[k - 1])
            prev = nxt
        else:
            els += [b.first, b.arc]
            fe += [feeds[k - 1], feeds[k]]
            ac += [accels[k - 1], accels[k]]
            prev = b.second
    els.append(prev)
    fe.append(feeds[-1])
    ac.append(accels[-1])
    return els, plan_speeds(els, fe, ac, **kw)


def close(a, b, scale):
    return abs(a - b) <= REL * max(abs(a), abs(b), scale)


def close_v2(a, b, scale):
    """Speeds compared as v**2, what the planner works in: where a corner is an exact
    reversal the object path's trimmed line carries a rounding turn of ~1e-16 that leaves
    a corner speed of ~1e-8 (the square root of rounding) instead of 0."""
    return close(a * a, b * b, scale * scale)


def assert_same(pts, feeds, accels, tol, **kw):
    els, sp = oracle(pts, feeds, accels, tol, **kw)
    plan = plan_polyline(pts, feeds, accels, tolerance=tol, **kw)
    assert plan.is_arc.size == len(els)
    vscale = max(feeds)
    for k, (el, s) in enumerate(zip(els, sp, strict=True)):
        assert bool(plan.is_arc[k]) == isinstance(el, Arc3D)
        assert close(plan.length[k], el.length, 1e-300)
        np.testing.assert_allclose(plan.start[k], el.start, rtol=0, atol=1e-9)
        np.testing.assert_allclose(plan.end[k], el.end, rtol=0, atol=1e-9)
        for name in ("entry", "cruise", "exit", "vmax"):
            assert close_v2(getattr(plan, name)[k], getattr(s, name), vscale), (k, name)
        assert close(plan.accel[k], s.accel, 1e-300), k
    new_els = plan.elements()
    for a, b in zip(new_els, els, strict=True):
        assert type(a) is type(b)
        np.testing.assert_allclose(a.point(np.linspace(0, a.length, 5)),
                                   b.point(np.linspace(0, b.length, 5)), rtol=0, atol=1e-9)
    for k in range(len(new_els) - 1):  # the pieces join bit for bit
        assert np.array_equal(new_els[k].end, new_els[k + 1].start)
    # a corner speed of 1e-8 instead of 0 (close_v2) shortens the braking by 1e-8/accel
    assert plan.duration == pytest.approx(sum(s.duration for s in sp), rel=REL, abs=1e-7)
    assert close_v2(plan.speeds()[0].cruise, sp[0].cruise, vscale)


coord = st.floats(-50.0, 50.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(coord, coord), min_size=2, max_size=12),
       st.sampled_from([0.0, 0.001, 0.05, 0.5]), st.floats(1.0, 200.0),
       st.floats(10.0, 5000.0), st.sampled_from([0.0, 5.0]),
       st.sampled_from([0.0, 0.5]))
def test_equals_blend_corner_and_plan_speeds(pts, tol, feed, accel, scv, mcr):
    pts = [p for k, p in enumerate(pts) if k == 0 or p != pts[k - 1]]
    if len(pts) < 2:
        return
    n = len(pts) - 1
    assert_same(pts, [feed] * n, [accel] * n, tol, square_corner_velocity=scv,
                min_cruise_ratio=mcr)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(coord, coord, coord), min_size=3, max_size=10),
       st.floats(0.001, 1.0), st.data())
def test_equals_with_axis_limits_and_per_segment_feeds(pts, tol, data):
    pts = [p for k, p in enumerate(pts) if k == 0 or p != pts[k - 1]]
    if len(pts) < 2:
        return
    n = len(pts) - 1
    feeds = data.draw(st.lists(st.floats(1.0, 300.0), min_size=n, max_size=n))
    accels = data.draw(st.lists(st.floats(10.0, 3000.0), min_size=n, max_size=n))
    vmax = data.draw(st.lists(st.floats(5.0, 100.0), min_size=3, max_size=3))
    amax = data.draw(st.lists(st.floats(50.0, 2000.0), min_size=3, max_size=3))
    assert_same(pts, feeds, accels, tol, axis_vmax=vmax, axis_amax=amax,
                square_corner_velocity=3.0, axis_vjump=[2.0, 3.0, 4.0],
                arc_tangential_ratio=0.6, end_speed=data.draw(st.floats(0.0, 10.0)))


def test_polygon_and_zigzag():
    gon = [(50 * math.cos(2 * math.pi * k / 100), 50 * math.sin(2 * math.pi * k / 100))
           for k in range(101)]
    assert_same(gon, [100.0] * 100, [1000.0] * 100, 0.006)
    zig = [(float(k), float(k % 2)) for k in range(41)]
    assert_same(zig, [100.0] * 40, [1000.0] * 40, 0.1, axis_vmax=[60, 60])


def test_repeated_points_merge_and_bad_input():
    plan = plan_polyline([(0, 0), (1, 0), (1, 0), (1, 1)], 10.0, 100.0, tolerance=0.01)
    assert plan.is_arc.tolist() == [False, True, False]
    assert plan.deviation[0] <= 0.01 * (1 + REL)
    with pytest.raises(MotionError, match="points"):
        plan_polyline([(0, 0)], 10.0, 100.0, tolerance=0.01)
    with pytest.raises(MotionError, match="points"):
        plan_polyline([(0, 0), (math.nan, 1)], 10.0, 100.0, tolerance=0.01)
    with pytest.raises(MotionError, match="feed"):
        plan_polyline([(0, 0), (1, 0), (1, 1)], [1.0], 100.0, tolerance=0.01)
    with pytest.raises(MotionError, match="tolerance"):
        plan_polyline([(0, 0), (1, 0)], 10.0, 100.0, tolerance=-1.0)
    with pytest.raises(InfeasibleError):
        plan_polyline([(0, 0), (1, 0)], 10.0, 100.0, tolerance=0.0, start_speed=100.0)
