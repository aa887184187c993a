"""A group axis stopped by a decelerating reaction: the group stops along its path.

Issue #12 (arc drift): a direct decelerating stop() of one axis of a group running an arc,
or a decelerating fault stop (a limit or alarm set to "decel"), made each axis decelerate
on its own (or the others stop at once): the axes left the arc by 416 pulses (stop) and
2693 pulses (decelerating fault) in the case below. Now every axis follows the path's own
stop to rest, as hold() does; immediate stops stay immediate.
"""

from __future__ import annotations

import math

import pytest

from openmotion.control import Controller
from openmotion.control.core.states import AxisState
from openmotion.control.groups.group import Group, GroupState

R = 20_000.0


def _arc_running() -> tuple[Controller, Group]:
    ctl = Controller()
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=100_000.0, acc_time=0.2)
    g.arc([R, 0.0], [2 * R, 0.0], direction="CW")  # centre (R, 0), through (R, R)
    ctl.advance(0.4)  # at full feed, a quarter of the way
    return ctl, g


def _drift_until_rest(ctl: Controller) -> tuple[float, int]:
    x, y = ctl["x"], ctl["y"]
    worst, n = 0.0, 0
    while (x.is_moving or y.is_moving) and n < 5000:
        ctl.step()
        n += 1
        worst = max(worst, abs(math.hypot(x.position - R, y.position) - R))
    return worst, n


@pytest.mark.parametrize("axis", ["x", "y"])
@pytest.mark.parametrize("how", ["stop", "fault"])
def test_a_decelerating_stop_of_one_axis_stops_the_group_along_its_arc(axis, how):
    ctl, g = _arc_running()
    a = ctl[axis]
    if how == "stop":
        a.stop()
    else:  # what a limit, alarm or soft limit set to "decel" does
        a.fault_stop("+EL", decelerate=True)
    assert g.state is GroupState.ERROR
    drift, cycles = _drift_until_rest(ctl)
    assert drift <= 1.0  # pulses (before: 416 for stop, 2693 for the fault)
    assert cycles > 1  # it decelerated, it did not stop at once
    assert not ctl["x"].is_moving and not ctl["y"].is_moving
    assert a.state is (AxisState.ERROR_STOP if how == "fault" else AxisState.STANDSTILL)
    other = ctl["y" if axis == "x" else "x"]
    assert other.state is AxisState.STANDSTILL
    assert ("+EL" if how == "fault" else "stopped outside the group") in g.error_message


def test_the_path_stop_is_the_hold_stop():
    """The group's stop after a decelerating axis stop ends where hold() would."""
    ctl, g = _arc_running()
    g.hold()
    _drift_until_rest(ctl)
    held = (ctl["x"].position, ctl["y"].position)
    ctl2, g2 = _arc_running()
    ctl2["x"].stop()
    _drift_until_rest(ctl2)
    assert (ctl2["x"].position, ctl2["y"].position) == pytest.approx(held, abs=1e-6)


def test_a_decelerating_fault_spliced_back_in_the_cycle_stays_on_the_arc():
    ctl, g = _arc_running()
    ctl["x"].fault_stop("+EL", decelerate=True, at=ctl.time - 0.7 * ctl.period)
    drift, _ = _drift_until_rest(ctl)
    assert drift <= 1.0


@pytest.mark.parametrize("how", ["stop_immediately", "disable", "fault"])
def test_immediate_stops_stay_immediate(how):
    ctl, g = _arc_running()
    x = ctl["x"]
    if how == "fault":
        x.fault_stop("ALM")
    else:
        getattr(x, how)()
    assert ctl["x"].motion is None and ctl["y"].motion is None
    assert g.state is GroupState.ERROR
