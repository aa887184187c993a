"""Single-axis motion in virtual time: exact end counts, planned durations, stops, states."""


import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.control import AxisState, Controller, MotionDone
from openmotion.errors import MotionError
from openmotion.profile.pcl import MoveSpec

S = AxisState


@pytest.fixture
def ctl():
    c = Controller(safety=False)
    c.enable_all()
    return c


def run_move(c, ax, timeout=30.0):
    t0 = c.time
    assert c.run_until(lambda: ax.motion_done == 0, timeout, event_driven=True)
    return c.time - t0


@given(
    distance=st.integers(-200_000, 200_000).filter(lambda d: d != 0),
    str_vel=st.floats(0, 2000),
    max_vel=st.floats(5_000, 200_000),
    tacc=st.floats(0.005, 0.3),
    tdec=st.floats(0.005, 0.3),
    shape=st.sampled_from("TS"),
)
@settings(max_examples=25, deadline=None)
def test_relative_move_ends_exactly_in_planned_time(distance, str_vel, max_vel, tacc, tdec,
                                                     shape):
    c = Controller(safety=False)
    c.enable_all()
    ax = c.axis("x")
    ax.counters.set_command(1234)
    spec = MoveSpec(shape, str_vel, max_vel, tacc, tdec)
    planned = spec.plan(distance).profile.duration
    ax.move_relative(distance, str_vel=str_vel, max_vel=max_vel, tacc=tacc, tdec=tdec,
                     shape=shape)
    assert ax.state is S.DISCRETE_MOTION
    took = run_move(c, ax, planned + 1.0)
    assert ax.counters.command == 1234 + distance
    assert ax.counters.feedback == distance  # ideal stepper, move ratio 1
    assert ax.counters.error == 0
    assert ax.state is S.STANDSTILL and ax.speed == 0.0
    # done at the first cycle end at or after the planned duration
    assert planned - 1e-9 <= took <= planned + c.period + 1e-9
    assert ax.counters.target == distance


def test_commanded_velocity_never_exceeds_max(ctl):
    ax = ctl.axis("y")
    ax.move_relative(50_000, max_vel=40_000, str_vel=500, tacc=0.05, tdec=0.08, shape="S",
                     vs_acc=5000, vs_dec=5000)
    speeds = []
    while ax.motion_done:
        ctl.step()
        speeds.append(ax.speed)
    assert max(speeds) <= 40_000 * (1 + 1e-9)
    assert ax.counters.command == 50_000


def test_absolute_move_uses_feedback_through_move_ratio(ctl):
    ax = ctl.axis("x")
    ax.move_relative(3000, max_vel=50_000, tacc=0.01)
    run_move(ctl, ax)
    # a stepper that slipped 40 pulses: feedback says 2960, command says 3000
    ctl.hardware.scenario.inject_step_loss(0, 40)
    ctl.step()
    assert ax.counters.error == 40
    ax.move_absolute(5000, max_vel=50_000, tacc=0.01)
    assert ax.motion.target == 5040  # distance = 5000 - feedback 2960
    run_move(ctl, ax)
    assert ax.counters.feedback == 5000
    assert ax.counters.command == 5040
    assert ax.counters.target == 5000


def test_absolute_move_with_move_ratio():
    from dataclasses import replace

    from openmotion.config import default_machine

    m = default_machine()
    # encoder with 2.5 feedback counts per command pulse (HSL 4.6 example ratio)
    x = replace(m.axes[0], encoder_lines_per_rev=6250, move_ratio=2.5)
    c = Controller(m.with_axis(x), safety=False)
    c.enable_all()
    ax = c.axis("x")
    ax.move_absolute(8000, max_vel=100_000, tacc=0.02)
    run_move(c, ax)
    assert ax.counters.command == 8000
    assert ax.counters.feedback == 20_000
    assert ax.counters.error == 0
    ax.move_absolute(4000, max_vel=100_000, tacc=0.02)
    run_move(c, ax)
    assert ax.counters.command == 4000 and ax.counters.feedback == 10_000


def test_velocity_mode_signed_and_change_speed(ctl):
    ax = ctl.axis("x")
    ax.fix_speed_range(50_000)
    ax.move_velocity(-20_000, str_vel=100, tacc=0.1)
    assert ax.state is S.CONTINUOUS_MOTION
    ctl.advance(0.3)
    assert ax.velocity == pytest.approx(-20_000)
    assert ax.motion_done == MotionDone.AT_MAXVEL
    ax.change_speed(40_000, 0.1)
    ctl.advance(0.05)
    assert ax.motion_done == MotionDone.ACCELERATING
    ctl.advance(0.2)
    assert ax.velocity == pytest.approx(-40_000)
    ax.stop()
    assert ax.state is S.STOPPING
    ctl.advance(0.01)
    assert ax.motion_done == MotionDone.DECELERATING
    assert run_move(ctl, ax) < 1.0
    assert ax.state is S.STANDSTILL and ax.velocity == 0.0
    assert ax.counters.command == ax.counters.feedback


