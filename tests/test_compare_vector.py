"""The compiled path-length pieces (VectorCycle: _compare.vector_pieces / vector_sums) are
the same floats as the numpy construction they replaced (tests/compare_oracle.py keeps it):
breakpoints B, quartics Q and cumulative lengths S bit for bit, on random motions with
zero-length records, nearly constant velocity, windows touching record starts, an empty
window and history specs read in place."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import compare_oracle as oracle
from openmotion import _compare
from openmotion.control.trigger import compare_math as cm
from openmotion.control.trigger.compare_math import Track, VectorCycle
from openmotion.history import MotionHistory
from openmotion.profile.segments import ProfileBuilder

oracle.set_gauss(cm._GL_X, cm._GL_W)

# a record: duration (0 = zero-length), jerk, accel, velocity (None: continue), nearly
# constant (a jerk of ~1e-9 relative: a constant-velocity piece up to rounding)
rec = st.tuples(st.sampled_from([0.0, 1e-9, 2e-4, 1e-3, 3e-3]),
                st.sampled_from([0.0, 1e-7, -3e6, 4e7]), st.floats(-2e5, 2e5),
                st.one_of(st.none(), st.floats(-1e5, 1e5)), st.booleans())


def _rows(recs, p0: float, v0: float) -> Track:  # noqa: ANN001
    ts, p, v, a, j = [], [], [], [], []
    t, x, vel = 0.0, p0, v0
    for dur, jerk, acc, vset, flat in recs:
        if vset is not None:
            vel = vset
        if flat:
            acc, jerk = acc * 1e-12, jerk * 1e-12
        ts.append(t)
        p.append(x)
        v.append(vel)
        a.append(acc)
        j.append(jerk)
        x += dur * (vel + dur * (acc / 2.0 + dur * jerk / 6.0))
        vel += dur * (acc + dur * jerk / 2.0)
        t += dur
    return Track(*(np.array(c, dtype=np.float64) for c in (ts, p, v, a, j)))


def _both(tracks, w, ta, t1, s0):  # noqa: ANN001, ANN202
    """The compiled VectorCycle; the numpy construction whole; the engine on the oracle."""
    got = VectorCycle(tracks, w, ta, t1, s0)
    built = cm._ck
    cm._ck = oracle
    try:
        swapped = VectorCycle(tracks, w, ta, t1, s0)
    finally:
        cm._ck = built
    B, Q, S = oracle.vector_cycle_numpy(tracks, w, ta, t1, s0)
    _same(swapped, got)
    return got, (B, Q, S)


def _same(a: VectorCycle, b: VectorCycle | tuple) -> None:  # noqa: ANN001
    want = b if isinstance(b, tuple) else (b.B, b.Q, b.S)
    for x, y in zip((a.B, a.Q, a.S), want, strict=True):
        assert x.shape == y.shape
        assert x.tobytes() == y.tobytes()  # (bit for bit: also the sign of a zero)


@given(recs=st.lists(st.lists(rec, min_size=1, max_size=6), min_size=1, max_size=3),
       v0=st.floats(-1e5, 1e5), w=st.lists(st.floats(0.01, 10.0), min_size=3, max_size=3),
       a=st.floats(-0.1, 1.1), b=st.floats(0.0, 1.0), on_knot=st.integers(-1, 5),
       s0=st.floats(-1e6, 1e6))
@settings(max_examples=400, deadline=None)
def test_vector_cycle_is_the_numpy_construction(recs, v0, w, a, b, on_knot, s0):
    tracks = [_rows(r, 0.0, v0 * (k + 1) / 3.0) for k, r in enumerate(recs)]
    span = max(float(t.ts[-1]) for t in tracks) + 1e-3
    ta = a * span
    if 0 <= on_knot < tracks[0].ts.size:  # the window starts on a record start
        ta = float(tracks[0].ts[on_knot])
    t1 = ta + b * 2e-3  # (b = 0: an empty window, B = [ta])
    got, want = _both(tracks, np.array(w[:len(tracks)]), ta, t1, s0)
    _same(got, want)
    assert got.B[0] == ta and got.B[-1] == t1
    assert np.all(np.diff(got.S) >= 0.0)


@given(segs=st.lists(st.tuples(st.floats(1e-4, 4e-3), st.floats(-1e7, 1e7),
                               st.floats(-1e5, 1e5), st.booleans()), min_size=1, max_size=5),
       v0=st.floats(-5e3, 5e3), cut=st.floats(0, 1), width=st.sampled_from([1e-3, 1e-4]))
@settings(max_examples=200, deadline=None)
def test_history_spec_reads_the_rows_in_place(segs, v0, cut, width):
    b = ProfileBuilder(0.0, v0, v_before=v0)
    for dur, jerk, accel, dwell in segs:
        if dwell:
            b.set_velocity(0.0)
            b.segment(dur, 0.0, accel=0.0)
        else:
            b.segment(dur, jerk, accel=accel)
    prof = b.build()
    h = MotionHistory(2)
    h.append(0, 0.0, prof)
    h.append(1, 0.0, prof)
    ta = cut * prof.duration
    t1 = ta + width
    rows = [Track(*h.rows(k, ta, t1)) for k in (0, 1)]
    specs = [(h._tracks[k],) for k in (0, 1)]
    w = np.array([1.0, 0.25])
    by_rows = VectorCycle(rows, w, ta, t1, 3.0)
    _same(VectorCycle(specs, w, ta, t1, 3.0), by_rows)
    got, want = _both(rows, w, ta, t1, 3.0)
    _same(got, want)
    _same(got, by_rows)


def test_constant_velocity_line_is_the_straight_length():
    tr = Track(np.array([0.0]), np.array([0.0]), np.array([300.0]), np.array([0.0]),
               np.array([0.0]))
    tr2 = Track(np.array([0.0]), np.array([0.0]), np.array([400.0]), np.array([0.0]),
                np.array([0.0]))
    vc = VectorCycle([tr, tr2], np.ones(2), 0.0, 1e-3, 10.0)
    assert vc.B.tolist() == [0.0, 1e-3]
    assert vc.end == pytest.approx(10.5, rel=1e-15)


def test_bad_arguments_raise():
    tr = Track(*(np.zeros(1) for _ in range(5)))
    with pytest.raises(ValueError, match="weights"):
        _compare.vector_pieces([tr, tr], np.ones(3), 0.0, 1.0)
    with pytest.raises(ValueError, match="axes"):
        _compare.vector_pieces([], np.ones(0), 0.0, 1.0)
    with pytest.raises(TypeError):
        _compare.vector_pieces([tr], [1.0], 0.0, 1.0)  # (a list: not a float64 buffer)
    with pytest.raises(ValueError, match="vector_sums"):
        _compare.vector_sums(np.zeros(3), np.zeros(5), np.zeros(2), np.zeros(2), 0.0,
                             1e-13, 10)
