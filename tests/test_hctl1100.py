"""HCTL-1100 emulation: registers, modes, filter, generators, inputs, commutator."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.compat import hctl1100_regs as R
from openmotion.compat.hctl1100 import HCTL1100
from openmotion.compat.hctl1100_commutator import (
    DRIVE_FULL_ONE,
    DRIVE_FULL_TWO,
    DRIVE_HALF,
    PHASE_A,
    PHASE_B,
    PHASE_C,
    PHASE_D,
    commutator_mask,
    winding_currents,
)
from openmotion.compat.hctl1100_profile import trapezoid_commands
from openmotion.compat.hctl1100_step import (
    DEFAULT_FILTER,
    TUNED_FILTER,
    oscillation,
    plot_step_responses,
    step_response,
)
from openmotion.control.loops.servo import LeadFilter
from openmotion.errors import MotionError
from openmotion.hw.sim.dcmotor import DCMotor

Mode = R.Mode


def chip() -> HCTL1100:
    return HCTL1100(DCMotor())


def put24(c, regs, value):
    for reg, b in zip(regs, R.split24(value), strict=True):
        c.write(reg, b)


CMD = (R.R_CMD_POS_MSB, R.R_CMD_POS_MID, R.R_CMD_POS_LSB)
FINAL = (R.R_FINAL_MSB, R.R_FINAL_MID, R.R_FINAL_LSB)


def read_actual(c):
    lsb = c.read(R.R_ACT_POS_LSB)
    return R.join24(c.read(R.R_ACT_POS_MSB), c.read(R.R_ACT_POS_MID), lsb)


# ---------------------------------------------------------------- reset, registers
def test_reset_state():
    c = chip()
    assert c.mode is Mode.INIT_IDLE
    assert [c.read(r) for r in (R.R_FILTER_A, R.R_FILTER_B, R.R_FILTER_K)] == [0xE5, 0x40, 0x40]
    assert c.read(R.R_SAMPLE_TIMER) == 0x40
    assert c.read(R.R_FLAG) == 0x02          # F1: in Init/Idle
    assert c.read(R.R_STATUS) == 0xE0        # F1, no STOP, no LIMIT
    assert c.sample_period == pytest.approx(16 * 65 / 2e6)


def test_sample_time_formula_and_range():
    assert R.sample_time(0x07) == pytest.approx(64e-6)
    assert R.sample_time(0xFF) == pytest.approx(2048e-6)
    c = chip()
    c.run_samples(1)
    c.write(R.R_SAMPLE_TIMER, 0x10)
    assert c.sample_period == pytest.approx(520e-6)  # latched; used after this sample
    t0 = c.time
    c.run_samples(1)
    assert c.time - t0 == pytest.approx(520e-6)
    t0 = c.time
    c.run_samples(3)
    assert c.time - t0 == pytest.approx(3 * 136e-6)


def test_sample_timer_reads_count_down():
    c = chip()
    c.run_samples(1)
    assert c.read(R.R_SAMPLE_TIMER) == 0x40
    c.advance(c.sample_period / 2)
    assert c.read(R.R_SAMPLE_TIMER) == 0x40 - 32
    c.advance(c.sample_period * 0.499)
    assert 0 <= c.read(R.R_SAMPLE_TIMER) <= 1


def test_sample_timer_below_mode_minimum_is_refused():
    c = chip()
    c.write(R.R_SAMPLE_TIMER, 0x00)  # fine in Init/Idle
    with pytest.raises(MotionError, match="minimum"):
        c.write(R.R_PROGRAM, R.PC_CONTROL)  # position control needs 07H
    assert c.mode is Mode.INIT_IDLE
    c.write(R.R_SAMPLE_TIMER, 0x07)
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    with pytest.raises(MotionError, match="0x06"):
        c.write(R.R_SAMPLE_TIMER, 0x06)
    c.write(R.R_ACCEL_MSB, 1)
    c.write(R.R_MAX_VEL, 10)
    put24(c, FINAL, 100)
    with pytest.raises(MotionError, match="trapezoidal profile minimum 0x0f"):
        c.write(R.R_FLAG, R.FLAG_SET | R.F0)
    assert c.mode is Mode.POSITION and not c.flags & 1


@pytest.mark.parametrize("reg,value", [(0x01, 0), (0x40, 0), (R.R_FILTER_A, 256),
                                       (R.R_FILTER_K, -1), (R.R_FILTER_B, 1.0),
                                       (R.R_MAX_VEL, 0x80), (R.R_COMM_RING, 0xFF),
                                       (R.R_STATUS, 0x08), (R.R_PROGRAM, 0x04)])
def test_bad_writes_raise_and_change_nothing(reg, value):
    c = chip()
    before = [c.read(r) for r in sorted(R.READABLE) if r != R.R_ACT_POS_LSB]
    with pytest.raises(MotionError):
        c.write(reg, value)
    assert [c.read(r) for r in sorted(R.READABLE) if r != R.R_ACT_POS_LSB] == before


def test_read_of_write_only_register_refused():
    with pytest.raises(MotionError, match="not a register"):
        chip().read(R.R_PROGRAM)


def test_flag_register_codes():
    c = chip()
    c.write(R.R_FLAG, 0xFC)  # upper bits ignored: sets F4
    assert c.read(R.R_FLAG) == 0x12
    c.write(R.R_FLAG, 0x04)
    c.write(R.R_FLAG, 0x09)  # F1 belongs to the chip
    assert c.read(R.R_FLAG) == 0x02 and c.ignored_writes == 1
    c.write(R.R_FLAG, 0x0B)
    with pytest.raises(MotionError, match="one control flag"):
        c.write(R.R_FLAG, 0x0D)
    assert c.read(R.R_FLAG) == 0x0A


def test_status_register_low_bits_only():
    c = chip()
    c.write(R.R_STATUS, 0xF5)  # upper 4 ignored
    assert c.read(R.R_STATUS) & 0x0F == 0x05


def test_program_counter_rules():
    c = chip()
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    assert c.mode is Mode.POSITION
    c.write(R.R_PROGRAM, R.PC_ALIGN)  # only from Init/Idle
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    assert c.mode is Mode.POSITION and c.ignored_writes == 2
    c.write(R.R_FILTER_K, 0x10)
    c.write(R.R_PROGRAM, R.PC_RESET)
    assert c.mode is Mode.INIT_IDLE and c.read(R.R_FILTER_K) == 0x40


# ---------------------------------------------------------------- 24-bit positions
def test_command_position_latches_on_lsb_and_wraps():
    c = chip()
    c.write(R.R_CMD_POS_MSB, 0x12)
    c.write(R.R_CMD_POS_MID, 0x34)
    assert c.command_position == 0
    c.write(R.R_CMD_POS_LSB, 0x56)
    assert c.command_position == 0x123456
    put24(c, CMD, -2)
    assert [c.read(r) for r in CMD] == [0xFF, 0xFF, 0xFE] and c.command_position == -2
    assert R.wrap24(0x7FFFFF + 1) == -0x800000


def test_actual_position_read_latch_preset_and_clear():
    c = chip()
    c.plant.theta = 2 * np.pi * 1000 / 4000  # 1000 counts
    c.write(R.R_ACT_POS_MID, 0)             # any write to R13H clears the counter
    assert read_actual(c) == 0
    c.plant.theta += 2 * np.pi * 300 / 4000
    lsb = c.read(R.R_ACT_POS_LSB)           # latches
    c.plant.theta += 2 * np.pi * 70000 / 4000
    assert R.join24(c.read(R.R_ACT_POS_MSB), c.read(R.R_ACT_POS_MID), lsb) == 300
    put24(c, (R.R_PRESET_MSB, R.R_PRESET_MID, R.R_PRESET_LSB), -5000)
    assert c.actual_position == -5000
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    put24(c, (R.R_PRESET_MSB, R.R_PRESET_MID, R.R_PRESET_LSB), 7)  # ignored outside idle
    assert c.ignored_writes == 3 and abs(c.actual_position + 5000) < 2


# ---------------------------------------------------------------- filter and PWM
def test_chip_filter_is_the_lead_filter_difference_equation():
    c = chip()
    c.write(R.R_FILTER_A, 0xC0)
    c.write(R.R_FILTER_B, 0x20)
    c.write(R.R_FILTER_K, 0x30)
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    ref = LeadFilter(0xC0, 0x20, 0x30, limit=127, quantize=True)
    put24(c, CMD, 40)
    for _ in range(60):
        c.run_samples(1)
        err = c.command_position - c._last_actual
        assert c.motor_command == ref.step_error(err)


def test_pwm_open_loop_in_idle_and_ignored_in_control():
    c = chip()
    c.write(R.R_PWM, 50)
    c.run_samples(20)
    assert c.plant.omega > 0 and c.read(R.R_PWM) == 50
    c.write(R.R_PWM, (-128) & 0xFF)
    assert c.motor_command == -128
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    c.write(R.R_PWM, 10)
    assert c.ignored_writes == 1


def test_step_responses_default_tuned_and_gain_too_high(tmp_path):
    default = step_response(*DEFAULT_FILTER, step=200, samples=500)
    tuned = step_response(*TUNED_FILTER, step=200, samples=500)
    assert tuned.overshoot <= 0.01 and tuned.settling_samples() < default.settling_samples()
    assert oscillation(tuned.actual, 200, 200).peak_to_peak == 0
    # the manual's table: more K, worse stability -> sustained oscillation on the trace
    hot = step_response(0xE5, 0x40, 0xFF, step=20, samples=800)
    osc = oscillation(hot.actual, 20, 400)
    assert osc.peak_to_peak >= 8 and osc.sign_changes >= 10 and osc.growth >= 0.8
    # the reset filter only hunts by a count or so around the target
    assert oscillation(step_response(*DEFAULT_FILTER, step=20, samples=800).actual, 20,
                       400).peak_to_peak <= 3 < osc.peak_to_peak / 2
    out = plot_step_responses([default, tuned], tmp_path / "step.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(MotionError):
        step_response(step=0)
    with pytest.raises(MotionError):
        plot_step_responses([], tmp_path / "x.png")


# ---------------------------------------------------------------- trapezoid
@settings(max_examples=60, deadline=None)
@given(dist=st.integers(-200000, 200000) | st.sampled_from([1, -1, 0x7FFFFF, -0x800000]),
       acc_raw=st.integers(1, 0x7FFF), vmax=st.integers(1, 127))
def test_trapezoid_commands_end_exactly_and_respect_limits(dist, acc_raw, vmax):
    acc = acc_raw / 256.0
    vpeak = min(vmax, (abs(dist) * acc) ** 0.5)
    assume(vpeak == 0 or abs(dist) / vpeak + vpeak / acc < 20000)  # keep examples fast
    pos = trapezoid_commands(100, dist, acc, vmax)
    assert pos[-1] == 100 + dist
    v = np.diff(np.concatenate(([100], pos)))
    assert np.all(np.abs(v) <= vmax + 1)  # one count of rounding
    assert np.all(np.sign(v) * np.sign(dist) >= 0)  # never backwards
    peak = np.abs(v).max()
    if abs(dist) / vmax - vmax / acc >= 2:  # Vmax reached well before halfway: cruise
        assert peak >= vmax - 1
    if vmax * vmax / acc > abs(dist):  # triangle: the peak is sqrt(dist * acc)
        assert peak <= (abs(dist) * acc) ** 0.5 + 1


def test_positions_wrap_at_24_bits_during_a_move():
    c = chip()
    put24(c, (R.R_PRESET_MSB, R.R_PRESET_MID, R.R_PRESET_LSB), 0x7FFF00)
    put24(c, CMD, 0x7FFF00)
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    c.write(R.R_ACCEL_MSB, 1)
    c.write(R.R_MAX_VEL, 20)
    put24(c, FINAL, 0x7FFF00 + 0x300)  # wraps to a negative final position
    c.write(R.R_FLAG, R.FLAG_SET | R.F0)
    c.run_samples(300)
    assert c.command_position == R.wrap24(0x7FFF00 + 0x300) < 0
    assert abs(R.wrap24(c.actual_position - c.command_position)) <= 1


def test_trapezoid_move_on_the_chip():
    c = chip()
    events = []
    c.listeners.append(lambda e: events.append(e.kind))
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    put24(c, CMD, 50)
    c.run_samples(100)
    c.write(R.R_ACCEL_MSB, 1)
    c.write(R.R_MAX_VEL, 30)
    put24(c, FINAL, 5050)
    c.write(R.R_FLAG, R.FLAG_SET | R.F0)
    assert c.mode is Mode.TRAPEZOID and c.read(R.R_STATUS) & R.ST_PROFILE
    put24(c, CMD, 0)  # no new command data during a profile: ignored
    tr = c.run_samples(400, record=True)
    assert c.mode is Mode.POSITION and not c.read(R.R_FLAG) & 1
    assert c.command_position == 5050 and events == ["profile_start", "profile_done"]
    assert tr.command[2] > 50 and np.all(np.diff(tr.command) <= 31)
    assert abs(c.actual_position - 5050) <= 1


# ---------------------------------------------------------------- velocity modes
def test_integral_velocity_zero_steady_state_error_and_stop():
    c = chip()
    c.write(R.R_FILTER_A, 0xD8)
    c.write(R.R_FILTER_B, 0x00)
    c.write(R.R_FILTER_K, 0x10)
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    c.write(R.R_ACCEL_LSB, 0x40)
    c.write(R.R_INT_VEL, 23)
    c.write(R.R_FLAG, R.FLAG_SET | R.F5)
    c.run_samples(300)
    tr = c.run_samples(400, record=True)
    v = np.diff(tr.actual)
    assert v[-200:].mean() == pytest.approx(23, abs=1 / 200)  # exact mean velocity
    lag = tr.command - tr.actual
    assert np.ptp(lag[-200:]) <= 2  # constant following error: no drift
    c.set_stop(True)
    c.run_samples(400)
    p = c.actual_position
    c.run_samples(100)
    assert c.actual_position == p and c.stop_latched
    c.set_stop(False)
    c.write(R.R_STATUS, 0)  # clears the latched STOP once the pin is inactive
    c.run_samples(300)
    assert c.actual_position - p > 1000
    with pytest.raises(MotionError, match="127"):
        c.write(R.R_INT_VEL, (-110) & 0xFF)
    c.write(R.R_FLAG, R.F5)
    assert c.mode is Mode.POSITION


def test_proportional_velocity_law_and_registers():
    c = chip()
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    v = -12 * 16 - 8  # -12.5 counts/sample, 12.4 fixed point
    c.write(R.R_PROP_VEL_LSB, v & 0xFF)
    c.write(R.R_PROP_VEL_MSB, (v >> 8) & 0xFF)
    c.write(R.R_FLAG, R.FLAG_SET | R.F3)
    c.run_samples(400)
    act = R.signed16(c.read(R.R_ACT_VEL_LSB) | c.read(R.R_ACT_VEL_MSB) << 8)
    assert -13 <= act <= -10  # proportional: a small steady-state error remains
    assert c.motor_command == int(16 * (-12.5 - act))
    c.write(R.R_FLAG, R.F3)
    assert c.mode is Mode.POSITION and abs(c.command_position - c.actual_position) <= 13


# ---------------------------------------------------------------- limit, align
def test_limit_enters_idle_and_holds_until_released():
    c = chip()
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    put24(c, CMD, 10000)
    c.run_samples(10)
    c.set_limit(True)
    assert c.mode is Mode.INIT_IDLE and c.motor_command == 0
    assert not c.read(R.R_STATUS) & R.ST_LIMIT_CLEAR
    c.write(R.R_PROGRAM, R.PC_CONTROL)  # cannot drive normally while LIMIT is active
    c.write(R.R_STATUS, 0)
    assert c.mode is Mode.INIT_IDLE and c.limit_latched
    c.set_limit(False)
    c.write(R.R_STATUS, 0)
    assert c.read(R.R_STATUS) & R.ST_LIMIT_CLEAR
    c.write(R.R_PROGRAM, R.PC_CONTROL)
    assert c.mode is Mode.POSITION


def test_align_energises_a_then_d_for_2048_samples_each():
    c = chip()
    c.write(R.R_PROGRAM, R.PC_ALIGN)
    assert c.mode is Mode.ALIGN and c.read(R.R_FLAG) & 0x10  # F4 held
    c.run_samples(2047)
    assert c.align_phase == "A" and c.commutator_output(0, 1) == PHASE_A
    c.run_samples(1)
    assert c.align_phase == "D"
    c.run_samples(2047)
    assert c.mode is Mode.ALIGN
    c.run_samples(1)
    assert c.mode is Mode.POSITION and c.command_position == 0 and not c.read(R.R_FLAG) & 0x10


# ---------------------------------------------------------------- commutator
def _sequence(x, y, drive, sign):
    seq = []
    rng = range(0, 80) if sign > 0 else range(80, 0, -1)
    for r in rng:
        cur = winding_currents(commutator_mask(r, 40, x, y, 0, sign), drive)
        if not seq or seq[-1] != cur:
            seq.append(cur)
    return seq[:8] if drive == DRIVE_HALF else seq[:4]


def test_stepper_sequences():
    assert _sequence(10, 0, DRIVE_FULL_ONE, 1) == [(1, 0), (0, 1), (-1, 0), (0, -1)]
    assert _sequence(10, 0, DRIVE_FULL_TWO, 1) == [(1, 1), (-1, 1), (-1, -1), (1, -1)]
    assert _sequence(5, 5, DRIVE_HALF, 1) == [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0),
                                              (-1, -1), (0, -1), (1, -1)]
    rev = _sequence(10, 0, DRIVE_FULL_ONE, -1)
    assert rev == [(0, -1), (-1, 0), (0, 1), (1, 0)] or len(set(rev)) == 4
    assert winding_currents(PHASE_A, DRIVE_HALF, shaping=True) == (2 ** 0.5, 0.0)
    assert commutator_mask(3, 40, 10, 0, 0, 0) == 0
    assert {commutator_mask(r, 40, 10, 0, 0, 1) for r in range(40)} == {
        PHASE_A, PHASE_B, PHASE_C, PHASE_D}
