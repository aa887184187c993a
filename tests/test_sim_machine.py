"""SimMachine with stepper plants: pulses, exact switch edges, hysteresis, logic levels,
step loss, scenario actions, E-stop, validation. Virtual time only."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, DriveConfig, MachineConfig, SwitchConfig
from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand, Hardware
from openmotion.hw.sim import SimMachine

DT = 0.001


def machine(*axes: AxisConfig, **kw) -> SimMachine:
    return SimMachine(MachineConfig(axes=axes or (AxisConfig("x"),), **kw))


def run_const_accel(m: SimMachine, axis: int, a: float, t_end: float) -> list:
    """p = a t^2 / 2 from rest, one cubic per 1 ms cycle; returns all edges."""
    edges = []
    n = round(t_end / DT)
    for k in range(n):
        t0 = k * DT
        m.command(axis, AxisCommand(t0, DT, 0.5 * a * t0 * t0, a * t0, a, 0.0))
        edges += m.advance(t0 + DT)
    return edges


def test_implements_hardware_protocol():
    assert isinstance(machine(), Hardware)


def test_ideal_stepper_follows_every_pulse_and_ends_on_target():
    m = machine()
    # a jerk-limited rise and fall to exactly 1234 pulses, split across cycles at odd times
    j = 4e8
    edges = []
    t = 0.0
    # up with +j for T, -j for T: p(2T) = j T^3 ; choose T so the peak is 1234 at rest? use
    # a symmetric S move: +j T, -j 2T, +j T ends at rest with p = 2 j T^3
    T = (1234 / (2 * j)) ** (1 / 3)
    segs = [(T, j), (2 * T, -j), (T, j)]
    p, v, a = 0.0, 0.0, 0.0
    for dur, jj in segs:
        m.command(0, AxisCommand(t, dur, p, v, a, jj))
        for k in range(1, 4):
            edges += m.advance(t + dur * k / 3)
            rb = m.read_axis(0)
            assert rb.pulses_out == rb.encoder
            assert m.motor_position(0) == rb.pulses_out
        p += v * dur + a * dur**2 / 2 + jj * dur**3 / 6
        v += a * dur + jj * dur**2 / 2
        a += jj * dur
        t += dur
    assert p == pytest.approx(1234, abs=1e-6)
    m.advance(t + 0.01)
    assert m.read_axis(0).pulses_out == 1234
    assert m.read_axis(0).encoder == 1234
    assert m.steps_lost(0) == 0


@pytest.mark.parametrize("half", [True, False])
@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-3e5, 3e5), st.floats(-3e8, 3e8)), min_size=1, max_size=6))
def test_pulse_count_follows_the_pulse_rule(half, pieces):
    """Monotone-or-not command chains: the count equals a dense brute-force scan of the
    rule. Half-pulse (default): pulse k at k - 1/2 up, k + 1/2 down (round to nearest).
    Floor (opt-out): pulse k at k itself (the last integer reached)."""
    m = machine()
    m.set_half_pulse(half)
    h = 0.5 if half else 0.0
    t, p = 0.0, 0.0
    for v, a in pieces:
        m.command(0, AxisCommand(t, DT, p, v, a))
        # brute force the rule on a dense grid (test-only loop)
        count = m.read_axis(0).pulses_out
        n = 2000
        for i in range(1, n + 1):
            s = DT * i / n
            u = p + v * s + a * s * s / 2
            if u >= count + 1 - h - 1e-9:
                count = math.floor(u + h + 1e-9)
            elif u <= count - 1 + h + 1e-9:
                count = math.ceil(u - h - 1e-9)
            if half:
                assert abs(count - u) <= 0.5 + 1e-9  # the quantization bound
        m.advance(t + DT)
        assert m.read_axis(0).pulses_out == count
        p += v * DT + a * DT * DT / 2
        t += DT


@pytest.mark.parametrize("half", [True, False])
def test_switch_edges_at_exact_analytic_times(half):
    a = 2e6
    ax = AxisConfig("x", org=SwitchConfig(1000.5, 200.0), pel=SwitchConfig(5000.0, 1e9))
    m = machine(ax)
    m.set_half_pulse(half)
    edges = [e for e in run_const_accel(m, 0, a, 0.08) if e.signal != "ez"]
    # stepper: org turns on at count 1001, off at 1201; pel on at 5000
    want = [("org", True, 1001), ("org", False, 1201), ("pel", True, 5000)]
    assert [(e.signal, e.level) for e in edges] == [w[:2] for w in want]
    for e, (_, _, k) in zip(edges, want, strict=True):
        # pulse k leaves when the command p = a t^2/2 reaches k - 1/2 (k: floor rule)
        kk = k - 0.5 if half else k
        assert abs(e.time - math.sqrt(2 * kk / a)) < 1e-9
        assert e.encoders == (k,)


def test_edges_time_ordered_across_axes_and_carry_all_encoders():
    axes = (AxisConfig("x", org=SwitchConfig(300.0, 10.0)),
            AxisConfig("y", org=SwitchConfig(100.0, 10.0)))
    m = machine(*axes)
    m.command(0, AxisCommand(0.0, DT, 0.0, 1e6))
    m.command(1, AxisCommand(0.0, DT, 0.0, 4e5))
    edges = [e for e in m.advance(DT) if e.signal == "org"]
    times = [e.time for e in edges]
    assert times == sorted(times)
    # pulse 100 of y leaves when its command reaches 99.5 (248.75 us); x's command is then
    # at 248.75, so x has emitted 249 pulses
    first = edges[0]
    assert first.axis == 1 and abs(first.time - 2.4875e-4) < 1e-9
    assert first.encoders == (249, 100)


def test_hysteresis_delays_release_in_both_directions():
    ax = AxisConfig("x", org=SwitchConfig(1000.0, 100.0, hysteresis=20.0))
    m = machine(ax)

    def goto(p_from, p_to, t):
        v = (p_to - p_from) / DT
        m.command(0, AxisCommand(t, DT, p_from, v))
        return [e for e in m.advance(t + DT) if e.signal == "org"]

    e = goto(0, 1105, 0.0)
    assert [(x.level, x.encoders[0]) for x in e] == [(True, 1000)]
    assert goto(1105, 1119, DT) == []          # inside the hysteresis band: still active
    e = goto(1119, 1125, 2 * DT)
    assert [(x.level, x.encoders[0]) for x in e] == [(False, 1120)]
    e = goto(1125, 1050, 3 * DT)               # back in: active below 1100
    assert [(x.level, x.encoders[0]) for x in e] == [(True, 1099)]
    e = goto(1050, 900, 4 * DT)                # release only below 980
    assert [(x.level, x.encoders[0]) for x in e] == [(False, 979)]


def test_nc_contact_reports_false_when_active():
    ax = AxisConfig("x", logic={"pel": "nc"}, pel=SwitchConfig(100.0, 1e6),
                    mel=SwitchConfig(-100.0, -1e6))
    m = machine(ax)
    assert m.read_axis(0).inputs["pel"] is True   # NC contact closed while not pressed
    assert m.read_axis(0).inputs["mel"] is False
    m.command(0, AxisCommand(0.0, DT, 0.0, 2e5))
    edges = [e for e in m.advance(DT) if e.signal == "pel"]
    assert [(e.level, e.encoders) for e in edges] == [(False, (100,))]
    assert m.read_axis(0).inputs["pel"] is False


def test_sd_edges_double_as_ltc_until_ltc_is_placed():
    ax = AxisConfig("x", sd=SwitchConfig(50.0, 10.0))
    m = machine(ax)
    m.command(0, AxisCommand(0.0, DT, 0.0, 1e5))
    sigs = [(e.signal, e.level) for e in m.advance(DT) if e.signal in ("sd", "ltc")]
    assert sigs == [("sd", True), ("ltc", True), ("sd", False), ("ltc", False)]
    m.scenario.place_switch(0, "ltc", 150.0, 1.0, at=DT)
    m.command(0, AxisCommand(DT, DT, 100.0, 1e5))
    edges = [e for e in m.advance(2 * DT) if e.signal in ("sd", "ltc")]
    assert [(e.signal, e.level, e.encoders[0]) for e in edges] == [
        ("ltc", True, 150), ("ltc", False, 151)]


def test_pullout_stepper_loses_steps_and_encoder_shows_it():
    drv = DriveConfig(type="stepper", pullout_speed=5e5, pullout_accel=1e12)
    m = machine(AxisConfig("x", drive=drv))
    edges = run_const_accel(m, 0, 1e9, 0.04)  # v reaches 5e5 at 0.5 ms
    del edges
    rb = m.read_axis(0)
    lost = m.steps_lost(0)
    # up to v = 5e5 the motor follows: p(5e-4) = 125 pulses; the rest is lost
    assert rb.pulses_out == pytest.approx(0.5 * 1e9 * 0.04**2, abs=1)
    assert lost == rb.pulses_out - 125
    assert rb.encoder == 125 and rb.encoder != rb.pulses_out


def test_pullout_accel_limit_stalls_while_accel_too_high():
    drv = DriveConfig(type="stepper", pullout_speed=1e12, pullout_accel=1e8)
    m = machine(AxisConfig("x", drive=drv))
    # accelerate hard for 1 ms (lost), then cruise for 1 ms (followed)
    m.command(0, AxisCommand(0.0, DT, 0.0, 0.0, 2e8))
    m.advance(DT)
    assert m.steps_lost(0) == 100 and m.read_axis(0).encoder == 0
    m.command(0, AxisCommand(DT, DT, 100.0, 2e5))
    m.advance(2 * DT)
    assert m.read_axis(0).pulses_out == 300
    assert m.read_axis(0).encoder == 200


def test_injected_step_loss_at_its_time_with_switch_edge():
    m = machine(AxisConfig("x", org=SwitchConfig(1000.0, 1e6)))
    m.command(0, AxisCommand(0.0, DT, 0.0, 2e6))
    m.scenario.inject_step_loss(0, 50, at=0.0002)
    edges = [e for e in m.advance(DT) if e.signal == "org"]
    rb = m.read_axis(0)
    assert rb.pulses_out == 2000 and rb.encoder == 1950 and m.steps_lost(0) == 50
    assert len(edges) == 1 and edges[0].level
    # org at motor 1000 = count 1050, whose pulse leaves at command 1049.5
    assert abs(edges[0].time - 1049.5 / 2e6) < 1e-9 and edges[0].encoders == (1000,)
    # a loss that drops the motor out of the switch releases it at the action time
    m.scenario.inject_step_loss(0, 1000, at=0.0015)
    edges = [e for e in m.advance(2 * DT) if e.signal == "org"]
    assert [(e.time, e.level, e.encoders) for e in edges] == [(0.0015, False, (950,))]


def test_estop_and_digital_inputs_fire_at_their_times():
    m = machine(AxisConfig("x", logic={"emg": "nc"}))
    assert m.read_input("emg") is True   # NC button, not pressed: closed
    m.scenario.press_estop(at=0.00025)
    m.scenario.release_estop(at=0.0031)
    m.scenario.set_input("di3", True, at=0.0007)
    edges = []
    for k in range(1, 5):
        edges += m.advance(k * DT)
    got = [(e.time, e.axis, e.signal, e.level) for e in edges if e.signal != "ez"]
    assert got == [(0.00025, None, "emg", False), (0.0007, None, "di3", True),
                   (0.0031, None, "emg", True)]
    assert m.read_input("di3") is True and m.scenario.pending == 0


def test_alarm_on_stepper_stops_motor_and_reports_alm_rdy():
    m = machine()
    m.scenario.trip_alarm(0, at=0.0005)
    m.scenario.clear_alarm(0, at=0.0015)
    m.command(0, AxisCommand(0.0, 2 * DT, 0.0, 1e5))
    edges = [(e.time, e.signal, e.level) for e in m.advance(2 * DT) if e.signal != "ez"]
    assert edges == [(0.0005, "alm", True), (0.0005, "rdy", False),
                     (0.0015, "alm", False), (0.0015, "rdy", True)]
    assert m.steps_lost(0) == 100
    assert m.read_axis(0).encoder == 100


def test_outputs_read_back():
    m = machine()
    m.write_output(None, "do2", True)
    m.write_output(0, "erc", True)
    assert m.read_output(None, "do2") and m.read_output(0, "erc")
    assert not m.read_output(0, "svon")


def test_command_jump_emits_pulses_at_once():
    m = machine(AxisConfig("x", org=SwitchConfig(10.0, 5.0)))
    m.command(0, AxisCommand(0.0, DT, 20.0))
    edges = [(e.time, e.level) for e in m.advance(DT) if e.signal == "org"]
    assert edges == [(0.0, True), (0.0, False)]
    assert m.read_axis(0).pulses_out == 20 == m.read_axis(0).encoder


def test_command_holds_end_after_its_cycle():
    m = machine()
    m.command(0, AxisCommand(0.0, DT, 0.0, 1e5))
    m.advance(5 * DT)
    assert m.read_axis(0).pulses_out == 100


@pytest.mark.parametrize("call", [
    lambda m: m.command(2, AxisCommand(0.0, DT, 0.0)),
    lambda m: m.command(0, AxisCommand(0.0, DT, float("nan"))),
    lambda m: m.command(0, AxisCommand(0.0, -DT, 0.0)),
    lambda m: m.command(0, (0.0, DT, 0.0)),
    lambda m: m.advance(-1.0),
    lambda m: m.advance(float("inf")),
    lambda m: m.write_output(0, "foo", True),
    lambda m: m.write_output(None, "do16", True),
    lambda m: m.write_output(0, "svon", 1),
    lambda m: m.read_input("di99"),
    lambda m: m.scenario.press_estop(at=-1.0),
    lambda m: m.scenario.place_switch(0, "ez", 0.0),
    lambda m: m.scenario.place_switch(0, "org", 0.0, width=0.0),
    lambda m: m.scenario.inject_step_loss(0, 1.5),
    lambda m: m.scenario.set_input("do1", True),
])
def test_invalid_calls_raise_and_change_nothing(call):
    m = machine()
    m.command(0, AxisCommand(0.0, DT, 0.0, 1e4))
    with pytest.raises(MotionError):
        call(m)
    assert m.time == 0.0 and m.scenario.pending == 0
    m.advance(DT)
    assert m.read_axis(0).pulses_out == 10


def test_config_validation():
    with pytest.raises(MotionError, match="drive.type"):
        machine(AxisConfig("x", drive=DriveConfig(type="hydraulic")))
    with pytest.raises(MotionError, match="config"):
        SimMachine("not a config")  # type: ignore[arg-type]
