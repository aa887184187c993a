"""Comparators 3 (step loss on the error counter) and 4 (general, with actions)."""

from __future__ import annotations

import pytest

from helpers import with_own_safety
from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.control import AxisState, Controller
from openmotion.control.guard.safety import Safety
from openmotion.errors import MotionError

S = AxisState


def setup(drive: DriveConfig | None = None) -> tuple[Controller, Safety]:
    ax = AxisConfig(name="a", lead=10.0, max_speed=1000.0, drive=drive or DriveConfig())
    return with_own_safety(MachineConfig("t", (ax,), 0, 0, 0.001))


@pytest.mark.parametrize("lost, tol, detected", [(50, 10, True), (50, 60, False),
                                                 (-30, 20, True)])
def test_injected_step_loss_is_detected_beyond_the_tolerance(lost, tol, detected) -> None:
    ctl, safety = setup()
    safety.cmp.set_error_counter_check("a", tol, True)
    ax = ctl.axis("a")
    ax.move_velocity(20_000.0, tacc=0.02)
    ctl.hardware.scenario.inject_step_loss(0, lost, at=0.1)
    ctl.advance(0.2)
    assert abs(ax.counters.error) == pytest.approx(abs(lost), abs=1)
    if detected:
        assert ax.state is S.ERROR_STOP and ax.fault == "step loss"
        ev = safety.cmp.events[-1]
        assert ev.comparator == "error_check" and ev.time == pytest.approx(0.1, abs=1.01e-3)
        assert safety.last_stop("a").reason == "step loss"
    else:
        assert ax.state is S.CONTINUOUS_MOTION and not safety.cmp.events


def test_pull_out_stepper_loses_steps_and_is_stopped() -> None:
    ctl, safety = setup(DriveConfig(type="stepper", pullout_speed=30_000.0,
                                    pullout_accel=1e6))
    safety.cmp.set_error_counter_check(0, 100, True)
    ax = ctl.axis(0)
    ax.move_relative(200_000.0, max_vel=60_000.0, tacc=0.05)
    ctl.run_until(lambda: ax.state is S.ERROR_STOP, 5.0)
    assert ax.fault == "step loss"
    assert ctl.hardware.steps_lost(0) > 100
    assert ax.position < 200_000.0


def test_error_check_rearms_after_reset_and_can_be_switched_off() -> None:
    ctl, safety = setup()
    safety.cmp.set_error_counter_check(0, 5, True)
    ax = ctl.axis(0)
    ctl.hardware.scenario.inject_step_loss(0, 20)
    ctl.step()
    assert ax.fault == "step loss" and len(safety.cmp.events) == 1
    ctl.advance(0.01)
    assert len(safety.cmp.events) == 1  # one-shot while the error stays
    ax.counters.reset_error()
    ax.reset()
    ctl.step()
    ctl.hardware.scenario.inject_step_loss(0, 20)
    ctl.step()
    assert len(safety.cmp.events) == 2
    safety.cmp.set_error_counter_check(0, 5, False)
    ax.counters.reset_error()
    ax.reset()
    ctl.hardware.scenario.inject_step_loss(0, 20)
    ctl.advance(0.01)
    assert ax.state is S.STANDSTILL and len(safety.cmp.events) == 2


def test_general_comparator_on_command_gives_the_exact_crossing_time() -> None:
    ctl, safety = setup()
    seen = []
    safety.cmp.on_event(seen.append)
    ax = ctl.axis(0)
    ax.move_velocity(10_000.0, tacc=0.01)  # reaches 50 pulses at 0.01 s, then 10 pulses/ms
    safety.cmp.set_general_comparator(0, "command", "=", "event", 1234.5)
    ctl.advance(0.2)
    assert len(seen) == 1 and seen[0] is safety.cmp.events[0]
    assert seen[0].time == pytest.approx(0.01 + (1234.5 - 50.0) / 10_000.0, abs=1e-9)
    assert ax.state is S.CONTINUOUS_MOTION
    assert safety.cmp.general_comparator(0) is None  # one-shot


