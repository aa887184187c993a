"""dc_servo drive in the simulator: exact motor motion under held duties, effort output,
SVON/alarm gating, encoder and switches seeing the motor."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, DCMotorConfig, DriveConfig, MachineConfig, SwitchConfig
from openmotion.errors import MotionError
from openmotion.hw.interface import EffortHardware
from openmotion.hw.sim import DCMotor, SimMachine
from openmotion.hw.sim.dcservo import DCServoPlant, motor_params
from openmotion.hw.sim.pulses import PulseGenerator


def dc_axis(name="x", **motor):
    return AxisConfig(name, pulses_per_rev=4000, encoder_lines_per_rev=1000, unit="pulse",
                      lead=4000.0, max_speed=200000.0,
                      drive=DriveConfig(type="dc_servo", motor=DCMotorConfig(**motor)))


def machine(*axes):
    return SimMachine(MachineConfig(axes=axes or (dc_axis(),)))


def test_sim_machine_is_effort_hardware():
    assert isinstance(machine(), EffortHardware)


@settings(max_examples=30, deadline=None)
@given(duties=st.lists(st.tuples(st.floats(-1.0, 1.0), st.floats(1e-5, 3e-3)),
                       min_size=1, max_size=12),
       load=st.floats(-0.02, 0.02))
def test_plant_pieces_are_monotone_and_match_the_exact_motor(duties, load):
    cfg = dc_axis(load_torque=load)
    plant = DCServoPlant(cfg)
    plant.svon = True
    ref = DCMotor(motor_params(cfg))
    scale = 4000 / (2 * math.pi)
    gen = PulseGenerator()
    t = 0.0
    m_prev = 0.0
    for duty, dt in duties:
        plant.set_effort(t, t, duty)
        pieces = plant.pieces(gen, t, t + dt)
        ref.advance(dt, duty)
        for p in pieces:
            assert p.t0 >= t and p.t1 <= t + dt + 1e-15
            assert p.m0 == pytest.approx(m_prev, abs=1e-9)
            mid = p.m_at(0.5 * (p.t0 + p.t1))
            lo, hi = min(p.m0, p.m1), max(p.m0, p.m1)
            assert lo - 1e-9 <= mid <= hi + 1e-9
            assert p.direction == (1 if p.m1 > p.m0 else -1)
            m_prev = p.m1
        t += dt
        assert plant.motor(gen) == pytest.approx(ref.theta * scale, rel=1e-12, abs=1e-9)
        assert m_prev == pytest.approx(plant.motor(gen), abs=1e-9)


def test_effort_moves_the_motor_and_encoder_counts_four_per_line():
    m = machine()
    m.write_output(0, "svon", True)
    m.command_effort(0, 0.0, 0.5)
    m.advance(0.02)
    pos = m.motor_position(0)
    assert pos > 100
    assert m.read_axis(0).encoder == math.floor(pos)  # 4000 counts/rev = 1 count per pulse
    assert m.read_axis(0).pulses_out == 0             # the pulse output follows the command


def test_effort_is_ignored_without_svon_and_during_an_alarm():
    m = machine()
    m.command_effort(0, 0.0, 1.0)
    m.advance(0.01)
    assert m.motor_position(0) == 0.0 and not m.read_axis(0).inputs["rdy"]
    m.write_output(0, "svon", True)
    assert m.read_axis(0).inputs["rdy"]
    m.scenario.trip_alarm(0, at=0.01)
    m.advance(0.02)
    assert not m.read_axis(0).inputs["rdy"]
    assert m.motor_position(0) == 0.0


def test_effort_scheduled_in_the_future_and_replaced():
    m = machine()
    m.write_output(0, "svon", True)
    m.command_effort(0, 0.005, 1.0)
    m.advance(0.004)
    assert m.motor_position(0) == 0.0
    m.advance(0.01)
    assert m.motor_position(0) > 0.0


def test_command_effort_refusals_change_nothing():
    m = SimMachine(MachineConfig(axes=(dc_axis(), AxisConfig("s"))))
    m.write_output(0, "svon", True)
    m.command_effort(0, 0.0, 0.3)
    with pytest.raises(MotionError, match="has no effort output"):
        m.command_effort(1, 0.0, 0.3)
    with pytest.raises(MotionError, match="value must be finite"):
        m.command_effort(0, 0.0, math.nan)
    m.advance(0.001)
    with pytest.raises(MotionError, match="t0 must be >= the hardware time"):
        m.command_effort(0, 0.0, -1.0)
    with pytest.raises(MotionError, match="axis must be an int"):
        m.command_effort(5, 0.001, 0.1)
    before = m.motor_position(0)
    m.advance(0.002)
    assert m.motor_position(0) > before  # still driven forward at 0.3


def test_switch_edge_is_exact_on_the_motor_motion():
    ax = dc_axis()
    from dataclasses import replace
    ax = replace(ax, org=SwitchConfig(position=300.0, width=50.0))
    m = machine(ax)
    m.write_output(0, "svon", True)
    m.command_effort(0, 0.0, 0.4)
    edges = [e for e in m.advance(0.05) if e.signal == "org"]
    assert edges and edges[0].level
    t = edges[0].time
    assert edges[0].encoders[0] == 300
    # the motor reaches the switch exactly at the edge time
    ref = DCMotor(motor_params(ax))
    ref.advance(t, 0.4)
    assert ref.theta * 4000 / (2 * math.pi) == pytest.approx(300.0, abs=1e-6)
