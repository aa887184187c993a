"""Groups: queue, indices, point-to-point, lines/arcs on the simulated XYZU table, hold,
continue, abort, override, delay, dry run, refusals and run-time faults."""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers import finish_group, table_without_mel
from openmotion.control import Controller
from openmotion.control.core.axis import AxisState
from openmotion.control.groups.group import (
    ERR_ARC,
    ERR_ARGUMENT,
    ERR_AXIS_BUSY,
    ERR_AXIS_STATE,
    ERR_GROUP,
    ERR_LIMIT,
    ERR_QUEUE_FULL,
    ERR_SPEED,
    ERR_STATE,
    Group,
    GroupError,
    GroupState,
)
from openmotion.errors import MotionError

FEED = 20_000.0
ACC_T = 0.05  # path accel 400 000 pps^2


def make(axes=("x", "y"), **kw) -> tuple[Controller, Group]:
    ctl = table_without_mel()  # the default table's -EL sits at -5 mm: allow both signs
    return ctl, Group(ctl, list(axes), feed=kw.pop("feed", FEED), acc_time=ACC_T, **kw)


finish = finish_group  # run until idle, queue empty, axes still; the end time


def sample(ctl: Controller, g: Group, t0: float, t1: float, n: int = 20001):
    t = np.linspace(t0, t1, n)
    return t, [ctl.history.sample(a.index, t) for a in g.axes]


def test_indices_and_queue_order():
    ctl, g = make()
    idx = [g.line([1000, 0]), g.delay(0.01), g.line([1000, 1000]), g.ptp([0, 0])]
    assert idx == [0, 1, 2, 3]
    assert g.queue_length == 4
    seen = []
    ctl.add_cycle_hook(lambda c, t: seen.append(g.current_index))
    finish(ctl, g)
    order = [i for k, i in enumerate(seen) if i >= 0 and (k == 0 or seen[k - 1] != i)]
    assert order == [0, 1, 2, 3]
    assert g.position.tolist() == [0.0, 0.0]
    g.reset_command_index()
    assert g.line([5, 5]) == 0


def test_line_keeps_ratio_and_axes_start_and_stop_together():
    ctl, g = make()
    t0 = ctl.time
    g.line([30_000, 12_000])
    t1 = finish(ctl, g)
    assert g.position.tolist() == [30_000.0, 12_000.0]  # exactly
    t, (sx, sy) = sample(ctl, g, t0, t1)
    moving_x, moving_y = np.abs(sx.v) > 1e-6, np.abs(sy.v) > 1e-6
    assert np.array_equal(moving_x, moving_y)
    ratio = sy.v[moving_x] / sx.v[moving_x]
    assert np.allclose(ratio, 12_000 / 30_000, rtol=1e-9)
    speed = np.hypot(sx.v, sy.v)
    assert speed.max() <= FEED * (1 + 1e-9)
    assert speed.max() >= FEED * (1 - 1e-9)  # long enough to cruise


def test_arc_stays_on_circle_and_ends_exactly():
    ctl, g = make()
    t0 = ctl.time
    g.arc([0, 10_000], [10_000, 10_000], direction="CW")  # quarter... half circle, R 10 000
    t1 = finish(ctl, g)
    assert g.position.tolist() == [10_000.0, 10_000.0]
    _, (sx, sy) = sample(ctl, g, t0, t1)
    r = np.hypot(sx.p - 0.0, sy.p - 10_000.0)
    assert np.max(np.abs(r - 10_000.0)) < 1e-3  # far inside the half-pulse bound
    speed = np.hypot(sx.v, sy.v)
    assert speed.max() <= FEED * (1 + 1e-6)


def test_circle_and_helix_end_on_target():
    ctl, g = make(("x", "y", "z"))
    g.circle([5000, 0])
    g.helix([5000, 0], [10_000, 0, 3000], direction="CW")
    finish(ctl, g)
    assert g.position.tolist() == [10_000.0, 0.0, 3000.0]


