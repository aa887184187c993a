"""Corner blends within a path tolerance, junction-deviation speed, centripetal speed."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.path import (
    BLEND_DIST_FRACTION,
    Arc3D,
    Line,
    blend_corner,
    centripetal_speed,
    corner_speed,
)

SQRT2_M1 = math.sqrt(2.0) - 1.0


def _seg_distance(p, a, b):
    """Distance of points p (k, N) from the segment a-b."""
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


def _unit(v):
    return v / np.linalg.norm(v)


@st.composite
def corners(draw):
    n = draw(st.integers(2, 5))
    vec = st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n)
    u1 = np.array(draw(vec))
    u2 = np.array(draw(vec))
    assume(np.linalg.norm(u1) > 0.1 and np.linalg.norm(u2) > 0.1)
    u1, u2 = _unit(u1), _unit(u2)
    turn = 2 * math.atan2(np.linalg.norm(u1 - u2), np.linalg.norm(u1 + u2))
    assume(1e-3 < turn < math.pi - 1e-3)
    corner = np.array(draw(st.lists(st.floats(-1e3, 1e3), min_size=n, max_size=n)))
    l1 = draw(st.floats(1e-3, 1e3))
    l2 = draw(st.floats(1e-3, 1e3))
    tol = draw(st.floats(1e-6, 10.0))
    return Line(corner - l1 * u1, corner), Line(corner, corner + l2 * u2), tol


@settings(max_examples=200, deadline=None)
@given(corners())
def test_blend_properties(data):
    first, second, tol = data
    blend = blend_corner(first, second, tol)
    assert blend is not None
    arc = blend.arc
    assert isinstance(arc, Arc3D)
    corner = first.end
    # joins bit for bit, ends of the original lines kept
    assert np.array_equal(blend.first.start, first.start)
    assert np.array_equal(blend.second.end, second.end)
    assert np.array_equal(blend.first.end, arc.start)
    assert np.array_equal(arc.end, blend.second.start)
    assert np.array_equal(arc.point(arc.length), blend.second.start)
    # tangent to both trimmed lines
    assert np.allclose(arc.start_tangent, first.direction, atol=1e-9)
    assert np.allclose(arc.end_tangent, second.direction, atol=1e-9)
    assert np.allclose(blend.first.direction, first.direction, atol=1e-9)
    assert np.allclose(blend.second.direction, second.direction, atol=1e-9)
    # uses at most half of each line
    d1 = first.length - blend.first.length
    d2 = blend.second.start - corner
    assert d1 <= BLEND_DIST_FRACTION * first.length * (1 + 1e-9) + 1e-9
    assert float(np.linalg.norm(d2)) <= BLEND_DIST_FRACTION * second.length * (1 + 1e-9) + 1e-9
    # within tolerance of the programmed corner, equal to it unless the lines were short
    eps = 1e-9 * max(1.0, float(np.abs(corner).max()))
    s = np.linspace(0.0, arc.length, 257)
    p = arc.point(s)
    dev = np.minimum(_seg_distance(p, first.start, corner), _seg_distance(p, corner, second.end))
    assert dev.max() <= tol * (1 + 1e-9) + eps
    assert blend.deviation <= tol * (1 + 1e-9)
    assert dev.max() <= blend.deviation * (1 + 1e-9) + eps
    # deviation = distance from the programmed corner point, reached at the arc's middle
    to_corner = np.linalg.norm(p - corner, axis=1)
    assert to_corner.min() == pytest.approx(blend.deviation, rel=1e-6, abs=eps)
    assert np.linalg.norm(arc.point(arc.length / 2) - corner) == pytest.approx(
        blend.deviation, rel=1e-6, abs=eps)
    half_used = math.isclose(d1, 0.5 * first.length, rel_tol=1e-9) or math.isclose(
        float(np.linalg.norm(d2)), 0.5 * second.length, rel_tol=1e-9)
    assert half_used or blend.deviation == pytest.approx(tol, rel=1e-9)
    # the arc lies in the plane of the two lines
    basis, _ = np.linalg.qr(np.stack([first.direction, second.direction], axis=1))
    rel = p - corner
    off_plane = rel - (rel @ basis) @ basis.T
    assert np.abs(off_plane).max() <= eps + 1e-9 * arc.radius


def test_right_angle_blend_numbers():
    first = Line([0.0, 0.0], [10.0, 0.0])
    second = Line([10.0, 0.0], [10.0, 10.0])
    blend = blend_corner(first, second, 0.1)
    # theta = 45 deg: d = T*(1 + sin)/cos, R = d*tan = d
    d = 0.1 * (1 + math.sqrt(0.5)) / math.sqrt(0.5)
    assert blend.arc.radius == pytest.approx(d)
    assert blend.first.end == pytest.approx([10.0 - d, 0.0])
    assert blend.second.start == pytest.approx([10.0, d])
    assert blend.arc.sweep == pytest.approx(math.pi / 2)
    assert blend.deviation == pytest.approx(0.1)
    assert np.linalg.norm(blend.arc.point(blend.arc.length / 2) - [10.0, 0.0]) == \
        pytest.approx(0.1)
    assert len(blend.elements) == 3


def test_blend_limited_to_half_of_short_lines():
    first = Line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    second = Line([1.0, 0.0, 0.0], [1.0, 0.0, 4.0])
    blend = blend_corner(first, second, 100.0)
    assert blend.first.length == pytest.approx(0.5)
    assert blend.arc.radius == pytest.approx(0.5)
    assert blend.deviation < 100.0
    assert blend.deviation == pytest.approx(0.5 * math.sqrt(2) - 0.5)


@pytest.mark.parametrize(
    ("end", "why"),
    [([20.0, 0.0], "collinear"), ([0.0, 0.0], "reversal"), ([5.0, 0.0], "reversal")],
)
def test_no_blend_for_collinear_or_reversal(end, why):
    first = Line([0.0, 0.0], [10.0, 0.0])
    assert blend_corner(first, Line([10.0, 0.0], end), 0.5) is None, why


@pytest.mark.parametrize("turn", [1e-7, math.pi - 1e-7])
def test_no_blend_within_a_microradian_of_straight_or_reversal(turn):
    first = Line([0.0, 0.0], [10.0, 0.0])
    end = [10.0 + 5.0 * math.cos(turn), 5.0 * math.sin(turn)]
    assert blend_corner(first, Line([10.0, 0.0], end), 0.5) is None
    assert blend_corner(first, Line([10.0, 0.0], [10.0 + 5.0 * math.cos(2e-6),
                                                  5.0 * math.sin(2e-6)]), 0.5) is not None


def test_no_blend_for_zero_tolerance_or_zero_length():
    first = Line([0.0, 0.0], [10.0, 0.0])
    assert blend_corner(first, Line([10.0, 0.0], [10.0, 5.0]), 0.0) is None
    assert blend_corner(first, Line([10.0, 0.0], [10.0, 0.0]), 1.0) is None


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        ((Line([0, 0], [1, 0]), Line([1, 0], [1, 1]), -1.0), {}, "tolerance must be >= 0"),
        ((Line([0, 0], [1, 0]), Line([1, 0], [1, 1]), math.nan), {}, "tolerance must be finite"),
        ((Line([0, 0], [1, 0]), Line([1, 1], [1, 2]), 0.1), {}, "second.start must equal"),
        ((Line([0, 0], [1, 0]), Line([1, 0, 0], [1, 1, 0]), 0.1), {}, "second must have 2"),
        ((Line([0, 0], [1, 0]), [1, 0], 0.1), {}, "must be Line"),
        ((Line([0, 0], [1, 0]), Line([1, 0], [1, 1]), 0.1), {"fraction": 0.6}, "fraction"),
        ((Line([0, 0], [1, 0]), Line([1, 0], [1, 1]), 0.1), {"fraction": 0.0}, "fraction"),
    ],
)
def test_blend_validation(args, kwargs, match):
    with pytest.raises(MotionError, match=match):
        blend_corner(*args, **kwargs)


# ---------------------------------------------------------------- junction speed
def test_corner_speed_anchor_values():
    assert corner_speed([1, 0], [0, 1], 1000.0, 5.0) == pytest.approx(5.0, rel=1e-12)
    assert corner_speed([1, 0], [1, 0], 1000.0, 5.0) == math.inf
    assert corner_speed([1, 0], [-1, 0], 1000.0, 5.0) == 0.0
    assert corner_speed([2, 0, 0], [0, 0, 3], 10.0, 5.0) == pytest.approx(5.0)  # normalized
    assert corner_speed([1, 0], [0, 1], 1000.0, 0.0) == 0.0
    # tiny moves: circle touches each move at most mid-move: v^2 = 0.5*L*a*tan(45 deg)
    assert corner_speed([1, 0], [0, 1], 1000.0, 5.0, lengths=(0.01, 1.0)) == \
        pytest.approx(math.sqrt(0.5 * 0.01 * 1000.0))


@settings(max_examples=200, deadline=None)
@given(st.floats(1e-3, math.pi - 1e-3), st.floats(1.0, 1e4), st.floats(0.1, 100.0))
def test_corner_speed_matches_junction_deviation_formula(turn, accel, scv):
    u1 = np.array([1.0, 0.0])
    u2 = np.array([math.cos(turn), math.sin(turn)])
    # grbl/Klipper textbook form: cos(theta) = -u1.u2, R = delta*sin(t/2)/(1 - sin(t/2))
    cos_theta = -float(u1 @ u2)
    sin_h = math.sqrt(0.5 * (1 - cos_theta))
    delta = scv**2 * SQRT2_M1 / accel
    expected = math.sqrt(accel * delta * sin_h / (1 - sin_h))
    assert corner_speed(u1, u2, accel, scv) == pytest.approx(expected, rel=1e-7)
    # sharper corners are slower
    sharper = np.array([math.cos(turn * 1.01), math.sin(turn * 1.01)]) if turn * 1.01 < math.pi \
        else -u1
    assert corner_speed(u1, sharper, accel, scv) <= corner_speed(u1, u2, accel, scv)


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        (([0, 0], [1, 0], 1.0, 1.0), {}, "u1 must be a non-zero direction"),
        (([1, 0], [1, 0, 0], 1.0, 1.0), {}, "u2 must have 2 axes"),
        (([1, 0], [0, 1], 0.0, 1.0), {}, "accel must be > 0"),
        (([1, 0], [0, 1], 1.0, -1.0), {}, "square_corner_velocity must be >= 0"),
        (([1, 0], [0, 1], 1.0, 1.0), {"lengths": (1.0,)}, "lengths must be two"),
        (([1, 0], [0, 1], 1.0, 1.0), {"lengths": (1.0, -1.0)}, "lengths must be >= 0"),
        (([1, 0], [0, 1], 1.0, 1.0), {"lengths": 3.0}, "lengths must be two"),
    ],
)
def test_corner_speed_validation(args, kwargs, match):
    with pytest.raises(MotionError, match=match):
        corner_speed(*args, **kwargs)


def test_centripetal_speed():
    assert centripetal_speed(4.0, 9.0) == 6.0
    assert centripetal_speed(0.0, 9.0) == 0.0
    with pytest.raises(MotionError, match="radius must be >= 0"):
        centripetal_speed(-1.0, 1.0)
    with pytest.raises(MotionError, match="normal_accel must be finite"):
        centripetal_speed(1.0, math.inf)


# -- the fast line-line constructions equal the validated one --------------------------------
def _same_element(a, b, rel=0.0):
    """a equals b bit for bit (rel 0) or within rel of the scale of each value."""
    def same(x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if rel == 0.0:
            return np.array_equal(x, y, equal_nan=True)
        scale = max(1.0, float(np.max(np.abs(y), initial=0.0, where=~np.isnan(y))))
        return bool(np.all((np.isnan(x) & np.isnan(y)) | (np.abs(x - y) <= rel * scale)))

    assert type(a) is type(b)
    assert same(a.length, b.length)
    # equal_nan: corners of subnormal size give NaN tangents, in both constructions alike
    for name in ("start", "end", "start_tangent", "end_tangent", "max_abs_tangent",
                 "axis_accel_weight"):
        assert same(getattr(a, name), getattr(b, name)), name
    assert same(a.max_curvature, b.max_curvature) if rel else (
        a.max_curvature == b.max_curvature or (math.isnan(a.max_curvature)
                                               and math.isnan(b.max_curvature)))
    s = np.linspace(0.0, b.length, 7)
    assert same(a.point(np.minimum(s, a.length)), b.point(s))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=9, max_size=9),
       st.floats(1e-6, 10.0), st.sampled_from([2, 3]))
def test_line_blend_equals_the_validated_construction(c, tol, dim):
    """The numpy construction (more than 64 axes) bit for bit; the compiled one
    (openmotion._corner) within 1e-9 relative: its dot products and cos/arctan2/hypot
    round differently from numpy's (BLAS may fuse multiply-adds), so bit for bit is not
    defined across machines (issue 14: 'bit for bit or within 1e-9')."""
    from openmotion.path.blend import _line_line_numpy
    from oracle_blend import blend_lines

    p0, p1, p2 = np.array(c[0:dim]), np.array(c[3:3 + dim]), np.array(c[6:6 + dim])
    first, second = Line(p0, p1), Line(p1, p2)
    # corners of subnormal size break Arc3D (NaN tangents, a 0 radius**2): not compared
    assume(first.length > 1e-100 and second.length > 1e-100)
    b = blend_corner(first, second, tol)
    n = _line_line_numpy(first, second, tol, 0.5)
    if b is None or n is None:
        assert b is None and n is None
        return
    f, arc, s, dev = blend_lines(first, second, tol)
    for got, rel in ((n, 0.0), (b, 1e-9)):
        _same_element(got.first, f, rel)
        _same_element(got.arc, arc, rel)
        _same_element(got.second, s, rel)
        assert abs(got.deviation - dev) <= rel * max(1.0, dev)
    # the compiled corner joins its pieces bit for bit, as the numpy one does
    assert b.first.end is b.arc.start and b.arc.end is b.second.start
    assert b.first.start is first.start and b.second.end is second.end


def test_line_blend_numpy_and_compiled_agree_in_many_axes():
    """Six axes (the compiled corner's loops over every axis) and the numpy path."""
    from openmotion.path.blend import _line_line_numpy

    rng = np.random.default_rng(7)
    for _ in range(50):
        p = rng.uniform(-100.0, 100.0, (3, 6))
        first, second = Line(p[0], p[1]), Line(p[1], p[2])
        b, n = blend_corner(first, second, 0.5), _line_line_numpy(first, second, 0.5, 0.5)
        assert (b is None) == (n is None)
        if b is not None:
            for x, y in zip(b.elements, n.elements, strict=True):
                _same_element(x, y, 1e-9)
