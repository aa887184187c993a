"""Velocity mode (tv_move / sv_move / v_change ramps) and the two stops."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.profile.pcl import MoveSpec
from openmotion.profile.segments import State
from openmotion.profile.velocity import (
    decel_stop,
    immediate_stop,
    stop_distance,
    velocity_move,
    velocity_ramp,
)

REL = 1e-9


def continuity(prof, *, v_jumps_ok=(), tol=1e-9):
    scale = 1.0 + float(np.max(np.abs(prof.p0))) if prof.n_segments else 1.0
    vscale = 1.0 + float(np.max(np.abs(prof.v0))) if prof.n_segments else 1.0
    for k in range(prof.n_segments - 1):
        e = prof.segment_end(k)
        assert e.p == pytest.approx(prof.p0[k + 1], abs=tol * scale)
        if k + 1 not in v_jumps_ok:
            assert e.v == pytest.approx(prof.v0[k + 1], abs=tol * vscale)


# ------------------------------------------------------------------ hand calculations
def test_tv_move_from_rest():
    # StrVel 100 -> MaxVel 1000 in 0.5 s: accel 1800, ramp distance (100+1000)/2*0.5 = 275
    prof = velocity_move(MoveSpec("T", 100, 1000, 0.5, 1), +1, start=10)
    assert prof.v0[0] == 100 and prof.a0[0] == pytest.approx(1800)
    assert prof.duration == pytest.approx(0.5)
    assert prof.end == State(pytest.approx(285), 1000, 0)
    # holds MaxVel after the ramp
    assert prof.state_at(1.5).p == pytest.approx(285 + 1000)
    assert prof.sample(2.5).v == 1000


def test_sv_move_from_rest_lasts_tacc():
    # VS=100 of 900: A = (900+200)/0.5 = 2200, J = 2200**2/200 = 24200; mean speed 550
    prof = velocity_move(MoveSpec("S", 100, 1000, 0.5, 1, 100), -1)
    assert prof.duration == pytest.approx(0.5, rel=1e-12)
    assert prof.end.v == -1000 and prof.end.p == pytest.approx(-275)
    assert np.max(np.abs(prof.j)) == pytest.approx(24200)
    assert np.max(np.abs(prof.a0)) == pytest.approx(2200)


@pytest.mark.parametrize("shape", ["T", "S"])
def test_v_change_from_cruise_table_4_6_accel_column(shape):
    # Table 4-6 row 1: 1000 -> 5000 pps in 0.1 s covers (1000+5000)/2*0.1 = 300 pulses
    prof = velocity_ramp(State(5000, 1000), 5000, 0.1, shape=shape)
    assert prof.duration == pytest.approx(0.1, rel=1e-12)
    assert prof.end.p - 5000 == pytest.approx(300, rel=1e-12)
    if shape == "T":
        assert prof.a0[0] == pytest.approx(40000)


def test_ramp_to_zero_stops_at_strvel():
    prof = velocity_ramp(State(0, -800), 0, 0.2, str_vel=200)
    # down to StrVel at 600/0.2 = 3000 pps^2, then the rate drops to 0
    assert prof.duration == pytest.approx(0.2)
    assert prof.segment_end(prof.n_segments - 1).v == pytest.approx(-200)
    assert prof.end.v == 0
    assert prof.end.p == pytest.approx(-(800 + 200) / 2 * 0.2)


def test_t_reversal_lasts_exactly_t_and_skips_strvel_band():
    prof = velocity_ramp(State(0, 500), -300, 0.5, str_vel=100)
    # covers 500->100 and -100->-300: 600 pps at 1200 pps^2 = 0.5 s
    assert prof.duration == pytest.approx(0.5)
    assert prof.v0[1] == -100
    assert prof.end.v == -300
    continuity(prof, v_jumps_ok=(1,))


# ------------------------------------------------------------------ properties
vel = st.floats(-1e5, 1e5)


@settings(max_examples=120, deadline=None)
@given(vel, st.floats(-1e6, 1e6), vel, st.floats(1e-3, 2.0), st.sampled_from("TS"),
       st.one_of(st.just(0.0), st.floats(1e-6, 1)))
def test_ramp_properties(v0, a0, vt, t, shape, fvs):
    a0 = a0 if v0 != 0 else 0.0  # at rest means a = 0
    assume(abs(vt - v0) > 1e-3 or (a0 != 0 and vt == v0))
    assume(v0 * vt >= 0)  # reversals tested separately
    dv = abs(vt - v0)
    vs = fvs * dv / 2
    prof = velocity_ramp(State(3.0, v0, a0), vt, t, shape=shape, vs=vs)
    assert prof.end.v == vt
    if prof.n_segments == 0:
        return
    last = prof.segment_end(prof.n_segments - 1)
    vpeak = float(np.max(np.abs(prof.v0)))
    assert last.v == pytest.approx(vt, abs=1e-9 * (1 + vpeak))
    if shape == "S":  # a T ramp ends with an acceleration jump to 0
        assert abs(last.a) <= 1e-6 * (1 + abs(a0) + dv / t)
    continuity(prof)
    if shape == "S":
        acc = (dv + 2 * (vs if vs > 0 else dv / 2)) / t
        jmax = acc * acc / (2 * (vs if vs > 0 else dv / 2)) if dv > 0 else math.inf
        assert np.all(np.abs(prof.j) <= jmax * (1 + REL)) or dv == 0
        s = prof.sample(np.linspace(0, prof.duration, 400))
        assert np.all(np.abs(s.a) <= max(acc, abs(a0)) * (1 + REL) + 1e-9)
        if a0 == 0:
            assert prof.duration == pytest.approx(t, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(st.floats(1, 1e5), st.floats(1, 1e5), st.floats(0, 1), st.floats(1e-3, 2.0))
def test_reversal_properties(v0, vt, fsv, t):
    sv = fsv * min(v0, vt)
    prof = velocity_ramp(State(0, v0), -vt, t, str_vel=sv, shape="S")
    assert prof.end.v == -vt
    s = prof.sample(np.linspace(0, prof.duration, 500))
    # the band (-StrVel, StrVel) is jumped over, never ramped through
    assert not np.any((np.abs(s.v) < sv * (1 - 1e-9)) & (np.abs(s.v) > 1e-9))


# ------------------------------------------------------------------ stops
@pytest.mark.parametrize("shape", ["T", "S"])
def test_decel_stop_at_decel_start_reproduces_move(shape):
    spec = MoveSpec(shape, 100, 1000, 0.5, 1, 0, 200 if shape == "S" else 0)
    plan = spec.plan(10000, start=-50)
    stop = decel_stop(plan.profile, plan.t_decel, spec)
    assert stop.duration == pytest.approx(plan.profile.duration, rel=1e-12)
    assert stop.end.p == pytest.approx(plan.profile.end.p, rel=1e-12)
    assert stop.end.v == 0


def test_decel_stop_hand_calc_t():
    # cruise at 1000 pps, StrVel 100, decel 900/1 = 900: (1000**2-100**2)/(2*900) = 550
    spec = MoveSpec("T", 100, 1000, 0.5, 1)
    plan = spec.plan(10000)
    p5 = plan.profile.state_at(5.0).p
    stop = decel_stop(plan.profile, 5.0, spec)
    assert stop.end.p == pytest.approx(p5 + 550)
    assert stop.duration == pytest.approx(6.0)
    assert stop_distance(spec, -1000) == pytest.approx(550)


def test_decel_stop_hand_calc_s():
    # S: a full decel ramp from MaxVel covers (MaxVel+StrVel)/2*Tdec = 550 in Tdec
    spec = MoveSpec("S", 100, 1000, 0.5, 1, 0, 300)
    stop = decel_stop(spec.plan(10000).profile, 5.0, spec)
    assert stop.duration == pytest.approx(6.0)
    assert stop_distance(spec, 1000) == pytest.approx(550)


@settings(max_examples=80, deadline=None)
@given(st.floats(0, 1), st.sampled_from("TS"), st.floats(0.01, 2), st.floats(0.01, 2),
       st.floats(0, 1), st.floats(0, 1), st.floats(-1e5, 1e5))
def test_decel_stop_any_time(frac, shape, tacc, tdec, fa, fd, dist):
    spec = MoveSpec(shape, 50, 2000, tacc, tdec, fa * 975, fd * 975)
    plan = spec.plan(dist)
    t = frac * plan.profile.duration
    stop = decel_stop(plan.profile, t, spec)
    assert stop.end.v == 0
    s = stop.sample(np.linspace(0, stop.duration, 800))
    sgn = math.copysign(1, dist)
    assert np.all(np.abs(s.v) <= 2000 * (1 + REL))
    assert np.all(sgn * s.v >= -1e-9)  # a stop never reverses
    r = spec.rates
    assert np.all(np.abs(s.a) <= max(r.accel, r.decel) * (1 + REL))
    assert np.all(np.abs(stop.j) <= max(r.jerk_acc, r.jerk_dec) * (1 + REL))
    # the stop never travels further than the original move (stops are no longer)
    assert sgn * stop.end.p <= sgn * plan.profile.end.p + 1e-6
    assert stop.state_at(t * (1 - 1e-12)).p == pytest.approx(plan.profile.state_at(t).p,
                                                               abs=1e-6)
    continuity(stop, v_jumps_ok=(0,))


def test_stops_on_velocity_profile_after_its_end():
    spec = MoveSpec("T", 0, 1000, 0.5, 0.25)
    prof = velocity_move(spec, +1)
    stop = decel_stop(prof, 3.0, spec)
    # ramp 250 pulses, hold 2.5 s (2500), decel 1000**2/(2*4000) = 125
    assert stop.end.p == pytest.approx(250 + 2500 + 125)
    assert stop.duration == pytest.approx(3.25)
    emg = immediate_stop(prof, 3.0)
    assert emg.end == State(pytest.approx(2750), 0.0, 0.0)
    assert emg.duration == 3.0


def test_immediate_stop_and_stop_below_strvel():
    spec = MoveSpec("T", 300, 1000, 0.5, 0.5)
    plan = spec.plan(1000)
    emg = immediate_stop(plan.profile, 0.1)
    assert emg.end.p == pytest.approx(plan.profile.state_at(0.1).p) and emg.end.v == 0
    # at t=0 the axis runs at StrVel: an sd_stop stops at once
    assert decel_stop(plan.profile, 0.0, spec).end.p == 0.0


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: velocity_ramp(State(0), 100, 0), "t_ramp"),
        (lambda: velocity_ramp(State(0), float("nan"), 1), "target_v"),
        (lambda: velocity_ramp(State(0), 50, 1, str_vel=100), "target_v"),
        (lambda: velocity_ramp(State(0), 50, 1, shape="Q"), "shape"),
        (lambda: velocity_ramp(State(0, float("inf")), 50, 1), "state.v"),
        (lambda: velocity_ramp(State(0), 50, 1, vs=-1), "vs"),
        (lambda: decel_stop("x", 0, MoveSpec("T", 0, 1, 1, 1)), "profile"),
        (lambda: decel_stop(velocity_ramp(State(0), 5, 1), -1, MoveSpec("T", 0, 1, 1, 1)), "t"),
        (lambda: decel_stop(velocity_ramp(State(0), 5, 1), 0, None), "spec"),
        (lambda: immediate_stop(velocity_ramp(State(0), 5, 1), float("nan")), "t"),
        (lambda: velocity_move(MoveSpec("T", 0, 1, 1, 1), 0), "direction"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(MotionError, match=name):
        call()
