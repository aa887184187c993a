"""Safety across motion types (issue 5 done-when): interpolating groups (lines, arcs,
blending), jogs and homing are stopped by limits, soft limits, alarms and E-stop, and the
command position never passes a soft limit."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest

from helpers import table_without_mel
from openmotion.control import AxisState, Controller
from openmotion.control.groups.group import ERR_LIMIT, Group, GroupError, GroupState
from openmotion.control.home.homing import Homing
from openmotion.control.home.homing_modes import HomeConfig
from openmotion.control.manual.jog import jog_conti

FEED = 20_000.0


def group(blend: bool) -> tuple[Controller, Group]:
    ctl = table_without_mel()  # the default table's -EL sits just below 0
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=0.05)
    if blend:
        g.enable_blend(50.0)
    return ctl, g


def pulses(ctl: Controller, i: int) -> int:
    return ctl.hardware.read_axis(i).pulses_out


def run_group(ctl: Controller, g: Group, cycles: int = 6000) -> float:
    """Run until the group is idle or in error; returns the largest y command seen."""
    ymax = -np.inf
    for _ in range(cycles):
        ctl.step()
        ymax = max(ymax, pulses(ctl, 1), ctl.axes[1].position)
        if g.state is GroupState.ERROR or (g.state is GroupState.IDLE and g.queue_length == 0
                                           and not any(a.is_moving for a in g.axes)):
            break
    return ymax


@pytest.mark.parametrize("blend", [False, True])
@pytest.mark.parametrize("action", ["immediate", "decel"])
def test_group_path_over_a_soft_limit_is_refused_before_it_starts(blend: bool,
                                                                   action: str) -> None:
    ctl, g = group(blend)
    ctl.safety.soft.set("y", 10_000, -100_000)
    ctl.safety.soft.enable("y", action)
    # the arc bulges to y = 12000 although every end point is inside the limit: refused
    # when it is queued (MCCL-style negative code), the queue left as it was
    g.line([8000, 8000])
    with pytest.raises(GroupError, match=r"\+ soft limit 10000") as err:
        g.arc([12000, 8000], [16000, 8000], direction="CW")
    assert err.value.code == ERR_LIMIT
    assert g.queue_length + (g.current_index >= 0) == 1
    g.line([20000, 0])  # the program goes on below the limit
    ymax = run_group(ctl, g)
    assert g.state is GroupState.IDLE and ymax <= 10_000
    assert (pulses(ctl, 0), pulses(ctl, 1)) == (20000, 0)


@pytest.mark.parametrize("blend", [False, True])
def test_group_path_inside_the_soft_limit_runs(blend: bool) -> None:
    ctl, g = group(blend)
    ctl.safety.soft.set("y", 10_000, -100_000)
    ctl.safety.soft.enable("y", "decel")
    g.line([8000, 8000])
    g.arc([12000, 8000], [16000, 8000], direction="CCW")  # bulges down, to y = 4000
    g.line([20000, 0])
    ymax = run_group(ctl, g)
    assert g.state is GroupState.IDLE and ymax <= 10_000
    assert (pulses(ctl, 0), pulses(ctl, 1)) == (20000, 0)


def test_group_extension_over_a_soft_limit_keeps_the_axes_together() -> None:
    ctl, g = group(False)
    ctl.safety.soft.set("y", 10_000, -100_000)
    ctl.safety.soft.enable("y", "decel")
    g.line([8000, 8000])
    ctl.advance(0.2)
    with contextlib.suppress(ValueError):
        g.arc([12000, 8000], [16000, 8000], direction="CW")
    ctl.advance(2.0)
    x, y = pulses(ctl, 0), pulses(ctl, 1)
    assert y <= 10_000
    assert x == 8000 or g.state is GroupState.ERROR and abs(x - y) < 2  # on the path


@pytest.mark.parametrize("blend", [False, True])
def test_group_estop_cuts_every_axis_on_the_path(blend: bool) -> None:
    ctl, g = group(blend)
    g.line([5000, 5000])
    g.line([20000, 20000])
    ctl.hardware.scenario.press_estop(at=0.4567)
    ctl.run_until(lambda: g.state is GroupState.ERROR, 5.0)
    ctl.advance(0.05)
    x, y = pulses(ctl, 0), pulses(ctl, 1)
    assert 0 < x < 20000 and abs(x - y) <= 1  # both cut at the same instant: on the line
    for i in (0, 1):
        assert ctl.axes[i].position == pytest.approx(ctl.history.state_at(i, 0.4567).p)
        assert abs(pulses(ctl, i) - ctl.axes[i].position) < 1.0
        assert ctl.axes[i].fault == "emergency stop"


@pytest.mark.parametrize("blend", [False, True])
def test_group_alarm_stops_every_axis(blend: bool) -> None:
    ctl, g = group(blend)
    g.line([5000, 5000])
    g.arc([5000, 10000], [5000, 15000], direction="CW")
    ctl.hardware.scenario.trip_alarm(1, at=0.35)
    ctl.run_until(lambda: g.state is GroupState.ERROR, 5.0)
    ctl.advance(0.3)
    assert not any(a.is_moving for a in g.axes)
    assert ctl.axes[1].fault == "servo alarm"
    with pytest.raises(ValueError):
        g.line([0, 0])


def test_group_limit_with_edge_stop_cuts_that_axis_at_the_edge() -> None:
    ctl, g = group(False)
    ctl.safety.set_edge_stop("y", True)
    ctl.hardware.scenario.place_switch(1, "pel", 8000.0, 1000.0)
    g.line([20_000, 20_000])
    ctl.run_until(lambda: g.state is GroupState.ERROR, 5.0)
    ctl.advance(0.05)
    assert pulses(ctl, 1) == 8000  # at the edge
    # the other axis stops at the cycle end (set_edge_stop's documented limit)
    assert 8000 <= pulses(ctl, 0) <= 8000 + FEED / np.sqrt(2) * ctl.period + 1


@pytest.mark.parametrize("action", ["immediate", "decel"])
@pytest.mark.parametrize("direction", [0, 1])
def test_jog_never_passes_a_soft_limit(action: str, direction: int) -> None:
    ctl = Controller()
    ctl.enable_all()
    ax = ctl.axes[0]
    ax.move_absolute(20_000, max_vel=50_000, tacc=0.05)
    ctl.wait_motion_done([0], timeout=5.0)
    ctl.safety.soft.set(0, 30_000, 10_000)
    ctl.safety.soft.enable(0, action)
    jog_conti(ctl, 0, direction, 40.0, tacc=0.05)
    worst = 0.0
    for _ in range(20_000):
        ctl.step()
        worst = max(worst, pulses(ctl, 0) - 30_000, 10_000 - pulses(ctl, 0))
        if ax.state is AxisState.ERROR_STOP and not ax.is_moving:
            break
    assert ax.fault == ("+SL" if direction == 0 else "-SL")
    assert worst <= 0.0


def test_jog_stops_at_the_limit_edge_and_on_estop() -> None:
    ctl = Controller()
    ctl.enable_all()
    ctl.safety.set_edge_stop(0, True)
    ax = ctl.axes[0]
    ctl.hardware.scenario.place_switch(0, "pel", 15_000.0, 1000.0)
    jog_conti(ctl, 0, 0, 40.0, tacc=0.05)
    ctl.run_until(lambda: ax.state is AxisState.ERROR_STOP, 10.0)
    ctl.advance(0.05)
    assert ax.fault == "+EL" and pulses(ctl, 0) == 15_000
    ctl2 = Controller()
    ctl2.enable_all()
    jog_conti(ctl2, 0, 0, 40.0, tacc=0.05)
    ctl2.hardware.scenario.press_estop(at=0.2345)
    ctl2.advance(0.3)
    p = ctl2.history.state_at(0, 0.2345).p
    assert ctl2.axes[0].fault == "emergency stop"
    assert abs(pulses(ctl2, 0) - p) < 1.0 and ctl2.axes[0].position == pytest.approx(p)


@pytest.mark.parametrize("cause", ["estop", "alarm"])
def test_homing_is_stopped_by_estop_and_alarm(cause: str) -> None:
    ctl = Controller()
    ctl.enable_all()
    ax = ctl.axes[0]
    home = Homing(ctl, "x", HomeConfig(mode=0, str_vel=100, max_vel=20_000, tacc=0.05))
    ctl.safety.soft.set(0, 1_000_000, -1_000_000)
    home.start()
    ctl.advance(0.1)
    t = ctl.time + 0.0123
    if cause == "estop":
        ctl.hardware.scenario.press_estop(at=t)
    else:
        ctl.hardware.scenario.trip_alarm(0, at=t)
    ctl.advance(0.5)
    assert ax.state is AxisState.ERROR_STOP and not ax.is_moving
    assert not home.running
    if cause == "estop":  # the E-stop cut is in the hardware: exact
        p = ctl.history.state_at(0, t).p
        assert abs(pulses(ctl, 0) - p) < 1.0
