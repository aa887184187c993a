"""Closed-loop dc_servo axes: the control layer's ServoLoop on the simulated DC motor."""

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.compat.hctl1100_step import oscillation
from openmotion.config import (
    AxisConfig,
    DCMotorConfig,
    DriveConfig,
    LoopConfig,
    MachineConfig,
    loads_machine,
)
from openmotion.control import AxisState, Controller
from openmotion.control.loops.servoloop import FOLLOWING_ERROR, ServoLoop
from openmotion.errors import MotionError

TUNED = LoopConfig(a=0xD8, b=0x00, k=0x10, samples_per_cycle=2)
CHIP_DEFAULT = LoopConfig(samples_per_cycle=2)  # A=E5h B=40h K=40h, 500 us sample
# PID+FF for the default motor: 1 duty ~ 4.9e5 counts/s, so kvff = kd + 1/4.9e5 cancels the
# derivative-on-feedback drag at speed; kaff = R J (2pi/4000) / (kt V) duty per count/s^2
PID = LoopConfig("pid", kp=0.01, kd=2e-5, samples_per_cycle=2)
PIDFF = replace(PID, kvff=2.2e-5, kaff=1.75e-8)


def dc_axis(loop=TUNED, **motor):
    return AxisConfig("x", pulses_per_rev=4000, encoder_lines_per_rev=1000, unit="pulse",
                      lead=4000.0, max_speed=200000.0,
                      drive=DriveConfig(type="dc_servo", motor=DCMotorConfig(**motor)),
                      loop=loop)


def controller(loop=TUNED, **motor):
    ctl = Controller(MachineConfig(axes=(dc_axis(loop, **motor), AxisConfig("s"))))
    return ctl, ctl.axis("x"), ctl.servo_loops["x"]


def t_move(loop=TUNED, dist=4000, settle=0.2, **motor):
    ctl, x, lp = controller(loop, **motor)
    x.enable()
    lp.start_trace()
    x.move_relative(dist, max_vel=40000, tacc=0.05)
    assert ctl.wait_motion_done(timeout=2.0)
    ctl.advance(settle)
    tr = lp.trace()
    return ctl, x, lp, tr, tr["command"] - tr["feedback"]


def test_only_axes_with_a_loop_get_one():
    ctl, _, lp = controller()
    assert set(ctl.servo_loops) == {"x"}
    assert lp.sample_period == pytest.approx(0.0005)


def test_tuned_filter_follows_a_t_move_and_ends_on_target():
    ctl, x, lp, tr, e = t_move(TUNED)
    assert x.state is AxisState.STANDSTILL
    assert x.position == 4000.0
    assert abs(x.counters.feedback - 4000) <= 2
    assert np.max(np.abs(e)) < 30                   # follows the move closely
    assert oscillation(tr["feedback"], 4000, 200).peak_to_peak == 0.0  # still after settling
    assert len(tr["t"]) == 2 * ctl.cycles   # two samples per cycle from the start


def test_chip_default_filter_works_with_its_one_count_limit_cycle():
    _, x, _, tr, e = t_move(CHIP_DEFAULT)
    assert abs(x.counters.feedback - 4000) <= 2
    assert np.max(np.abs(e)) < 30
    assert oscillation(tr["feedback"], 4000, 200).peak_to_peak <= 2.0


def test_far_too_high_gain_oscillates():
    _, _, _, tr_ok, _ = t_move(TUNED)
    _, _, _, tr_hi, _ = t_move(replace(CHIP_DEFAULT, k=0xFF))
    calm = oscillation(tr_ok["feedback"], 4000, 200)
    osc = oscillation(tr_hi["feedback"], 4000, 200)
    assert osc.peak_to_peak >= 8.0 and osc.sign_changes >= 10  # sustained, many counts
    assert osc.growth > 0.5                                      # not dying out
    assert calm.peak_to_peak == 0.0


def test_one_sample_per_ms_default_filter_is_unstable():
    """The chip's default filter was meant for a ~0.5 ms sample; at 1 ms it rings hard."""
    _, _, _, tr, _ = t_move(LoopConfig())
    assert oscillation(tr["feedback"], 4000, 100).peak_to_peak > 20.0


def test_pid_feed_forward_reduces_the_following_error():
    _, x0, _, _, e0 = t_move(PID)
    _, x1, _, _, e1 = t_move(PIDFF)
    peak0, peak1 = np.max(np.abs(e0)), np.max(np.abs(e1))
    assert peak1 < peak0 / 10
    assert peak1 <= 3.0
    assert abs(x1.counters.feedback - 4000) <= 2


