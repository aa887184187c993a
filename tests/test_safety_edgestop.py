"""Hardware edge stops: the pulse output ends at the exact EL / ALM / EMG edge time (as a
PCL6045 does), and the controller's command position and history agree."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, DriveConfig, MachineConfig, SwitchConfig
from openmotion.control import AxisState, Controller
from openmotion.control.guard.safety import Safety
from openmotion.errors import MotionError

PEL, MEL = 20_000.0, -20_000.0


def machine(logic: str = "no") -> MachineConfig:
    axes = tuple(AxisConfig(name=n, lead=10.0, max_speed=500.0,
                            logic={"pel": logic, "mel": logic},
                            drive=DriveConfig(type="ideal_stepper"),
                            pel=SwitchConfig(position=PEL, width=5000.0),
                            mel=SwitchConfig(position=MEL, width=-5000.0))
                 for n in ("a", "b"))
    return MachineConfig("t", axes, 4, 4, 0.001)


def setup(logic: str = "no", edge_stop: bool = True) -> tuple[Controller, Safety]:
    ctl = Controller(machine(logic), safety=False)
    safety = Safety(ctl)
    for ax in ctl.axes:
        assert safety.set_edge_stop(ax.name, edge_stop)
    ctl.enable_all()
    return ctl, safety


def edge_time(ctl: Controller, axis: int, signal: str) -> float:
    t = ctl.hardware.stop_time(axis)
    assert t is not None
    return t


def run_to_stop(ctl: Controller, axis: int = 0) -> None:
    ax = ctl.axes[axis]
    assert ctl.run_until(lambda: ax.state is AxisState.ERROR_STOP, 10.0)
    ctl.advance(0.01)


@settings(max_examples=15, deadline=None)
@given(speed=st.floats(5_000.0, 200_000.0), sign=st.sampled_from([1, -1]),
       logic=st.sampled_from(["no", "nc"]), kind=st.sampled_from(["velocity", "absolute"]))
def test_limit_stops_pulses_at_the_edge(speed: float, sign: int, logic: str, kind: str) -> None:
    ctl, safety = setup(logic)
    ax = ctl.axes[0]
    if kind == "velocity":
        ax.move_velocity(sign * speed, tacc=0.05)
    else:  # a positioning move whose target lies past the switch (soft limits off)
        ax.move_absolute(sign * 40_000, max_vel=speed, tacc=0.05)
    hit = {"t": None}
    while ax.state is not AxisState.ERROR_STOP:
        ctl.step()
        if hit["t"] is None:
            hit["t"] = ctl.hardware.stop_time(0)
        assert ctl.time < 20.0
    t_edge = hit["t"]
    assert t_edge is not None and t_edge <= ctl.time
    ctl.advance(0.02)
    # the switch is active on [MEL - 5000, MEL): going down, pulse MEL - 1 trips it
    edge = PEL if sign > 0 else MEL - 1
    out = ctl.hardware.read_axis(0).pulses_out
    assert out == edge  # the pulse that tripped the switch is the last one out
    # the command holds that count (not the plan's value at the edge, half a pulse short)
    assert ctl.hardware.command_position(0) == edge
    assert ax.position == out  # the controller agrees: it rests on a whole pulse
    assert ax.fault == ("+EL" if sign > 0 else "-EL")
    assert ctl.history.state_at(0, ctl.time).p == pytest.approx(ax.position, abs=1e-6)
    # the history ends at the edge time: after it the axis holds
    st_edge = ctl.history.state_at(0, t_edge)
    assert st_edge.p == pytest.approx(ax.position, abs=1e-6)
    assert safety.last_stop(0).time == pytest.approx(t_edge, abs=1e-12)
    # the axis can still be moved away from the limit after reset
    ax.reset()
    ax.move_relative(-sign * 1000, max_vel=5_000.0, tacc=0.05)
    ctl.wait_motion_done([0], timeout=5.0)
    assert ctl.hardware.read_axis(0).pulses_out == pytest.approx(out - sign * 1000, abs=1)


def test_without_edge_stop_the_axis_stops_a_cycle_later() -> None:
    ctl, _ = setup(edge_stop=False)
    ax = ctl.axes[0]
    ax.move_velocity(97_300.0, tacc=0.05)
    run_to_stop(ctl)
    out = ctl.hardware.read_axis(0).pulses_out
    assert ctl.hardware.stop_time(0) is None
    assert out - PEL > 1.0  # the rest of the edge's cycle was output (up to v*T = 100)
    assert out - PEL <= 100.0 + 1.0


def test_moving_away_from_an_active_limit_is_not_cut() -> None:
    ctl, _ = setup()
    ax = ctl.axes[0]
    ax.move_velocity(50_000.0, tacc=0.05)
    run_to_stop(ctl)
    ax.reset()
    start = ctl.hardware.read_axis(0).pulses_out
    ax.move_relative(-3000, max_vel=20_000.0, tacc=0.05)
    ctl.wait_motion_done([0], timeout=5.0)
    assert ctl.hardware.read_axis(0).pulses_out == start - 3000
    assert ax.state is AxisState.STANDSTILL


def test_decel_mode_and_suspended_limits_are_not_armed() -> None:
    ctl, safety = setup()
    safety.set_el("a", "decel")
    ax = ctl.axes[0]
    ax.move_velocity(50_000.0, str_vel=1000.0, tacc=0.05)
    run_to_stop(ctl)
    assert ctl.hardware.stop_time(0) is None
    assert ctl.hardware.read_axis(0).pulses_out > PEL + 1.0  # decelerated past the edge
    ctl2, safety2 = setup()
    ax2 = ctl2.axes[0]
    with safety2.suspended("a", "pel"):
        ax2.move_relative(21_000, max_vel=50_000.0, tacc=0.05)
        ctl2.wait_motion_done([0], timeout=5.0)
    assert ctl2.hardware.read_axis(0).pulses_out == 21_000
    assert ax2.state is AxisState.STANDSTILL


@settings(max_examples=10, deadline=None)
@given(t_press=st.floats(0.06, 0.3), va=st.floats(5_000.0, 80_000.0),
       vb=st.floats(-80_000.0, -5_000.0))
def test_estop_cuts_every_axis_at_the_edge(t_press: float, va: float, vb: float) -> None:
    ctl, _ = setup(edge_stop=False)  # E-stop is always armed
    ctl.axes[0].move_velocity(va, tacc=0.05)
    ctl.axes[1].move_absolute(-15_000, max_vel=abs(vb), tacc=0.05)
    ctl.hardware.scenario.press_estop(at=t_press)
    planned = [None, None]
    while not ctl.estop_active:
        ctl.step()
    for i in (0, 1):
        assert ctl.hardware.stop_time(i) == pytest.approx(t_press, abs=1e-12)
        planned[i] = ctl.history.state_at(i, t_press).p
    ctl.advance(0.02)
    for i in (0, 1):
        ax = ctl.axes[i]
        out = ctl.hardware.read_axis(i).pulses_out
        assert ax.state is AxisState.ERROR_STOP and ax.fault == "emergency stop"
        assert abs(out - planned[i]) < 1.0
        assert ax.position == pytest.approx(planned[i], abs=1e-6)
    with pytest.raises(MotionError):
        ctl.axes[0].move_velocity(1000.0)


def test_alarm_immediate_cut_at_the_edge() -> None:
    ctl, _ = setup()
    ax = ctl.axes[0]
    ax.move_velocity(60_000.0, tacc=0.05)
    ctl.hardware.scenario.trip_alarm(0, at=0.1234)
    ctl.run_until(lambda: ax.state is AxisState.ERROR_STOP, 1.0)
    p = ctl.history.state_at(0, 0.1234).p
    ctl.advance(0.01)
    assert ctl.hardware.stop_time(0) is None  # cleared on later cycles
    assert abs(ctl.hardware.read_axis(0).pulses_out - p) < 1.0
    assert ax.position == pytest.approx(p, abs=1e-6)


def test_arm_stop_validates() -> None:
    hw = Controller(machine(), safety=False).hardware
    with pytest.raises(MotionError):
        hw.arm_stop(0, "nope", True)
    with pytest.raises(MotionError):
        hw.arm_stop(None, "pel", True)
    with pytest.raises(MotionError):
        hw.arm_stop(0, "pel", True, 2)
    with pytest.raises(MotionError):
        hw.arm_stop(0, "pel", 1)  # type: ignore[arg-type]