def test_ptp_waits_for_every_axis():
    ctl, g = make()
    g.set_ptp_speed(2.0)  # 2 % of 500 000 pps
    g.ptp([1000, 20_000])
    i1 = g.ptp([3000, 20_000])
    t_x_done = []
    t_second = []

    def watch(c, t):
        x = g.axes[0]
        if not x.is_moving and x.position == 1000 and not t_x_done:
            t_x_done.append(t)
        if g.current_index == i1 and not t_second:
            t_second.append(t)

    ctl.add_cycle_hook(watch)
    t0 = ctl.time
    finish(ctl, g)
    y_end = t0 + ctl.history.end_time(g.axes[1].index) - t0
    assert t_x_done and t_second
    assert t_second[0] > t_x_done[0] + 0.1  # x waited while y was still running
    assert t_second[0] >= y_end - 1e-9 or g.axes[1].position == 20_000
    assert g.position.tolist() == [3000.0, 20_000.0]


def test_two_groups_run_independently_at_the_same_time():
    ctl = Controller()
    ctl.enable_all()
    a = Group(ctl, {"x": "x", "y": "y"}, feed=FEED, acc_time=ACC_T)
    b = Group(ctl, {"z": "z", "u": "u"}, feed=FEED, acc_time=ACC_T)
    a.line([20_000, 0])
    a.line([20_000, 20_000])
    b.line([10_000, 10_000])
    b.ptp([0, 0])
    both = []
    ctl.add_cycle_hook(lambda c, t: both.append(
        a.state is GroupState.MOVING and b.state is GroupState.MOVING))
    ctl.step()
    ctl.run_until(lambda: a.state is GroupState.IDLE and b.state is GroupState.IDLE, 30)
    assert sum(both) > 100
    assert a.position.tolist() == [20_000.0, 20_000.0]
    assert b.position.tolist() == [0.0, 0.0]
    with pytest.raises(GroupError) as e:
        Group(ctl, ["x"])
    assert e.value.code == ERR_AXIS_BUSY
    a.close()
    Group(ctl, ["x"])  # released


def _square(g: Group) -> None:
    g.line([20_000, 0])
    g.line([20_000, 20_000])
    g.line([0, 20_000])
    g.arc([0, 10_000], [0, 0], direction="CCW")


def test_hold_and_continue_end_exactly_where_the_run_ends():
    ctl, g = make()
    t0 = ctl.time
    _square(g)
    ctl.advance(0.7)
    assert g.state is GroupState.MOVING
    g.hold()
    assert g.state is GroupState.HOLDING
    ctl.run_until(lambda: g.state is GroupState.HELD, 5)
    held_at = g.position
    assert all(not a.is_moving for a in g.axes)
    ctl.advance(0.2)
    assert np.array_equal(g.position, held_at)
    with pytest.raises(GroupError) as e:
        g.hold()
    assert e.value.code == ERR_STATE
    g.cont()
    t1 = finish(ctl, g)
    assert g.position.tolist() == [0.0, 0.0]
    # the whole run stays on the programmed square
    _, (sx, sy) = sample(ctl, g, t0, t1)
    on_edge = np.minimum.reduce([np.abs(sy.p), np.abs(sx.p - 20_000), np.abs(sy.p - 20_000),
                                 np.abs(np.hypot(sx.p, sy.p - 10_000) - 10_000)])
    assert on_edge.max() < 1e-3


def test_abort_stops_and_empties_the_queue():
    ctl, g = make()
    _square(g)
    g.line([5000, 5000])
    ctl.advance(0.3)
    g.abort()
    assert g.queue_length == 0
    ctl.run_until(lambda: g.state is GroupState.IDLE, 5)
    assert all(not a.is_moving for a in g.axes)
    p = g.position
    assert 0 < p[0] < 20_000 and abs(p[1]) < 1e-6  # stopped on the first line
    ctl.advance(0.2)
    assert np.array_equal(g.position, p)
    g.line([0, 0])  # the group takes new commands from where it stopped
    finish(ctl, g)
    assert g.position.tolist() == [0.0, 0.0]


