"""In-position control (control.guard.inposition, MCCL 2.10.2)."""

from __future__ import annotations

import dataclasses

import pytest

from openmotion.config import DriveConfig, default_machine
from openmotion.control import Controller
from openmotion.control.core.states import AxisState, MotionDone
from openmotion.control.guard.inposition import INPOS_TIMEOUT, NO_ERROR, InPositionControl
from openmotion.errors import MotionError


def _servo_machine(bandwidth_hz: float = 5.0) -> Controller:
    """x and y on a lagging servo, so the feedback settles after the command ends."""
    cfg = default_machine()
    servo = DriveConfig(type="servo", bandwidth_hz=bandwidth_hz, inp_band=1.0)
    axes = tuple(dataclasses.replace(a, drive=servo) if a.name in ("x", "y") else a
                 for a in cfg.axes)
    ctl = Controller(dataclasses.replace(cfg, axes=axes))
    ctl.enable_all()
    return ctl


def test_next_queued_command_waits_until_in_position():
    ctl = _servo_machine()
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 3)
    ip.set_check_time("x", 2.0)
    ip.enable(["x"])
    ax = ctl.axis("x")
    log = []
    ip.queue(lambda: ax.move_relative(10000, max_vel=50000, tacc=0.05))
    ip.queue(lambda: log.append((ctl.time, ax.counters.error, ax.motion_done)))
    ip.queue(lambda: ax.move_relative(-10000, max_vel=50000, tacc=0.05))
    ctl.step()
    t_end = ax.motion.t_end
    saw_waiting = False
    while ip.pending or ax.motion_done:
        saw_waiting |= ax.motion is None and ax.motion_done == MotionDone.WAITING_INP
        ctl.step()
    assert saw_waiting
    (t_next, err, done), = log
    assert t_next > t_end + 0.05          # a 5 Hz servo needs time to settle
    assert abs(err) <= 3 and done == 0
    assert ip.in_position("x") and ip.error_code == NO_ERROR


def test_without_in_position_the_queue_follows_the_command():
    ctl = _servo_machine()
    ip = InPositionControl(ctl)
    ax = ctl.axis("x")
    log = []
    ip.queue(lambda: ax.move_relative(10000, max_vel=50000, tacc=0.05))
    ip.queue(lambda: log.append((ctl.time, ax.counters.error)))
    ctl.step()
    t_end = ax.motion.t_end
    ctl.run_until(lambda: ip.pending == 0, 2.0)
    (t_next, err), = log
    assert t_next <= t_end + ctl.period + 1e-9 and abs(err) > 3


def test_check_time_passes_error_code_and_error_stop():
    ctl = _servo_machine(bandwidth_hz=1.0)
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 1)
    ip.set_check_time("x", 0.05)
    ip.enable()
    ax = ctl.axis("x")
    ran = []
    ip.queue(lambda: ax.move_relative(20000, max_vel=80000, tacc=0.05))
    ip.queue(lambda: ran.append(1))
    ctl.step()
    t_end = ax.motion.t_end
    ctl.run_until(lambda: ip.error_code != NO_ERROR, 2.0)
    assert ip.error_code == INPOS_TIMEOUT and ip.error_axis == 0
    assert ctl.time >= t_end + 0.05 - 1e-9
    assert ctl.time <= t_end + 0.05 + 2 * ctl.period
    assert ax.state is AxisState.ERROR_STOP and ax.fault == "in-position timeout"
    assert ip.pending == 0 and ran == []   # the following commands are stopped
    with pytest.raises(MotionError, match="clear_error"):
        ip.queue(lambda: None)
    ip.clear_error()
    assert ip.error_code == NO_ERROR
    ax.reset()
    ip.queue(lambda: ran.append(2))
    ctl.step()
    assert ran == [2]