def test_velocity_mode_s_curve(ctl):
    ax = ctl.axis("z")
    ax.move_velocity(30_000, shape="S", tacc=0.2)
    ctl.advance(0.1)
    assert ax.motion_done == MotionDone.ACCELERATING
    ctl.advance(0.15)
    assert ax.velocity == pytest.approx(30_000)
    ax.stop_immediately()
    assert ax.state is S.STANDSTILL and ax.motion_done == 0


def test_motion_done_codes_through_a_move(ctl):
    ax = ctl.axis("x")
    ax.move_relative(2000, str_vel=200, max_vel=10_000, tacc=0.05, tdec=0.05)
    seen = []
    while ax.motion_done:
        code = ax.motion_done
        if not seen or seen[-1] != code:
            seen.append(code)
        ctl.step()
    assert seen == [MotionDone.ACCELERATING, MotionDone.AT_MAXVEL, MotionDone.DECELERATING]


# -- stops in every motion state ---------------------------------------------------------
PHASES = {"accelerating": 0.05, "cruising": 0.3, "decelerating": 0.55}


@pytest.mark.parametrize("shape", "TS")
@pytest.mark.parametrize("phase", list(PHASES))
@pytest.mark.parametrize("kind", ["decel", "immediate"])
def test_stop_in_every_phase(ctl, shape, phase, kind):
    ax = ctl.axis("x")
    # 0.1 s accel, 0.4 s cruise at 20000 pps, 0.1 s decel: 10000 pulses
    ax.move_relative(10_000, max_vel=20_000, tacc=0.1, tdec=0.1, shape=shape)
    ctl.advance(PHASES[phase])
    v_before = ax.speed
    assert v_before > 0
    if kind == "decel":
        ax.stop()
        assert ax.state is S.STOPPING
        with pytest.raises(ValueError, match="stopping"):
            ax.move_relative(10, max_vel=100)
        speeds = []
        while ax.motion_done:
            ctl.step()
            speeds.append(ax.speed)
        # a T stop never speeds up; an S stop while accelerating first brings the
        # acceleration to zero at the move's jerk, which may reach (never pass) MaxVel
        assert max(speeds) <= (v_before if shape == "T" else 20_000) * (1 + 1e-9)
        assert len(speeds) * ctl.period <= 0.15 + 2 * ctl.period
    else:
        ax.stop_immediately()
    assert ax.state is S.STANDSTILL and ax.speed == 0.0 and ax.motion_done == 0
    ctl.advance(0.01)
    assert ax.counters.command == ax.counters.feedback
    assert 0 < ax.counters.command <= 10_000
    # the axis moves again and ends exactly
    expected = round(ax.position - 500)  # a stop may end between two counts
    ax.move_relative(-500, max_vel=20_000, tacc=0.01)
    run_move(ctl, ax)
    assert ax.counters.command == expected
    assert ax.position == expected


def test_stop_during_velocity_mode_and_at_rest(ctl):
    ax = ctl.axis("u")
    ax.stop()  # at rest: nothing happens
    assert ax.state is S.STANDSTILL
    ax.move_velocity(5000, tacc=0.05)
    ctl.advance(0.02)
    ax.stop(tdec=0.2)  # 5000 pps -> 0 in 0.2 s: from 2000 pps it takes 0.08 s
    ctl.advance(0.05)
    assert ax.state is S.STOPPING
    run_move(ctl, ax)
    assert ax.state is S.STANDSTILL
    # an immediate stop also ends a decelerating stop
    ax.move_velocity(-5000, tacc=0.05)
    ctl.advance(0.1)
    ax.stop()
    ctl.advance(0.01)
    assert ax.state is S.STOPPING
    ax.stop_immediately()
    assert ax.state is S.STANDSTILL and ax.motion_done == 0
    p = ax.counters.command
    ctl.advance(0.05)
    assert ax.counters.command == p


def test_jerk_limited_move(ctl):
    from openmotion.profile.jerk import jerk_limited_duration

    ax = ctl.axis("y")
    ax.move_jerk_limited(30_000, v_max=50_000, a_max=400_000, j_max=8e6)
    planned = jerk_limited_duration(30_000, 50_000, 400_000, 8e6)
    took = run_move(ctl, ax)
    assert ax.counters.command == 30_000
    assert planned - 1e-9 <= took <= planned + ctl.period + 1e-9


def test_units_wrapper(ctl):
    ax = ctl.axis("x")  # 1000 pulses/mm
    ax.move_relative(2.5, max_vel=100.0, tacc=0.01, units=True)
    run_move(ctl, ax)
    assert ax.counters.command == 2500
    ax.move_absolute(-1.0, max_vel=100.0, tacc=0.01, units=True)
    run_move(ctl, ax)
    assert ax.counters.command == -1000
    assert ax.units.to_units(ax.position) == pytest.approx(-1.0)


