"""MotionHistory: records equal the profiles, splicing, truncation, exact crossings, memory."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st

from longrun import size
from openmotion.errors import MotionError
from openmotion.history import MotionHistory
from openmotion.profile.segments import Profile, ProfileBuilder, State

EPS = np.finfo(float).eps


def scurve(p: float = 0.0, d: float = 7.0) -> Profile:
    """A symmetric S-curve move of distance d (|d| >= 2) from p: jerk 1000, 10/s cruise."""
    jm, tj, tc = 1000.0, 0.1, (abs(d) - 2.0) / 10.0
    b = ProfileBuilder(p, direction=math.copysign(1.0, d))
    b.segment(tj, jm).segment(tj, -jm).segment(tc).segment(tj, -jm).segment(tj, jm)
    return b.build(end_p=p + d)


def velocity_ramp(v0: float, v1: float, t: float, p: float = 0.0) -> Profile:
    b = ProfileBuilder(p, v0)
    b.segment(t, accel=(v1 - v0) / t)
    return b.build(end_v=v1)


def random_profile(draw, p0: float = 0.0) -> Profile:
    """A random piecewise-cubic profile (continuous, arbitrary signs)."""
    n = draw(st.integers(1, 5))
    v = draw(st.floats(-50, 50, allow_subnormal=False))
    a = draw(st.floats(-500, 500, allow_subnormal=False))
    b = ProfileBuilder(p0, v, a)
    for _ in range(n):
        dur = draw(st.floats(1e-3, 0.5))
        jerk = draw(st.floats(-1e4, 1e4, allow_subnormal=False))
        b.segment(dur, jerk)
    end_v = b.state.v
    return b.build(end_v=end_v)


profiles = st.composite(random_profile)


# ----------------------------------------------------------------------------- reading
@settings(max_examples=40, deadline=None)
@given(pr=profiles(), t_abs=st.floats(-100.0, 1000.0))
def test_sample_equals_profile(pr: Profile, t_abs: float) -> None:
    h = MotionHistory(2, positions=[pr.start.p, 3.0], t_start=t_abs - 1.0)
    h.append(0, t_abs, pr)
    rel = np.linspace(0.0, pr.duration + 0.5, 301)
    got = h.sample(0, t_abs + rel)
    want = pr.sample(rel)
    scale = 1.0 + np.max(np.abs(want.p))
    # Absolute times round the relative time by ulp(t_abs); allow that much slope error.
    tol_t = 4 * np.spacing(abs(t_abs) + pr.duration + 1.0)
    vmax = np.max(np.abs(want.v)) + 1.0
    amax = np.max(np.abs(want.a)) + 1.0
    np.testing.assert_allclose(got.p, want.p, rtol=0, atol=1e-12 * scale + vmax * tol_t)
    np.testing.assert_allclose(got.v, want.v, rtol=0, atol=1e-12 * vmax + amax * tol_t)
    # Before the profile the history holds what was there: the initial standstill.
    early = h.sample(0, t_abs - np.linspace(0.01, 2.0, 20))
    assert np.all(early.p == pr.start.p) and np.all(early.v == 0.0)
    # state_at agrees with sample.
    for r in (0.0, pr.duration / 3, pr.duration, pr.duration + 0.25):
        s = h.state_at(0, t_abs + r)
        smp = h.sample(0, t_abs + r)
        assert s.p == pytest.approx(float(smp.p), abs=1e-12 * scale)
        assert s.v == pytest.approx(float(smp.v), abs=1e-12 * vmax)
        assert s.a == pytest.approx(float(smp.a), abs=1e-12 * amax)
    # The other axis never moved.
    assert np.all(h.sample(1, t_abs + rel).p == 3.0)


def test_end_is_exact_target_and_holds() -> None:
    pr = scurve(0.0, 1234.5)
    h = MotionHistory(1)
    h.append(0, 2.0, pr)
    t_end = 2.0 + pr.duration
    assert h.end_time(0) == t_end
    assert h.end_state(0) == State(1234.5, 0.0, 0.0)
    assert h.state_at(0, t_end) == State(1234.5, 0.0, 0.0)
    assert np.all(h.position_at(0, np.array([t_end, t_end + 1e6])) == 1234.5)
    assert h.position_at(0, 0.5) == 0.0  # before the move: standstill
    assert isinstance(h.position_at(0, 0.5), float)


def test_velocity_ramp_tail_keeps_constant_speed() -> None:
    pr = velocity_ramp(0.0, 100.0, 0.5)
    h = MotionHistory(1)
    h.append(0, 1.0, pr)
    s = h.state_at(0, 11.5)
    assert s.v == 100.0
    assert s.p == pytest.approx(pr.end.p + 100.0 * 10.0, rel=1e-15)


def test_sample_shapes_and_scalar() -> None:
    h = MotionHistory(1)
    h.append(0, 0.0, scurve())
    s = h.sample(0, np.zeros((3, 4)))
    assert s.p.shape == (3, 4) and s.j.shape == (3, 4)
    assert h.sample(0, 0.05).p.shape == ()


# ----------------------------------------------------------------------------- writing
def test_append_splices_onto_running_motion() -> None:
    first = velocity_ramp(0.0, 100.0, 0.5)
    h = MotionHistory(1)
    h.append(0, 0.0, first)
    t_change = 0.8
    st_change = h.state_at(0, t_change)
    # Re-planned motion from the state at the change: ramp down to 20.
    b = ProfileBuilder(st_change.p, st_change.v)
    b.segment(0.4, accel=-200.0)
    second = b.build(end_v=20.0)
    h.append(0, t_change, second)
    # Before the change: the old motion; after: the new one, exactly.
    t_before = np.linspace(0.0, t_change, 50, endpoint=False)
    np.testing.assert_array_equal(h.sample(0, t_before).p, first.sample(t_before).p)
    t_after = np.linspace(t_change, 3.0, 50)
    np.testing.assert_allclose(h.sample(0, t_after).p, second.sample(t_after - t_change).p,
                               rtol=1e-13)
    assert h.state_at(0, 5.0).v == 20.0
    # The old tail (100/s forever) is gone: records are monotone in time.
    assert np.all(np.diff(h.records(0)["ts"]) >= 0)
    # The initial record (also at t=0) was replaced; first: ramp + cut tail; second + tail.
    assert h.n_records(0) == 4


def test_append_spliced_profile_at_its_original_start() -> None:
    # The controller re-appends a Profile.splice(...) result at the move's start time.
    first = velocity_ramp(0.0, 100.0, 0.5)
    h = MotionHistory(1)
    h.append(0, 1.0, first)
    st_change = first.state_at(0.3)
    tail = ProfileBuilder(st_change.p, st_change.v, st_change.a).segment(0.2, accel=-100.0)
    spliced = first.splice(0.3, tail.build(end_v=st_change.v - 20.0))
    h.append(0, 1.0, spliced)
    t = np.linspace(0.0, 3.0, 301)
    np.testing.assert_allclose(h.sample(0, 1.0 + t).p, spliced.sample(t).p, rtol=1e-14,
                               atol=1e-12)
    assert h.state_at(0, 10.0).v == spliced.end.v


def test_truncate_before_all_records() -> None:
    h = MotionHistory(1, positions=[4.0], t_start=5.0)
    assert h.truncate(0, 2.0) == State(4.0, 0.0, 0.0)
    assert h.start_time(0) == 2.0 and h.n_records(0) == 1


def test_append_after_end_leaves_standstill_gap() -> None:
    h = MotionHistory(1)
    a = scurve(0.0, 7.0)
    h.append(0, 0.0, a)
    b = scurve(7.0, -7.0)
    h.append(0, 5.0, b)
    gap = np.linspace(a.duration, 5.0, 20)
    assert np.all(h.sample(0, gap).p == 7.0)
    assert np.all(h.sample(0, gap).v == 0.0)
    assert h.state_at(0, 100.0) == State(0.0, 0.0, 0.0)


def test_append_before_all_records_replaces_them() -> None:
    h = MotionHistory(1, t_start=10.0, positions=[5.0])
    pr = scurve(5.0, 3.0)
    h.append(0, 3.0, pr)
    assert h.start_time(0) == 3.0
    assert h.state_at(0, 3.0 + pr.duration).p == 8.0


def test_truncate_holds_position_at_rest() -> None:
    pr = velocity_ramp(0.0, 100.0, 0.5)
    h = MotionHistory(1)
    h.append(0, 0.0, pr)
    before = h.state_at(0, 0.3)
    got = h.truncate(0, 0.3)
    assert got == before and got.v > 0
    after = h.sample(0, np.array([0.3, 0.31, 10.0]))
    assert np.all(after.p == before.p)
    assert np.all(after.v == 0.0) and np.all(after.a == 0.0)
    # Earlier motion unchanged.
    assert h.state_at(0, 0.2) == pr.state_at(0.2)
    # Truncating exactly at a record start replaces that record.
    n = h.n_records(0)
    h.truncate(0, 0.3)
    assert h.n_records(0) == n


# ----------------------------------------------------------------------------- memory
def test_memory_bounded_with_window() -> None:
    h = MotionHistory(1, window_s=1.0)
    pr = scurve(0.0, 2.0)  # 4 segments + tail
    caps = []
    t = 0.0
    n = size(30_000, 100_000)  # 30 windows of appends (100 with --long)
    for i in range(n):
        h.append(0, t, pr if i % 2 == 0 else pr.shifted(0.0))
        t += 0.001  # each append splices onto the previous one 1 ms later
        if i % (n // 10) == 0:
            caps.append(h.capacity(0))
    # About one record per append stays in the 1 s window: ~1000 live rows, capacity
    # at most twice that, and flat after the warm-up.
    assert h.n_records(0) < 1.0 / 0.001 + 20
    assert max(caps) <= 4 * 1000
    assert caps[1:] == [caps[1]] * (len(caps) - 1)
    assert h.capacity(0) == caps[1]
    # Still exact within the window.
    assert h.state_at(0, t - 0.001 + pr.duration).p == 2.0
    assert h.start_time(0) >= t - 1.0 - 0.01


def test_memory_bounded_long_moves() -> None:
    h = MotionHistory(2, window_s=5.0)
    pr = scurve(0.0, 7.0)
    for i in range(20_000):
        h.append(i % 2, i * 1.0, pr)
    assert h.capacity(0) <= 64 and h.capacity(1) <= 64
    assert h.n_records(0) <= 6 * 4


def test_forget_before_keeps_covering_record() -> None:
    h = MotionHistory(1, window_s=1000.0)
    for i in range(10):
        h.append(0, i * 2.0, scurve(0.0, 7.0) if i % 2 == 0 else scurve(7.0, -7.0))
    want = h.sample(0, np.linspace(9.0, 30.0, 100))
    h.forget_before(9.0)
    got = h.sample(0, np.linspace(9.0, 30.0, 100))
    np.testing.assert_array_equal(got.p, want.p)
    assert h.start_time(0) <= 9.0
    h.expire(2000.0)
    assert h.start_time(0) == h.end_time(0)


# ----------------------------------------------------------------------------- crossings
def brute_roots(h: MotionHistory, level: float, t0: float, t1: float, n: int = 200_001):
    """Sign changes of p - level on a dense grid, refined by scalar bisection."""
    t = np.linspace(t0, t1, n)
    f = h.position_at(0, t) - level
    idx = np.flatnonzero(np.sign(f[:-1]) * np.sign(f[1:]) < 0)
    roots = []
    for i in idx:
        lo, hi = t[i], t[i + 1]
        slo = np.sign(f[i])
        while True:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
            if np.sign(h.position_at(0, mid) - level) == slo:
                lo = mid
            else:
                hi = mid
        roots.append((hi, 1 if slo < 0 else -1))
    return roots


@st.composite
def cubic_cases(draw):
    pr = draw(profiles())
    t_abs = draw(st.floats(0.0, 40_000.0))
    lo = float(np.min(pr.sample(np.linspace(0, pr.duration, 200)).p))
    hi = float(np.max(pr.sample(np.linspace(0, pr.duration, 200)).p))
    level = draw(st.floats(lo - 0.1 * abs(hi - lo), hi + 0.1 * abs(hi - lo)))
    return pr, t_abs, level


@settings(max_examples=60, deadline=None)
@given(case=cubic_cases())
def test_crossings_match_brute_force(case) -> None:
    pr, t_abs, level = case
    assume(math.isfinite(level))
    h = MotionHistory(1, positions=[pr.start.p], t_start=t_abs - 1.0)
    h.append(0, t_abs, pr)
    t0, t1 = t_abs - 0.01, t_abs + pr.duration + 0.01
    n = 200_001
    grid = np.linspace(t0, t1, n)
    smp = h.sample(0, grid)
    f = smp.p - level
    # Well-conditioned cases only: the grid must resolve every root (no two roots in one
    # cell) and the level must not graze an extremum (tangent touches are tested below).
    h_step = (t1 - t0) / (n - 1)
    vmax = float(np.max(np.abs(smp.v))) + 1e-9
    # Local extrema of the position on the grid (velocity changes sign between samples).
    ext_idx = np.flatnonzero(np.sign(smp.v[:-1]) != np.sign(smp.v[1:]))
    ext = np.abs(f[ext_idx])
    scale = 1.0 + float(np.max(np.abs(smp.p)))
    if ext.size:
        assume(ext.min() > 1e-6 * scale)
        assume(2 * ext.min() / vmax > 4 * h_step)
    assume(np.min(np.abs(f)) > 0.0)
    assume(abs(f[0]) > 1e-9 * scale)
    want = brute_roots(h, level, t0, t1, n)
    times, dirs = h.crossing_events(0, level, t0, t1)
    event(f"{min(len(want), 3)}+ roots")
    assert len(times) == len(want)
    for (tw, dw), tg, dg in zip(want, times, dirs, strict=True):
        v = abs(float(h.state_at(0, tg).v)) + 1e-300
        tol = max(1e-12 * max(1.0, abs(tg)), 64 * EPS * scale / v)
        assert abs(tg - tw) <= tol
        assert dg == dw
    # Direction filters partition the events.
    up = h.crossings(0, level, t0, t1, direction=1)
    down = h.crossings(0, level, t0, t1, direction=-1)
    assert len(up) + len(down) == len(times)
    np.testing.assert_array_equal(np.sort(np.concatenate([up, down])), times)


def test_crossing_linear_exact() -> None:
    h = MotionHistory(1)
    h.append(0, 0.0, velocity_ramp(100.0, 100.0, 1.0))  # constant 100/s
    t = h.crossings(0, 37.0, 0.0, 2.0)
    assert t.shape == (1,)
    assert abs(t[0] - 0.37) <= 1e-15


def test_crossing_arrival_at_target_counts_once() -> None:
    pr = scurve(0.0, 7.0)
    h = MotionHistory(1)
    h.append(0, 1.0, pr)
    t = h.crossings(0, 7.0, 0.0, 10.0)
    assert t.shape == (1,)
    assert 1.0 + pr.duration - 1e-3 <= t[0] <= 1.0 + pr.duration
    assert h.crossings(0, 7.0, 0.0, 10.0, direction=-1).size == 0
    # Querying a window that starts during the dwell at the level: nothing arrives.
    assert h.crossings(0, 7.0, 5.0, 10.0).size == 0
    # Leaving the start position (a dwell at the level until t=1): no event either.
    assert h.crossings(0, 0.0, 0.0, 10.0).size == 0


def test_crossing_tangent_touch() -> None:
    # Rise from below to a peak exactly at the level (record starts at the peak), then fall.
    h = MotionHistory(1, positions=[-1.0])
    b = ProfileBuilder(-1.0, 2.0, -2.0)
    b.segment(1.0)  # p: -1 -> 0 at t=1 with v=0 ... as computed in floats
    up = b.build(end_v=0.0, end_p=0.0)
    h.append(0, 0.0, up)
    down = ProfileBuilder(0.0, 0.0, -2.0).segment(1.0).build(end_p=-1.0)
    h.append(0, 1.0, down)
    times, dirs = h.crossing_events(0, 0.0, -1.0, 3.0)
    assert times.size == 1 and dirs[0] == 1
    assert abs(times[0] - 1.0) <= 1e-7  # tangent: conditioned as sqrt(eps)
    assert h.crossings(0, 0.0, -1.0, 3.0, direction=-1).size == 0
    # Touch from above, mirrored.
    g = MotionHistory(1, positions=[1.0])
    g.append(0, 0.0, ProfileBuilder(1.0, -2.0, 2.0).segment(1.0).build(end_p=0.0))
    g.append(0, 1.0, ProfileBuilder(0.0, 0.0, 2.0).segment(1.0).build(end_p=1.0))
    times, dirs = g.crossing_events(0, 0.0, -1.0, 3.0)
    assert times.size == 1 and dirs[0] == -1


def test_crossing_interior_extremum_touch() -> None:
    # p(t) = -(t-1)^2 on [0, 2]: touches 0 at t = 1 inside one record.
    h = MotionHistory(1, positions=[-1.0])
    h.append(0, 0.0, ProfileBuilder(-1.0, 2.0, -2.0).segment(2.0).build(end_p=-1.0))
    times, dirs = h.crossing_events(0, 0.0, 0.0, 2.0)
    assert times.size == 1 and dirs[0] == 1 and abs(times[0] - 1.0) <= 1e-7


def test_crossing_inclusive_ends_and_jumps() -> None:
    h = MotionHistory(1)
    h.append(0, 0.0, velocity_ramp(10.0, 10.0, 1.0))
    # Root exactly at t1 and exactly at t0 are included.
    assert h.crossings(0, 5.0, 0.0, 0.5).tolist() == [0.5]
    assert h.crossings(0, 5.0, 0.5, 1.0).tolist() == [0.5]
    assert h.crossings(0, 5.0, 0.6, 1.0).size == 0
    # A position jump across the level (a record starting at another position) is an event
    # at the record start.
    h.append(0, 2.0, ProfileBuilder(50.0).build(end_p=50.0))
    times, dirs = h.crossing_events(0, 30.0, 1.5, 3.0)
    assert times.tolist() == [2.0] and dirs.tolist() == [1]
    # Zero-width query.
    assert h.crossings(0, 5.0, 0.5, 0.5).tolist() == [0.5]
    assert h.crossings(0, 5.0, 0.7, 0.7).size == 0


def test_crossings_many_records_vectorized() -> None:
    # Back and forth 7 pulses every second for 200 s: one crossing of the midpoint each.
    h = MotionHistory(1, window_s=1000.0)
    up, dn = scurve(0.0, 7.0), scurve(7.0, -7.0)
    for i in range(200):
        h.append(0, i * 1.0, up if i % 2 == 0 else dn)
    t = h.crossings(0, 3.5, 0.0, 300.0)
    assert t.size == 200
    d = h.crossings(0, 3.5, 0.0, 300.0, direction=1)
    np.testing.assert_allclose(d - np.arange(100) * 2.0, 0.45, atol=1e-12)
    np.testing.assert_allclose(h.position_at(0, t), 3.5, atol=1e-12)


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda h: h.append(5, 0.0, scurve()), "axis"),
        (lambda h: h.append(-1, 0.0, scurve()), "axis"),
        (lambda h: h.append(True, 0.0, scurve()), "axis"),
        (lambda h: h.append(0, math.nan, scurve()), "t_abs"),
        (lambda h: h.append(0, 0.0, "move"), "profile"),
        (lambda h: h.truncate(0, math.inf), "t_abs"),
        (lambda h: h.state_at(0, math.nan), "t"),
        (lambda h: h.sample(0, [0.0, math.nan]), "times"),
        (lambda h: h.sample(0, ["x"]), "times"),
        (lambda h: h.crossings(0, math.nan, 0.0, 1.0), "level"),
        (lambda h: h.crossings(0, 1.0, 2.0, 1.0), "t1"),
        (lambda h: h.crossings(0, 1.0, 0.0, 1.0, direction=2), "direction"),
        (lambda h: h.forget_before(math.nan), "t"),
    ],
)
def test_bad_input_refused_and_changes_nothing(call, match) -> None:
    h = MotionHistory(2)
    h.append(0, 0.5, scurve())
    before = {k: v.copy() for k, v in h.records(0).items()}
    with pytest.raises(MotionError, match=match):
        call(h)
    after = h.records(0)
    for k in before:
        np.testing.assert_array_equal(before[k], after[k])


@pytest.mark.parametrize(
    "kwargs",
    [{"n_axes": 0}, {"n_axes": 1.5}, {"n_axes": 2, "window_s": 0.0},
     {"n_axes": 2, "window_s": math.inf}, {"n_axes": 2, "positions": [1.0]},
     {"n_axes": 1, "positions": [math.nan]}, {"n_axes": 1, "t_start": math.nan}],
)
def test_bad_construction(kwargs) -> None:
    with pytest.raises(MotionError):
        MotionHistory(**kwargs)


@st.composite
def multi_record_cases(draw):
    """Several spliced profiles, a level near the motion and a query window."""
    h = MotionHistory(1, window_s=1e6)
    t = 0.0
    p = 0.0
    for _ in range(draw(st.integers(1, 4))):
        pr = draw(profiles(p))
        h.append(0, t, pr)
        cut = draw(st.floats(0.0, pr.duration + 0.2))
        t += cut
        p = h.state_at(0, t).p
    span = h.end_time(0) + 0.5
    t0 = draw(st.floats(-0.5, span))
    t1 = draw(st.floats(t0, span + 0.5))
    if draw(st.booleans()):  # a level the motion certainly reaches inside the window
        level = float(h.position_at(0, t0 + draw(st.floats(0.0, 1.0)) * (t1 - t0)))
    else:
        probe = h.position_at(0, np.linspace(t0, t1, 50))
        level = draw(st.floats(float(probe.min()) - 1.0, float(probe.max()) + 1.0))
    return h, level, t0, t1


@settings(max_examples=150, deadline=None)
@given(case=multi_record_cases())
def test_scalar_and_vector_crossings_agree(case) -> None:
    import openmotion.crossings as hist  # the solver MotionHistory.crossing_events uses

    h, level, t0, t1 = case
    old = hist._SCALAR_RECORDS
    try:
        hist._SCALAR_RECORDS = 10**9
        ts, ds = h.crossing_events(0, level, t0, t1)
        hist._SCALAR_RECORDS = 0
        tv, dv = h.crossing_events(0, level, t0, t1)
    finally:
        hist._SCALAR_RECORDS = old
    event(f"{min(ts.size, 3)}+ events")
    np.testing.assert_array_equal(ts, tv)
    np.testing.assert_array_equal(ds, dv)
    # Every event is in the window, in time order.
    assert np.all((ts >= t0) & (ts <= t1))
    assert np.all(np.diff(ts) >= 0)


def test_rows_and_record_at_read_the_store_without_copying() -> None:
    """rows(): the records covering [t0, t1] plus the one leading in, as read-only views;
    record_at(): the record in force at t, None before the oldest one."""
    h = MotionHistory(1, t_start=0.0)
    pr = scurve(0.0, 7.0)
    h.append(0, 1.0, pr)
    rec = h.records(0)
    ts, p0, v0, a0, j = h.rows(0, 1.15, 1.25)
    k0 = int(np.searchsorted(rec["ts"], 1.15, side="right")) - 2
    k1 = int(np.searchsorted(rec["ts"], 1.25, side="right"))
    np.testing.assert_array_equal(ts, rec["ts"][k0:k1])
    np.testing.assert_array_equal(j, rec["j"][k0:k1])
    assert len(p0) == len(v0) == len(a0) == len(ts) >= 2
    with pytest.raises(ValueError):
        p0[0] = 1.0  # a view of the store: readers cannot write into it
    k = int(np.searchsorted(rec["ts"], 1.2, side="right")) - 1
    assert h.record_at(0, 1.2) == tuple(float(rec[c][k]) for c in ("ts", "p0", "v0", "a0", "j"))
    assert h.record_at(0, -1.0) is None
    h.append(0, 1.0, pr)  # the store stays writable for its owner
    with pytest.raises(MotionError, match="t1 must be finite"):
        h.rows(0, 0.0, math.nan)
    with pytest.raises(MotionError, match="axis must be in"):
        h.record_at(1, 0.0)


def test_subnormal_jerk_or_acceleration_does_not_overflow() -> None:
    """A record with a subnormal jerk (or acceleration) has a velocity root beyond any
    time: the vectorised solver leaves it out instead of dividing into an overflow, and
    agrees with the scalar one."""
    import warnings

    import openmotion.crossings as cr

    ts = np.array([0.0, 1.0, 2.0])
    for v, a, j in (([0.0, 1.0, 1.0], [2.0, 0.0, 0.0], [2.2250738585072014e-308, 0.0, 0.0]),
                    ([1.0, -1.0, 1.0], [5e-324, 0.0, 1.0], [0.0, 0.0, 0.0])):
        p0 = np.array([0.0, 1.0, 2.0])
        va, aa, ja = np.array(v), np.array(a), np.array(j)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            c1, c2 = cr._critical_points(va, aa, ja)
            old = cr._SCALAR_RECORDS
            try:
                cr._SCALAR_RECORDS = 0
                tv, dv = cr.find_crossings(ts, p0, va, aa, ja, 1.5, 0.0, 3.0)
                cr._SCALAR_RECORDS = 10**9
                tsc, dsc = cr.find_crossings(ts, p0, va, aa, ja, 1.5, 0.0, 3.0)
            finally:
                cr._SCALAR_RECORDS = old
        assert not np.any(np.isinf(c1)) and not np.any(np.isinf(c2))
        np.testing.assert_array_equal(tv, tsc)
        np.testing.assert_array_equal(dv, dsc)


def test_state_at_gives_the_position_at_bit_for_bit():
    """compare_due reads the command position with the scalar state_at: the same float as
    position_at's vectorized path at every time (before, on and between records)."""
    h = MotionHistory(1, positions=[12.5], t_start=0.3)
    h.append(0, 0.5, scurve(12.5, 7.0))
    h.append(0, 1.7, velocity_ramp(0.0, -3.0, 0.4, 5.0))
    rng = np.random.default_rng(3)
    times = np.concatenate([rng.uniform(0.0, 4.0, 400), [0.0, 0.3, 0.5, 1.7, 2.1, 9.0]])
    arr = h.position_at(0, times)
    for t, p in zip(times.tolist(), arr.tolist(), strict=True):
        assert h.state_at(0, t).p == p == h.position_at(0, t)
        assert math.copysign(1.0, h.state_at(0, t).p) == math.copysign(1.0, p)
