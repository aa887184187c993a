"""Time-optimal jerk-limited moves: physics of the profile, optimality against ruckig."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.profile.jerk import (
    jerk_limited,
    jerk_limited_duration,
    jerk_limited_sync,
)
from openmotion.profile.segments import Profile, State

REL = 1e-9


# --------------------------------------------------------------- shared checker
def segment_extremes(prof: Profile) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration at every segment start, end and velocity vertex."""
    n = prof.n_segments
    if n == 0:
        return np.zeros(1), np.zeros(1)
    dur = np.append(prof.t0[1:], prof.duration) - prof.t0
    a0, v0, j = prof.a0, prof.v0, prof.j
    with np.errstate(divide="ignore", invalid="ignore"):
        tv = np.where(j != 0.0, -a0 / j, 0.0)
    tv = np.clip(tv, 0.0, dur)
    vs = [v0, v0 + dur * (a0 + dur * j / 2), v0 + tv * (a0 + tv * j / 2)]
    accs = [a0, a0 + dur * j]
    return np.concatenate(vs), np.concatenate(accs)


def assert_valid_move(prof: Profile, *, start: State | tuple, target: float, v_max: float,
                      a_max: float, j_max: float, d_max: float | None = None,
                      end_v: float = 0.0, frame: float | None = None,
                      v_allow: float | None = None, a_allow: float | None = None) -> None:
    """Limits, continuity of p/v/a, exact end. `frame`: sign in which a_max is "forward"
    (default: the direction of the net move); `v_allow`/`a_allow` widen the limits for an
    initial state that already exceeds them."""
    d_max = a_max if d_max is None else d_max
    p_s, v_s, a_s = (tuple(start) + (0.0, 0.0))[:3]
    assert prof.end.p == target
    assert prof.end.v == end_v
    if prof.n_segments == 0:
        assert prof.duration == 0.0
        return
    smp = prof.sample(np.linspace(0.0, prof.duration, 4001))
    # positions are compared relative to the largest excursion of the motion
    scale = max(abs(target - p_s), np.abs(smp.p - p_s).max(), np.abs(prof.p0 - p_s).max(),
                abs(v_s) * prof.duration) + 1.0
    a_big = max(a_max, d_max, abs(a_s), a_allow or 0.0)
    v_big = max(v_max, abs(v_s), v_allow or 0.0)
    # Segment times are absolute, so a time inside a segment is known to ~1 ulp of the
    # duration: evaluated a and v carry that error times j and a (matters when j/a is huge).
    t_ulp = 4.0 * math.ulp(prof.duration)
    a_tol = REL * a_big + j_max * t_ulp
    v_tol = REL * v_big + a_big * t_ulp
    assert prof.p0[0] == pytest.approx(p_s, abs=REL * scale)
    assert prof.v0[0] == pytest.approx(v_s, abs=REL * v_big)
    assert prof.a0[0] == pytest.approx(a_s, abs=REL * a_big)
    # continuity across boundaries and into the end state
    for k in range(prof.n_segments):
        e = prof.segment_end(k)
        if k + 1 < prof.n_segments:
            nxt = (prof.p0[k + 1], prof.v0[k + 1], prof.a0[k + 1])
        else:
            nxt = (prof.end.p, prof.end.v, 0.0)
        assert e.p == pytest.approx(nxt[0], abs=REL * scale), f"p jump after segment {k}"
        assert e.v == pytest.approx(nxt[1], abs=v_tol), f"v jump after segment {k}"
        assert e.a == pytest.approx(nxt[2], abs=a_tol), f"a jump after segment {k}"
    sgn = frame if frame is not None else (1.0 if target >= p_s else -1.0)
    a_fwd = max(a_max, a_allow or 0.0)
    a_bwd = max(d_max, a_allow or 0.0)
    vlim = max(v_max, v_allow or 0.0)
    # stored segment data is exact up to rounding of the planner itself
    assert (sgn * prof.a0).max() <= a_fwd * (1 + REL)
    assert (-sgn * prof.a0).max() <= a_bwd * (1 + REL)
    assert np.abs(prof.j).max() <= j_max * (1 + REL)
    # evaluated motion: at segment extremes and on a dense sampling
    vs, accs = segment_extremes(prof)
    vs = np.concatenate([vs, smp.v])
    accs = np.concatenate([accs, smp.a])
    assert np.abs(vs).max() <= vlim * (1 + REL) + v_tol
    assert (sgn * accs).max() <= a_fwd * (1 + REL) + a_tol
    assert (-sgn * accs).max() <= a_bwd * (1 + REL) + a_tol
    assert np.abs(smp.j).max() <= j_max * (1 + REL)


