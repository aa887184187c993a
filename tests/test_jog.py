"""Jog by pulses, short stroke and continuous (MCCL 2.6.2 III); group axes are refused."""

from __future__ import annotations

import pytest

from openmotion.control import Controller
from openmotion.control.core.states import AxisState
from openmotion.control.groups.group import Group
from openmotion.control.manual.jog import jog_conti, jog_pulse, jog_space, stop_jog
from openmotion.errors import MotionError


@pytest.fixture
def ctl() -> Controller:
    c = Controller(safety=False)
    c.enable_all()
    return c


def test_jog_pulse_only_at_standstill(ctl):
    jog_pulse(ctl, "x", 100)
    with pytest.raises(MotionError, match="standstill"):
        jog_pulse(ctl, "x", 5)
    ctl.wait_motion_done(timeout=2)
    assert ctl.axis("x").position == 100
    jog_pulse(ctl, "x", -2048)
    ctl.wait_motion_done(timeout=5)
    assert ctl.axis("x").position == 100 - 2048
    for bad in (0, 2049, 1.5, True):
        with pytest.raises(MotionError):
            jog_pulse(ctl, "x", bad)


def test_jog_space_moves_user_units(ctl):
    jog_space(ctl, "y", 2.5, 10)  # 2.5 mm at 10 % of 500 mm/s
    ctl.wait_motion_done(timeout=5)
    ax = ctl.axis("y")
    assert ax.position == round(2.5 * ax.units.pulses_per_unit)
    for args in ((0.0, 10), (1.0, 0), (1.0, 101), (float("nan"), 10)):
        with pytest.raises(MotionError):
            jog_space(ctl, "y", *args)


def test_jog_conti_stops_at_the_limit_switch_ahead(ctl):
    ctl.hardware.scenario.place_switch(0, "pel", 20_000.0, 1000.0)
    jog_conti(ctl, "x", 0, 4)  # 20 000 pps
    ctl.run_until(lambda: not ctl.axis("x").is_moving, 5)
    ax = ctl.axis("x")
    assert not ax.is_moving and ax.state is AxisState.STANDSTILL
    assert 20_000 <= ax.position < 21_000  # detected, then a decelerating stop


def test_jog_conti_border_and_stop(ctl):
    jog_conti(ctl, "z", 0, 2, border=3.0)
    ctl.run_until(lambda: not ctl.axis("z").is_moving, 5)
    z = ctl.axis("z")
    assert z.position == 3.0 * z.units.pulses_per_unit
    jog_conti(ctl, "z", 1, 2)
    ctl.advance(0.2)
    assert ctl.axis("z").is_moving
    stop_jog(ctl, "z")
    ctl.run_until(lambda: not ctl.axis("z").is_moving, 5)
    assert ctl.axis("z").position < 3.0 * z.units.pulses_per_unit
    with pytest.raises(MotionError, match="ahead"):
        jog_conti(ctl, "z", 0, 2, border=-100.0)
    with pytest.raises(MotionError):
        jog_conti(ctl, "z", 2, 2)


def test_group_axes_cannot_jog(ctl):
    g = Group(ctl, ["x", "y"])
    with pytest.raises(MotionError, match="group"):
        jog_pulse(ctl, "x", 10)
    g.close()
    jog_pulse(ctl, "x", 10)
