"""Pulse accuracy: the simulator's pulse record, control.groups.accuracy, and the exact distance
to arcs that contour_error uses. Group runs on lines and arcs are in test_group_blend."""

from __future__ import annotations

import math

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller, count_accuracy, pulse_accuracy
from openmotion.control.groups import pathexec as px
from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand
from openmotion.hw.sim import SimMachine
from openmotion.path import Arc, Line


def machine() -> SimMachine:
    return SimMachine(MachineConfig(axes=(AxisConfig("x"),)))


@pytest.mark.parametrize("half", [True, False])
def test_pulse_record_has_every_pulse_at_its_exact_time(half):
    m = machine()
    m.set_half_pulse(half)
    m.record_pulses()
    a = 2e6  # p = a t^2 / 2 up over 3 cycles, then back down at constant speed
    for k in range(3):
        t0 = k * 1e-3
        m.command(0, AxisCommand(t0, 1e-3, a * t0 * t0 / 2, a * t0, a))
        m.advance(t0 + 1e-3)
    m.command(0, AxisCommand(3e-3, 1e-3, 9.0, -4e3))
    m.advance(5e-3)
    rec = m.pulse_record(0)
    t, c = rec.pulses()
    h = 0.5 if half else 0.0
    up = c[: 9]  # 1..9 on the way up: pulse k at a t^2/2 = k - h
    assert up.tolist() == list(range(1, 10))
    assert np.allclose(t[:9], np.sqrt(2.0 * (up - h) / a), atol=1e-12, rtol=0)
    down = c[9:]  # 8..5 on the way down: pulse k at 9 - 4000 (t - 3 ms) = k + h
    assert down.tolist() == [8, 7, 6, 5]
    assert np.allclose(t[9:], 3e-3 + (9.0 - (down + h)) / 4e3, atol=1e-12, rtol=0)
    assert rec.start_count == 0 and m.read_axis(0).pulses_out == 5
    assert np.allclose(rec.command_at(t), c - h * np.sign(np.r_[
        np.ones(9), -np.ones(4)]), atol=1e-9)


def test_pulse_record_validation_and_capacity():
    m = machine()
    with pytest.raises(MotionError, match="record_pulses"):
        m.pulse_record(0)
    for bad in (0, -3, 2.5, True):
        with pytest.raises(MotionError, match="capacity"):
            m.record_pulses(capacity=bad)
    with pytest.raises(MotionError, match="on"):
        m.record_pulses("yes")
    m.record_pulses(capacity=2)
    for k in range(4):  # four cycles of motion: more stretches than the capacity
        m.command(0, AxisCommand(k * 1e-3, 1e-3, 10.0 * k, 1e4))
        m.advance((k + 1) * 1e-3)
    with pytest.raises(MotionError, match="capacity"):
        m.pulse_record(0)
    m.record_pulses(False)
    with pytest.raises(MotionError, match="record_pulses"):
        m.pulse_record(0)


def test_counters_follow_the_pulse_rule_after_moves_and_stops():
    ctl = Controller()
    ctl.enable_all()
    x = ctl.axis("x")
    x.move_absolute(1000, max_vel=20_000.0, tacc=0.05)
    assert ctl.wait_motion_done(timeout=5)
    c = x.counters
    assert (c.command, c.feedback, c.error, x.position) == (1000, 1000, 0, 1000.0)
    assert ctl.hardware.read_axis(0).pulses_out == 1000
    # a decelerating stop ends between pulses: the counters show the plan rounded to
    # nearest, which is what the generator emitted; the axis keeps the float plan
    for d in (7_321, -4_567):
        x.move_relative(d, max_vel=29_876.3, tacc=0.047)
        ctl.advance(0.0737)
        x.stop()
        assert ctl.wait_motion_done(timeout=5)
        p = x.position
        assert p != round(p)  # the stop did end between pulses
        assert c.command == round(p) == ctl.hardware.read_axis(0).pulses_out
        assert c.feedback == c.command and abs(c.command - p) <= 0.5
        assert ctl.hardware.command_position(0) == pytest.approx(p, abs=1e-9)
    # the next move still ends exactly on its whole-pulse target
    x.move_absolute(-250, max_vel=30_000.0, tacc=0.05)
    assert ctl.wait_motion_done(timeout=5)
    assert (c.command, c.feedback, x.position) == (-250, -250, -250.0)


