"""Arc (plane arcs, full circles, helices) and Arc3D (three points): properties and errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.path import Arc, Arc3D, Direction, PathElement

TWO_PI = 2.0 * math.pi
finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@st.composite
def plane_arcs(draw):
    """(arc, centre_in_plane, radius, sweep) built from exact circle data."""
    n = draw(st.integers(2, 5))
    i, j = draw(st.permutations(range(n)))[:2]
    centre = np.array(draw(st.lists(finite, min_size=2, max_size=2)))
    radius = draw(st.floats(0.1, 1e3))
    a0 = draw(st.floats(-math.pi, math.pi))
    sweep = draw(st.floats(1e-3, TWO_PI - 1e-3))
    direction = draw(st.sampled_from([Direction.CW, Direction.CCW]))
    sign = 1.0 if direction is Direction.CCW else -1.0
    start = np.array(draw(st.lists(finite, min_size=n, max_size=n)))
    end = np.array(draw(st.lists(finite, min_size=n, max_size=n)))
    if draw(st.booleans()):  # plain circle: other axes stay
        end = start.copy()
    start[[i, j]] = centre + radius * np.array([math.cos(a0), math.sin(a0)])
    a1 = a0 + sign * sweep
    end[[i, j]] = centre + radius * np.array([math.cos(a1), math.sin(a1)])
    arc = Arc(start, centre, end, plane=(i, j), direction=direction)
    return arc, centre, radius, sweep


def _num_derivative(el, s, h):
    return (el.point(s + h) - el.point(s - h)) / (2.0 * h)


@settings(max_examples=150, deadline=None)
@given(plane_arcs(), st.floats(0.0, 1.0))
def test_plane_arc_properties(data, frac):
    arc, centre, radius, sweep = data
    assert isinstance(arc, PathElement)
    i, j = arc.plane
    # exact ends
    assert np.array_equal(arc.point(0.0), arc.start)
    assert np.array_equal(arc.point(arc.length), arc.end)
    # geometry recovered
    assert arc.radius == pytest.approx(radius, rel=1e-9)
    assert arc.sweep == pytest.approx(sweep, abs=1e-9 * max(1.0, 1e3 / radius))
    helix = arc.end - arc.start
    helix[[i, j]] = 0.0
    assert arc.length == pytest.approx(math.hypot(arc.radius * arc.sweep,
                                                  float(np.linalg.norm(helix))), rel=1e-12)
    s = np.linspace(0.0, arc.length, 257)
    p = arc.point(s)
    # on the circle in the plane
    r = np.hypot(p[:, i] - centre[0], p[:, j] - centre[1])
    assert np.allclose(r, radius, rtol=1e-9, atol=1e-9)
    # other axes move linearly with s
    others = [k for k in range(arc.dim) if k not in (i, j)]
    if others:
        lin = arc.start[others] + np.outer(s / arc.length, arc.end[others] - arc.start[others])
        assert np.allclose(p[:, others], lin, rtol=0, atol=1e-9 * 1e3)
    # unit tangent equal to the numerical derivative
    t = arc.tangent(s)
    assert np.allclose(np.linalg.norm(t, axis=-1), 1.0, atol=1e-12)
    h = min(1e-4 * radius, arc.length / 8)
    sm = frac * (arc.length - 2 * h) + h
    assert np.allclose(_num_derivative(arc, sm, h), arc.tangent(sm), atol=1e-6)
    # direction sense: CCW means the (i, j) cross product of radius and tangent is > 0
    rad = arc.point(sm)[[i, j]] - centre
    cross = rad[0] * arc.tangent(sm)[j] - rad[1] * arc.tangent(sm)[i]
    assert (cross > 0) == (arc.direction is Direction.CCW)
    # curvature
    pitch = float(np.linalg.norm(helix)) / arc.sweep
    assert arc.curvature(sm) == pytest.approx(radius / (radius**2 + pitch**2), rel=1e-9)
    # per-axis bounds hold and are tight (dense sampling)
    dense = np.linspace(0.0, arc.length, 4001)
    td = np.abs(arc.tangent(dense)).max(axis=0)
    assert np.all(td <= arc.max_abs_tangent + 1e-12)
    assert np.allclose(td, arc.max_abs_tangent, atol=2e-6)


def test_hsl_circular_interpolation_example():
    # HSL-4XMO manual 4.6: XY from (0,0) around centre (1000,0) to (1800,600).
    cw = Arc([0.0, 0.0], [1000.0, 0.0], [1800.0, 600.0], direction=Direction.CW)
    ccw = Arc([0.0, 0.0], [1000.0, 0.0], [1800.0, 600.0], direction=Direction.CCW)
    phi = math.atan2(600.0, 800.0)
    assert cw.radius == 1000.0
    assert cw.length == pytest.approx(1000.0 * (math.pi - phi), rel=1e-14)
    assert ccw.length == pytest.approx(1000.0 * (math.pi + phi), rel=1e-14)
    assert np.allclose(cw.start_tangent, [0.0, 1.0])  # CW at 9 o'clock goes up
    assert np.allclose(ccw.start_tangent, [0.0, -1.0])
    assert np.allclose(cw.end_tangent, [0.6, -0.8])
    assert np.allclose(cw.point(1000.0 * (math.pi / 2)), [1000.0, 1000.0])
    assert np.array_equal(cw.point(cw.length), [1800.0, 600.0])
    rel = Arc.relative([0.0, 0.0], [1000.0, 0.0], [1800.0, 600.0], direction="CW")
    assert rel.length == cw.length


def test_relative_arc_in_zu_plane_moves_other_axes_linearly():
    start = [10.0, 20.0, 5.0, 5.0]
    arc = Arc.relative(start, [3.0, 0.0], [2.0, 2.0, 3.0, 3.0], plane=(2, 3), direction=1)
    assert arc.radius == 3.0
    assert np.array_equal(arc.centre, [10.0, 20.0, 8.0, 5.0])
    assert np.array_equal(arc.end, [12.0, 22.0, 8.0, 8.0])
    assert arc.sweep == pytest.approx(3 * math.pi / 2)  # CCW from 9 o'clock to 12 o'clock
    mid = arc.point(arc.length / 2)
    assert mid[:2] == pytest.approx([11.0, 21.0])


def test_full_circle_and_extra_turns():
    circle = Arc([1.0, 0.0], [0.0, 0.0], [1.0, 0.0], direction=Direction.CW)
    assert circle.sweep == TWO_PI
    assert circle.length == pytest.approx(TWO_PI)
    assert np.allclose(circle.point(math.pi), [-1.0, 0.0])
    assert np.allclose(circle.point(math.pi / 2), [0.0, -1.0])  # clockwise
    assert np.array_equal(circle.point(circle.length), [1.0, 0.0])
    two = Arc([1.0, 0.0], [0.0, 0.0], [1.0, 0.0], turns=1)
    assert two.length == pytest.approx(2 * TWO_PI)
    # a full-turn helix: end above start
    helix = Arc([2.0, 0.0, 0.0], [0.0, 0.0], [2.0, 0.0, 5.0])
    assert helix.sweep == TWO_PI
    assert helix.length == pytest.approx(math.hypot(2 * TWO_PI, 5.0))
    c = 5.0 / TWO_PI
    assert helix.curvature(1.0) == pytest.approx(2.0 / (4.0 + c * c))
    assert np.allclose(helix.point(helix.length / 2), [-2.0, 0.0, 2.5])


def test_end_within_tolerance_is_reached_exactly_and_path_is_continuous():
    r = 100.0
    end = [0.0, r * (1 + 0.9e-6)]  # 0.9e-6 R outside the circle: accepted
    arc = Arc([r, 0.0], [0.0, 0.0], end)
    assert np.array_equal(arc.point(arc.length), end)
    s = np.linspace(0.0, arc.length, 1001)
    steps = np.linalg.norm(np.diff(arc.point(s), axis=0), axis=1)
    assert steps.max() < 1.01 * arc.length / 1000


@pytest.mark.parametrize("miss", [2e-6, 1e-3, -5e-6])
def test_arc_command_error_names_the_distance(miss):
    r = 100.0
    msg = r"arc command error: end is 0\.0*[0-9.]+ from the circle"
    with pytest.raises(MotionError, match=msg):
        Arc([r, 0.0], [0.0, 0.0], [0.0, r * (1 + miss)])
    # a looser tolerance accepts it
    arc = Arc([r, 0.0], [0.0, 0.0], [0.0, r * (1 + miss)], tol=1e-2)
    assert np.array_equal(arc.end, [0.0, r * (1 + miss)])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(start=[0, 0], centre=[0, 0], end=[0, 0]), "radius > 0"),
        (dict(start=[1, 0], centre=[0, 0, 0], end=[0, 1]), "centre must have 2"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], plane=(0, 0)), "plane must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], plane=(0, 2)), "plane must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], plane="xy"), "plane must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], direction=2), "direction must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], direction="up"), "direction must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], turns=-1), "turns must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], turns=1.5), "turns must be"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], tol=math.nan), "tol must be finite"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1], tol=-1), "tol must be >= 0"),
        (dict(start=[1, 0], centre=[0, math.nan], end=[0, 1]), "centre must be finite"),
        (dict(start=[1, 0], centre=[0, 0], end=[0, 1, 2]), "end must have 2 axes"),
    ],
)
def test_arc_validation(kwargs, match):
    with pytest.raises(MotionError, match=match):
        Arc(**kwargs)


def test_relative_validation():
    with pytest.raises(MotionError, match="end_offset must have 3 axes"):
        Arc.relative([0, 0, 0], [1, 0], [1, 1])
    with pytest.raises(MotionError, match="centre_offset must have 2"):
        Arc.relative([0, 0, 0, 0], [1, 0, 0], [1, 1, 0, 0])


def _random_frame(data, n):
    vecs = np.array(data.draw(st.lists(st.floats(-1, 1), min_size=2 * n, max_size=2 * n)))
    q, rmat = np.linalg.qr(vecs.reshape(2, n).T)
    assume(abs(rmat[0, 0]) > 1e-3 and abs(rmat[1, 1]) > 1e-3)
    return q[:, 0], q[:, 1]


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_arc3d_through_three_points(data):
    n = data.draw(st.integers(2, 5))
    e1, e2 = _random_frame(data, n)
    centre = np.array(data.draw(st.lists(finite, min_size=n, max_size=n)))
    radius = data.draw(st.floats(0.1, 1e3))
    phi_end = data.draw(st.floats(1e-2, TWO_PI - 1e-2))
    phi_via = data.draw(st.floats(0.05, 0.95)) * phi_end

    def on(phi):
        return centre + radius * (math.cos(phi) * e1 + math.sin(phi) * e2)

    arc = Arc3D(on(0.0), on(phi_via), on(phi_end))
    assert isinstance(arc, PathElement)
    scale = 1e-9 * max(1.0, float(np.abs(centre).max()) / radius)
    assert arc.radius == pytest.approx(radius, rel=scale * 10)
    assert arc.sweep == pytest.approx(phi_end, abs=scale * 10)
    assert np.allclose(arc.circle_centre, centre, atol=1e-6 * radius)
    assert np.array_equal(arc.point(0.0), arc.start)
    assert np.array_equal(arc.point(arc.length), arc.end)
    # passes through via, in order
    assert np.allclose(arc.point(radius * phi_via * arc.length / (radius * arc.sweep)),
                       on(phi_via), atol=1e-6 * radius)
    s = np.linspace(0.0, arc.length, 129)
    p = arc.point(s)
    assert np.allclose(np.linalg.norm(p - centre, axis=1), radius, rtol=1e-6)
    t = arc.tangent(s)
    assert np.allclose(np.linalg.norm(t, axis=-1), 1.0, atol=1e-12)
    h = min(1e-4 * radius, arc.length / 8)
    sm = 0.5 * arc.length
    assert np.allclose(_num_derivative(arc, sm, h), arc.tangent(sm), atol=1e-5)
    assert arc.curvature(sm) == pytest.approx(1.0 / radius, rel=1e-6)
    td = np.abs(arc.tangent(np.linspace(0.0, arc.length, 4001))).max(axis=0)
    assert np.all(td <= arc.max_abs_tangent + 1e-9)


def test_arc3d_mccl_style_examples():
    up = Arc3D([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0])
    down = Arc3D([1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [-1.0, 0.0, 0.0])
    assert up.length == pytest.approx(math.pi) and down.length == pytest.approx(math.pi)
    assert np.allclose(up.point(math.pi / 2), [0.0, 1.0, 0.0])
    assert np.allclose(down.point(math.pi / 2), [0.0, -1.0, 0.0])
    # via past the half: 270 degree arc; tilted plane
    big = Arc3D([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0])
    assert big.sweep == pytest.approx(1.5 * math.pi)
    tilted = Arc3D([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 3.0])
    p = tilted.point(np.linspace(0.0, tilted.length, 9))
    normal = np.cross([1.0, 1.0, 1.0], [2.0, 2.0, 3.0])
    assert np.allclose(p @ normal, 0.0, atol=1e-12)  # stays in the plane of the points
    assert np.allclose(np.linalg.norm(p - tilted.circle_centre, axis=1), tilted.radius)


@pytest.mark.parametrize(
    ("pts", "match"),
    [
        (([0, 0, 0], [1, 1, 1], [2, 2, 2]), "collinear"),
        (([0, 0, 0], [2, 2, 2], [1, 1, 1]), "collinear"),
        (([0, 0, 0], [0, 0, 0], [1, 0, 0]), "distinct"),
        (([0, 0, 0], [1, 0, 0], [1, 0, 0]), "distinct"),
        (([0, 0, 0], [1, 0, 0], [0, 0, 0]), "distinct"),
    ],
)
def test_arc3d_command_errors(pts, match):
    with pytest.raises(MotionError, match=f"arc command error: .*{match}"):
        Arc3D(*pts)


def test_arc3d_validation_and_from_frame():
    with pytest.raises(MotionError, match="via must have 3 axes"):
        Arc3D([0, 0, 0], [1, 0], [0, 1, 0])
    arc = Arc3D.from_frame([0, 0], [1, 0], [0, 1], 2.0, math.pi / 2)
    assert np.allclose(arc.end, [0.0, 2.0])
    with pytest.raises(MotionError, match="orthonormal"):
        Arc3D.from_frame([0, 0], [1, 0], [1, 1], 2.0, 1.0)
    with pytest.raises(MotionError, match="radius must be > 0"):
        Arc3D.from_frame([0, 0], [1, 0], [0, 1], 0.0, 1.0)
    with pytest.raises(MotionError, match="sweep must be <= 2\\*pi"):
        Arc3D.from_frame([0, 0], [1, 0], [0, 1], 1.0, 7.0)
    with pytest.raises(MotionError, match="start is .* from the arc"):
        Arc3D.from_frame([0, 0], [1, 0], [0, 1], 1.0, 1.0, start=[1.1, 0.0])