@pytest.mark.parametrize("action, state", [("stop", S.STANDSTILL), ("slow_stop", S.STOPPING)])
def test_general_comparator_stop_actions(action, state) -> None:
    ctl, safety = setup()
    ax = ctl.axis(0)
    safety.cmp.set_general_comparator(0, "command", ">", action, 2000.0)
    ax.move_velocity(10_000.0, tacc=0.01)
    ctl.run_until(lambda: bool(safety.cmp.events), 1.0)
    assert ax.state is state
    assert 2000.0 <= ax.position <= 2000.0 + 10_000.0 * ctl.period + 1e-9
    assert ctl.wait_motion_done(timeout=1.0)


def test_cmp_v_change_changes_speed_when_the_comparator_fires() -> None:
    ctl, safety = setup()
    ax = ctl.axis(0)
    with pytest.raises(MotionError, match="cmp_v_change"):
        safety.cmp.set_general_comparator(0, "feedback", ">", "change_speed", 3000.0)
    safety.cmp.cmp_v_change(0, 4000.0, 0.02)
    safety.cmp.set_general_comparator(0, "feedback", ">", "change_speed", 3000.0)
    ax.move_velocity(10_000.0, tacc=0.01)
    ctl.run_until(lambda: bool(safety.cmp.events), 1.0)
    ctl.advance(0.05)
    assert ax.speed == pytest.approx(4000.0)
    ev = safety.cmp.events[0]
    assert ev.action == "change_speed" and ev.value > 3000.0 and ev.note == ""


def test_change_speed_action_refused_is_reported_in_the_event() -> None:
    ctl, safety = setup()
    ax = ctl.axis(0)
    safety.cmp.cmp_v_change(0, 9e5, 0.02)  # above the move's MaxVel: refused by change_speed
    safety.cmp.set_general_comparator(0, "command", ">", "change_speed", 500.0)
    ax.move_velocity(10_000.0, tacc=0.01)
    ctl.run_until(lambda: bool(safety.cmp.events), 1.0)
    assert "refused" in safety.cmp.events[0].note
    assert ax.speed == pytest.approx(10_000.0)


def test_general_comparator_on_the_error_and_general_counters() -> None:
    ctl, safety = setup()
    ax = ctl.axis(0)
    safety.cmp.set_general_comparator(0, "error", "<", "event", -5.0)
    ctl.hardware.scenario.inject_step_loss(0, -10)  # motor ahead: error -10
    ctl.step()
    assert safety.cmp.events[-1].value == -10.0
    ax.counters.set_general(0, "command")
    safety.cmp.set_general_comparator(0, "general", "=", "event", 300.0)
    ax.move_relative(1000.0, max_vel=20_000.0, tacc=0.01)
    assert ctl.wait_motion_done(timeout=1.0)
    assert safety.cmp.events[-1].comparator == "general"
    assert safety.cmp.events[-1].value >= 300.0


@pytest.mark.parametrize("call, match", [
    (lambda c: c.set_error_counter_check(0, -1, True), "tolerance"),
    (lambda c: c.set_error_counter_check(0, 1.5, True), "tolerance"),
    (lambda c: c.set_error_counter_check(0, 3, 1), "on"),
    (lambda c: c.set_general_comparator(0, "speed", "=", "event", 1.0), "source"),
    (lambda c: c.set_general_comparator(0, "command", ">=", "event", 1.0), "method"),
    (lambda c: c.set_general_comparator(0, "command", "=", "beep", 1.0), "action"),
    (lambda c: c.set_general_comparator(0, "command", "=", "event", float("nan")), "data"),
    (lambda c: c.cmp_v_change(0, 0.0, 0.1), "new_vel"),
    (lambda c: c.cmp_v_change(0, 100.0, 0.0), "tacc"),
    (lambda c: c.on_event(3), "callable"),
])
def test_bad_comparator_settings_are_refused(call, match) -> None:
    ctl, safety = setup()
    with pytest.raises(MotionError, match=match):
        call(safety.cmp)
    assert safety.cmp.general_comparator(0) is None
