"""Safety: end limits, slow-down, alarm, E-stop, ERC, RDY and io_status, in virtual time."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import with_own_safety
from openmotion.config import AxisConfig, DriveConfig, MachineConfig, SwitchConfig
from openmotion.control import AxisState, Controller
from openmotion.control.guard.safety import IO_STATUS_BITS, Safety, io_status
from openmotion.errors import MotionError
from openmotion.profile.jerk import jerk_limited
from openmotion.profile.pcl import MoveSpec
from openmotion.profile.velocity import stop_distance

S = AxisState
PEL, MEL = 20_000.0, -20_000.0


def machine(logic: str = "no", drive: str = "ideal_stepper") -> MachineConfig:
    """Axis "a": limits at +-20000 pulses (5000 wide); axis "s": a servo, no limits."""
    a = AxisConfig(name="a", lead=10.0, max_speed=500.0,
                   logic={"pel": logic, "mel": logic, "sd": logic},
                   drive=DriveConfig(type=drive),
                   pel=SwitchConfig(position=PEL, width=5000.0),
                   mel=SwitchConfig(position=MEL, width=-5000.0))
    s = AxisConfig(name="s", lead=10.0, max_speed=500.0, drive=DriveConfig(type="servo"))
    return MachineConfig("t", (a, s), 4, 4, 0.001)


def setup(logic: str = "no") -> tuple[Controller, Safety]:
    return with_own_safety(machine(logic))


def start(ax, kind: str, sign: int = 1) -> None:
    """Start a move of `kind` towards +-30000 (past the limit)."""
    d = 30_000.0 * sign
    if kind == "velocity":
        ax.move_velocity(50_000.0 * sign, tacc=0.05)
    elif kind == "relative":
        ax.move_relative(d, max_vel=50_000.0, tacc=0.05)
    elif kind == "absolute":
        ax.move_absolute(d, max_vel=50_000.0, tacc=0.05, shape="S")
    elif kind == "jerk":
        ax.move_jerk_limited(d, v_max=50_000.0, a_max=1e6, j_max=5e7)
    else:
        pr = jerk_limited(d, 50_000.0, 1e6, 5e7, start=ax.position)
        ax.run_profile(pr, stop_accel=1e6, stop_jerk=5e7)


KINDS = ("velocity", "relative", "absolute", "jerk", "profile")


@pytest.mark.parametrize("logic", ["no", "nc"])
@pytest.mark.parametrize("kind", KINDS)
def test_limit_stops_every_motion_kind_immediately(kind: str, logic: str) -> None:
    ctl, safety = setup(logic)
    ax = ctl.axis("a")
    assert not ctl.input_active(0, "pel")
    start(ax, kind)
    assert ctl.run_until(lambda: ax.state is S.ERROR_STOP, 3.0)
    assert ax.fault == "+EL" and ax.motion is None
    rec = safety.last_stop("a")
    assert rec is not None and rec.reason == "+EL"
    # the edge is where the switch starts, at its exact time: pulse 20000 carries the
    # stepper onto it, and that pulse leaves when the plan passes 19999.5 (half-pulse
    # rule); the stop is at most one cycle of travel further (the cycle the edge happened
    # in was already output)
    assert rec.position == pytest.approx(PEL - 0.5, abs=1e-6)
    assert PEL <= ax.position <= PEL + rec.velocity * ctl.period + 1e-6
    assert ctl.time - ctl.period <= rec.time <= ctl.time
    ctl.advance(0.05)
    assert ax.position == pytest.approx(ctl.hardware.command_position(0))
    assert io_status(ctl, "a") >> IO_STATUS_BITS["pel"] & 1


@pytest.mark.parametrize("kind", ["velocity", "relative", "jerk", "profile"])
def test_decelerating_limit_stop_starts_at_the_edge_time(kind: str) -> None:
    ctl, safety = setup()
    safety.set_el("a", "decel")
    ax = ctl.axis("a")
    start(ax, kind)
    assert ctl.run_until(lambda: ax.fault == "+EL", 3.0)
    rec = safety.last_stop("a")
    assert rec is not None and rec.velocity > 0.0
    assert ax.motion is not None and ax.motion.kind == "stop"  # still decelerating
    h = ctl.history
    v_edge = h.state_at(0, rec.time).v
    assert v_edge == pytest.approx(rec.velocity)
    # the plan decelerates from the edge instant on (not from the next cycle)
    assert h.state_at(0, rec.time + 1e-4).v < v_edge
    assert ctl.wait_motion_done(["a"], 2.0)
    assert ax.state is S.ERROR_STOP  # the stop ended, the fault stays
    assert ax.position > PEL
    ctl.advance(0.01)
    # residual of the cycle model: the pulses output equal the plan within a pulse
    assert abs(ctl.hardware.command_position(0) - ax.position) < 1.0


def test_decel_mode_uses_the_moves_deceleration() -> None:
    ctl, safety = setup()
    safety.set_el(0, 1)
    ax = ctl.axis("a")
    ax.move_velocity(50_000.0, tacc=0.05)  # 1e6 pps^2
    ctl.run_until(lambda: ax.fault is not None, 3.0)
    t = safety.last_stop(0).time
    s0, s1 = ctl.history.state_at(0, t + 0.001), ctl.history.state_at(0, t + 0.011)
    assert (s0.v - s1.v) / 0.01 == pytest.approx(1e6, rel=1e-6)


def test_direction_sensitive_move_away_allowed_towards_refused() -> None:
    ctl, safety = setup("nc")
    ax = ctl.axis("a")
    ax.move_velocity(50_000.0, tacc=0.05)
    ctl.run_until(lambda: ax.fault == "+EL", 3.0)
    with pytest.raises(MotionError, match="reset"):
        ax.move_relative(-100.0, max_vel=1000.0)
    ax.reset()  # allowed while the limit is still active
    assert ax.state is S.STANDSTILL and ctl.input_active(0, "pel")
    snap = ax.snapshot()
    for go in (lambda: ax.move_relative(100.0, max_vel=1000.0),
               lambda: ax.move_velocity(1000.0),
               lambda: ax.move_jerk_limited(100.0, v_max=1e3, a_max=1e5, j_max=1e7)):
        with pytest.raises(MotionError, match=r"\+EL is active"):
            go()
        assert ax.snapshot() == snap
    ax.move_relative(-3000.0, max_vel=20_000.0, tacc=0.01)
    assert ctl.wait_motion_done(["a"], 2.0)
    assert ax.state is S.STANDSTILL and not ctl.input_active(0, "pel")


@pytest.mark.parametrize("sensitive", [True, False])
def test_limit_behind_the_motion_stops_only_when_insensitive(sensitive: bool) -> None:
    ctl, safety = setup()
    safety.set_limit_check("a", True, direction_sensitive=sensitive)
    ax = ctl.axis("a")
    ax.move_velocity(-20_000.0, tacc=0.02)
    # a +EL switch appears under the axis while it moves away from it (e.g. a wiring fault)
    sc = ctl.hardware.scenario
    sc.place_switch(0, "pel", -10_000.0, 12_000.0, at=0.1)
    ctl.advance(0.2)
    assert ctl.input_active(0, "pel")
    if sensitive:
        assert ax.state is S.CONTINUOUS_MOTION
    else:
        assert ax.state is S.ERROR_STOP and ax.fault == "+EL"
        assert safety.last_stop(0).time == pytest.approx(0.1)


def test_minus_limit_and_limit_check_disabled() -> None:
    ctl, safety = setup()
    ax = ctl.axis("a")
    ax.move_velocity(-50_000.0, tacc=0.05)
    ctl.run_until(lambda: ax.fault is not None, 3.0)
    assert ax.fault == "-EL" and ax.position <= MEL
    ctl2, safety2 = setup()
    safety2.set_limit_check("a", False)
    ax2 = ctl2.axis("a")
    ax2.move_relative(30_000.0, max_vel=50_000.0, tacc=0.05)
    assert ctl2.wait_motion_done(["a"], 3.0)
    assert ax2.state is S.STANDSTILL and ax2.position == 30_000.0


def test_suspend_lets_homing_use_the_limit_then_resume_stops() -> None:
    ctl, safety = setup()
    ax = ctl.axis("a")
    with safety.suspended("a", "pel"):
        ax.move_velocity(20_000.0, tacc=0.02)
        ctl.run_until(lambda: ctl.input_active(0, "pel"), 3.0)
        ctl.advance(0.05)
        assert ax.state is S.CONTINUOUS_MOTION
        assert "pel" in safety.settings("a").suspended
    assert "pel" not in safety.settings("a").suspended
    ctl.step()  # the level check catches a motion still heading into the active limit
    assert ax.state is S.ERROR_STOP and ax.fault == "+EL"
    safety.suspend("a", "mel")
    safety.resume("a", "mel")
    assert safety.settings("a").suspended == set()


def test_fault_hooks_see_every_axis_stop() -> None:
    ctl, safety = setup()
    seen: list[tuple[str, str]] = []
    safety.on_axis_fault(lambda ax, reason: seen.append((ax.name, reason)))
    ctl.axis("a").move_velocity(50_000.0, tacc=0.05)
    ctl.run_until(lambda: bool(seen), 3.0)
    assert seen == [("a", "+EL")]


def test_servo_alarm_immediate_and_decel_and_refusal() -> None:
    for mode in ("immediate", "decel"):
        ctl, safety = setup()
        safety.set_alm("s", mode)
        ax = ctl.axis("s")
        ax.move_velocity(20_000.0, tacc=0.1)
        ctl.hardware.scenario.trip_alarm(1, at=0.2)
        ctl.advance(0.2005)
        assert ax.state is S.ERROR_STOP and ax.fault == "servo alarm"
        assert (ax.motion is not None) == (mode == "decel")
        rec = safety.last_stop("s")
        assert rec.time == pytest.approx(0.2) and rec.reason == "servo alarm"
        if mode == "decel":
            assert ctl.history.state_at(1, 0.2005).v < ctl.history.state_at(1, 0.2).v
        ctl.wait_motion_done(["s"], 1.0)
        with pytest.raises(MotionError, match="alarm"):
            ax.reset()
        assert io_status(ctl, "s") >> IO_STATUS_BITS["alm"] & 1
        ctl.hardware.scenario.clear_alarm(1)
        ctl.step()
        ax.reset()
        ax.move_relative(100.0, max_vel=1000.0)  # motion allowed again
        assert ctl.wait_motion_done(["s"], 1.0)


def test_motion_refused_while_alarm_active_without_fault() -> None:
    ctl, safety = setup()
    ax = ctl.axis("s")
    ctl.hardware.scenario.trip_alarm(1)
    ctl.step()
    ax._state = S.STANDSTILL  # as if reset had been forced: the motion check still refuses
    with pytest.raises(MotionError, match="ALM"):
        ax.move_velocity(1000.0)


def test_estop_stops_every_axis_and_refuses_motion_until_released_and_reset() -> None:
    ctl, safety = setup()
    safety.set_erc("s", 0.003)
    a, s = ctl.axis("a"), ctl.axis("s")
    a.move_velocity(10_000.0, tacc=0.05)
    s.move_velocity(-10_000.0, tacc=0.05)
    ctl.hardware.scenario.press_estop(at=0.1)
    ctl.advance(0.1005)
    assert a.state is S.ERROR_STOP and s.state is S.ERROR_STOP
    assert a.fault == s.fault == "emergency stop"
    assert ctl.hardware.read_output(1, "erc")  # ERC pulse on the E-stop
    assert io_status(ctl, "a") >> IO_STATUS_BITS["emg"] & 1
    for go in (a.reset, lambda: a.move_velocity(100.0)):
        with pytest.raises(MotionError, match="emergency|ErrorStop"):
            go()
    ctl.advance(0.004)
    assert not ctl.hardware.read_output(1, "erc")
    ctl.hardware.scenario.release_estop()
    ctl.step()
    a.reset()
    a.move_relative(50.0, max_vel=1000.0)
    assert ctl.wait_motion_done(["a"], 1.0) and a.position == pytest.approx(a.position)


def test_erc_pulse_width_on_limit_and_after_a_decelerating_stop() -> None:
    ctl, safety = setup()
    safety.set_erc("a", 0.005)
    ax = ctl.axis("a")
    ax.move_velocity(50_000.0, tacc=0.05)
    ctl.run_until(lambda: ax.fault is not None, 3.0)
    hw = ctl.hardware
    assert hw.read_output(0, "erc")
    t_on = ctl.time
    ctl.run_until(lambda: not hw.read_output(0, "erc"), 0.1)
    assert ctl.time - t_on == pytest.approx(0.005, abs=1.01e-3)
    # decelerating stop: the pulse comes when the stop ends
    ctl2, safety2 = setup()
    safety2.set_el("a", "decel")
    safety2.set_erc("a", 0.002)
    ax2 = ctl2.axis("a")
    ax2.move_velocity(50_000.0, tacc=0.05)
    ctl2.run_until(lambda: ax2.fault is not None, 3.0)
    assert not ctl2.hardware.read_output(0, "erc")
    ctl2.run_until(lambda: ax2.motion is None, 1.0)
    ctl2.step()
    assert ctl2.hardware.read_output(0, "erc")
    safety2.pulse_erc("a", 0.001)  # home completion
    with pytest.raises(MotionError, match="width"):
        safety.pulse_erc("s")


def test_sd_level_slows_to_strvel_and_recovers() -> None:
    ctl, safety = setup()
    safety.set_sd("a", True)
    ax = ctl.axis("a")
    ctl.hardware.scenario.place_switch(0, "sd", 5000.0, 3000.0)
    ax.move_velocity(20_000.0, str_vel=2000.0, tacc=0.02)
    ctl.run_until(lambda: ctl.input_active(0, "sd"), 1.0)
    ctl.advance(0.05)
    assert ax.speed == pytest.approx(2000.0)
    assert io_status(ctl, "a") >> IO_STATUS_BITS["sd"] & 1
    ctl.run_until(lambda: not ctl.input_active(0, "sd"), 3.0)
    ctl.advance(0.05)
    assert ax.speed == pytest.approx(20_000.0)


def test_sd_latched_holds_strvel_until_the_move_ends() -> None:
    ctl, safety = setup("nc")
    safety.set_sd("a", True, latched=True)
    ax = ctl.axis("a")
    ctl.hardware.scenario.place_switch(0, "sd", 2000.0, 500.0)
    ax.move_relative(12_000.0, max_vel=20_000.0, str_vel=1000.0, tacc=0.02)
    ctl.run_until(lambda: ax.position > 3000.0, 1.0)
    ctl.advance(0.05)
    assert not ctl.input_active(0, "sd")
    assert ax.speed == pytest.approx(1000.0)
    assert ctl.wait_motion_done(["a"], 15.0) and ax.position == 12_000.0
    # SD disabled: no slow-down
    safety.set_sd("a", False)
    ax.move_relative(-12_000.0, max_vel=20_000.0, str_vel=1000.0, tacc=0.02)
    ctl.run_until(lambda: ctl.input_active(0, "sd"), 2.0)
    ctl.advance(0.005)
    assert ax.speed == pytest.approx(20_000.0)


def test_sd_without_strvel_makes_a_decelerating_stop() -> None:
    ctl, safety = setup()
    safety.set_sd("a", True)
    ax = ctl.axis("a")
    ctl.hardware.scenario.place_switch(0, "sd", 1000.0, 30_000.0)
    ax.move_jerk_limited(15_000.0, v_max=20_000.0, a_max=1e6, j_max=5e7)
    ctl.run_until(lambda: ctl.input_active(0, "sd"), 1.0)
    ctl.step()
    assert ax.state is S.STOPPING
    assert ctl.wait_motion_done(["a"], 1.0) and ax.position < 15_000.0


def test_sd_mode_stop_slows_down_and_stops_without_a_fault() -> None:
    """HSL sd_mode 1: SD active makes a decelerating stop (not a slow run at StrVel)."""
    ctl, safety = setup()
    safety.set_sd("a", True, stop=True)
    assert safety.settings("a").sd_stop
    ax = ctl.axis("a")
    ctl.hardware.scenario.place_switch(0, "sd", 5000.0, 30_000.0)
    ax.move_relative(20_000.0, max_vel=20_000.0, str_vel=2000.0, tacc=0.02)
    ctl.run_until(lambda: ctl.input_active(0, "sd"), 1.0)
    ctl.step()
    assert ax.state is S.STOPPING
    assert ctl.wait_motion_done(["a"], 1.0)
    assert 5000.0 < ax.position < 20_000.0 and ax.fault is None and ax.speed == 0.0
    with pytest.raises(MotionError, match="stop"):
        safety.set_sd("a", True, stop=1)  # type: ignore[arg-type]
    assert safety.settings("a").sd_stop  # unchanged by the refusal


def test_rdy_check_svon_and_io_status_bits() -> None:
    ctl, safety = setup()
    s = ctl.axis("s")
    w = io_status(ctl, "s")
    assert w >> IO_STATUS_BITS["svon"] & 1
    safety.set_servo("s", False)
    assert not io_status(ctl, "s") >> IO_STATUS_BITS["svon"] & 1
    safety.set_servo("s", True)
    ctl.step()
    safety.set_rdy_check("s", True)
    s.move_velocity(1000.0)
    ctl.step()
    assert io_status(ctl, "s") >> IO_STATUS_BITS["dir"] & 1
    s.stop_immediately()
    # RDY required: while the drive is not ready, motion is refused
    ctl.hardware.write_output(1, "svon", False)
    ctl.step()
    assert not ctl.input_active(1, "rdy")
    with pytest.raises(MotionError, match="RDY"):
        s.move_velocity(1000.0)
    assert safety.io_status("s") == io_status(ctl, 1)


def test_inp_wait_through_safety() -> None:
    ctl, safety = setup()
    s = ctl.axis("s")
    safety.set_inp("s", True)
    s.move_relative(2000.0, max_vel=40_000.0, tacc=0.01)
    ctl.run_until(lambda: s.motion is None, 1.0)
    assert s.motion_done in (0, 14)
    assert ctl.wait_motion_done(["s"], 1.0)
    assert ctl.input_active(1, "inp")


@pytest.mark.parametrize("call, match", [
    (lambda sf: sf.set_el("a", "fast"), "mode"),
    (lambda sf: sf.set_el("a", True), "mode"),
    (lambda sf: sf.set_alm("a", 2), "mode"),
    (lambda sf: sf.set_erc("a", -1.0), "width"),
    (lambda sf: sf.set_erc("a", float("nan")), "width"),
    (lambda sf: sf.set_sd("a", 1), "enabled"),
    (lambda sf: sf.set_limit_check("a", True, direction_sensitive="yes"), "direction"),
    (lambda sf: sf.suspend("a", "org"), "signal"),
    (lambda sf: sf.set_rdy_check("zz", True), "axis"),
    (lambda sf: Safety(sf.ctl), "already"),
])
def test_bad_settings_are_refused_and_change_nothing(call, match) -> None:
    ctl, safety = setup()
    before = [safety.settings(i) for i in range(2)]
    with pytest.raises(MotionError, match=match):
        call(safety)
    assert [safety.settings(i) for i in range(2)] == before


def test_detach_removes_the_reactions() -> None:
    ctl, safety = setup()
    safety.detach()
    ax = ctl.axis("a")
    ax.move_relative(30_000.0, max_vel=50_000.0, tacc=0.05)
    assert ctl.wait_motion_done(["a"], 3.0) and ax.state is S.STANDSTILL
    Safety(ctl)  # may be attached again


@settings(max_examples=15, deadline=None)
@given(speed=st.floats(1e3, 3e5), tacc=st.floats(0.005, 0.2), shape=st.sampled_from("TS"),
       strv=st.floats(0.0, 0.3), reach=st.floats(0.02, 0.3), decel=st.booleans())
def test_limit_stop_residuals_over_speeds(speed, tacc, shape, strv, reach, decel) -> None:
    """Immediate: at most one cycle of travel past the edge. Decelerating: the stop is
    planned from the edge instant (it ends exactly one stopping distance after the edge
    state) and the pulse output matches the plan within a pulse."""
    ctl, safety = setup()
    safety.set_el("a", "decel" if decel else "immediate")
    where = 200.5 + speed * reach
    ctl.hardware.scenario.place_switch(0, "pel", where, 1e7)
    ax = ctl.axis("a")
    ax.move_velocity(speed, str_vel=strv * speed, tacc=tacc, shape=shape)
    assert ctl.run_until(lambda: ax.fault is not None, 5.0)
    rec = safety.last_stop("a")
    # a stepper reaches the switch on pulse ceil(where), which leaves half a pulse before
    # (the edge instant is a root of the cycle's cubic, found to ~1e-11 s: at 3e5 pps
    # that is a few 1e-6 pulse)
    assert rec.position == pytest.approx(math.ceil(where) - 0.5, abs=1e-5)
    ctl.run_until(lambda: ax.motion is None, 5.0)
    ctl.step()
    assert abs(ctl.hardware.command_position(0) - ax.position) < 1.0
    if decel:
        st0 = ctl.history.state_at(0, rec.time)
        spec = MoveSpec(shape, strv * speed, speed, tacc, tacc, 0.0, 0.0)
        assert ax.position == pytest.approx(st0.p + stop_distance(spec, st0.v, st0.a),
                                            abs=1e-6)
    else:
        assert rec.position <= ax.position <= rec.position + speed * ctl.period + 1e-6


def test_a_group_engine_stops_its_other_axes_through_the_fault_hook() -> None:
    ctl, safety = setup()
    a, s = ctl.axis("a"), ctl.axis("s")

    def group_stop(ax, reason):  # what an interpolating group would do
        if ax is a and s.motion is not None:
            s.fault_stop(f"group: {reason}", decelerate=True)

    safety.on_axis_fault(group_stop)
    a.move_velocity(50_000.0, tacc=0.05)
    s.move_velocity(20_000.0, tacc=0.05)
    ctl.run_until(lambda: a.fault is not None, 3.0)
    assert s.state is S.ERROR_STOP and s.fault == "group: +EL"
    assert ctl.wait_motion_done(timeout=1.0)


def test_a_limit_cuts_short_another_faults_deceleration() -> None:
    ctl, safety = setup()
    ax = ctl.axis("a")
    ax.move_velocity(50_000.0, tacc=0.05)
    ctl.run_until(lambda: ax.position > PEL - 1000.0, 2.0)
    ax.fault_stop("test fault", decelerate=True)  # 1250 pulses to stop: past the limit
    ctl.run_until(lambda: ax.motion is None, 1.0)
    assert ax.fault == "+EL"
    assert ax.position <= PEL + 50_000.0 * ctl.period + 1e-6


@pytest.mark.parametrize("jumps", [False, True])
def test_rdy_lost_while_moving_stops_the_same_way_cycle_by_cycle_and_jumping(jumps) -> None:
    """The RDY edge wakes a jump (Safety's edge hook lists "rdy"): with virtual time
    jumping, the axis stops at the same cycle and position as cycle by cycle."""
    results = []
    for jump in (False, jumps):
        ctl, safety = setup()
        ctl.virtual_jumps = jump
        s = ctl.axis("s")
        safety.set_rdy_check("s", True)
        ctl.step()
        s.move_relative(40_000.0, max_vel=20_000.0, tacc=0.05)
        ctl.hardware.scenario.set_drive_ready(s.index, False, at=ctl.time + 0.3004)
        ctl.advance(1.0)
        assert s.fault == "drive not ready"
        results.append((s.position, [e.time for e in ctl.events.events("fault")]))
    assert results[0] == results[1]
