"""Line and the shared path-element helpers: exact ends, vectorized queries, validation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.path import Direction, Line, PathElement

coord = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)


@st.composite
def lines(draw):
    n = draw(st.integers(2, 6))
    a = draw(st.lists(coord, min_size=n, max_size=n))
    b = draw(st.lists(coord, min_size=n, max_size=n))
    return Line(a, b)


@settings(max_examples=150, deadline=None)
@given(lines(), st.floats(0.0, 1.0))
def test_line_properties(line, frac):
    assert isinstance(line, PathElement)
    assert np.array_equal(line.point(0.0), line.start)
    assert np.array_equal(line.point(line.length), line.end)
    assert line.length == pytest.approx(float(np.linalg.norm(line.end - line.start)), rel=1e-12)
    s = frac * line.length
    p = line.point(s)
    expected = line.start + frac * (line.end - line.start)
    assert np.allclose(p, expected, rtol=0, atol=1e-9 * max(1.0, float(np.abs(line.end).max(
        initial=0.0)), float(np.abs(line.start).max())))
    if line.length > 0:
        assert np.linalg.norm(line.tangent(s)) == pytest.approx(1.0, abs=1e-12)
        # tangent points from start to end
        assert float(line.tangent(s) @ (line.end - line.start)) == pytest.approx(line.length,
                                                                                  rel=1e-9)
    assert line.curvature(s) == 0.0
    assert line.max_curvature == 0.0


def test_line_vectorized_shapes_and_scalar_results():
    line = Line([0.0, 0.0, 0.0], [3.0, 4.0, 12.0])
    assert line.length == 13.0
    s = np.linspace(0.0, 13.0, 12).reshape(3, 4)
    assert line.point(s).shape == (3, 4, 3)
    assert line.tangent(s).shape == (3, 4, 3)
    assert line.curvature(s).shape == (3, 4)
    assert isinstance(line.curvature(1.0), float)
    assert line.point(6.5).tolist() == [1.5, 2.0, 6.0]
    assert np.array_equal(line.tangent(0.0), [3 / 13, 4 / 13, 12 / 13])
    assert np.array_equal(line.start_tangent, line.end_tangent)
    assert np.array_equal(line.max_abs_tangent, [3 / 13, 4 / 13, 12 / 13])


def test_line_end_is_exact_even_when_float_sum_is_not():
    # start + length * u does not reproduce end in floating point here.
    line = Line([0.1, 0.7], [1e5 + 0.3, -2.9])
    assert np.array_equal(line.point(line.length), line.end)
    assert np.array_equal(line.point([0.0, line.length])[1], line.end)


def test_zero_length_line():
    line = Line([1.0, 2.0], [1.0, 2.0])
    assert line.length == 0.0
    assert np.array_equal(line.point(0.0), [1.0, 2.0])
    assert np.array_equal(line.tangent(0.0), [0.0, 0.0])
    with pytest.raises(MotionError, match="s must be in"):
        line.point(1.0)


def test_s_is_validated_and_clipped_within_slack():
    line = Line([0.0, 0.0], [10.0, 0.0])
    assert np.array_equal(line.point(10.0 + 1e-12), line.end)
    assert np.array_equal(line.point(-1e-12), line.start)
    for bad in (-0.1, 10.1, math.nan, math.inf):
        with pytest.raises(MotionError, match="s must"):
            line.point(bad)
    with pytest.raises(MotionError, match="s must"):
        line.tangent([1.0, 11.0])
    with pytest.raises(MotionError, match="s must"):
        line.curvature("x")


def test_points_are_copied_and_read_only():
    a = np.array([0.0, 0.0])
    line = Line(a, [1.0, 1.0])
    a[0] = 5.0
    assert line.start[0] == 0.0
    with pytest.raises(ValueError):
        line.start[0] = 1.0
    with pytest.raises(AttributeError):
        line.length = 3.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("start", "end", "match"),
    [
        ([0.0], [1.0], "start must be a 1-D point of at least 2 axes"),
        ([0.0, math.nan], [1.0, 1.0], "start must be finite"),
        ([0.0, 0.0], [1.0, math.inf], "end must be finite"),
        ([0.0, 0.0], [1.0, 1.0, 1.0], "end must have 2 axes"),
        ([[0.0, 0.0]], [1.0, 1.0], "start must be a 1-D point"),
        (["a", "b"], [1.0, 1.0], "start must be a sequence of real numbers"),
        (None, [1.0, 1.0], "start must be"),
    ],
)
def test_line_validation(start, end, match):
    with pytest.raises(MotionError, match=match):
        Line(start, end)


def test_direction_enum_matches_mccl_constants():
    assert Direction.CW == 0 and Direction.CCW == 1
