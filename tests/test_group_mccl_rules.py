"""Core rules from the MCCL manual, on plain groups (every user of groups gets them): the
per-period pulse caps, the exact delay, the working interval, the compensation slots, the
MCCL homing speeds and the in-position wait."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import finish_group, table_without_mel
from openmotion.control import Controller
from openmotion.control.groups.group import (
    ERR_SPEED,
    PERIOD_PULSES_DEFAULT,
    PERIOD_PULSES_MAX,
    Group,
    GroupError,
    GroupState,
)
from openmotion.control.guard.softlimits import working_interval
from openmotion.control.home.homing_modes import HomeConfig
from openmotion.control.loops.compensation import PitchCompTable
from openmotion.errors import MotionError


def machine(period):
    ctl = Controller(period=period)
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    return ctl


def pulses_per_period(ctl, axis, t0, t1):
    T = ctl.period
    t = np.arange(round(t0 / T), round(t1 / T) + 1) * T
    return np.diff(ctl.history.sample(axis, t).p)


def test_default_caps_and_the_32768_rule():
    assert (PERIOD_PULSES_MAX, PERIOD_PULSES_DEFAULT) == (32768, 30000.0)
    ctl = machine(0.01)
    g = Group(ctl, ["x", "y"], feed=1000.0)
    assert g.period_pulse_caps == ((30000.0, 30000.0), (30000.0, 30000.0))
    before = g.period_pulse_caps
    for bad in ([0, 1], [32769, 1], [1.5, 2], [math.nan, 1], [1]):
        with pytest.raises(MotionError):
            g.set_period_pulse_caps(speed=bad)
    assert g.period_pulse_caps == before


def test_slow_policy_keeps_every_period_under_the_cap():
    # a 10 ms period; x may run 500 mm/s x 1000 pulses/mm = 500 000 pps = 5000 per period
    ctl = machine(0.01)
    g = Group(ctl, ["x", "y"], feed=400_000.0, acc_time=0.05)
    g.set_period_pulse_caps(speed=[1500, 1500])        # 150 000 pps
    with pytest.raises(GroupError) as e:
        g.line([200_000, 50_000])
    assert e.value.code == ERR_SPEED
    g.set_axis_limit_policy("slow")
    t0 = ctl.time
    g.line([200_000, 50_000])
    t1 = finish_group(ctl, g, 60)
    n = pulses_per_period(ctl, 0, t0, t1)
    assert n.max() <= 1500 * (1 + 1e-9)
    assert n.max() >= 1500 * (1 - 1e-6)             # it runs at the cap
    assert g.position.tolist() == [200_000.0, 50_000.0]


def test_ptp_speed_is_capped_per_period():
    ctl = machine(0.01)
    g = Group(ctl, ["x"], feed=1000.0)
    g.set_ptp_speed(100)
    g.set_period_pulse_caps(speed=[800])            # 80 000 pps < the axis's 500 000
    t0 = ctl.time
    g.ptp([40_000])
    t1 = finish_group(ctl, g, 60)
    assert pulses_per_period(ctl, 0, t0, t1).max() == pytest.approx(800)


def test_delay_counts_from_the_exact_end_and_the_next_path_starts_exactly():
    ctl = table_without_mel()
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    g.line([10_007, 0])        # ends inside a cycle
    g.delay(0.2)
    g.line([20_000, 0])
    t1 = finish_group(ctl, g)
    t = np.arange(0.0, t1, 1e-6)
    moving = np.abs(ctl.history.sample(0, t).v) > 1e-9
    edges = t[np.nonzero(np.diff(moving.astype(int)))[0] + 1]
    assert edges[2] - edges[1] == pytest.approx(0.2, abs=3e-6)
    assert g.position.tolist() == [20_000.0, 0.0]


def test_delay_on_an_idle_group_starts_now():
    ctl = table_without_mel()
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    ctl.advance(0.01)
    t_q = ctl.time
    g.delay(0.05)
    assert g.state is GroupState.MOVING
    g.line([1000, 0])
    t1 = finish_group(ctl, g)
    t = np.arange(t_q, t1, 1e-6)
    v = ctl.history.sample(0, t).v
    assert t[np.nonzero(np.abs(v) > 1e-9)[0][0]] - t_q == pytest.approx(0.05, abs=3e-6)


@settings(max_examples=100, deadline=None)
@given(hi=st.floats(1e-3, 1e6), lo=st.floats(-1e6, -1e-3), fh=st.floats(0, 1), fl=st.floats(0, 1))
def test_working_interval(hi, lo, fh, fl):
    a, b = working_interval(hi, lo, fh * hi, fl * -lo)
    assert a == lo + fl * -lo and b == hi - fh * hi
    assert lo <= a <= 0.0 <= b <= hi
    with pytest.raises(MotionError):
        working_interval(hi, lo, hi * 1.01 + 1.0, 0.0)
    with pytest.raises(MotionError):
        working_interval(hi, lo, 0.0, -lo * 1.01 + 1.0)
    with pytest.raises(MotionError):
        working_interval(hi, -lo, 0.0, 0.0)


def test_compensation_slots_for_the_stroke():
    fw = [0] * 256
    fw[:8] = [22, 20, 15, 11, 0, 10, 12, 15]
    t = PitchCompTable.from_slots(10000, 4, fw, [0] * 256, (-40000.0, 30000.0))
    assert t.span == (-40000, 30000) and t.forward == (22, 20, 15, 11, 0, 10, 12, 15)
    assert t.value(15000, 1) == 11                  # 10 + round(0.5 x 2)
    with pytest.raises(MotionError, match="cover"):
        PitchCompTable.from_slots(10000, 4, fw, [0] * 256, (-40001.0, 30000.0))
    with pytest.raises(MotionError, match="cover"):
        PitchCompTable.from_slots(10000, 250, fw, [0] * 256, (0.0, 60001.0))


def test_mccl_home_speeds_are_a_tenth():
    c = HomeConfig(mode="mccl_normal", max_vel=20000.0, str_vel=500.0, tacc=0.1, tdec=0.4)
    assert c.speed("creep") == c.speed("str") == 2000.0
    assert c.accel == 200_000.0 and c.decel == 50_000.0   # max_vel / tacc, / tdec
    h = HomeConfig(mode=1, max_vel=20000.0, str_vel=500.0, tacc=0.1)
    assert h.speed("str") == 500.0 and h.decel == h.accel  # HSL modes keep StrVel


def test_wait_in_position_ends_each_command_alone():
    ctl = table_without_mel()
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    g.enable_blend(100.0)
    g.set_wait_in_position(True)
    g.line([20_000, 0])
    g.line([20_000, 20_000])
    t1 = finish_group(ctl, g)
    t = np.arange(0.0, t1, 1e-5)
    speed = np.hypot(ctl.history.sample(0, t).v, ctl.history.sample(1, t).v)
    mid = (t > 0.5) & (t < t1 - 0.5)
    assert speed[mid].min() < 1e-6                  # it stops at the corner (no blend)
    with pytest.raises(MotionError):
        g.set_wait_in_position(1)


def test_hold_and_override_while_a_path_waits_for_its_exact_start():
    for action in ("hold", "override", "abort"):
        ctl = table_without_mel()
        g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
        g.line([10_007, 0])
        g.delay(0.2)
        g.line([20_000, 0])

        def waiting(g=g, ctl=ctl):
            r = g._run
            return r is not None and r.plan is not None and r.plan.t0 > ctl.time

        assert ctl.run_until(waiting, 5)
        if action == "hold":
            g.hold()
            assert ctl.run_until(lambda g=g: g.state is GroupState.HELD, 2)
            g.cont()
        elif action == "override":
            g.set_override(50)
        else:
            g.abort()
        finish_group(ctl, g)
        assert g.position.tolist() == ([10_007.0, 0.0] if action == "abort"
                                       else [20_000.0, 0.0])