def test_override_changes_speed_smoothly_on_the_path():
    ctl, g = make()
    g.set_max_pulse_acc([380_000, 380_000])
    t0 = ctl.time
    g.line([60_000, 30_000])
    ctl.advance(0.25)
    g.set_override(40)
    ctl.advance(0.4)
    g.set_override(150)
    t1 = finish(ctl, g)
    assert g.position.tolist() == [60_000.0, 30_000.0]
    _, (sx, sy) = sample(ctl, g, t0, t1)
    speed = np.hypot(sx.v, sy.v)
    assert speed.max() == pytest.approx(1.5 * FEED, rel=1e-6)
    low = speed[(np.linspace(t0, t1, speed.size) > t0 + 0.5)
                & (np.linspace(t0, t1, speed.size) < t0 + 0.6)]
    assert np.allclose(low, 0.4 * FEED, rtol=1e-6)
    for s in (sx, sy):
        assert np.max(np.abs(s.a)) <= 380_000 * (1 + 1e-9)
        assert np.max(np.abs(np.diff(s.v))) < 380_000 * (t1 - t0) / (speed.size - 1) * 1.01
    # on the line all the time
    assert np.max(np.abs(sx.p * 30_000 - sy.p * 60_000)) / math.hypot(6e4, 3e4) < 1e-6


def test_override_during_blended_path_keeps_limits():
    ctl, g = make()
    g.set_max_pulse_acc([400_000, 400_000])
    g.enable_blend(100.0)
    t0 = ctl.time
    _square(g)
    ctl.advance(0.4)
    g.set_override(30)
    ctl.advance(0.5)
    g.set_override(120)
    t1 = finish(ctl, g)
    assert g.position.tolist() == [0.0, 0.0]
    _, samples = sample(ctl, g, t0, t1)
    for s in samples:
        assert np.max(np.abs(s.a)) <= 400_000 * (1 + 1e-6)


def test_delay_between_commands():
    ctl, g = make()
    g.line([2000, 0])
    g.delay(0.25)
    g.line([2000, 2000])
    starts = {}

    def watch(c, t):
        starts.setdefault(g.current_index, t)

    ctl.add_cycle_hook(watch)
    finish(ctl, g)
    end_first = starts[1]
    assert starts[2] - end_first == pytest.approx(0.25, abs=2 * ctl.period)


def test_dry_run_plans_without_pulses():
    ctl, g = make()
    g.enable_dry_run()
    g.line([10_000, 5000])
    mid = []
    ctl.add_cycle_hook(lambda c, t: mid.append(g.position.copy()))
    finish(ctl, g)
    assert g.position.tolist() == [10_000.0, 5000.0]
    assert any(0 < p[0] < 10_000 for p in mid)
    assert [a.position for a in g.axes] == [0.0, 0.0]
    assert all(a.state is AxisState.STANDSTILL for a in g.axes)
    with pytest.raises(GroupError):
        g.line([1, 1])
        g.enable_dry_run(False)  # not idle: refused


@pytest.mark.parametrize("call, code", [
    (lambda g: g.line([float("nan"), 0]), ERR_ARGUMENT),
    (lambda g: g.line([1000, 0]), ERR_ARGUMENT),
    (lambda g: g.line([1, 2, 3]), ERR_ARGUMENT),
    (lambda g: g.arc([0, 1000], [500, 500]), ERR_ARC),
    (lambda g: g.arc3d([2000, 0], [3000, 0]), ERR_ARC),
    (lambda g: g.delay(-1.0), ERR_ARGUMENT),
])
def test_bad_commands_are_refused_and_change_nothing(call, code):
    ctl, g = make()
    g.line([1000, 0])
    before = (g.queue_length, g.state, g._tail.copy())
    with pytest.raises(GroupError) as e:
        call(g)
    assert e.value.code == code
    assert (g.queue_length, g.state) == before[:2] and np.array_equal(g._tail, before[2])
    assert g.line([1000, 1000]) == 1  # the index sequence did not move