# ------------------------------------------------------------------ strategies
def log_uniform(lo: float, hi: float):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


distances = st.tuples(st.sampled_from([-1.0, 1.0]), log_uniform(1e-3, 2**27 - 1)).map(
    lambda t: t[0] * t[1])
vels = log_uniform(1e-1, 1e7)
accs_ = log_uniform(1e-1, 1e9)
jerks = log_uniform(1e-1, 1e12)


# ----------------------------------------------------------------------- tests
def test_ruckig_failure_case_is_solved():
    args = (9846.652521797609, 442.65611753961855, 98221.75531948937, 48860762.86873084)
    prof = jerk_limited(*args)
    assert prof.duration == pytest.approx(22.25099, abs=5e-6)
    assert_valid_move(prof, start=(0.0,), target=args[0], v_max=args[1], a_max=args[2],
                      j_max=args[3])


@settings(max_examples=150, deadline=None)
@given(distances, vels, accs_, jerks, st.one_of(st.none(), accs_), st.floats(-1e6, 1e6))
def test_profile_is_valid(dist, v, a, j, d, start):
    prof = jerk_limited(dist, v, a, j, d_max=d, start=start)
    assert_valid_move(prof, start=(start,), target=start + dist, v_max=v, a_max=a,
                      j_max=j, d_max=d)
    assert prof.duration == jerk_limited_duration(dist, v, a, j, d_max=d) or \
        prof.duration == pytest.approx(jerk_limited_duration(dist, v, a, j, d_max=d),
                                       rel=1e-14)


@settings(max_examples=60, deadline=None)
@given(distances, vels, accs_, jerks)
def test_negative_distance_mirrors_positive(dist, v, a, j):
    fwd = jerk_limited(abs(dist), v, a, j)
    back = jerk_limited(-abs(dist), v, a, j)
    assert back.duration == fwd.duration
    np.testing.assert_array_equal(back.v0, -fwd.v0)
    np.testing.assert_array_equal(back.j, -fwd.j)
    assert back.end.p == -abs(dist)


def test_symmetric_seven_phase_closed_form():
    # all seven phases present: T = L/V + V/A + A/J
    L, V, A, J = 1000.0, 400.0, 1000.0, 10000.0
    prof = jerk_limited(L, V, A, J)
    assert prof.duration == pytest.approx(L / V + V / A + A / J, rel=1e-14)
    assert [round(ph.duration, 12) for ph in prof.phases()] == [0.1, 0.3, 0.1, 2.0, 0.1,
                                                                0.3, 0.1]
    # A reached, no cruise: L = Vp*(Vp/A + A/J)
    L, V = 50.0, 1e6
    vp = (-A * A / J + math.sqrt((A * A / J) ** 2 + 4 * A * L)) / 2
    assert jerk_limited(L, V, A, J).duration == pytest.approx(2 * (vp / A + A / J),
                                                              rel=1e-13)
    # neither: pure jerk triangle, T = 4*(L/(2J))**(1/3)
    L = 0.5
    assert jerk_limited(L, V, A, J).duration == pytest.approx(4 * (L / (2 * J)) ** (1 / 3),
                                                              rel=1e-13)
    # cruise without reaching A: T = L/V + 2*sqrt(V/J)
    V, A = 100.0, 1e5
    assert jerk_limited(1000.0, V, A, J).duration == pytest.approx(
        1000.0 / V + 2 * math.sqrt(V / J), rel=1e-13)


def test_reaches_the_limits_where_it_should():
    prof = jerk_limited(1e6, 400.0, 1000.0, 10000.0, d_max=500.0)
    s = prof.sample(np.linspace(0, prof.duration, 20001))
    assert s.v.max() == pytest.approx(400.0, rel=1e-12)
    assert s.a.max() == pytest.approx(1000.0, rel=1e-12)
    assert s.a.min() == pytest.approx(-500.0, rel=1e-12)
    assert np.abs(s.j).max() == 10000.0


