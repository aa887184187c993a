"""The corners of a run of lines in one compiled call (path/blend.py `_line_run`, the
streaming join's `_blend_run`): bit for bit what blend_corner and the group's pay test give
corner after corner (tests/oracle_blend.py), over random polylines with degenerate corners
(straight, reversals, repeated points, tiny and far-off segments, 2 to 6 axes)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.control.groups.grouptypes import _Cmd
from openmotion.path import Arc3D, Line
from openmotion.path.blend import _line_run
from oracle_blend import blend_run


def _bits(x) -> bytes:  # noqa: ANN001
    return np.asarray(x, dtype=np.float64).tobytes()


def same_element(a, b) -> None:  # noqa: ANN001
    """a and b are the same element bit for bit (every value the planner reads)."""
    assert type(a) is type(b)
    names = ["start", "end", "length", "max_curvature", "max_abs_tangent",
             "axis_accel_weight", "start_tangent", "end_tangent"]
    if isinstance(a, Arc3D):
        names.append("via")
        fa, fb = a._frame, b._frame
        for f in ("centre", "e1", "e2", "radius", "sweep", "helix", "start", "end",
                  "length", "lin", "t_start", "t_end"):
            assert _bits(getattr(fa, f)) == _bits(getattr(fb, f)), f
    else:
        names.append("direction")
    for name in names:
        assert _bits(getattr(a, name)) == _bits(getattr(b, name)), name


def same_run(got, want) -> None:  # noqa: ANN001
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert (g is None) == (w is None)
        if g is not None:
            for x, y in zip(g, w, strict=True):
                same_element(x, y)
            assert g[0].end is g[1].start and g[1].end is g[2].start


@st.composite
def polylines(draw):  # noqa: ANN001, ANN201
    """Points of a polyline with degenerate corners mixed in."""
    dim = draw(st.integers(2, 6))
    n = draw(st.integers(3, 10))
    coord = st.floats(-1e3, 1e3)
    pts = [np.array(draw(st.lists(coord, min_size=dim, max_size=dim)))]
    for _ in range(1, n):
        p = pts[-1]
        d = p - pts[-2] if len(pts) > 1 else np.ones(dim)
        kind = draw(st.sampled_from(["free", "free", "same", "straight", "back", "tiny",
                                     "near", "side"]))
        t = draw(st.floats(0.01, 3.0))
        if kind == "free":
            q = np.array(draw(st.lists(coord, min_size=dim, max_size=dim)))
        elif kind == "same":
            q = p.copy()
        elif kind == "straight":
            q = p + t * d
        elif kind == "back":
            q = p - t * d
        elif kind == "tiny":
            q = p + 1e-9 * np.array(draw(st.lists(st.floats(-1, 1), min_size=dim,
                                                  max_size=dim)))
        elif kind == "near":  # almost straight: turns about the tangent threshold
            w = np.zeros(dim)
            w[draw(st.integers(0, dim - 1))] = draw(st.floats(-1e-5, 1e-5))
            q = p + t * d + w * float(np.linalg.norm(d))
        else:  # a right angle in the first two axes
            q = p + t * np.concatenate([[-d[1], d[0]], np.zeros(dim - 2)])
        pts.append(q)
    return np.array(pts) + draw(st.sampled_from([0.0, 1e6]))


@settings(max_examples=300, deadline=None)
@given(polylines(), st.floats(1e-6, 10.0), st.booleans(), st.booleans(), st.data())
def test_line_run_is_blend_corner_corner_after_corner(pts, tol, shared, pays, data):
    """Shared ends (Line.chain_of, the program runner's) or lines of their own (Group.line),
    with and without the pay test: bit for bit the oracle's run."""
    lines = Line.chain_of(pts.copy()) if shared else \
        [Line(p, q) for p, q in zip(pts[:-1], pts[1:], strict=True)]
    m = len(lines) - 1
    accel = feed = None
    if pays:
        accel = data.draw(st.lists(st.floats(1.0, 1e6), min_size=m, max_size=m))
        feed = data.draw(st.lists(st.floats(0.1, 1e4), min_size=m, max_size=m))
    got = _line_run(lines[0], lines[1:], tol, accel=accel, feed=feed)
    same_run(got, blend_run(lines[0], lines[1:], tol, accel, feed))


def test_line_run_stops_before_a_line_that_starts_elsewhere():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 1.0], [2.0, 2.0]])
    lines = [Line(p, q) for p, q in zip(pts[:-1], pts[1:], strict=True)]
    lines[2] = Line(pts[2] + [1e-12, 0.0], pts[3])  # (within blend_corner's gap check)
    got = _line_run(lines[0], lines[1:], 0.1)
    assert len(got) == 1
    same_run(got, blend_run(lines[0], lines[1:2], 0.1))


