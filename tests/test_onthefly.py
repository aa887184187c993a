"""Change speed / position on the fly: seed Tables 4-6 and 4-7, properties, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.errors import InfeasibleError, MotionError
from openmotion.profile.onthefly import change_position, change_speed, final_decel_start
from openmotion.profile.pcl import MoveSpec
from openmotion.profile.velocity import stop_distance, velocity_move

REL = 1e-9


def rnd(x):  # the seed tables round to the nearest pulse, halves up
    return math.floor(x + 0.5)


def continuous(prof, skip=()):
    for k in range(prof.n_segments - 1):
        e = prof.segment_end(k)
        assert e.p == pytest.approx(prof.p0[k + 1], abs=1e-7 * (1 + abs(e.p)))
        if k + 1 not in skip:
            assert e.v == pytest.approx(prof.v0[k + 1], abs=1e-7 * (1 + abs(e.v)))


# ------------------------------------------------------------------ Table 4-6
TABLE_4_6 = [  # NewVel, Tacc, accel pulses, decel pulses, total, OK
    (5000, 0.1, 300, 313, 613, True),
    (5000, 1.0, 3000, 3125, 6125, False),
    (10000, 0.1, 550, 556, 1106, True),
    (50000, 0.1, 2550, 2551, 5101, False),
]


@pytest.mark.parametrize("new_vel, tacc, n_acc, n_dec, n_tot, ok", TABLE_4_6)
def test_table_4_6(new_vel, tacc, n_acc, n_dec, n_tot, ok):
    # HSL_M_start_tr_move(0, 10000, 0, 1000, 0.1, 0.1); v_change at 5000 pulses
    spec = MoveSpec("T", 0, 1000, 0.1, 0.1)
    prof = spec.plan(10000).profile
    t = 0.1 + (5000 - 50) / 1000  # cruise reached after 50 pulses
    assert prof.state_at(t).p == pytest.approx(5000)
    a = (new_vel - 1000) / tacc  # the new rate, for the change and the final decel
    assert rnd((new_vel**2 - 1000**2) / (2 * a)) == n_acc
    assert rnd(new_vel**2 / (2 * a)) == n_dec
    if not ok:
        with pytest.raises(InfeasibleError, match="remain"):
            change_speed(prof, t, spec, new_vel, tacc, target=10000)
        return
    c = change_speed(prof, t, spec, new_vel, tacc, target=10000)
    assert (rnd(c.needed_accel), rnd(c.needed_decel)) == (n_acc, n_dec)
    assert rnd(c.needed_accel + c.needed_decel) == n_tot
    assert c.remaining == pytest.approx(5000)
    assert c.profile.end.p == 10000 and c.profile.end.v == 0
    # the change lasts Tacc; the final deceleration runs at the same rate
    assert c.spec.max_vel == new_vel
    assert c.spec.rates.accel == pytest.approx(a) and c.spec.rates.decel == pytest.approx(a)
    s = c.profile.sample(np.linspace(0, c.profile.duration, 3000))
    assert np.max(s.v) <= new_vel * (1 + REL)
    continuous(c.profile, skip=(0,))


def test_v_limit_caps_new_vel_and_velocity_mode():
    spec = MoveSpec("S", 100, 1000, 0.2, 0.2, 100, 100)
    prof = velocity_move(spec, -1)
    c = change_speed(prof, 1.0, spec, 8000, 0.1, v_limit=3000)
    assert c.target is None and c.profile.end.v == -3000
    # from a = 0 the S change lasts exactly Tacc
    assert c.profile.duration == pytest.approx(1.1)
    assert c.spec.max_vel == 3000


# ------------------------------------------------------------------ Table 4-7
TABLE_4_7 = [  # CurrentPos, OK, go back
    (4000, True, False), (4501, False, False), (5000, False, False), (5499, False, False),
    (6000, True, True), (9499, True, True), (9500, False, False), (9999, False, False),
]


@pytest.mark.parametrize("shape", ["T", "S"])
@pytest.mark.parametrize("cur, ok, back", TABLE_4_7)
def test_table_4_7(shape, cur, ok, back):
    # HSL_M_start_ta_move(0, 10000, 0, 1000, 0.5, 1): deceleration 0.5*1000*1 = 500 pulses
    # (the S-curve ramp has the same mean speed, so the same 500 pulses and table)
    spec = MoveSpec(shape, 0, 1000, 0.5, 1)
    plan = spec.plan(10000)
    assert stop_distance(spec, 1000) == pytest.approx(500)
    assert final_decel_start(plan.profile) == pytest.approx(9.75)
    if cur < 9500:
        t = 0.5 + (cur - 250) / 1000  # accel covers 250 pulses in 0.5 s
    else:  # inside the deceleration: solve the position on the profile
        ts = np.linspace(9.75, 10.75, 100001)
        t = float(ts[np.searchsorted(plan.profile.sample(ts).p, cur)])
    assert plan.profile.state_at(t).p == pytest.approx(cur, abs=0.05)
    if not ok:
        with pytest.raises(InfeasibleError):
            change_position(plan.profile, t, spec, 5000)
        return
    c = change_position(plan.profile, t, spec, 5000)
    assert c.reverse == back and c.target == 5000
    assert c.profile.end.p == 5000 and c.profile.end.v == 0
    s = c.profile.sample(np.linspace(0, c.profile.duration, 4000))
    assert np.all(np.abs(s.v) <= 1000 * (1 + REL))
    if back:  # decelerates to a stop (500 pulses past), reverses
        k = max(i for i, lb in enumerate(c.profile.labels) if lb.startswith("stop"))
        assert c.profile.segment_end(k).p == pytest.approx(cur + 500)
        assert np.max(s.p) <= cur + 500 + 1e-6
        assert np.min(s.v) == pytest.approx(-1000)


# ------------------------------------------------------------------ properties
@settings(max_examples=60, deadline=None)
@given(st.sampled_from("TS"), st.floats(0, 500), st.floats(0.01, 1), st.floats(0.01, 1),
       st.floats(0, 0.99), st.floats(-5e4, 5e4), st.floats(0, 1))
def test_change_position_properties(shape, sv, tacc, tdec, frac, new, fvs):
    spec = MoveSpec(shape, sv, 2000, tacc, tdec, fvs * (1000 - sv / 2), 0)
    plan = spec.plan(20000)
    t = frac * final_decel_start(plan.profile)
    st0 = plan.profile.state_at(t)
    assume(abs(new - st0.p) >= stop_distance(spec, st0.v, st0.a) + 1e-6)
    c = change_position(plan.profile, t, spec, new)
    prof = c.profile
    assert prof.end.p == new
    r = spec.rates
    s = prof.sample(np.linspace(0, prof.duration, 3000))
    assert np.all(np.abs(s.v) <= 2000 * (1 + REL))
    assert np.all(np.abs(s.a) <= max(r.accel, r.decel) * (1 + REL))
    assert np.all(np.abs(prof.j[np.isfinite(prof.j)]) <= max(r.jerk_acc, r.jerk_dec) * (1 + REL))
    last = prof.segment_end(prof.n_segments - 1)
    assert last.p == pytest.approx(new, abs=1e-6)
    if not c.reverse:  # one direction only: towards the new target
        toward = 1.0 if new >= st0.p else -1.0
        assert np.all(toward * s.v[s.v != 0] > 0)
        continuous(prof, skip=(0,))


@settings(max_examples=60, deadline=None)
@given(st.sampled_from("TS"), st.floats(0.2, 0.8), st.floats(100, 2e4), st.floats(0.01, 1))
def test_change_speed_properties(shape, frac, new, tacc):
    spec = MoveSpec(shape, 50, 1000, 0.1, 0.2)
    plan = spec.plan(-50000, start=100)
    t = frac * plan.profile.duration
    try:
        c = change_speed(plan.profile, t, spec, new, tacc, target=-49900)
    except InfeasibleError:
        return
    prof = c.profile
    assert prof.end.p == -49900 and prof.end.v == 0
    s = prof.sample(np.linspace(0, prof.duration, 3000))
    assert np.all(s.v <= 1e-9)  # never reverses
    assert np.all(-s.v <= max(new, 1000) * (1 + REL))
    assert c.needed_accel + c.needed_decel <= c.remaining * (1 + 1e-12) + 1e-9
    continuous(prof, skip=(0,))


# ------------------------------------------------------------------ refusals, bad input
def test_refusals_and_bad_input():
    spec = MoveSpec("T", 0, 1000, 0.5, 1)
    prof = spec.plan(10000).profile
    with pytest.raises(InfeasibleError, match="over"):
        change_position(prof, 11.0, spec, 0)
    with pytest.raises(MotionError, match="new_target"):
        change_position(prof, 1.0, spec, 2**28)
    with pytest.raises(MotionError, match="new_vel"):
        change_speed(prof, 1.0, spec, -5, 0.1, target=10000)
    with pytest.raises(MotionError, match="tacc"):
        change_speed(prof, 1.0, spec, 500, 0, target=10000)
    with pytest.raises(MotionError, match="v_limit"):
        change_speed(prof, 1.0, spec, 500, 0.1, v_limit=float("nan"))
    with pytest.raises(MotionError, match="spec"):
        change_speed(prof, 1.0, "T", 500, 0.1)
    with pytest.raises(MotionError, match="t "):
        change_speed(prof, -1.0, spec, 500, 0.1)
    with pytest.raises(InfeasibleError, match="not moving"):
        change_speed(prof, 20.0, spec, 500, 0.1)
    with pytest.raises(MotionError, match="new_vel"):
        change_speed(spec.plan(100).profile, 0.1, MoveSpec("T", 50, 100, 1, 1), 10, 0.1)
