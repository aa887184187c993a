"""Look-ahead speed planning: reachability, limits, corners, per-axis limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.errors import InfeasibleError, MotionError
from openmotion.path import (
    Arc,
    Line,
    blend_corner,
    corner_speed,
    plan_speeds,
)
from openmotion.path.blend import TANGENT_ANGLE

REL = 1e-9


def _check_plan(elements, plan, feed, accel, *, axis_vmax=None, axis_amax=None,
                end_speed=0.0, start_speed=0.0):
    """Invariants every plan must satisfy; returns nothing, asserts everything."""
    assert len(plan) == len(elements)
    assert plan[0].entry == pytest.approx(start_speed, rel=REL, abs=1e-12)
    assert plan[-1].exit <= end_speed * (1 + REL) + 1e-12
    for k, (el, sp) in enumerate(zip(elements, plan, strict=True)):
        assert sp.length == el.length
        assert 0.0 <= sp.entry <= sp.cruise * (1 + REL) + 1e-12
        assert sp.exit <= sp.cruise * (1 + REL) + 1e-12
        assert sp.cruise <= sp.vmax * (1 + REL) <= feed * (1 + REL) ** 2
        assert sp.accel <= accel * (1 + REL)
        # reachable with at most `accel` along the element
        d_acc = (sp.cruise**2 - sp.entry**2) / (2 * sp.accel)
        d_dec = (sp.cruise**2 - sp.exit**2) / (2 * sp.accel)
        assert d_acc + d_dec <= el.length * (1 + REL) + 1e-12
        assert abs(sp.exit**2 - sp.entry**2) <= 2 * sp.accel * el.length * (1 + REL) + 1e-12
        if k:
            assert sp.entry == plan[k - 1].exit
        if el.max_curvature > 0:
            # total acceleration on an arc: tangential and normal parts within accel
            a_n = el.max_curvature * sp.cruise**2
            assert math.hypot(sp.accel, a_n) <= accel * (1 + REL)
        if axis_vmax is not None:
            assert np.all(sp.cruise * el.max_abs_tangent <= np.asarray(axis_vmax) * (1 + REL))
        if axis_amax is not None and el.max_curvature == 0:
            assert np.all(sp.accel * el.max_abs_tangent <= np.asarray(axis_amax) * (1 + REL))
        elif axis_amax is not None:  # circle: worst case of |a_t*t_i| + |a_n*n_i| per axis
            s = np.linspace(0.0, el.length, 201)
            t = np.abs(el.tangent(s))
            phi = (s * el.sweep / el.length)[:, None]
            e1, e2 = el.basis
            n = np.abs(np.cos(phi) * e1 + np.sin(phi) * e2)
            worst = (sp.accel * t + el.max_curvature * sp.cruise**2 * n).max(axis=0)
            assert np.all(worst <= np.asarray(axis_amax) * (1 + 1e-6))


@st.composite
def polylines(draw, blend=False):
    n = draw(st.integers(2, 3))
    count = draw(st.integers(2, 8))
    pts = [np.array(draw(st.lists(st.floats(-100, 100), min_size=n, max_size=n)))
           for _ in range(count + 1)]
    lines = [Line(a, b) for a, b in zip(pts, pts[1:], strict=False)]
    assume(all(line.length > 1e-3 for line in lines))
    if not blend:
        return lines
    tol = draw(st.floats(1e-3, 5.0))
    out = []
    cur = lines[0]
    for nxt in lines[1:]:
        b = blend_corner(cur, nxt, tol, fraction=0.25)
        if b is None:
            out.append(cur)
            cur = nxt
        else:
            out += [b.first, b.arc]
            cur = b.second
    out.append(cur)
    return out


limits = st.tuples(st.floats(1.0, 500.0), st.floats(1.0, 5e3), st.floats(0.0, 50.0))


@settings(max_examples=150, deadline=None)
@given(polylines(), limits)
def test_plan_invariants_on_polylines(lines, lim):
    feed, accel, scv = lim
    plan = plan_speeds(lines, feed, accel, square_corner_velocity=scv)
    _check_plan(lines, plan, feed, accel)
    for k in range(1, len(lines)):
        u1, u2 = lines[k - 1].direction, lines[k].direction
        if 2 * math.asin(min(1.0, np.linalg.norm(u1 - u2) / 2)) >= TANGENT_ANGLE:
            vc = corner_speed(u1, u2, accel, scv, lengths=(lines[k - 1].length, lines[k].length))
            assert plan[k].entry <= vc * (1 + REL) + 1e-12


@settings(max_examples=100, deadline=None)
@given(polylines(blend=True), limits, st.data())
def test_plan_invariants_with_blend_arcs_and_axis_limits(elements, lim, data):
    feed, accel, scv = lim
    dim = elements[0].dim
    vmax = data.draw(st.lists(st.floats(1.0, 1e3), min_size=dim, max_size=dim))
    amax = data.draw(st.lists(st.floats(1.0, 1e4), min_size=dim, max_size=dim))
    plan = plan_speeds(elements, feed, accel, square_corner_velocity=scv,
                       axis_vmax=vmax, axis_amax=amax)
    _check_plan(elements, plan, feed, accel, axis_vmax=vmax, axis_amax=amax)


def test_blended_zigzag_never_stops_at_tangent_junctions():
    # far from the origin, short segments: tangents carry rounding, still no exact stops
    pts = [np.array([1e5 + 3.0 * k, 1e5 + (k % 2) * 1.5, 7.0]) for k in range(12)]
    lines = [Line(a, b) for a, b in zip(pts, pts[1:], strict=False)]
    elements = [lines[0]]
    for nxt in lines[1:]:
        b = blend_corner(elements.pop(), nxt, 0.2, fraction=0.25)
        elements += [b.first, b.arc, b.second]
    plan = plan_speeds(elements, 20.0, 500.0)  # scv 0: any real corner would be a stop
    assert all(sp.entry > 1.0 for sp in plan[1:])
    _check_plan(elements, plan, 20.0, 500.0)


def test_long_line_reaches_feed_and_stops():
    (sp,) = plan_speeds([Line([0, 0], [1000, 0])], 100.0, 50.0)
    assert (sp.entry, sp.cruise, sp.exit) == (0.0, 100.0, 0.0)
    assert sp.duration == pytest.approx(1000 / 100 + 100 / 50)


def test_short_line_is_a_triangle():
    (sp,) = plan_speeds([Line([0, 0], [1, 0])], 100.0, 50.0)
    assert sp.cruise == pytest.approx(math.sqrt(50.0 * 1.0))
    assert sp.duration == pytest.approx(2 * math.sqrt(1.0 / 50.0))


def test_collinear_lines_pass_at_full_speed():
    lines = [Line([0, 0], [10, 0]), Line([10, 0], [20, 0]), Line([20, 0], [30, 0])]
    plan = plan_speeds(lines, 5.0, 100.0)
    assert plan[1].entry == 5.0 and plan[2].entry == 5.0
    assert sum(p.duration for p in plan) == pytest.approx(30 / 5 + 5 / 100)


def test_square_corner_and_exact_stop():
    lines = [Line([0, 0], [100, 0]), Line([100, 0], [100, 100])]
    assert plan_speeds(lines, 50.0, 1000.0)[1].entry == 0.0  # scv 0: exact stop
    plan = plan_speeds(lines, 50.0, 1000.0, square_corner_velocity=5.0)
    assert plan[1].entry == pytest.approx(5.0)
    reverse = [Line([0, 0], [100, 0]), Line([100, 0], [0, 0])]
    assert plan_speeds(reverse, 50.0, 1000.0, square_corner_velocity=5.0)[1].entry == 0.0


def test_backward_pass_brakes_early_for_a_stop():
    lines = [Line([0, 0], [100, 0]), Line([100, 0], [100.5, 0])]
    plan = plan_speeds(lines, 50.0, 100.0)
    # the short last move ends at rest: its entry is what braking over 0.5 allows
    assert plan[1].entry == pytest.approx(math.sqrt(2 * 100.0 * 0.5))
    assert plan[1].exit == 0.0


def test_end_and_start_speed():
    lines = [Line([0, 0], [10, 0])]
    (sp,) = plan_speeds(lines, 20.0, 10.0, start_speed=5.0, end_speed=20.0)
    assert sp.entry == 5.0
    assert sp.exit == pytest.approx(math.sqrt(25 + 2 * 10 * 10))
    with pytest.raises(InfeasibleError, match="start_speed 30"):
        plan_speeds([Line([0, 0], [0.1, 0])], 50.0, 10.0, start_speed=30.0)


def test_per_axis_speed_and_accel_limits():
    x_line = [Line([0, 0], [1000, 0])]
    (sp,) = plan_speeds(x_line, 50.0, 100.0, axis_vmax=[10.0, 100.0], axis_amax=[20.0, 1e9])
    assert sp.cruise == 10.0 and sp.accel == 20.0
    diag = [Line([0, 0], [1000, 1000])]
    (sp,) = plan_speeds(diag, 50.0, 100.0, axis_vmax=[10.0, 10.0])
    assert sp.cruise == pytest.approx(10.0 * math.sqrt(2))
    (sp,) = plan_speeds(diag, 50.0, 100.0, axis_vmax=[math.inf, math.inf])
    assert sp.cruise == 50.0


def test_arc_centripetal_and_tangential_split():
    arc = Arc([10.0, 0.0], [0.0, 0.0], [10.0, 0.0])  # full circle R = 10
    (sp,) = plan_speeds([arc], 100.0, 40.0)
    assert sp.accel == pytest.approx(20.0)  # 0.5 * accel tangential
    assert sp.vmax == pytest.approx(math.sqrt(math.sqrt(0.75) * 40.0 * 10.0))
    (sp,) = plan_speeds([arc], 100.0, 40.0, arc_tangential_ratio=0.8)
    assert sp.accel == pytest.approx(32.0)
    assert sp.vmax == pytest.approx(math.sqrt(0.6 * 40.0 * 10.0))


def test_zero_length_element_sits_on_its_junction():
    lines = [Line([0, 0], [10, 0]), Line([10, 0], [10, 0]), Line([10, 0], [20, 0])]
    plan = plan_speeds(lines, 5.0, 100.0)
    assert plan[1].entry == plan[1].exit == plan[1].cruise == 5.0 == plan[0].exit
    assert plan[1].duration == 0.0
    zero = plan_speeds([Line([0, 0], [0, 0])], 5.0, 100.0)
    assert zero[0].cruise == 0.0


def test_tangent_line_arc_junction_is_not_a_corner():
    line = Line([-100.0, 10.0], [0.0, 10.0])
    arc = Arc([0.0, 10.0], [0.0, 0.0], [10.0, 0.0], direction="CW")
    plan = plan_speeds([line, arc], 100.0, 40.0)  # scv 0 would stop at a real corner
    assert plan[1].entry == pytest.approx(plan[1].vmax)


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        (([], 1.0, 1.0), {}, "elements must be a non-empty"),
        (("ab", 1.0, 1.0), {}, "elements must be a non-empty"),
        (([1.0], 1.0, 1.0), {}, r"elements\[0\] must be a path element"),
        (([Line([0, 0], [1, 0]), Line([1, 0, 0], [2, 0, 0])], 1.0, 1.0), {},
         r"elements\[1\] must have 2 axes"),
        (([Line([0, 0], [1, 0])], 0.0, 1.0), {}, "feed must be > 0"),
        (([Line([0, 0], [1, 0])], 1.0, math.nan), {}, "accel must be finite"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"square_corner_velocity": -1}, "square_corner"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"start_speed": -1}, "start_speed must be >= 0"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"end_speed": math.inf}, "end_speed must be"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"axis_vmax": [1.0]}, "axis_vmax must be 2"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"axis_amax": [1.0, 0.0]}, "axis_amax must be 2"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"axis_amax": [1.0, math.nan]}, "axis_amax"),
        (([Line([0, 0], [1, 0])], 1.0, 1.0), {"arc_tangential_ratio": 1.0}, "arc_tangential"),
    ],
)
def test_plan_validation(args, kwargs, match):
    with pytest.raises(MotionError, match=match):
        plan_speeds(*args, **kwargs)