def test_mixed_regime_root_is_exact():
    # A reached but D not: the quartic in sqrt(V) must balance the distance exactly
    L, V, A, D, J = 200.0, 1e9, 100.0, 5000.0, 1e4
    prof = jerk_limited(L, V, A, J, d_max=D)
    last = prof.segment_end(prof.n_segments - 1)
    assert last.p == pytest.approx(L, rel=1e-13)
    assert last.v == pytest.approx(0.0, abs=1e-10)


def test_zero_distance_is_empty():
    prof = jerk_limited(0.0, 1.0, 1.0, 1.0, start=5.0)
    assert prof.n_segments == 0 and prof.duration == 0.0
    assert prof.end.p == 5.0 and prof.start.p == 5.0


ruckig = pytest.importorskip("ruckig")


def _ruckig_duration(otg, inp, traj, dist, v, a, j, d):
    inp.target_position = [dist]
    inp.max_velocity = [v]
    inp.max_jerk = [j]
    if d is None:
        inp.max_acceleration, inp.min_acceleration = [a], None
    elif dist >= 0:
        inp.max_acceleration, inp.min_acceleration = [a], [-d]
    else:
        inp.max_acceleration, inp.min_acceleration = [d], [-a]
    try:
        otg.calculate(inp, traj)
    except ruckig.RuckigError:
        return None
    return traj.duration


def test_durations_equal_ruckig_over_many_magnitudes():
    otg, inp, traj = ruckig.Ruckig(1), ruckig.InputParameter(1), ruckig.Trajectory(1)
    inp.current_position = [0.0]
    rng = np.random.default_rng(7)
    solved = 0
    worst = 0.0
    for i in range(3000):
        dist = rng.choice([-1, 1]) * 10 ** rng.uniform(-3, 8)
        v, a, j = 10 ** rng.uniform(0, 7), 10 ** rng.uniform(0, 9), 10 ** rng.uniform(0, 12)
        d = None if i % 2 else 10 ** rng.uniform(0, 9)
        ref = _ruckig_duration(otg, inp, traj, dist, v, a, j, d)
        ours = jerk_limited_duration(dist, v, a, j, d_max=d)
        assert math.isfinite(ours) and ours > 0
        if ref is None:
            continue
        solved += 1
        worst = max(worst, abs(ours - ref) / ref)
    assert solved > 2500
    assert worst < 1e-6


# ------------------------------------------------------------------- time sync
@settings(max_examples=60, deadline=None)
@given(st.lists(distances, min_size=1, max_size=4), vels, accs_, jerks,
       st.one_of(st.none(), accs_))
def test_sync_profiles_share_duration_and_stay_valid(dists, v, a, j, d):
    profs = jerk_limited_sync(dists, v, a, j, d_max=d)
    t_opt = max(jerk_limited_duration(x, v, a, j, d_max=d) for x in dists)
    for x, prof in zip(dists, profs, strict=True):
        assert prof.duration == t_opt or prof.duration == pytest.approx(t_opt, rel=1e-14)
        assert_valid_move(prof, start=(0.0,), target=x, v_max=v, a_max=a, j_max=j, d_max=d)
    assert len({p.duration for p in profs}) == 1


def test_sync_per_axis_limits_and_dwell():
    profs = jerk_limited_sync([1000.0, -30.0, 0.0], [400.0, 50.0, 1.0], 1000.0,
                              [1e4, 1e3, 1.0], starts=[1.0, 2.0, 3.0])
    assert [p.duration for p in profs] == [pytest.approx(3.0, rel=1e-14)] * 3
    assert len({p.duration for p in profs}) == 1
    assert profs[1].end.p == -28.0 and profs[2].end.p == 3.0
    assert_valid_move(profs[1], start=(2.0,), target=-28.0, v_max=50.0, a_max=1000.0,
                      j_max=1e3)
    # the slow axis cruises below its own cap to arrive together
    assert np.abs(profs[1].v0).max() < 50.0
    assert profs[2].sample([1.5]).p[0] == 3.0


