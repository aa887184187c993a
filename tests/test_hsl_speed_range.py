"""The PCL6045 speed-range model (control.cards.speed_range): register grid, ramp-time range,
moves slowed or refused exactly as the range allows; axes without it stay exact."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import free_axes
from openmotion.control.cards.speed_range import (
    MAX_RANGE_PPS,
    SpeedRange,
    attach_speed_model,
    on_range,
    verify_speed,
)
from openmotion.errors import InfeasibleError, MotionError
from openmotion.profile.pcl import MoveSpec


def test_multiplier_is_the_finest_that_reaches_the_range():
    for top in (5000, 140000, 1e6, 6.5535e6):
        r = SpeedRange.for_speed(top)
        assert r.max_speed >= top * (1 - 1e-12)
        if r.divider < 4096:
            assert 65535 * 300 / (r.divider + 1) < top   # one finer would not reach it
    assert SpeedRange.for_speed(140000).divider == 140
    assert SpeedRange.for_speed(100).divider == 4096       # RMG is 12 bits
    for bad in (0, -1, math.nan, MAX_RANGE_PPS * 1.01, "x"):
        with pytest.raises(MotionError):
            SpeedRange.for_speed(bad)


@settings(max_examples=200, deadline=None)
@given(st.floats(10, 6e6), st.floats(0, 1), st.floats(0.01, 1))
def test_ramp_range_ratio_and_grid(top, sv_frac, mv_frac):
    mv = top * mv_frac
    sv = mv * sv_frac
    rng = SpeedRange.for_speed(top)
    t_min, t_max = rng.acc_time_range(sv, mv)
    steps = rng.speed_register(mv) - rng.start_register(sv)
    if steps > 0:
        assert t_max / t_min == pytest.approx(32768)
        assert t_min == pytest.approx(steps * 8 / 19.6608e6)
    assert abs(rng.grid(mv) - mv) <= rng.multiplier / 2 * (1 + 1e-9)


def test_verify_speed_refuses_bad_input():
    with pytest.raises(MotionError):
        verify_speed(-1, 5000)
    with pytest.raises(MotionError):
        verify_speed(6000, 5000)
    with pytest.raises(InfeasibleError, match="range"):
        verify_speed(0, 5000, 4000)


def test_on_range_slows_short_ramps_and_refuses_long_ones():
    spec = MoveSpec("T", 0.0, 5000.0, 0.001, 0.002)
    slow = on_range(spec)
    t_min, _ = SpeedRange.for_speed(5000).acc_time_range(0, 5000)
    assert slow.tacc == slow.tdec == pytest.approx(t_min)
    fast = on_range(spec, 140000)
    assert (fast.tacc, fast.tdec) == (0.001, 0.002)
    assert fast.max_vel == SpeedRange.for_speed(140000).grid(5000)
    with pytest.raises(InfeasibleError, match="tacc must be <="):
        on_range(MoveSpec("T", 0.0, 5000.0, 1000.0, 0.1))
    with pytest.raises(InfeasibleError, match="speed range"):
        on_range(spec, 4000)


def test_axis_with_and_without_the_model():
    c = free_axes(2)
    x, y = c.axes
    attach_speed_model(x)
    x.move_relative(5000, max_vel=5000, tacc=0.001)
    y.move_relative(5000, max_vel=5000, tacc=0.001)
    assert x.motion.spec.tacc > 0.02 and y.motion.spec.tacc == 0.001   # y stays exact
    assert c.wait_motion_done(timeout=10)
    assert x.counters.command == y.counters.command == 5000
    x.fix_speed_range(20000)
    before = x.snapshot()
    with pytest.raises(InfeasibleError):
        x.move_relative(5000, max_vel=30000, tacc=0.1)
    assert x.snapshot() == before
    x.move_velocity(7777.0, tacc=0.05)
    c.advance(0.2)
    assert x.speed == SpeedRange.for_speed(20000).grid(7777.0)