def test_count_accuracy_from_arrays_and_its_validation():
    t = np.array([0.0, 1.0, 2.0])
    cmd = np.array([[0.0, 0.0], [0.5, 0.2], [1.0, 0.4]])
    before = np.array([[0, 0], [0, 0], [1, 0]])
    after = np.array([[0, 0], [1, 0], [1, 0]])
    acc = count_accuracy(t, before, after, cmd, cmd, [Line([0, 0], [1.0, 0.4])])
    assert acc.axis_error == (0.5, 0.4)
    assert acc.command_error == (0.0, 0.0)
    assert acc.samples == 3
    # (1, 0) is the worst point: its distance to the line through (1, 0.4)
    d = 0.4 / math.hypot(1.0, 0.4)
    assert acc.contour_error == pytest.approx(d, abs=1e-12) and acc.contour_time in (1.0, 2.0)
    line = [Line([0, 0], [1, 1])]
    with pytest.raises(MotionError, match="times"):
        count_accuracy(np.zeros(0), before[:0], after[:0], cmd[:0], cmd[:0], line)
    with pytest.raises(MotionError, match="planned"):
        count_accuracy(t, before, after, cmd, cmd[:2], line)
    with pytest.raises(MotionError, match="elements"):
        count_accuracy(t, before, after, cmd, cmd, [])


def test_pulse_accuracy_validation():
    ctl = Controller()
    els = [Line([0, 0], [1, 1])]
    with pytest.raises(MotionError, match="record_pulses"):
        pulse_accuracy(ctl, ["x", "y"], els, 0.0, 1.0)
    ctl.hardware.record_pulses()
    with pytest.raises(MotionError, match="t1"):
        pulse_accuracy(ctl, ["x", "y"], els, 1.0, 1.0)
    with pytest.raises(MotionError, match="t0"):
        pulse_accuracy(ctl, ["x", "y"], els, float("nan"), 1.0)
    with pytest.raises(MotionError, match="axes"):
        pulse_accuracy(ctl, [], els, 0.0, 1.0)
    with pytest.raises(MotionError, match="axes"):
        pulse_accuracy(ctl, "xy", els, 0.0, 1.0)

    class NoRecord:  # a back end without a pulse record
        def __init__(self, hw):
            self._hw = hw

        def __getattr__(self, name):
            if name == "pulse_record":
                raise AttributeError(name)
            return getattr(self._hw, name)

    ctl2 = Controller(hardware=NoRecord(SimMachine(ctl.config)))
    with pytest.raises(MotionError, match="records pulses"):
        pulse_accuracy(ctl2, [0], els, 0.0, 1.0)


def test_contour_error_is_exact_on_arcs_and_close_on_helices():
    arc = Arc([100.0, 0.0], [0.0, 0.0], [0.0, 100.0])  # quarter circle, CCW
    pts = np.array([[0.0, 0.0], [70.0, 70.0], [100.0 + 1e-7, 0.0], [-5.0, -5.0],
                    [0.0, 100.25]])
    want = [100.0, 100.0 - math.hypot(70.0, 70.0), 1e-7, math.hypot(105.0, 5.0), 0.25]
    got = px.contour_error(pts, [arc])
    assert np.allclose(got, want, atol=1e-12, rtol=0)
    # a helix (z rises 60 over the quarter turn) goes through the general search
    hel = Arc([100.0, 0.0, 0.0], [0.0, 0.0], [0.0, 100.0, 60.0])
    s = np.linspace(0.0, hel.length, 41)
    on = hel.point(s)
    normal = -np.concatenate([on[:, :2] / 100.0, np.zeros((41, 1))], axis=1)  # to the axis
    assert px.contour_error(on, [hel]).max() < 1e-9
    assert np.allclose(px.contour_error(on + 0.3 * normal, [hel]), 0.3, atol=1e-9, rtol=0)