def test_sync_solves_stretch_precisely():
    profs = jerk_limited_sync([1e5, 1.0, 1e-3], 1e3, 1e4, 1e6, d_max=3e3)
    for prof, x in zip(profs, [1e5, 1.0, 1e-3], strict=True):
        last = prof.segment_end(prof.n_segments - 1)
        assert last.p == pytest.approx(x, rel=1e-9)
        assert last.v == pytest.approx(0.0, abs=1e-9)


def test_sync_plain_float_path_equals_the_checked_path():
    """Floats within range skip the per-value checks; other number types take them: the
    same profiles either way, and a bad value in either form is refused by name."""
    dists, v, a, j, d = [120.0, -35.5, 0.0], [400.0, 50.0, 9.0], 1000.0, [1e4, 1e3, 10.0], 700.0
    fast = jerk_limited_sync(dists, v, a, j, d_max=d, starts=(1.0, 2.0, 3.0))
    slow = jerk_limited_sync(np.array(dists), [np.float64(x) for x in v], 1000, j,
                             d_max=np.float64(d), starts=[1, 2, 3])
    for p, q in zip(fast, slow, strict=True):
        assert p.t0.tobytes() == q.t0.tobytes() and p.p0.tobytes() == q.p0.tobytes()
        assert (p.duration, p.start, p.end, p.labels) == (q.duration, q.start, q.end, q.labels)
    for kw, name in (({"distances": [1.0, 2.0**27]}, r"distances\[1\]"),
                     ({"v_max": [1.0, 2e9]}, r"axis 1: v_max"),
                     ({"d_max": [1.0, float("nan")]}, r"axis 1: d_max"),
                     ({"starts": (0.0, 2.0**41)}, r"starts\[1\]")):
        args = {"distances": [1.0, 2.0], "v_max": 1.0, "a_max": 1.0, "j_max": 1.0} | kw
        with pytest.raises(MotionError, match=name):
            jerk_limited_sync(args.pop("distances"), args.pop("v_max"), args.pop("a_max"),
                              args.pop("j_max"), **args)


def test_sync_tiny_distance_beside_a_long_move():
    """A distance of 1e-200 synced to a move of 1 pulse: its cruise cap is ~1e-200 pps,
    whose square underflows (the Python cap search raised ZeroDivisionError here)."""
    for tiny in (8.276690573396938e-252, 1e-200):
        long_move, short = jerk_limited_sync([1.0, tiny], 1.0, 1.0, 1.0)
        assert short.duration == long_move.duration
        assert short.end.p == tiny and short.end.v == 0.0
        assert np.isfinite(short.dt).all() and short.dt.sum() == pytest.approx(
            short.duration, rel=1e-12)
        assert_valid_move(short, start=(0.0,), target=tiny, v_max=1.0, a_max=1.0, j_max=1.0)


# ------------------------------------------------------------------ validation
@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"distance": float("nan")}, "distance"),
        ({"distance": 2.0**27}, "distance"),
        ({"distance": "x"}, "distance"),
        ({"v_max": 0.0}, "v_max"),
        ({"a_max": -1.0}, "a_max"),
        ({"j_max": float("inf")}, "j_max"),
        ({"d_max": 0.0}, "d_max"),
        ({"start": float("nan")}, "start"),
    ],
)
def test_invalid_arguments_are_refused(kwargs, name):
    args = {"distance": 10.0, "v_max": 1.0, "a_max": 1.0, "j_max": 1.0} | kwargs
    extra = {k: args.pop(k) for k in ("d_max", "start") if k in args}
    with pytest.raises(MotionError, match=name):
        jerk_limited(args["distance"], args["v_max"], args["a_max"], args["j_max"], **extra)


def test_sync_invalid_arguments():
    with pytest.raises(MotionError, match="distances"):
        jerk_limited_sync([], 1.0, 1.0, 1.0)
    with pytest.raises(MotionError, match="v_max"):
        jerk_limited_sync([1.0, 2.0], [1.0], 1.0, 1.0)
    with pytest.raises(MotionError, match=r"axis 1: a_max"):
        jerk_limited_sync([1.0, 2.0], 1.0, [1.0, 0.0], 1.0)
    with pytest.raises(MotionError, match=r"distances\[0\]"):
        jerk_limited_sync([float("inf")], 1.0, 1.0, 1.0)