def test_the_pay_test_refuses_a_tight_sharp_corner():
    """A sharp corner with a tiny tolerance crawls: the compiled pay test drops it, as
    groupstream._blend_pays does; a generous one keeps it."""
    lines = Line.chain_of(np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 0.3]]))
    for tol, kept in ((1e-6, False), (0.5, True)):
        got = _line_run(lines[0], lines[1:], tol, accel=[100.0], feed=[200.0])
        assert (got[0] is not None) is kept
        same_run(got, blend_run(lines[0], lines[1:], tol, [100.0], [200.0]))


@pytest.mark.parametrize("angle", [0.05, 0.3, 1.0])
def test_the_pay_test_flips_where_the_oracle_flips(angle):
    """Sharp corners, tolerances across the pay test's boundary (tight arcs crawl, wide
    ones pay): the compiled decision is the oracle's at every step (it flips where that
    one flips)."""
    pts = np.array([[0.0, 0.0], [2.0, 0.0], [2.0 - 2.0 * math.cos(angle),
                                               2.0 * math.sin(angle)]])
    lines = Line.chain_of(pts)
    kept = []
    for tol in np.geomspace(1e-9, 0.5, 300):
        for accel, feed in ((50.0, 40.0), (500.0, 5.0)):
            got = _line_run(lines[0], lines[1:], float(tol), accel=[accel], feed=[feed])
            same_run(got, blend_run(lines[0], lines[1:], float(tol), [accel], [feed]))
            kept.append(got[0] is not None)
    assert any(kept) and not all(kept)


def _group(corner_velocity: float = 0.0) -> Group:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xyz")
    ctl = Controller(MachineConfig(name="run", axes=axes))
    ctl.enable_all()
    g = Group(ctl, ["x", "y", "z"], units=True, feed=40.0, acc_time=0.05)
    g.enable_blend(0.01)
    if corner_velocity:
        g.set_corner_velocity(corner_velocity)
    return g


@pytest.mark.parametrize("corner_velocity", [0.0, 5.0])
def test_group_blend_run_is_blend_new_corner_after_corner(corner_velocity):
    """The group's run over lines (shared ends, own ends, a gap), arcs and zero-length
    lines: bit for bit its `_blend_new` corner after corner."""
    g = _group(corner_velocity)
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.uniform(-1.0, 1.0, (30, 3)), axis=0)
    els: list = list(Line.chain_of(pts[:12].copy()))
    els += [Line(p, q) for p, q in zip(pts[11:19], pts[12:20], strict=True)]
    els.append(Line(pts[19], pts[19]))  # zero length
    mid = pts[19] + [0.3, 0.4, 0.0]
    arc = Arc3D(pts[19], mid, pts[19] + [0.0, 1.0, 0.0])
    els.append(arc)
    els += [Line(arc.end, pts[20]), Line(pts[20] + [1e-13, 0, 0], pts[21])]
    els += list(Line.chain_of(pts[21:].copy()))
    cmds = [_Cmd(index=k, kind="path", elements=(el,), feed=30.0 + k, accel=400.0 + 10 * k,
                 decel=None if k % 3 else 350.0) for k, el in enumerate(els)]
    got = g._blend_run(els[0], cmds[1:])
    want, prev = [], els[0]
    for c in cmds[1:]:
        b = g._blend_new(prev, c.elements[0], c)
        want.append(b)
        prev = c.elements[0] if b is None else b[2]
    same_run(got, want)
    if not corner_velocity:  # (with one the corners are taken at it instead)
        assert sum(b is not None for b in got) > 10


def test_group_elements_equal_the_corner_by_corner_chain():
    """`_elements` (pre-blended corners first, then runs) gives the elements and owners the
    corner-by-corner construction gives."""
    g = _group()
    pts = np.array([(0.05 * k, 0.5 * math.sin(k / 15.0), 0.0) for k in range(60)])
    els = Line.chain_of(pts)
    cmds = [_Cmd(index=k, kind="path", elements=(el,), feed=40.0, accel=800.0)
            for k, el in enumerate(els)]
    first, out, owners = g._elements(cmds[1:], els[0])
    prev, want, want_owners = els[0], [], []
    for c in cmds[1:]:
        b = g._blend_new(prev, c.elements[0], c)
        if b is None:
            want.append(c.elements[0])
            want_owners.append(c.index)
        else:
            if want:
                want[-1] = b[0]
            else:
                want_first = b[0]
            want += [b[1], b[2]]
            want_owners += [c.index, c.index]
        prev = want[-1]
    same_element(first, want_first)
    assert owners == want_owners
    for x, y in zip(out, want, strict=True):
        same_element(x, y)