def test_per_axis_tolerance_in_user_units():
    """MCCL Fig. 18: tolerances X 0.5 mm, Y 0.3 mm; errors 0.3 mm and 1 mm -> X in position,
    Y not, so the system is not in position (steppers that lost those steps)."""
    ctl = Controller(default_machine())
    ctl.enable_all()
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 0.5, units=True)
    ip.set_tolerance("y", 0.3, units=True)
    assert ip.tolerance("x") == 500 and ip.tolerance("y") == 600  # 1000 and 2000 pulses/mm
    ip.enable(["x", "y"])
    sc = ctl.hardware.scenario
    sc.inject_step_loss(0, 300)                   # 0.3 mm on x
    sc.inject_step_loss(1, 2000)                  # 1 mm on y
    ctl.axis("x").move_relative(20000, max_vel=50000, tacc=0.05)
    ctl.axis("y").move_relative(20000, max_vel=50000, tacc=0.05)
    ctl.advance(1.0)
    assert ip.position_error("x") == 300 and ip.position_error("y") == 2000
    assert ip.in_position("x") and not ip.in_position("y")
    assert not ip.in_position()
    assert ctl.axis("x").motion_done == 0
    assert ctl.axis("y").motion_done == MotionDone.WAITING_INP
    ip.disable(["y"])
    assert ip.in_position() and not ip.enabled("y") and ctl.axis("y").motion_done == 0


def test_disable_releases_a_waiting_axis():
    ctl = _servo_machine(bandwidth_hz=1.0)
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 0)
    ip.set_check_time("x", 10.0)
    ip.enable(["x"])
    ax = ctl.axis("x")
    ax.move_relative(5000, max_vel=50000, tacc=0.05)
    ctl.advance(0.3)
    assert ax.motion is None and ax.motion_done == MotionDone.WAITING_INP
    with pytest.raises(MotionError, match="running"):
        ax.move_relative(10, max_vel=1000)
    ip.disable(["x"])
    assert ax.motion_done == 0
    ctl.step()
    assert ax.state is AxisState.STANDSTILL


def test_ideal_stepper_is_in_position_at_once():
    ctl = Controller(default_machine())
    ctl.enable_all()
    ip = InPositionControl(ctl)
    ip.enable()
    ax = ctl.axis("z")
    ax.move_relative(4000, max_vel=40000, tacc=0.02)
    t_end = ax.motion.t_end
    assert ctl.wait_motion_done(timeout=2.0)
    assert ctl.time <= t_end + ctl.period + 1e-9 and ip.in_position()


def test_bad_input_refused_state_unchanged():
    ctl = _servo_machine()
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 4)
    ip.set_check_time("x", 0.5)
    before = (list(ip._tol), list(ip._check), list(ip._enabled))
    bad = [
        lambda: ip.set_tolerance("x", -1),
        lambda: ip.set_tolerance("x", float("nan")),
        lambda: ip.set_tolerance("q", 1),
        lambda: ip.set_check_time("x", 0.0),
        lambda: ip.set_check_time("x", float("inf")),
        lambda: ip.set_check_time(7, 1.0),
        lambda: ip.enable(["x", "nope"]),
        lambda: ip.enable("x"),
        lambda: ip.disable([9]),
        lambda: ip.queue(42),
    ]
    for call in bad:
        with pytest.raises(MotionError):
            call()
    assert (list(ip._tol), list(ip._check), list(ip._enabled)) == before
    assert ip.pending == 0 and all(a.done_gates == [] for a in ctl.axes)


def test_refused_queued_command_drops_the_rest():
    ctl = _servo_machine()
    ip = InPositionControl(ctl)
    ax = ctl.axis("x")
    ran = []
    ip.queue(lambda: ax.move_relative(10, max_vel=float("nan")))
    ip.queue(lambda: ran.append(1))
    ctl.step()
    assert isinstance(ip.failure, MotionError) and ip.pending == 0 and ran == []


def test_check_time_also_after_a_decelerating_stop():
    ctl = _servo_machine(bandwidth_hz=1.0)
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 1)
    ip.set_check_time("x", 0.1)
    ip.enable(["x"])
    ax = ctl.axis("x")
    ax.move_velocity(40000, tacc=0.05)
    ctl.advance(0.2)
    ax.stop(0.05)
    ctl.advance(0.05)
    assert ax.motion is None and ax.motion_done == MotionDone.WAITING_INP
    assert ax.state is AxisState.STOPPING
    ctl.run_until(lambda: ip.error_code != NO_ERROR, 1.0)
    assert ip.error_code == INPOS_TIMEOUT and ax.state is AxisState.ERROR_STOP