def test_tiny_distances_and_extreme_magnitudes_never_fail():
    """Every value within the documented ranges (docs/ranges.md) plans a finite move."""
    from openmotion import limits
    from openmotion.profile.batch import jerk_limited_durations

    for dist in (5e-324, 1e-310, 1e-100):
        prof = jerk_limited(dist, 1e4, 1e-3, 1e-3)
        assert math.isfinite(prof.duration) and prof.duration > 0
        assert prof.end.p == dist
        # the pure jerk triangle: L = 2*J*tj**3, T = 4*tj
        assert prof.duration == pytest.approx(4 * (dist / 2e-3) ** (1 / 3), rel=1e-12)
    rng = np.random.default_rng(5)
    lo = np.log10([1e-100, limits.PPS_MIN, limits.PPS2_MIN, limits.PPS3_MIN, limits.PPS2_MIN])
    hi = np.log10([2**27 - 1, limits.PPS_MAX, limits.PPS2_MAX, limits.PPS3_MAX,
                   limits.PPS2_MAX])
    e = 10 ** rng.uniform(lo, hi, (500, 5))
    e = np.concatenate([e, np.array([[2**27 - 1, 1e-3, 1e-3, 1e-3, 1e-3],
                                     [1e-100, 1e9, 1e13, 1e18, 1e13],
                                     [2**27 - 1, 1e9, 1e-3, 1e18, 1e13]])])
    batch = jerk_limited_durations(*e.T)
    for row, tb in zip(e, batch, strict=True):
        t = jerk_limited_duration(*row[:4], d_max=row[4])
        assert math.isfinite(t) and t == pytest.approx(tb, rel=1e-12)


@settings(max_examples=300, deadline=None)
@given(st.floats(-1e6, 1e6), st.floats(1e-3, 1e5), st.floats(1e-3, 1e5), st.floats(1e-3, 1e5),
       st.floats(1e-3, 1e5), st.floats(-1e3, 1e3))
def test_direct_build_equals_profile_builder_bit_for_bit(d, v, a, j, dd, start):
    """The compiled builder's profile is ProfileBuilder's, segment call by call, from the
    oracle's phase times (tests/jerk_oracle.py)."""
    import jerk_oracle as O
    from openmotion.limits import check_pulses

    times = O.phase_times(abs(d), v, a, dd, j)
    assume(all(math.isfinite(x) for x in times))
    p1 = jerk_limited(d, v, a, j, d_max=dd, start=start)
    # from the start as validated (check_pulses makes -0.0 a 0.0)
    p2 = O.build_with_builder(check_pulses("start", start), d, times, a, dd, j)
    for f in ("t0", "p0", "v0", "a0", "j", "dt"):
        x, y = getattr(p1, f), getattr(p2, f)
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), f
    assert (p1.duration, p1.start, p1.end, p1.labels) == (p2.duration, p2.start, p2.end,
                                                          p2.labels)


@pytest.mark.parametrize("args, name", [
    ((1000, 1000, 1e5, 5e-324), "j_max"), ((1000, 1000, 5e-324, 1e5), "a_max"),
    ((1000, 1e-300, 1e5, 1e6), "v_max"), ((1000, 1e10, 1e5, 1e6), "v_max"),
    ((1000, 1000, 1e14, 1e6), "a_max"), ((1000, 1000, 1e5, 1e19), "j_max"),
])
def test_values_outside_the_ranges_are_refused_by_name(args, name):
    """#12 defect 10: jerk_limited(1000, 1000, 1e5, 5e-324) raised ZeroDivisionError."""
    from openmotion.profile.batch import jerk_limited_durations

    for call in (lambda: jerk_limited(*args), lambda: jerk_limited_duration(*args),
                 lambda: jerk_limited_sync([args[0], 1.0], *args[1:]),
                 lambda: jerk_limited_durations(*args)):
        with pytest.raises(MotionError, match=name) as info:
            call()
        assert "pps" in str(info.value)
