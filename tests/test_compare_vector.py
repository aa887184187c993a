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
from helpers import segment_profile
from openmotion import _compare
from openmotion.control.trigger import compare_math as cm
from openmotion.control.trigger.compare_math import Track, VectorCycle
from openmotion.history import MotionHistory

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
    prof = segment_profile(segs, v0)
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


def test_many_axes_are_one_path_length():
    """Any number of axes (no 8-axis limit): 12 axes at 100 pulses/s each."""
    tr = Track(np.array([0.0]), np.array([0.0]), np.array([100.0]), np.zeros(1), np.zeros(1))
    got, want = _both([tr] * 12, np.ones(12), 0.0, 1e-3, 0.0)
    _same(got, want)
    assert got.end == pytest.approx(0.1 * 12 ** 0.5, rel=1e-15)


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
    with pytest.raises(ValueError, match="axis"):
        _compare.vector_pieces([], np.ones(0), 0.0, 1.0)
    with pytest.raises(TypeError):
        _compare.vector_pieces([tr], [1.0], 0.0, 1.0)  # (a list: not a float64 buffer)
    with pytest.raises(ValueError, match="vector_sums"):
        _compare.vector_sums(np.zeros(3), np.zeros(5), np.zeros(2), np.zeros(2), 0.0,
                             1e-13, 10)


# ---------------------------------------------------------------------------- scan driver
class _Job:
    """What bank_scan reads and writes on a job object."""

    def __init__(self, index: int, hits: int) -> None:
        self.index, self.hits = index, hits


def _driver(mod, vc: VectorCycle, spec: tuple, index: int, hits: int,  # noqa: ANN001
            ta: float, t1: float) -> tuple:
    from openmotion.control.trigger.compare_io import OutputLine

    job, line = _Job(index, hits), OutputLine(3, False)
    res = mod.bank_scan(mod.bank_new([spec]), [job], [], [line], [], ta, t1,
                        [(vc.B, vc.S, vc.Q)])
    if res is not None:
        res = (np.frombuffer(res[0]).tolist(), np.frombuffer(res[1], dtype=np.int64).tolist(),
               list(res[3]))
    return res, job.index, job.hits, line.edges


@given(recs=st.lists(st.lists(rec, min_size=1, max_size=5), min_size=2, max_size=2),
       v0=st.floats(-1e5, 1e5), s0=st.floats(0.0, 50.0), start=st.floats(-5.0, 80.0),
       step=st.floats(0.05, 30.0), n=st.integers(1, 40),
       after=st.one_of(st.none(), st.floats(0.0, 400.0)), repeat=st.booleans(),
       as_seq=st.booleans(), index=st.integers(0, 3), hits=st.integers(0, 3),
       armed=st.floats(-0.5, 1.5), act=st.sampled_from([(0, 1, 0.0), (1, 0, 0.0),
                                                          (2, 1, 1e-5)]))
@settings(max_examples=300, deadline=None)
def test_driver_path_length_jobs_are_levelJob_scan(recs, v0, s0, start, step, n, after,
                                                   repeat, as_seq, index, hits, armed, act):
    """bank_scan's kind 2 (a LevelJob on a VectorSource) fires what LevelJob.scan fires on
    the same VectorCycle (VectorCycle.scan), and the same as the oracle's job loop."""
    tracks = [_rows(r, 0.0, v0 * (k + 1) / 2.0) for k, r in enumerate(recs)]
    ta, t1 = 1e-4, 2e-3
    vc = VectorCycle(tracks, np.array([1.0, 0.5]), ta, t1, s0)
    if repeat:
        n, after, index = 1, None, 0
    levels = (start, step) if as_seq else start + step * np.arange(n, dtype=np.float64)
    t_armed = ta + armed * (t1 - ta)
    spec = (2, (0,), 1, repeat, levels, n, after, 0.0, t_armed, 7, *act, 0, 3)
    got = _driver(_compare, vc, spec, index, hits, ta, t1)
    assert got == _driver(oracle, vc, spec, index, hits, ta, t1)
    a = max(ta, t_armed)  # LevelJob.scan
    size = n + (after is not None)
    want = [] if a >= t1 or (not repeat and index >= size) else \
        vc.scan(levels, n, after, index, a, repeat)
    res, idx, hit_count, _ = got
    times = [] if res is None else res[0][0::2]
    assert times == [tf for tf, _ in want]
    assert hit_count == hits + len(want)
    assert idx == (index if repeat else index + len(want))
    finished = not repeat and idx >= size
    assert (res is not None and res[2] == [0]) == finished