def test_units_velocity_mode_on_a_reversed_axis():
    from dataclasses import replace

    from openmotion.config import default_machine

    m = default_machine()
    c = Controller(m.with_axis(replace(m.axes[0], reverse=True)), safety=False)
    c.enable_all()
    ax = c.axis("x")
    ax.move_velocity(10.0, tacc=0.01, units=True)  # +10 mm/s = -10000 pps
    c.advance(0.05)
    assert ax.velocity == pytest.approx(-10_000)
    ax.stop_immediately()


def test_setting_counters_mid_move_does_not_disturb_motion(ctl):
    ax = ctl.axis("x")
    ax.move_relative(6000, max_vel=20_000, tacc=0.05)
    ctl.advance(0.1)
    profile = ax.motion.profile
    ax.counters.set_command(-5)
    ax.counters.set_feedback(77)
    ax.counters.set_general(3, source="command")
    assert ax.motion.profile is profile
    err = ax.counters.error
    run_move(ctl, ax)
    assert ctl.hardware.read_axis(0).pulses_out == 6000
    assert ax.counters.error == err == 0
    assert ax.counters.feedback - ax.counters.command == 82
    assert ax.counters.general - ax.counters.command == 8


def test_28bit_wrap_during_a_move(ctl):
    ax = ctl.axis("x")
    ax.counters.set_command(2**27 - 100)
    ax.counters.set_feedback(2**27 - 100)
    ax.move_relative(300, max_vel=10_000, tacc=0.01)
    run_move(ctl, ax)
    assert ax.counters.command == -(2**27) + 200
    assert ax.counters.feedback == -(2**27) + 200
    assert ax.counters.error == 0
    ax.move_relative(-300, max_vel=10_000, tacc=0.01)
    run_move(ctl, ax)
    assert ax.counters.command == 2**27 - 100


@given(
    distance=st.integers(-100_000, 100_000).filter(lambda d: abs(d) > 100),
    max_vel=st.floats(5_000, 100_000),
    tacc=st.floats(0.01, 0.2),
    shape=st.sampled_from("TS"),
    frac=st.floats(0.0, 1.0),
    immediate=st.booleans(),
)
@settings(max_examples=25, deadline=None)
def test_stop_at_any_time_property(distance, max_vel, tacc, shape, frac, immediate):
    c = Controller(safety=False)
    c.enable_all()
    ax = c.axis("x")
    ax.move_relative(distance, max_vel=max_vel, tacc=tacc, shape=shape)
    c.advance(frac * ax.motion.profile.duration)
    if ax.motion_done == 0:
        return
    at = ax.position
    if immediate:
        ax.stop_immediately()
    else:
        ax.stop()
    top = 0.0
    while ax.motion_done:
        c.step()
        top = max(top, ax.speed)
    assert top <= max_vel * (1 + 1e-9)
    assert ax.state is S.STANDSTILL
    end = ax.position
    sgn = 1 if distance > 0 else -1
    assert sgn * (end - at) >= -1e-6  # never backs up
    assert sgn * (end - distance) <= 1e-6  # never passes the target
    c.step()
    assert ax.counters.command == ax.counters.feedback


def test_run_profile_executes_an_external_profile(ctl):
    from openmotion.profile.jerk import jerk_limited

    ax = ctl.axis("x")
    ax.counters.set_command(100)
    prof = jerk_limited(5000, 40_000, 400_000, 8e6, start=100.0)
    before = ax.snapshot()
    with pytest.raises(MotionError, match="start at the axis position"):
        ax.run_profile(jerk_limited(5000, 40_000, 400_000, 8e6), stop_accel=1e5, stop_jerk=1e7)
    with pytest.raises(MotionError, match="stop_accel"):
        ax.run_profile(prof, stop_accel=0, stop_jerk=1e7)
    assert ax.snapshot() == before
    ax.run_profile(prof, stop_accel=400_000, stop_jerk=8e6)
    assert ax.state is S.DISCRETE_MOTION
    run_move(ctl, ax)
    assert ax.counters.command == 5100 and ax.state is S.STANDSTILL
    # replace a running external profile mid-way, then stop it
    ax.run_profile(jerk_limited(-5000, 40_000, 400_000, 8e6, start=5100.0),
                   stop_accel=400_000, stop_jerk=8e6)
    ctl.advance(0.1)
    st = ax.motion.profile.state_at(ctl.time - ax.motion.t_start)
    p_cmd = ax.position
    from openmotion.profile.retarget import retarget

    new = retarget(type(st)(p_cmd, st.v, st.a), -20_000.0, 40_000, 400_000, 8e6)
    ax.run_profile(new, stop_accel=400_000, stop_jerk=8e6, replace_running=True)
    ctl.advance(0.05)
    ax.stop()
    assert ax.state is S.STOPPING
    run_move(ctl, ax)
    assert ax.state is S.STANDSTILL and -20_000 < ax.counters.command < 5100
    assert ax.speed == 0.0