def test_integral_holds_position_against_a_load_torque():
    _, x_p, _, _, e_p = t_move(TUNED, load_torque=0.005)
    _, x_i, _, _, e_i = t_move(replace(PIDFF, ki=0.5), load_torque=0.005)
    assert abs(e_p[-1]) >= 3                  # proportional-only filter: a droop
    assert abs(np.mean(e_i[-100:])) <= 1.0    # integral: no droop


def test_following_error_trips_error_stop_and_refuses_motion_until_reset():
    tight = replace(TUNED, following_error=200.0)
    ctl, x, lp, tr, e = t_move(tight, current_limit=0.05)  # far too weak to accelerate
    assert x.state is AxisState.ERROR_STOP and x.fault == FOLLOWING_ERROR
    assert lp.tripped and lp.duty == 0.0 and not lp.closed
    assert 200.0 < np.max(np.abs(e)) < 230.0
    assert ctl.hardware._axes[0].plant.duty == 0.0  # amplifier command off
    snap = x.snapshot()
    with pytest.raises(MotionError, match="ErrorStop"):
        x.move_relative(100, max_vel=1000, tacc=0.01)
    assert x.snapshot() == snap
    x.reset()
    ctl.step()
    assert lp.closed and not lp.tripped
    fb = x.counters.feedback
    x.move_relative(100, max_vel=1000, tacc=0.01)     # gentle: the weak motor manages
    assert ctl.wait_motion_done(timeout=1.0)
    ctl.advance(0.2)
    assert x.state is AxisState.STANDSTILL
    assert abs(x.counters.feedback - (fb + 100)) <= 3


def test_same_move_with_enough_current_does_not_trip():
    _, x, _, _, _ = t_move(replace(TUNED, following_error=200.0))
    assert x.state is AxisState.STANDSTILL


def test_loop_is_off_while_disabled_and_closes_on_the_current_position():
    ctl, x, lp = controller(TUNED, load_torque=0.002)  # the load drags an unpowered motor
    ctl.advance(0.05)
    assert not lp.closed and lp.duty == 0.0
    assert not ctl.hardware.read_output(0, "svon")
    drifted = ctl.hardware.read_axis(0).encoder
    assert drifted < -5
    x.enable()
    assert ctl.hardware.read_output(0, "svon")
    ctl.advance(0.2)
    assert lp.closed
    assert abs(lp.bias - drifted) <= 1       # closed where the motor was, no jump
    assert abs(x.counters.feedback - drifted) <= 6
    x.disable()
    ctl.step()
    assert not lp.closed and lp.duty == 0.0


def test_detach_stops_sampling():
    ctl, x, lp = controller()
    x.enable()
    lp.start_trace()
    ctl.advance(0.01)
    n = len(lp.trace()["t"])
    lp.detach()
    ctl.advance(0.01)
    assert len(lp.trace()["t"]) == n == 20


def test_sample_hook_times_and_validation():
    ctl, _, _ = controller(LoopConfig(samples_per_cycle=1))
    seen = []
    ctl.add_sample_hook(lambda c, t: seen.append(round(t * 1e4)), 4)
    ctl.step()
    assert seen == [0, 2, 5, 8]
    for bad in (0, 1.5, True, 1001):
        with pytest.raises(MotionError, match="per_cycle must be an int"):
            ctl.add_sample_hook(lambda c, t: None, bad)
    with pytest.raises(MotionError, match="hook must be callable"):
        ctl.add_sample_hook(3)


def test_servo_loop_refusals():
    ctl, _, _ = controller()
    with pytest.raises(MotionError, match="no loop configured"):
        ServoLoop(ctl, "s")
    with pytest.raises(MotionError, match="has no effort output"):
        ServoLoop(ctl, "s", TUNED)
    with pytest.raises(MotionError, match="axis 0 has no effort output"):
        Controller(MachineConfig(axes=(replace(AxisConfig("s"), loop=TUNED),)))


