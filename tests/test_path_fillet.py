"""Fillet blends of corners with arcs (line-arc, arc-line, arc-arc) and arc trimming
(`Arc.sub`, `Arc3D.sub`): tangency, tolerance, kept ends, coplanarity, closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.control.groups.pathexec import contour_error
from openmotion.errors import MotionError
from openmotion.path import Arc, Arc3D, Line, blend_corner
from openmotion.path.fillet import model_error


def _closest(arc, corner) -> float:
    """Distance from `corner` to the arc: dense samples, then a ternary search."""
    s = np.linspace(0.0, arc.length, 4001)
    d = np.linalg.norm(arc.point(s) - corner, axis=1)
    k = int(np.argmin(d))
    lo, hi = s[max(k - 1, 0)], s[min(k + 1, len(s) - 1)]

    def f(x: float) -> float:
        return float(np.linalg.norm(arc.point(x) - corner))

    for _ in range(200):
        m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        if f(m1) < f(m2):
            hi = m2
        else:
            lo = m1
    return min(f(0.5 * (lo + hi)), float(d.min()))


def _embed(p2, plane, n, base):
    """A 2-D point into n axes: plane axes from p2, the others = base."""
    out = np.array(base, dtype=float)
    out[list(plane)] = p2
    return out


def _incoming(corner, ang, k, length, plane, n, base):
    """Element ending at `corner` (2-D) with tangent angle `ang` and signed curvature k."""
    t = np.array([math.cos(ang), math.sin(ang)])
    c3 = _embed(corner, plane, n, base)
    if k == 0.0:
        return Line(_embed(corner - length * t, plane, n, base), c3)
    nrm = np.array([-t[1], t[0]])
    centre = corner + nrm / k
    phi = -k * length  # rotate the corner about the centre backwards along the path
    rel = corner - centre
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    start = centre + rot @ rel
    return Arc(_embed(start, plane, n, base), centre, c3, plane=plane,
               direction="CCW" if k > 0 else "CW")


def _outgoing(corner, ang, k, length, plane, n, base):
    t = np.array([math.cos(ang), math.sin(ang)])
    c3 = _embed(corner, plane, n, base)
    if k == 0.0:
        return Line(c3, _embed(corner + length * t, plane, n, base))
    nrm = np.array([-t[1], t[0]])
    centre = corner + nrm / k
    phi = k * length
    rel = corner - centre
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    end = centre + rot @ rel
    return Arc(c3, centre, _embed(end, plane, n, base), plane=plane,
               direction="CCW" if k > 0 else "CW")


@st.composite
def arc_corners(draw):
    n = draw(st.integers(2, 4))
    plane = tuple(draw(st.permutations(range(n)))[:2])
    base = draw(st.lists(st.floats(-1e3, 1e3), min_size=n, max_size=n))
    corner = np.array(draw(st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=2)))
    a1 = draw(st.floats(-math.pi, math.pi))
    turn = draw(st.floats(1e-3, math.pi - 1e-3)) * draw(st.sampled_from([-1.0, 1.0]))
    kinds = draw(st.sampled_from(["la", "al", "aa"]))

    def curv(is_arc: bool) -> tuple[float, float]:
        if not is_arc:
            return 0.0, draw(st.floats(1e-2, 1e3))
        radius = draw(st.floats(1e-2, 1e3))
        sweep = draw(st.floats(0.05, 6.0))
        return draw(st.sampled_from([-1.0, 1.0])) / radius, radius * sweep

    k1, l1 = curv(kinds[0] == "a")
    k2, l2 = curv(kinds[1] == "a")
    first = _incoming(corner, a1, k1, l1, plane, n, base)
    second = _outgoing(corner, a1 + turn, k2, l2, plane, n, base)
    tol = draw(st.floats(1e-5, 10.0))
    return first, second, tol


@settings(max_examples=150, deadline=None)
@given(arc_corners())
def test_fillet_properties(data):
    first, second, tol = data
    b = blend_corner(first, second, tol)
    assert b is not None
    arc = b.arc
    corner = first.end
    scale = max(1.0, float(np.abs(corner).max()))
    eps = 1e-12 * scale
    # same kinds, kept ends bit for bit, joins bit for bit
    assert type(b.first) is type(first) and type(b.second) is type(second)
    assert np.array_equal(b.first.start, first.start)
    assert np.array_equal(b.second.end, second.end)
    assert np.array_equal(b.first.end, arc.start)
    assert np.array_equal(arc.end, b.second.start)
    # tangent at both joints (the look-ahead treats turns below 1e-6 rad as straight)
    assert np.abs(arc.start_tangent - b.first.end_tangent).max() <= 1e-9
    assert np.abs(arc.end_tangent - b.second.start_tangent).max() <= 1e-9
    # trimmed elements: on the same curve, at most half of each used
    for old, new, at_end in ((first, b.first, True), (second, b.second, False)):
        cut = old.length - new.length
        assert 0.0 < cut <= 0.5 * old.length * (1 + 1e-9) + eps
        s = np.linspace(0.0, new.length, 33)
        ref = old.point(s if at_end else s + cut)
        assert np.abs(new.point(s) - ref).max() <= 1e-9 * max(1.0, old.length) + 4 * eps
        if isinstance(old, Arc):
            assert new.radius == old.radius and new.plane == old.plane
            assert new.direction == old.direction
    # deviation: how far the blend passes from the corner; <= T, and = T unless a length
    # or the fillet's existence limits the radius
    d = _closest(arc, corner)
    assert b.deviation <= tol * (1 + 1e-9) + eps
    # `deviation` bounds the distance; it is exact up to what the arcs' end corrections
    # (rounding of the test's arc ends, here) can add
    corr = sum(el.end_correction for el in (first, second) if isinstance(el, Arc))
    assert d <= b.deviation * (1 + 1e-9) + 10 * eps
    slack = 3 * corr + 10 * eps + model_error(arc.radius, arc.sweep)
    assert d >= b.deviation * (1 - 1e-6) - slack
    # not limited by a length or by an arc it must fit inside: the tolerance is used up
    limited = any(old.length - new.length >= 0.5 * old.length * (1 - 1e-4)
                  for old, new in ((first, b.first), (second, b.second)))
    inside = any(isinstance(el, Arc) and arc.radius >= 0.998 * el.radius
                 for el in (first, second))
    bigger = blend_corner(first, second, 1.01 * tol)
    stuck = bigger is not None and bigger.arc.radius <= arc.radius * (1 + 1e-6)
    assert limited or inside or stuck or abs(b.deviation - tol) <= 1e-6 * tol + slack
    # the blend also stays within the tolerance of the programmed elements
    p = arc.point(np.linspace(0.0, arc.length, 101))
    assert contour_error(p, [first, second]).max() <= tol * (1 + 1e-3) + 10 * eps
    # in the elements' plane: the other axes keep their values
    others = [k for k in range(first.dim) if k not in first.plane] if isinstance(first, Arc) \
        else [k for k in range(second.dim) if k not in second.plane]
    assert np.all(p[:, others] == corner[others])


def test_line_into_circle_closed_form():
    # incoming line along +x to the origin; outgoing arc CW about (R, 0) leaves along +y.
    # The fillet (radius r, centre (xc, r)) touches the circle from outside:
    # (R - xc)**2 + r**2 = (R + r)**2, and its distance from the corner is |(xc, r)| - r.
    big_r, tol = 5.0, 0.2
    first = Line([-10.0, 0.0], [0.0, 0.0])
    second = Arc([0.0, 0.0], [big_r, 0.0], [2 * big_r, 0.0], direction="CW")
    b = blend_corner(first, second, tol)
    r = b.arc.radius
    xc = big_r - math.sqrt(big_r**2 + 2 * big_r * r)
    assert b.arc.circle_centre == pytest.approx([xc, r], rel=1e-9)
    assert math.hypot(xc, r) - r == pytest.approx(tol, rel=1e-9)
    assert b.deviation == pytest.approx(tol, rel=1e-9)
    assert b.first.end == pytest.approx([xc, 0.0], rel=1e-9)
    assert np.linalg.norm(b.second.start - [big_r, 0.0]) == pytest.approx(big_r, rel=1e-12)
    assert b.arc.sweep < math.pi / 2  # the arc itself turns part of the corner


def test_arc_arc_symmetric_numbers():
    # two quarter circles of radius 10 meeting at a right-angle corner, mirror images: the
    # fillet is symmetric (equal cuts), centred on the bisector
    a = Arc([0.0, 0.0], [0.0, 10.0], [10.0, 10.0])            # ends at (10,10) going +y
    b = Arc([10.0, 10.0], [10.0, 0.0], [0.0, 0.0])            # leaves it going -x, CCW
    res = blend_corner(a, b, 0.05)
    assert res is not None
    cut1 = a.length - res.first.length
    cut2 = b.length - res.second.length
    assert cut1 == pytest.approx(cut2, rel=1e-9)
    assert res.deviation == pytest.approx(0.05, rel=1e-9)


def test_spiral_arc_ends_are_blended_within_tolerance():
    # G-code arcs whose end is only on the circle within tolerance (a correction spread
    # along the arc) still blend; the correction counts into the deviation
    first = Line([0.0, 0.0], [10.0, 0.0])
    second = Arc([10.0, 0.0], [15.0, 0.0], [20.004, 0.0], direction="CW", tol=1e-3)
    assert second.end_correction > 1e-3
    b = blend_corner(first, second, 0.1)
    assert b is not None
    assert b.deviation <= 0.1
    assert np.array_equal(b.arc.start, b.first.end) and np.array_equal(b.arc.end,
                                                                       b.second.start)
    assert np.abs(b.arc.end_tangent - b.second.start_tangent).max() <= 1e-9
    assert _closest(b.arc, first.end) <= b.deviation * (1 + 1e-9)
    assert np.array_equal(b.second.end, second.end)


def test_arc3d_corner_in_its_plane_is_blended():
    first = Arc3D([0.0, 0.0, 1.0], [5.0, 5.0, 1.0], [10.0, 0.0, 1.0])
    b = blend_corner(first, Line([10.0, 0.0, 1.0], [20.0, 0.0, 1.0]), 0.1)
    assert isinstance(b.first, Arc3D)
    assert b.deviation == pytest.approx(0.1, rel=1e-9)
    assert np.all(b.arc.point(np.linspace(0, b.arc.length, 9))[:, 2] == 1.0)


@pytest.mark.parametrize(
    ("first", "second", "why"),
    [
        (Line([0, 0, 0], [10, 0, 0]), Arc([10, 0, 0], [10, 5], [10, 10, 3]), "helix"),
        (Line([0, 0, 0], [10, 0, 1]), Arc([10, 0, 1], [10, 5], [10, 10, 1]), "line off plane"),
        (Arc([0, 0, 0], [0, 5], [0, 10, 0]), Arc([0, 10, 0], [10, 5], [0, 10, 10], plane=(1, 2)),
         "arcs in two planes"),
        (Line([0, 0], [10, 0]), Arc([10, 0], [10, 5], [15, 5]), "tangent"),
        (Line([0, 0], [10, 0]), Arc([10, 0], [10, -5], [10, -10], direction="CW"), "tangent"),
        (Line([0, 0], [10, 0]), Arc([10, 0], [10, 5], [10, 10], direction="CW"), "reversal"),
        (Arc3D([0, 0, 0], [5, 5, 1], [10, 0, 0]), Line([10, 0, 0], [20, 0, 5]), "off plane"),
    ],
)
def test_no_fillet_cases(first, second, why):
    assert blend_corner(first, second, 0.5) is None, why


def test_fillet_zero_tolerance_and_validation():
    line = Line([0.0, 0.0], [10.0, 0.0])
    arc = Arc([10.0, 0.0], [15.0, 0.0], [20.0, 0.0], direction="CW")
    assert blend_corner(line, arc, 0.0) is None
    with pytest.raises(MotionError, match="must be Line, Arc or Arc3D"):
        blend_corner(line, "arc", 0.1)  # type: ignore[arg-type]
    with pytest.raises(MotionError, match="second.start must equal"):
        blend_corner(line, Arc([10.0, 1.0], [15.0, 1.0], [20.0, 1.0]), 0.1)


# ---------------------------------------------------------------- trimming arcs
@settings(max_examples=100, deadline=None)
@given(st.floats(0.0, 0.99), st.floats(0.01, 1.0), st.integers(0, 1), st.booleans(),
       st.floats(-5.0, 5.0))
def test_arc_sub_is_the_same_curve(a, span, turns, ccw, z):
    arc = Arc([3.0, 1.0, 0.0], [1.0, 1.0], [1.0, 3.0, z], direction="CCW" if ccw else "CW",
              turns=turns)
    s0 = a * arc.length
    s1 = min(arc.length, s0 + span * (arc.length - s0))
    assume(s1 > s0)
    part = arc.sub(s0, s1)
    assert isinstance(part, Arc)
    assert part.length == pytest.approx(s1 - s0, rel=1e-12, abs=1e-12)
    s = np.linspace(0.0, part.length, 17)
    assert np.abs(part.point(s) - arc.point(np.minimum(s0 + s, arc.length))).max() < 1e-12
    assert np.abs(part.tangent(s) - arc.tangent(np.minimum(s0 + s, arc.length))).max() < 1e-12
    assert part.radius == arc.radius and part.direction == arc.direction
    if s0 == 0.0:
        assert np.array_equal(part.start, arc.start)
    if s1 == arc.length:
        assert np.array_equal(part.end, arc.end)


def test_arc_sub_keeps_ends_and_corrections_bit_for_bit():
    arc = Arc([10.0, 0.0], [0.0, 0.0], [0.0, 10.00001], tol=1e-5)  # end off the circle
    head, tail = arc.sub(0.0, 5.0), arc.sub(5.0, arc.length)
    assert head.start is arc.start and np.array_equal(tail.end, arc.end)
    assert np.array_equal(head.end, tail.start)
    assert arc.sub(0.0, arc.length) is arc
    a3 = Arc3D([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0])
    part = a3.sub(0.5, 2.0)
    assert isinstance(part, Arc3D)
    assert np.abs(part.point([0.0, 1.5]) - a3.point([0.5, 2.0])).max() < 1e-15


@pytest.mark.parametrize(("s0", "s1"), [(-0.1, 1.0), (1.0, 1.0), (2.0, 1.0), (0.0, 100.0),
                                        (math.nan, 1.0)])
def test_arc_sub_validation(s0, s1):
    arc = Arc([1.0, 0.0], [0.0, 0.0], [0.0, 1.0])
    with pytest.raises(MotionError, match="s0|s1"):
        arc.sub(s0, s1)


def test_from_frame_end_slack():
    e1, e2 = [1.0, 0.0], [0.0, 1.0]
    with pytest.raises(MotionError, match="end is"):
        Arc3D.from_frame([0, 0], e1, e2, 1.0, 1.0, end=[math.cos(1.0), math.sin(1.0) + 1e-4])
    a = Arc3D.from_frame([0, 0], e1, e2, 1.0, 1.0, end=[math.cos(1.0), math.sin(1.0) + 1e-4],
                         end_slack=2e-4)
    assert a.point(a.length).tolist() == [math.cos(1.0), math.sin(1.0) + 1e-4]
    with pytest.raises(MotionError, match="end_slack must be >= 0"):
        Arc3D.from_frame([0, 0], e1, e2, 1.0, 1.0, end_slack=-1.0)
