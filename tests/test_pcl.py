"""PCL6045 T/S-curve moves: hand calculations, seed numbers, properties, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.profile.pcl import MoveSpec, scurve, trapezoid

REL = 1e-9


def check_profile(prof, spec, distance, start, rates):
    """Invariants every PCL move satisfies."""
    assert prof.end.p == start + distance  # exact target
    assert prof.end.v == 0.0 and prof.start.v == 0.0
    if distance == 0:
        assert prof.n_segments == 0
        return
    sgn = math.copysign(1.0, distance)
    vmax = spec.max_vel * (1 + REL)
    # starts at StrVel, ends at StrVel (then jumps to 0)
    assert prof.v0[0] == pytest.approx(sgn * spec.str_vel, abs=1e-12)
    last = prof.segment_end(prof.n_segments - 1)
    scale = abs(distance) + abs(start) + 1.0
    assert last.v == pytest.approx(sgn * spec.str_vel, rel=1e-9, abs=1e-9 * spec.max_vel)
    assert last.p == pytest.approx(start + distance, abs=1e-9 * scale)
    # continuity of position and velocity between segments
    for k in range(prof.n_segments - 1):
        e = prof.segment_end(k)
        assert e.p == pytest.approx(prof.p0[k + 1], abs=1e-9 * scale)
        assert e.v == pytest.approx(prof.v0[k + 1], abs=1e-9 * spec.max_vel + 1e-12)
    # limits, per phase, sampled (vectorized)
    t = np.linspace(0.0, prof.duration, 2001)
    s = prof.sample(t)
    assert np.all(np.abs(s.v) <= vmax)
    assert np.all(sgn * s.v >= -1e-9 * spec.max_vel)  # never reverses
    for k, lb in enumerate(prof.labels):
        lim_a = rates.accel if lb.startswith("accel") else rates.decel
        lim_j = rates.jerk_acc if lb.startswith("accel") else rates.jerk_dec
        e = prof.segment_end(k)
        assert abs(prof.a0[k]) <= lim_a * (1 + REL) and abs(e.a) <= lim_a * (1 + REL)
        assert abs(prof.j[k]) <= lim_j * (1 + REL)
        if lb == "cruise":
            assert prof.a0[k] == 0 and prof.j[k] == 0


# ----------------------------------------------------------------- hand calculations
def test_trapezoid_reached_hand_calc():
    # HSL_M_start_ta_move(0, 10000, 0, 1000, 0.5, 1): accel 250, decel 500 pulses,
    # cruise 9250 pulses at 1000 pps -> 9.25 s; total 0.5 + 9.25 + 1 = 10.75 s.
    plan = MoveSpec("T", 0, 1000, 0.5, 1).plan(10000)
    assert plan.profile.duration == pytest.approx(10.75, rel=1e-12)
    assert plan.t_decel == pytest.approx(9.75, rel=1e-12)
    assert not plan.reduced
    assert plan.rates.accel == 2000 and plan.rates.decel == 1000
    ph = plan.profile.phases()
    assert [p.distance for p in ph] == pytest.approx([250, 9250, 500])


def test_trapezoid_with_strvel_hand_calc():
    # S=200, V=1000, Tacc=0.4, Tdec=0.8, D=5000: ramps (200+1000)/2*(0.4+0.8) = 720,
    # cruise (5000-720)/1000 = 4.28 s -> duration 5.48 s.
    prof = trapezoid(5000, 200, 1000, 0.4, 0.8)
    assert prof.duration == pytest.approx(5.48, rel=1e-12)
    assert prof.v0[0] == 200 and prof.state_at(5.48 + 1).v == 0


def test_trapezoid_not_reached_hand_calc():
    # D=100, S=0, V=1000, Tacc=Tdec=1: a=d=1000, V'^2 = 2*D*a*d/(a+d) = 1e5,
    # V' = 316.227..., duration 2*V'/1000.
    plan = MoveSpec("T", 0, 1000, 1, 1).plan(100)
    vp = math.sqrt(1e5)
    assert plan.reduced
    assert plan.effective.max_vel == pytest.approx(vp, rel=1e-12)
    assert plan.effective.tacc == pytest.approx(vp / 1000, rel=1e-12)
    assert plan.profile.duration == pytest.approx(2 * vp / 1000, rel=1e-12)
    # StrVel kept, accel unchanged
    assert plan.effective.str_vel == 0 and plan.effective.rates.accel == pytest.approx(1000)


def test_trapezoid_not_reached_with_strvel_asymmetric():
    # S=100, V=2000, Tacc=0.5 (a=3800), Tdec=1 (d=1900), D=300:
    # V'^2 = S^2 + 2*D*a*d/(a+d) = 1e4 + 2*300*3800*1900/5700 = 770000
    vp = math.sqrt(1e4 + 2 * 300 * 3800 * 1900 / 5700)
    plan = MoveSpec("T", 100, 2000, 0.5, 1).plan(-300, start=50)
    assert plan.effective.max_vel == pytest.approx(vp, rel=1e-12)
    assert plan.profile.duration == pytest.approx((vp - 100) / 3800 + (vp - 100) / 1900)
    assert plan.profile.end.p == -250
    assert plan.profile.v0[0] == -100


def test_scurve_reached_hand_calc():
    # S=0, V=1000, Tacc=0.5, VSacc=100 -> A=(1000+200)/0.5=2400, J=2400**2/200=28800;
    # Tdec=1, VSdec=0 (pure S) -> D=2000, J=4000. Ramps cover (0+1000)/2*1.5 = 750 pulses;
    # cruise (10000-750)/1000 = 9.25 s; duration 10.75 s.
    plan = MoveSpec("S", 0, 1000, 0.5, 1, 100, 0).plan(10000)
    r = plan.rates
    assert (r.accel, r.jerk_acc) == pytest.approx((2400, 28800))
    assert (r.decel, r.jerk_dec) == pytest.approx((2000, 4000))
    assert plan.profile.duration == pytest.approx(10.75, rel=1e-12)
    ph = plan.profile.phases()
    # jerk region covers VS=100 pps, linear region 100->900 (seed-facts 1.2 correction)
    assert ph[0].v_end == pytest.approx(100) and ph[1].v_end == pytest.approx(900)
    assert ph[0].duration == pytest.approx(2400 / 28800)


def test_scurve_vs0_equals_vs_half():
    a = scurve(5000, 100, 1100, 0.3, 0.6, 0, 0)
    b = scurve(5000, 100, 1100, 0.3, 0.6, 500, 500)
    t = np.linspace(0, a.duration, 301)
    assert a.duration == pytest.approx(b.duration, rel=1e-12)
    np.testing.assert_allclose(a.sample(t).p, b.sample(t).p, rtol=1e-12, atol=1e-9)


def test_scurve_pure_not_reached_hand_calc():
    # pure S, S=0, V=1000, Tacc=Tdec=1: J = 4*V/T^2 = 4000. Each ramp of x has duration
    # 2*sqrt(x/J) and mean speed x/2, so D = x*2*sqrt(x/J) -> x = (D*sqrt(J)/2)**(2/3).
    J = 4000.0
    x = (100 * math.sqrt(J) / 2) ** (2 / 3)
    plan = MoveSpec("S", 0, 1000, 1, 1).plan(100)
    assert plan.reduced
    assert plan.effective.max_vel == pytest.approx(x, rel=1e-12)
    assert plan.profile.duration == pytest.approx(4 * math.sqrt(x / J), rel=1e-12)
    assert plan.effective.rates.jerk_acc == pytest.approx(J, rel=1e-9)


def test_scurve_linear_not_reached_hand_calc():
    # S=50, V=1050, Tacc=Tdec=1, VS=100: A=1200, J=7200 (A/J=1/6), VS region 2*VS=200.
    # With both ramps keeping a linear region: D = (S+V)/2*((V-S)*k + m), k=2/A, m=2*A/J
    # -> k*V^2 + m*V + (m*S - k*S^2 - 2*D) = 0.
    A, J, S, D = 1200.0, 7200.0, 50.0, 800.0
    k, m = 2 / A, 2 * A / J
    c = m * S - k * S * S - 2 * D
    V = (-m + math.sqrt(m * m - 4 * k * c)) / (2 * k)
    assert V - S >= 200  # linear region still present
    plan = MoveSpec("S", S, 1050, 1, 1, 100, 100).plan(D)
    assert plan.effective.max_vel == pytest.approx(V, rel=1e-12)
    assert plan.effective.vs_acc == 100  # VS unchanged while a linear region remains
    assert plan.profile.duration == pytest.approx(2 * ((V - S) / A + A / J), rel=1e-12)


def test_constant_speed_move():
    prof = trapezoid(-300, 600, 600, 0.1, 0.1, start=7)
    assert prof.duration == pytest.approx(0.5)
    assert prof.n_segments == 1 and prof.v0[0] == -600 and prof.end.p == -293


def test_zero_distance_is_empty():
    prof = scurve(0, 10, 100, 1, 1, 0, 0, start=5)
    assert prof.n_segments == 0 and prof.duration == 0 and prof.end.p == 5


@pytest.mark.parametrize("dist", [100, 249, 250, 251, 400, 5000])
def test_hctl1100_triangle_trapezoid_rule(dist):
    # AIM104 appendix 1 (HCTL-1100): trapezoid if MaxVel is reached before the halfway
    # point, else triangle. Maps to StrVel = 0, Tacc = Tdec: a = 1000, V = 500 -> the
    # ramp covers V^2/(2a) = 125 pulses, so MaxVel is reached iff 125 <= dist/2.
    plan = MoveSpec("T", 0, 500, 0.5, 0.5).plan(dist)
    assert plan.reduced == (dist / 2 < 125)
    prof = plan.profile
    mid = prof.state_at(prof.duration / 2)
    assert mid.p == pytest.approx(dist / 2)  # symmetric about the halfway point
    if plan.reduced:  # triangle: peak at the halfway point, v = sqrt(a*dist)
        assert mid.v == pytest.approx(math.sqrt(1000 * dist))


# ------------------------------------------------------------------ properties
# speeds are 0 or >= limits.PPS_MIN (docs/ranges.md)
speeds = st.tuples(st.one_of(st.just(0.0), st.floats(1e-3, 5e4)),
                   st.floats(1, 1e6)).map(lambda t: (t[0], t[0] + t[1]))
times = st.floats(1e-3, 5.0)
fracs = st.one_of(st.just(0.0), st.floats(1e-5, 1.0))
# pulses: sub-micro-pulse moves are not meaningful (a 5e-324 move has no representable time)
dists = st.one_of(st.just(0.0), st.floats(1e-6, 1e7), st.floats(-1e7, -1e-6))


@settings(max_examples=150, deadline=None)
@given(speeds, times, times, fracs, fracs, dists, st.floats(-1e6, 1e6),
       st.sampled_from("TS"))
def test_move_properties(sv, tacc, tdec, fa, fd, dist, start, shape):
    s, v = sv
    half = (v - s) / 2
    spec = MoveSpec(shape, s, v, tacc, tdec, fa * half, fd * half)
    plan = spec.plan(dist, start)
    check_profile(plan.profile, spec, dist, start, plan.rates)
    eff, r = plan.effective, plan.rates
    if dist == 0:
        return
    # durations are the effective Tacc + Tdec (+ cruise)
    cruise = sum(ph.duration for ph in plan.profile.phases() if ph.label == "cruise")
    if eff.max_vel == s:  # peak rounds to StrVel: a constant-speed move at StrVel
        assert plan.profile.duration == pytest.approx(abs(dist) / s, rel=1e-9)
        return
    # rel 1e-7: when dv << StrVel the peak V = StrVel + x carries ulp(StrVel)/x error
    assert plan.profile.duration == pytest.approx(eff.tacc + eff.tdec + cruise, rel=1e-7)
    if plan.reduced:
        # lowered peak: ramps alone cover the distance; StrVel, accel (limit) and jerk kept
        assert eff.max_vel <= v * (1 + REL) and eff.str_vel == s
        covered = (s + eff.max_vel) / 2 * (eff.tacc + eff.tdec)
        # eff.tacc carries the ulp(V)/(V - StrVel) relative error of the peak
        cond = 4 * math.ulp(eff.max_vel) / (eff.max_vel - s)
        assert covered == pytest.approx(abs(dist), rel=1e-7 + cond, abs=1e-9)
        er = eff.rates
        assert er.accel <= r.accel * (1 + REL) and er.decel <= r.decel * (1 + REL)
        if shape == "S" and eff.max_vel > s:
            assert er.jerk_acc == pytest.approx(r.jerk_acc, rel=1e-6)
            assert er.jerk_dec == pytest.approx(r.jerk_dec, rel=1e-6)
        if shape == "T" and eff.max_vel > s:
            assert er.accel == pytest.approx(r.accel, rel=1e-6)
    else:
        assert eff == spec and plan.profile.duration == pytest.approx(
            tacc + tdec + (abs(dist) - (s + v) / 2 * (tacc + tdec)) / v, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(speeds, times, times, st.floats(1.0, 1e6))
def test_longer_moves_never_slower_peak(sv, tacc, tdec, dist):
    s, v = sv
    spec = MoveSpec("S", s, v, tacc, tdec)
    a, b = spec.plan(dist), spec.plan(dist * 1.5)
    assert b.effective.max_vel >= a.effective.max_vel * (1 - 1e-12)
    assert b.profile.duration >= a.profile.duration * (1 - 1e-12)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(distance=float("nan")), "distance"),
        (dict(distance=float("inf")), "distance"),
        (dict(distance=2**27), "distance"),
        (dict(str_vel=-1), "str_vel"),
        (dict(max_vel=0), "max_vel"),
        (dict(max_vel=50), "max_vel"),  # below str_vel
        (dict(tacc=0), "tacc"),
        (dict(tdec=-0.1), "tdec"),
        (dict(tacc=float("nan")), "tacc"),
        (dict(vs_acc=451), "vs_acc"),
        (dict(vs_dec=-1), "vs_dec"),
        (dict(start=float("inf")), "start"),
        (dict(max_vel="fast"), "max_vel"),
    ],
)
def test_bad_input(kwargs, name):
    args = dict(distance=1000, str_vel=100, max_vel=1000, tacc=0.1, tdec=0.1, vs_acc=0,
                vs_dec=0, start=0.0)
    args.update(kwargs)
    with pytest.raises(MotionError, match=name):
        scurve(**args)


def test_bad_shape_and_max_distance_ok():
    with pytest.raises(MotionError, match="shape"):
        MoveSpec("X", 0, 1, 1, 1)
    prof = trapezoid(-(2**27 - 1), 0, 1e6, 0.1, 0.1)
    assert prof.end.p == -(2**27 - 1)


@pytest.mark.parametrize("shape", "TS")
@pytest.mark.parametrize("dist", [0.001953125, 1e-6, 1e-9, -3e-7])
def test_sub_pulse_move_plans_with_derived_ramps_under_1ns(shape, dist):
    """A tiny move's automatic velocity decrease derives Tacc/Tdec far below the 1 ns user
    minimum; the derived spec is the controller's, so the move plans and ends exactly
    (CI found sv=391, tacc=5, tdec=1 ms, dist=2^-9 refused with 'tdec must satisfy ...')."""
    spec = MoveSpec(shape, 391.0, 392.0, 5.0, 0.001)
    plan = spec.plan(dist)
    assert plan.reduced
    assert plan.effective.max_vel >= plan.effective.str_vel
    assert plan.profile.end.p == dist
    assert plan.profile.end.v == 0.0


def test_derived_spec_keeps_the_structural_rules():
    spec = MoveSpec("S", 0.0, 1000.0, 0.1, 0.1)
    with pytest.raises(MotionError, match="derived"):
        spec.derived(tacc=0.0)
    with pytest.raises(MotionError, match="derived"):
        spec.derived(max_vel=-1.0)
    with pytest.raises(MotionError, match="derived"):
        spec.derived(vs_acc=600.0)
    tiny = spec.derived(tacc=1e-12)
    assert tiny.tacc == 1e-12 and tiny.shape == "S" and tiny.max_vel == 1000.0
