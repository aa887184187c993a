"""Change of speed and of position on the fly, issued at the axis positions of HSL-4XMO
Tables 4-6 and 4-7 (manual section 4.11): accepted and refused exactly as the tables say."""

import pytest

from openmotion.control import AxisState, Controller, MotionDone
from openmotion.errors import InfeasibleError, MotionError

S = AxisState


def controller():
    c = Controller()
    c.enable_all()
    return c


def reach(c, ax, position):
    """Run until the commanded position reaches `position` (a cycle end)."""
    assert c.run_until(lambda: ax.position >= position - 1e-6, 30.0)


# Table 4-6: start_tr_move(0, 10000, 0, 1000, 0.1, 0.1); v_change at 5000 pulses.
TABLE_4_6 = [
    (5000, 0.1, True),
    (5000, 1.0, False),
    (10000, 0.1, True),
    (50000, 0.1, False),
]


def refused_then_as_planned(c, ax, planned_end, change):
    """`change()` is refused (InfeasibleError) leaving the axis exactly as it was, and the
    original move then ends on its planned time."""
    before = ax.snapshot()
    with pytest.raises(InfeasibleError):
        change()
    assert ax.snapshot() == before
    assert c.run_until(lambda: ax.motion_done == 0, 30.0, event_driven=True)
    assert planned_end - 1e-9 <= c.time <= planned_end + c.period + 1e-9


@pytest.mark.parametrize("new_vel,tacc,ok", TABLE_4_6)
def test_table_4_6_v_change(new_vel, tacc, ok):
    c = controller()
    ax = c.axis("x")
    ax.fix_speed_range(50_000)  # HSL: required before v_change above the move's MaxVel
    ax.move_relative(10_000, str_vel=0, max_vel=1000, tacc=0.1, tdec=0.1)
    planned_end = ax.motion.t_end
    reach(c, ax, 5000)
    if ok:
        ax.change_speed(new_vel, tacc)
        assert ax.state is S.DISCRETE_MOTION
        c.advance(tacc / 2)
        assert ax.motion_done == MotionDone.ACCELERATING
        top = 0.0
        while ax.motion_done:
            c.step()
            top = max(top, ax.speed)
        assert top == pytest.approx(new_vel, rel=1e-6)
        assert c.time < planned_end
    else:
        refused_then_as_planned(c, ax, planned_end, lambda: ax.change_speed(new_vel, tacc))
    assert ax.counters.command == 10_000


def test_v_change_above_move_maxvel_needs_fixed_range():
    c = controller()
    ax = c.axis("x")
    ax.move_relative(10_000, max_vel=1000, tacc=0.1)
    reach(c, ax, 5000)
    before = ax.snapshot()
    with pytest.raises(MotionError, match="speed range"):
        ax.change_speed(5000, 0.1)
    assert ax.snapshot() == before
    ax.change_speed(500, 0.1)  # slowing down is always within the range
    c.advance(0.2)
    assert ax.speed == pytest.approx(500)
    ax.unfix_speed_range()
    assert c.wait_motion_done(timeout=30)
    assert ax.counters.command == 10_000


# Table 4-7: start_ta_move(0, 10000, 0, 1000, 0.5, 1); p_change(0, 5000) at CurrentPos.
TABLE_4_7 = [
    (4000, True, False),
    (4501, False, False),
    (5000, False, False),
    (5499, False, False),
    (6000, True, True),
    (9499, True, True),
    (9500, False, False),
    (9999, False, False),
]


@pytest.mark.parametrize("current,ok,go_back", TABLE_4_7)
def test_table_4_7_p_change(current, ok, go_back):
    c = controller()
    ax = c.axis("x")
    ax.move_absolute(10_000, str_vel=0, max_vel=1000, tacc=0.5, tdec=1.0)
    planned_end = ax.motion.t_end
    reach(c, ax, current)
    assert ax.position == pytest.approx(current, abs=2)
    if ok:
        ax.change_position(5000)
        assert ax.counters.target == 5000
        highest = ax.position
        while ax.motion_done:
            c.step()
            highest = max(highest, ax.position)
        assert ax.counters.command == 5000
        assert (highest > max(current, 5000)) == go_back  # overshoot, then come back
        assert highest <= 10_000
    else:
        refused_then_as_planned(c, ax, planned_end, lambda: ax.change_position(5000))
        assert ax.counters.command == 10_000


def test_change_position_to_a_new_target_ahead():
    c = controller()
    ax = c.axis("y")
    ax.move_absolute(20_000, max_vel=40_000, tacc=0.05, shape="S")
    c.advance(0.2)
    ax.change_position(30_000)
    assert c.wait_motion_done(timeout=5)
    assert ax.counters.command == 30_000 and ax.counters.target == 30_000


def test_on_the_fly_needs_a_running_move():
    c = controller()
    ax = c.axis("x")
    before = ax.snapshot()
    with pytest.raises(MotionError, match="running move"):
        ax.change_speed(100, 0.1)
    with pytest.raises(MotionError, match="running move"):
        ax.change_position(100)
    assert ax.snapshot() == before


def test_velocity_mode_change_speed_keeps_the_original_range():
    c = controller()
    ax = c.axis("x")
    ax.move_velocity(8000, tacc=0.05)
    c.advance(0.1)
    ax.change_speed(2000, 0.05)  # down: fine
    c.advance(0.1)
    assert ax.speed == pytest.approx(2000)
    ax.change_speed(8000, 0.05)  # back up to the original MaxVel: still within range
    c.advance(0.1)
    assert ax.speed == pytest.approx(8000)
    before = ax.snapshot()
    with pytest.raises(InfeasibleError, match="speed range"):
        ax.change_speed(8001, 0.05)
    assert ax.snapshot() == before
    ax.stop()
    assert c.wait_motion_done(timeout=2)


def test_stop_during_a_jerk_limited_move():
    c = controller()
    ax = c.axis("y")
    ax.move_jerk_limited(100_000, v_max=50_000, a_max=200_000, j_max=4e6)
    c.advance(0.4)
    v = ax.speed
    assert v > 0
    ax.stop()
    assert ax.state is S.STOPPING
    top = 0.0
    while ax.motion_done:
        c.step()
        top = max(top, ax.speed)
    assert top <= 50_000 * (1 + 1e-9)
    assert ax.state is S.STANDSTILL and 0 < ax.counters.command < 100_000
    before = ax.snapshot()
    with pytest.raises(MotionError, match="running move"):
        ax.change_speed(100, 0.1)
    assert ax.snapshot() == before
