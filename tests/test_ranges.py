"""Representable ranges (openmotion.limits, docs/ranges.md) and the values that broke later.

Issue #12 defects 9 and 10: tiny and huge numbers crashed the planners (ZeroDivisionError,
OverflowError), returned NaN or a 0 s profile that jumps, or were accepted and broke the
next cycle. Each is now refused up front by check_quantity, naming parameter, rule, unit.
"""

from __future__ import annotations

import math
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import free_axes
from openmotion import limits
from openmotion.control.groups.group import Group
from openmotion.control.trigger.compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    Toggle,
    WindowJob,
)
from openmotion.errors import MotionError
from openmotion.limits import check_quantity
from openmotion.profile import (
    State,
    jerk_limited,
    jerk_limited_sync,
    quantize,
    retarget,
    scurve,
    trapezoid,
)


@pytest.mark.parametrize("call, name, unit", [
    (lambda: jerk_limited(1000, 1000, 1e5, 5e-324), "j_max", "pps^3"),
    (lambda: jerk_limited_sync([1000, 5], 1000, 1e5, 5e-324), "j_max", "pps^3"),
    (lambda: retarget(State(0), 1000, 1000, 1e-300, 1e5), "a_max", "pps^2"),
    (lambda: retarget(State(0), 1000, 1000, 1e5, 5e-324), "j_max", "pps^3"),
    (lambda: scurve(1000, 0, 1000, 1e300, 0.1, 0, 0), "tacc", " s"),
    (lambda: quantize(jerk_limited(10, 100, 1e3, 1e4), 5e-324), "period", " s"),
    (lambda: trapezoid(1000, 0, 5e-324, .1, .1), "max_vel", "pps"),
    (lambda: trapezoid(1000, 0, 1000, .1, .1, start=10**400), "start", "pulses"),
])
def test_planner_inputs_outside_the_ranges_are_refused(call, name, unit):
    with pytest.raises(MotionError, match=name) as info:
        call()
    assert unit in str(info.value)


def test_move_ratio_out_of_range_changes_nothing():
    ctl = free_axes(1)
    x = ctl["x"]
    before = (x.counters.move_ratio, x.counters.error)
    for bad in (5e-324, 1e300, 0.0, -1.0, math.nan, True, "2"):
        with pytest.raises(MotionError, match="move_ratio"):
            x.set_move_ratio(bad)
        assert (x.counters.move_ratio, x.counters.error) == before
    ctl.advance(0.01)
    assert x.counters.error == before[1]


def test_step_loss_beyond_a_counter_is_refused_and_the_cycle_runs():
    ctl = free_axes(1)
    for bad in (10**400, 2**31, 1.0, True, np.float64(3)):
        with pytest.raises(MotionError, match="pulses"):
            ctl.hardware.scenario.inject_step_loss(0, bad)
    ctl.hardware.scenario.inject_step_loss(0, np.int64(3))  # a numpy integer is an integer
    ctl.advance(0.01)


@pytest.mark.parametrize("bad", [[10**400, 0], [1e13, 0], [True, 0], ["1", 0], [None, 0]])
def test_group_points_beyond_float_range_are_refused(bad):
    ctl = free_axes(2)
    g = Group(ctl, ["x", "y"], feed=1000.0, acc_time=0.1)
    with pytest.raises(MotionError, match="target"):
        g.line(bad)
    assert g.queue_length == 0


def test_compare_tables_beyond_float_range_are_refused():
    ctl = free_axes(2)
    eng = CompareEngine(ctl)
    with pytest.raises(MotionError, match="levels"):
        LevelJob(AxisSource(0), [10**400], Toggle(0))
    with pytest.raises(MotionError, match="levels"):
        LevelJob(AxisSource(0), ["5"], Toggle(0))
    with pytest.raises(MotionError, match="points"):
        WindowJob([0, 1], [[10**400, 0.0]], 1.0, Toggle(0))
    with pytest.raises(MotionError, match="axes"):
        WindowJob("xy", [[1.0, 0.0]], 1.0, Toggle(0))
    assert eng is not None


# ------------------------------------------------------------------ the checker itself
@pytest.mark.parametrize("kind", sorted(limits.RANGES))
def test_every_kind_has_a_documented_row(kind):
    with open(Path(__file__).parents[1] / "docs" / "ranges.md", encoding="utf-8") as f:
        text = f.read()
    assert f"`{kind}`" in text


@settings(max_examples=400, derandomize=True, deadline=None)
@given(st.sampled_from(sorted(k for k in limits.RANGES if k != "count")),
       st.one_of(st.floats(allow_nan=True), st.integers(-10**400, 10**400)),
       st.booleans(), st.booleans())
def test_check_quantity_accepts_exactly_its_range(kind, value, zero, signed):
    r = limits.RANGES[kind]
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    m = abs(x)
    ok = math.isfinite(x) and m <= r.maximum and (signed or x >= 0.0) \
        and (zero or x != 0.0) and (signed or zero or x == 0.0 or m >= r.minimum)
    try:
        got = check_quantity("q", value, kind, zero=zero, signed=signed)
    except MotionError as e:
        assert not ok, (value, kind, zero, signed)
        assert str(e).startswith("q must ")
        assert r.unit in str(e)
    else:
        assert ok, (value, kind, zero, signed)
        assert got == x


@pytest.mark.parametrize("bad", [True, "1", Decimal(1), None, np.array([1.0]), [1.0], 1j])
def test_check_quantity_refuses_non_numbers(bad):
    with pytest.raises(MotionError, match="^q must be a real number"):
        check_quantity("q", bad, "pps")