def test_a_path_length_job_already_passed_finishes_in_the_driver():
    """A distance table whose values VECTOR_MOVED has already passed is exhausted when
    armed; the driver reports it done with no firing (empty rows, not None) and the engine
    drops it, then a live job on the same line fires as in the Python loop."""
    from helpers import free_axes, start_line
    from openmotion.control.trigger.compare import (
        CompareEngine,
        LevelJob,
        Pulse,
        VectorSource,
        every_distance,
    )

    c = free_axes(2)
    eng = CompareEngine(c)
    src = VectorSource((0, 1))
    eng.set_vector_moved(src, 1000.0)
    eng.output(2)  # (the line exists: the job is the driver's from the first cycle)
    old = eng.add(LevelJob(src, [10.0, 20.0], Pulse(2, 1e-5)))
    assert eng.job(old).remaining == 0 and eng.job(old).skipped == 2
    live = eng.add(every_distance(src, 50.0, Pulse(2, 1e-5), start=1050.0))
    start_line(c, [0.0, 0.0], [300.0, 400.0], v=5e4, a=5e6)
    assert c.wait_motion_done(timeout=30.0)
    assert old not in eng.jobs
    assert eng.job(live).hits == 10  # 1050, 1100, ..., 1500 on a path of 500
    assert sorted(set(eng.log.arrays()["job"].tolist())) == [live]


def _untimed_run(native: bool) -> tuple:
    from helpers import free_axes, start_line
    from openmotion.control.trigger import compare as engine
    from openmotion.control.trigger.compare import (
        LevelJob,
        LevelSeq,
        Pulse,
        SetLevel,
        Toggle,
        VectorSource,
        every_distance,
    )
    from test_compare_timed import UntimedSim

    actions = engine._ACTIONS
    if not native:
        engine._ACTIONS = {}  # every job through the Python loop
    try:
        c = free_axes(2, hardware=UntimedSim)
        eng = engine.CompareEngine(c)
        assert not eng.timed
        src = VectorSource((0, 1), (1.0, 2.0))
        eng.add(every_distance(src, 7.5, Pulse(1, 3e-4), start=3.0))
        eng.add(LevelJob(src, LevelSeq(10.0, 12.5, 20), Toggle(2), after_final=400.0))
        eng.add(LevelJob(VectorSource((1,)), [55.0], SetLevel(3), repeat=True))
        for o in (1, 2, 3):
            eng.output(o)
        assert len(eng._group(None).native) == (3 if native else 0)
        start_line(c, [0.0, 0.0], [300.0, -400.0], v=4e4, a=4e6)
        assert c.wait_motion_done(timeout=30.0)
        start_line(c, [300.0, -400.0], [0.0, 0.0], v=6e4, a=8e6)
        assert c.wait_motion_done(timeout=30.0)
        c.advance(0.002)
        log = {k: v.tolist() for k, v in eng.log.arrays().items()}
        return log, {n: ln.edges for n, ln in eng._lines.items()}, eng.vector_moved(src)
    finally:
        engine._ACTIONS = actions


def test_untimed_hardware_driver_is_the_python_loop():
    """Path-length jobs after the cycle (hardware without timed outputs): the driver's
    firings, log and waveforms are the per-job Python loop's."""
    got = _untimed_run(True)
    assert got == _untimed_run(False)
    assert len(got[0]["time"]) > 40
