"""Servo plant: exact 2nd-order response, settling and INP, SVON/RDY/ALM, ERC, edges."""

from __future__ import annotations

import math

import numpy as np
import pytest

from openmotion.config import AxisConfig, DriveConfig, MachineConfig, SwitchConfig
from openmotion.hw.interface import AxisCommand
from openmotion.hw.sim import SimMachine

DT = 0.001


def servo(damping: float = 0.9, bw: float = 30.0, **ax) -> SimMachine:
    drv = DriveConfig(type="servo", bandwidth_hz=bw, damping=damping, inp_band=5.0)
    return SimMachine(MachineConfig(axes=(AxisConfig("x", drive=drv, **ax),)))


def rk4_reference(w: float, z: float, r, t_end: float, n: int) -> float:
    """Fine RK4 of x'' = w^2 (r - x) - 2 z w x' (test-only reference)."""
    h = t_end / n
    x = v = 0.0
    for i in range(n):
        t = i * h

        def f(t, x, v):
            return v, w * w * (r(t) - x) - 2 * z * w * v

        k1 = f(t, x, v)
        k2 = f(t + h / 2, x + h / 2 * k1[0], v + h / 2 * k1[1])
        k3 = f(t + h / 2, x + h / 2 * k2[0], v + h / 2 * k2[1])
        k4 = f(t + h, x + h * k3[0], v + h * k3[1])
        x += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return x


@pytest.mark.parametrize("damping", [0.5, 1.0, 1.7])
def test_response_matches_numerical_integration(damping):
    m = servo(damping)
    m.write_output(0, "svon", True)
    j = 3e9  # a cubic command over 10 ms, then hold

    def r(t):
        t = min(t, 0.01)
        return j * t**3 / 6

    m.command(0, AxisCommand(0.0, 0.01, 0.0, 0.0, 0.0, j))
    m.advance(0.02)
    ref = rk4_reference(2 * math.pi * 30.0, damping, r, 0.02, 20000)
    assert m.motor_position(0) == pytest.approx(ref, abs=1e-6)


def test_ramp_lag_settles_and_inp_comes_on():
    m = servo()
    m.write_output(0, "svon", True)
    edges = m.advance(0.0)
    assert {(e.signal, e.level) for e in edges} == {("rdy", True), ("inp", True)}
    v = 1e5
    m.command(0, AxisCommand(0.0, 0.05, 0.0, v))
    edges = [e for e in m.advance(0.05) if e.signal == "inp"]
    assert [e.level for e in edges] == [False]
    # steady ramp error of a 2nd-order lag: 2 z v / w
    lag = 2 * 0.9 * v / (2 * math.pi * 30.0)
    assert m.command_position(0) - m.motor_position(0) == pytest.approx(lag, rel=1e-3)
    t, on = 0.05, []
    while t < 0.3 and not on:
        t += DT
        on = [e for e in m.advance(t) if e.signal == "inp"]
    assert on and on[0].level
    rb = m.read_axis(0)
    assert rb.inputs["inp"] and abs(rb.encoder - 5000) <= 5
    m.advance(0.6)
    assert m.read_axis(0).encoder == 5000 and m.motor_position(0) == 5000.0


def test_switch_edge_time_is_where_the_motor_crosses():
    m = servo(org=SwitchConfig(2000.0, 50.0))
    m.write_output(0, "svon", True)
    m.command(0, AxisCommand(0.0, 0.03, 0.0, 1e5))
    edges = [e for e in m.advance(0.1) if e.signal == "org"]
    assert [e.level for e in edges] == [True, False]
    # re-simulate to each edge time and check the motor is on the switch boundary
    for e, level in zip(edges, (2000.0, 2050.0), strict=True):
        m2 = servo()
        m2.write_output(0, "svon", True)
        m2.command(0, AxisCommand(0.0, 0.03, 0.0, 1e5))
        m2.advance(e.time)
        assert m2.motor_position(0) == pytest.approx(level, abs=1e-6)


def test_servo_off_motor_stays_put_and_alarm_drops_ready():
    m = servo()
    m.command(0, AxisCommand(0.0, DT, 0.0, 1e5))
    m.advance(DT)
    assert m.motor_position(0) == 0.0 and m.read_axis(0).pulses_out == 100
    assert not m.read_axis(0).inputs["rdy"]
    m.write_output(0, "svon", True)  # deviation cleared at servo-on: no jump
    m.advance(0.1)
    assert m.motor_position(0) == pytest.approx(0.0, abs=1e-9)
    m.scenario.trip_alarm(0, at=0.1005)
    m.command(0, AxisCommand(0.1, 0.01, 100.0, 1e4))
    edges = [(e.time, e.signal, e.level) for e in m.advance(0.2)]
    assert (0.1005, "alm", True) in edges and (0.1005, "rdy", False) in edges
    assert (0.1005, "inp", False) in edges
    x = m.motor_position(0)
    m.advance(0.3)
    assert m.motor_position(0) == x   # stays put while in alarm


def test_erc_clears_following_error():
    m = servo()
    m.write_output(0, "svon", True)
    m.command(0, AxisCommand(0.0, 0.01, 0.0, 1e5))
    m.advance(0.01)
    x = m.motor_position(0)
    assert m.command_position(0) - x > 500
    m.write_output(0, "erc", True)
    m.advance(0.3)
    # the motor stops near where it was (it only decelerates), far from the command
    assert abs(m.motor_position(0) - x) < 1000 and m.command_position(0) - m.motor_position(0) > 0


def test_runs_are_deterministic_and_edges_ordered():
    # same run twice gives bit-identical edges (no hidden state, no clocks)
    def run():
        m = servo(org=SwitchConfig(500.0, 10.0))
        m.write_output(0, "svon", True)
        out = []
        for k in range(30):
            m.command(0, AxisCommand(k * DT, DT, k * 50.0, 5e4))
            out += m.advance((k + 1) * DT)
        return [(e.time, e.signal, e.level, e.encoders) for e in out]
    a, b = run(), run()
    assert a == b and np.all(np.diff([e[0] for e in a]) >= 0)