def test_speed_checks_name_the_axis():
    ctl, g = make()
    with pytest.raises(GroupError) as e:
        g.set_feed(1e9)
    assert e.value.code == ERR_SPEED
    g.set_max_pulse_speed([5000, 50_000])
    with pytest.raises(GroupError, match="axis x") as e:
        g.line([10_000, 0])
    assert e.value.code == ERR_SPEED
    g.line([0, 10_000])  # y may run at 20 000 pps
    with pytest.raises(MotionError):
        g.set_max_pulse_speed([1, -1])


def test_queue_overflow():
    ctl, g = make(queue_size=3)
    for k in range(3):
        g.line([1000 * (k + 1), 0])
    with pytest.raises(GroupError) as e:
        g.line([9999, 1])
    assert e.value.code == ERR_QUEUE_FULL
    assert g.queue_length == 3


def test_axis_in_error_stop_refused():
    ctl, g = make()
    g.axes[1].fault_stop("test")
    with pytest.raises(GroupError) as e:
        g.line([100, 100])
    assert e.value.code == ERR_AXIS_STATE


def test_limit_switch_stops_all_axes_of_the_group():
    ctl, g = make()
    ctl.hardware.scenario.place_switch(1, "pel", 8000.0, 1000.0)
    g.line([20_000, 20_000])
    g.line([0, 0])
    ctl.step()
    ctl.run_until(lambda: g.state is GroupState.ERROR, 5)
    assert g.state is GroupState.ERROR
    assert g.error_code in (ERR_LIMIT, -10)
    assert g.queue_length == 0
    ctl.advance(0.05)
    assert all(not a.is_moving for a in g.axes)
    p = g.position
    assert 8000 <= p[1] < 9000 and abs(p[0] - p[1]) < 1e-6  # stopped together, on the path
    with pytest.raises(GroupError) as e:
        g.line([0, 0])
    assert e.value.code in (ERR_GROUP, ERR_AXIS_STATE)
    g.clear_error()
    assert g.error_code == 0 and g.state is GroupState.IDLE


def test_limit_with_safety_attached_stops_the_group_through_the_fault_hook():
    safety_mod = pytest.importorskip("openmotion.control.guard.safety")
    ctl, g = make()
    assert safety_mod.Safety.of(ctl) is not None  # attached by default
    ctl.hardware.scenario.place_switch(0, "pel", 6000.0, 1000.0)
    g.line([20_000, 10_000])
    ctl.step()
    ctl.run_until(lambda: g.state is GroupState.ERROR, 5)
    assert g.error_code == ERR_LIMIT
    assert g.axes[0].state is AxisState.ERROR_STOP
    assert not g.axes[1].is_moving
    p = g.position
    assert abs(p[0] - 2 * p[1]) < 1e-6  # both axes stopped at the same path point


def test_hold_during_delay_keeps_the_rest_of_the_delay():
    ctl, g = make()
    g.delay(0.3)
    g.line([1000, 1000])
    ctl.advance(0.1)
    g.hold()
    assert g.state is GroupState.HELD
    ctl.advance(0.5)
    assert g.position.tolist() == [0.0, 0.0]
    g.cont()
    t_cont = ctl.time
    ctl.run_until(lambda: g.current_index == 1, 2)
    assert ctl.time - t_cont == pytest.approx(0.2, abs=3 * ctl.period)
    finish(ctl, g)
    assert g.position.tolist() == [1000.0, 1000.0]


def test_slow_policy_plans_down_to_axis_limits():
    ctl, g = make()
    g.set_max_pulse_speed([8000, 50_000])
    g.set_max_pulse_acc([100_000, 1e6])
    with pytest.raises(GroupError):
        g.line([10_000, 10_000])
    g.set_axis_limit_policy("slow")
    t0 = ctl.time
    g.line([10_000, 10_000])
    t1 = finish(ctl, g)
    _, (sx, sy) = sample(ctl, g, t0, t1)
    assert np.abs(sx.v).max() <= 8000 * (1 + 1e-9)
    assert np.abs(sx.a).max() <= 100_000 * (1 + 1e-9)
    assert g.position.tolist() == [10_000.0, 10_000.0]