@pytest.mark.parametrize(("kw", "msg"), [
    ({"compensator": "pi"}, r"loop.compensator must be one of lead, pid"),
    ({"a": 256}, r"loop.a must be an integer in \[0, 255\]"),
    ({"k": -1}, r"loop.k must be an integer in \[0, 255\]"),
    ({"b": 1.5}, r"loop.b must be an integer"),
    ({"compensator": "pid"}, r"loop.kp must be > 0 for the pid compensator"),
    ({"kd": -1.0}, r"loop.kd must be >= 0"),
    ({"kvff": math.nan}, r"loop.kvff must be finite"),
    ({"samples_per_cycle": 0}, r"loop.samples_per_cycle must be an integer in \[1, 1000\]"),
    ({"following_error": 0.0}, r"loop.following_error must be > 0 counts"),
    ({"following_error": math.nan}, r"loop.following_error must be > 0 counts"),
])
def test_loop_config_rules(kw, msg):
    with pytest.raises(MotionError, match=msg):
        LoopConfig(**kw)


@pytest.mark.parametrize(("kw", "msg"), [
    ({"resistance": 0.0}, r"motor.resistance must be > 0"),
    ({"inertia": -1.0}, r"motor.inertia must be > 0"),
    ({"ke": -0.1}, r"motor.ke must be >= 0"),
    ({"current_limit": math.inf}, r"motor.current_limit must be finite"),
    ({"load_torque": "x"}, r"motor.load_torque must be a real number"),
])
def test_motor_config_rules(kw, msg):
    with pytest.raises(MotionError, match=msg):
        DCMotorConfig(**kw)


def test_dc_servo_gets_a_default_loop_and_round_trips_through_toml():
    from openmotion.config import dumps_machine

    ax = AxisConfig("x", drive=DriveConfig(type="dc_servo"))
    assert ax.loop == LoopConfig()
    m = MachineConfig(axes=(dc_axis(replace(PIDFF, following_error=math.inf),
                                    load_torque=0.001), AxisConfig("s")))
    text = dumps_machine(m)
    assert "[axes.x.loop]" in text and "[axes.x.drive.motor]" in text
    assert "[axes.s.loop]" not in text and "[axes.s.drive.motor]" not in text
    assert loads_machine(text) == m
    with pytest.raises(MotionError, match=r"axes\.x\.loop\.kpp: unknown key; did you mean 'kp'"):
        loads_machine(text.replace("kp =", "kpp ="))
    with pytest.raises(MotionError, match=r"axes\.x\.drive\.motor\.kt must be > 0"):
        loads_machine(text.replace("kt = 0.03", "kt = 0.0"))


def test_example_machine_file_loads_and_moves():
    from pathlib import Path

    from openmotion.config import load_machine

    cfg = load_machine(Path(__file__).parent.parent / "examples" / "dc_servo.toml")
    ctl = Controller(cfg)
    ax = ctl.axes[0]
    ax.enable()
    ax.move_relative(2000, max_vel=20000, tacc=0.05)
    assert ctl.wait_motion_done(timeout=2.0)
    ctl.advance(0.1)
    assert abs(ax.counters.feedback - 2000) <= 2


def test_inject_step_moves_the_motor_not_the_command_counter():
    ctl, x, lp = controller()
    with pytest.raises(MotionError, match="the loop is open"):
        lp.inject_step(100)
    x.enable()
    ctl.step()
    for bad, msg in ((math.nan, "counts must be finite"), (2e6, r"counts must be within")):
        with pytest.raises(MotionError, match=msg):
            lp.inject_step(bad)
    assert lp.bias == 0.0
    lp.inject_step(200)
    ctl.advance(0.1)
    assert x.position == 0.0
    assert abs(x.counters.feedback - 200) <= 1


def test_servo_tuning_example_writes_a_plot(tmp_path):
    import runpy
    from pathlib import Path

    mod = runpy.run_path(str(Path(__file__).parent.parent / "examples" / "servo_tuning.py"))
    out = tmp_path / "tuning.png"
    mod["main"](str(out))
    assert out.stat().st_size > 10_000
    t, x = mod["step_response"](0xD8, 0x00, 0x10, duration=0.05)
    assert abs(x[-1] - mod["STEP"]) <= 1


@settings(max_examples=8, deadline=None)
@given(dist=st.integers(-6000, 6000).filter(lambda d: abs(d) >= 10),
       vmax=st.floats(2000.0, 60000.0), tacc=st.floats(0.02, 0.1))
def test_tuned_loop_ends_within_two_counts_of_any_feasible_move(dist, vmax, tacc):
    ctl, x, lp = controller()
    x.enable()
    x.move_relative(dist, max_vel=vmax, tacc=tacc)
    assert ctl.wait_motion_done(timeout=5.0)
    ctl.advance(0.15)
    assert x.state is AxisState.STANDSTILL
    assert abs(x.counters.feedback - dist) <= 2
    assert lp.peak_error < 40
