"""The compiled look-ahead preparation (src/openmotion/_chain_prep.c and _chain_elem.c in
openmotion._corner: steps 1-2 of path/lookahead.py, the per-element limits and junction
caps, memoized across calls) against the Python path it stands in for
(`lookahead._prepare(..., compiled=False)`, the code it replaced): bit for bit on random
chains of lines, arcs, trimmed and zero-length elements, fresh and through the memo."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion import _corner
from openmotion.control.groups.pathexec import Trimmed
from openmotion.errors import InfeasibleError, MotionError
from openmotion.path import Arc, Arc3D, Line, blend_corner
from openmotion.path import lookahead as la

# pathexec.Trimmed is known as a path element once checked
assert la._is_element(Trimmed(Line(np.zeros(2), np.ones(2)), 0.5))


def _bits(x):
    """Floats as their bit patterns (nested lists and tuples kept)."""
    if isinstance(x, (list, tuple)):
        return type(x)(_bits(v) for v in x)
    if isinstance(x, float):
        return x.hex()
    return x


def _both(els, kw, fresh: bool = True):
    """`_prepare` compiled and in Python: (compiled result or error, Python's)."""
    args = (els, kw["feed"], kw["accel"], kw["scv"], kw["v_start"], kw["v_end"],
            kw["vmax"], kw["amax"], kw["vjump"], kw["ratio"], kw["mcr"], kw["decel"])
    if fresh:
        la._PREP_MEMO.clear()
    out = []
    for compiled in (True, False):
        before = la._PREP_MEMO[:1]
        try:
            out.append(_bits(la._prepare(*args, compiled=compiled)))
        except (MotionError, ValueError) as e:  # (InfeasibleError is a MotionError)
            out.append((type(e), str(e)))
        if compiled:  # whether the compiled path answered (it stores a record)
            ran = la._PREP_MEMO[:1] != before
    return out[0], out[1], ran


def _arc_through(p: np.ndarray, q: np.ndarray, bulge: float) -> Arc3D | Line:
    """An arc from p to q bulging sideways by `bulge` of the chord (a line if flat)."""
    d = q - p
    side = np.zeros_like(d)
    side[1 if abs(d[0]) >= abs(d[1]) else 0] = 1.0
    side -= (side @ d) / max(d @ d, 1e-300) * d
    n = np.linalg.norm(side)
    if n == 0.0 or np.linalg.norm(d) < 1e-6:
        return Line(p, q)
    via = 0.5 * (p + q) + bulge * np.linalg.norm(d) * side / n
    try:
        return Arc3D(p, via, q)
    except MotionError:
        return Line(p, q)


def _blended(segs: list, tol: float) -> list:
    """The elements with their line-line corners blended within tol (0: none), as a
    stream joins them."""
    els: list = []
    cur = segs[0]
    for nxt in segs[1:]:
        b = blend_corner(cur, nxt, tol) if tol > 0.0 and isinstance(cur, Line) \
            and isinstance(nxt, Line) else None
        if b is None:
            els.append(cur)
            cur = nxt
        else:
            els += [b.first, b.arc]
            cur = b.second
    return els + [cur]


@st.composite
def chains(draw):
    """Elements laid end to end: lines (some of length 0, some straight on), blended
    corners (arcs from the compiled blend), arcs through three points (sharp junctions),
    a planar Arc, a trimmed first element."""
    dim = draw(st.sampled_from([2, 3, 4]))
    n = draw(st.integers(1, 10))
    coord = st.floats(-20.0, 20.0, allow_nan=False)
    pts = [np.array(draw(st.lists(coord, min_size=dim, max_size=dim)))]
    for _ in range(n):
        kind = draw(st.sampled_from(["free", "same", "straight"]))
        if kind == "same":
            pts.append(pts[-1].copy())
        elif kind == "straight" and len(pts) > 1:
            pts.append(pts[-1] + 0.5 * (pts[-1] - pts[-2]))
        else:
            pts.append(np.array(draw(st.lists(coord, min_size=dim, max_size=dim))))
    segs: list = []
    for p, q in zip(pts[:-1], pts[1:], strict=True):
        shape = draw(st.sampled_from(["line", "line", "arc"]))
        segs.append(_arc_through(p, q, draw(st.floats(0.05, 0.6))) if shape == "arc"
                    else Line(p, q))
    els = _blended(segs, draw(st.sampled_from([0.0, 0.01, 0.5])))
    if draw(st.booleans()):  # a planar arc at the end (its own element type)
        e = els[-1].end
        centre = e.copy()
        centre[0] += 2.0
        end = centre.copy()
        end[0] -= 2.0 * math.cos(0.7)
        end[1] += 2.0 * math.sin(0.7)
        els.append(Arc(e, centre, end))
    if draw(st.booleans()) and els[0].length > 0.0:  # re-planned mid-element
        els[0] = Trimmed(els[0], draw(st.floats(0.0, 0.9)) * els[0].length)
    return els


def _per(draw, n, lo, hi, allow_none=False):
    opts = [st.floats(lo, hi), st.lists(st.floats(lo, hi), min_size=n, max_size=n)]
    if allow_none:
        opts.append(st.none())
    return draw(st.one_of(*opts))


@st.composite
def limits(draw, els):
    n, dim = len(els), els[0].dim
    ax = st.one_of(st.none(), st.lists(st.one_of(st.floats(1.0, 500.0), st.just(math.inf)),
                                       min_size=dim, max_size=dim).map(np.array))
    accel = _per(draw, n, 10.0, 1000.0)
    decel = draw(st.sampled_from(["none", "same", "own"]))
    if decel == "same":  # given, equal to the accelerations
        decel = list(accel) if isinstance(accel, list) else accel
    else:
        decel = None if decel == "none" else _per(draw, n, 5.0, 2000.0)
    return {"feed": _per(draw, n, 1.0, 200.0), "accel": accel, "decel": decel,
            "scv": draw(st.sampled_from([0.0, 0.01, 1.0, 50.0])), "v_start": 0.0,
            "v_end": draw(st.sampled_from([0.0, 0.5, 100.0])), "vmax": draw(ax),
            "amax": draw(ax), "vjump": draw(ax), "ratio": draw(st.floats(0.1, 0.9)),
            "mcr": draw(st.sampled_from([0.0, 0.0, 0.3]))}


@settings(max_examples=300, deadline=None)
@given(st.data())
def test_prepare_bit_for_bit(data) -> None:
    els = data.draw(chains())
    kw = data.draw(limits(els))
    got, want, ran = _both(els, kw)
    assert got == want
    assert ran or not isinstance(got[0], list) or not got[3]  # (compiled unless no length)


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_prepare_through_the_memo_bit_for_bit(data) -> None:
    """A stream's re-plans: the chain less its first elements, its last one replaced, new
    ones appended, the feeds scaled (an override), a deceleration or the limits changed;
    each compiled through the memo of the calls before, as the Python path computes it
    afresh."""
    els = data.draw(chains())
    more = data.draw(chains())
    if more[0].dim != els[0].dim:
        more = [Line(np.resize(e.start, els[0].dim), np.resize(e.end, els[0].dim))
                for e in more]
    kw = data.draw(limits(els + more))
    got, want, _ = _both(els + more, kw)
    assert got == want
    for _ in range(3):
        cut = data.draw(st.integers(0, len(els)))
        nxt = els[cut:] + more
        if nxt and data.draw(st.booleans()):  # the last element trimmed by a blend
            last = nxt[-1]
            nxt[-1] = Trimmed(last, 0.0, 0.5 * last.length) if last.length > 0 else last
        if not nxt:
            break
        k = dict(kw)
        n = len(nxt)
        for name in ("feed", "accel", "decel"):
            v = kw[name]
            if isinstance(v, list):  # the per-element values follow the elements
                v = (v[cut:] + v)[:n]
            k[name] = v
        change = data.draw(st.sampled_from(["none", "feed", "accel", "decel", "vmax",
                                            "scv"]))
        if change == "feed":
            k["feed"] = [f * 0.5 for f in k["feed"]] if isinstance(k["feed"], list) \
                else k["feed"] * 0.5
        elif change == "accel":
            k["accel"] = [a * (1.5 if j % 2 else 1.0) for j, a in enumerate(
                k["accel"] if isinstance(k["accel"], list) else [k["accel"]] * n)]
        elif change == "decel":
            k["decel"] = 77.0
        elif change == "vmax":
            k["vmax"] = np.full(nxt[0].dim, 3.0)
        elif change == "scv":
            k["scv"] = 2.5
        got, want, ran = _both(nxt, k, fresh=False)
        assert got == want
        assert ran or not isinstance(got[0], list) or not got[3]
        els, kw = nxt, k
        more = []


def test_a_user_element_type_and_bad_arguments() -> None:
    """A user's element type is read through its attributes; anything the compiled path
    does not take (a limit out of range, elements of other axis counts, no length) gives
    the Python path's result or error."""

    class Seg:  # a path element of the user's own (duck-typed)
        def __init__(self, a, b):
            self._l = Line(np.array(a, float), np.array(b, float))

        def __getattr__(self, name):
            return getattr(self._l, name)

    line = Line(np.zeros(2), np.array([1.0, 0.0]))
    els = [Seg([0.0, 0.0], [1.0, 0.0]), Seg([1.0, 0.0], [1.0, 1.0])]
    kw = {"feed": 10.0, "accel": 100.0, "decel": None, "scv": 1.0, "v_start": 0.0,
          "v_end": 0.0, "vmax": None, "amax": None, "vjump": None, "ratio": 0.5,
          "mcr": 0.0}
    got, want, ran = _both(els, kw)
    assert got == want and not isinstance(got[0], type) and ran
    els = [line, Line(line.end, np.array([1.0, 1.0]))]
    for bad in ({"feed": 0.0}, {"accel": [1.0]}, {"decel": -1.0}, {"scv": math.nan},
                {"vmax": np.array([1.0, 0.0])}, {"amax": [1.0, 2.0, 3.0]}, {"ratio": 1.0},
                {"mcr": 1.0}, {"v_end": -1.0}, {"feed": True}, {"feed": [10.0, math.inf]}):
        got, want, ran = _both(els, {**kw, **bad})
        assert got == want and got[0] in (MotionError, ValueError) and not ran, bad
    got, want, ran = _both(els, kw)
    assert got == want and ran
    got, want, _ = _both([line, Line(np.zeros(3), np.ones(3))], kw)
    assert got == want and "axes" in got[1]
    got, want, _ = _both([Line(np.zeros(2), np.zeros(2))], {**kw, "v_start": 1.0})
    assert got == want and got[0] is InfeasibleError
    with pytest.raises(MotionError, match="path element"):
        la._prepare([object()], 1.0, 1.0, 0.0, 0.0, 0.0, None, None, None, 0.5, 0.0, None)


def test_curve_knots_compiled_equal_python() -> None:
    """`_curve_knots` in one compiled call equals the Python preparation followed by the
    compiled passes (the way it went before), on a blended stream."""
    rng = np.random.default_rng(7)
    pts = np.cumsum(rng.normal(size=(60, 3)), axis=0)
    els = _blended([Line(p, q) for p, q in zip(pts[:-1], pts[1:], strict=True)], 0.05)
    kw = {"square_corner_velocity": 0.5, "axis_vmax": np.full(3, 30.0),
          "axis_amax": np.full(3, 500.0)}
    la._PREP_MEMO.clear()
    for a in range(0, len(els) - 5, 7):
        part = els[a:]
        got = la._curve_knots(part, 20.0, 300.0, 1.5, start_speed=0.0, **kw)
        pr = la._prepare(part, 20.0, 300.0, 0.5, 0.0, 0.0, kw["axis_vmax"], kw["axis_amax"],
                         None, 0.5, 0.0, None, compiled=False)
        _, _, _, live, acc, cap, length, dec, jcap2, v_start, _ = pr
        out = np.empty((2, 3 * len(live) + 1))
        m = _corner.chain_curve(jcap2, acc, dec, cap, length, 0.0, 1.5, out)
        assert got is not None
        assert got[0].tobytes() == out[0, :m].tobytes()
        assert got[1].tobytes() == out[1, :m].tobytes()
        assert got[2] == min(dec)


@pytest.mark.parametrize("turn", [0.0, 3e-7, 9.99e-7, 1e-6, 1.001e-6, 2e-6, 1e-5, 0.3])
def test_tangent_test_at_its_threshold(turn) -> None:
    """Junctions turning about TANGENT_ANGLE: the compiled path calls them tangent only
    where `_junction_cap` certainly does (else it asks `_junction_cap`): with no corner
    speed a corner is an exact stop, a tangent junction none."""
    a = Line(np.zeros(3), np.array([1.0, 0.0, 0.0]))
    b = Line(a.end, a.end + np.array([math.cos(turn), math.sin(turn), 0.0]))
    kw = {"feed": 10.0, "accel": 100.0, "decel": None, "scv": 0.0, "v_start": 0.0,
          "v_end": 0.0, "vmax": None, "amax": np.full(3, 50.0), "vjump": np.full(3, 0.5),
          "ratio": 0.5, "mcr": 0.0}
    got, want, ran = _both([a, b], kw)
    assert got == want and ran
    if abs(turn - 1e-6) > 1e-9:
        assert (float.fromhex(got[8][1]) == 0.0) == (turn > 1e-6)


def test_arc_end_tangents() -> None:
    """An arc's own tangents at each end (a line leaving it along its start tangent, or
    arriving along its end tangent, turns a corner there)."""
    arc = Arc3D(np.zeros(2), np.array([1.0, 1.0]), np.array([2.0, 0.0]))
    t0, t1 = arc.start_tangent, arc.end_tangent
    before = Line(-t1, np.zeros(2))  # arrives along the arc's end tangent
    after = Line(arc.end, arc.end + t0)  # leaves along the arc's start tangent
    kw = {"feed": 10.0, "accel": 100.0, "decel": None, "scv": 1.0, "v_start": 0.0,
          "v_end": 0.0, "vmax": None, "amax": None, "vjump": None, "ratio": 0.5,
          "mcr": 0.0}
    got, want, ran = _both([before, arc, after], kw)
    assert got == want and ran
    assert all(float.fromhex(x) < 10.0 ** 2 for x in got[8][1:3])  # both corners slow
