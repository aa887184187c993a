"""Counters of HSL-4XMO section 4.9: 28-bit wrap, independence, error through move ratio."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.control.core.counters import CLOCK_HZ, COUNTER_MAX, COUNTER_MIN, Counters, wrap28
from openmotion.control.core.states import TRANSITIONS, AxisState, can_transition, transition
from openmotion.errors import MotionError


@given(st.integers(-(2**40), 2**40))
@settings(max_examples=200)
def test_wrap28_range_and_congruence(x):
    w = wrap28(x)
    assert COUNTER_MIN <= w <= COUNTER_MAX
    assert (w - x) % (1 << 28) == 0


def test_wrap28_edges():
    assert wrap28(COUNTER_MAX) == COUNTER_MAX
    assert wrap28(COUNTER_MAX + 1) == COUNTER_MIN
    assert wrap28(COUNTER_MIN - 1) == COUNTER_MAX


def test_command_counter_wraps_with_pulses():
    c = Counters()
    c.set_command(COUNTER_MAX - 2)
    c.update(5, 5, 0.0)
    assert c.command == COUNTER_MIN + 2
    assert c.feedback == 5


@given(st.integers(-(2**30), 2**30), st.integers(-(2**30), 2**30),
       st.integers(COUNTER_MIN, COUNTER_MAX))
@settings(max_examples=100)
def test_setting_one_counter_leaves_others(pulses, enc, value):
    c = Counters()
    c.set_general(0, source="command")
    c.update(pulses, enc, 1.0)
    before = (c.command, c.feedback, c.error, c.general)
    c.set_command(value)
    assert c.command == value
    assert (c.feedback, c.error, c.general) == before[1:]
    c.set_feedback(value)
    assert c.feedback == value and c.error == before[2] and c.general == before[3]
    c.set_general(value)
    assert c.general == value and c.error == before[2]


def test_error_counter_through_move_ratio():
    c = Counters(move_ratio=2.5)
    c.update(1000, 2500, 0.0)   # 1000 pulses out, 2500 encoder counts = 1000 pulses back
    assert c.error == 0
    c.update(1000, 2400, 0.0)   # 40 command pulses lost
    assert c.error == 40
    c.reset_error()
    assert c.error == 0
    c.update(1100, 2400, 0.0)
    assert c.error == 100


def test_move_ratio_change_keeps_error_reading():
    c = Counters()
    c.update(100, 90, 0.0)
    assert c.error == 10
    c.set_move_ratio(2.0)
    assert c.error == 10
    with pytest.raises(MotionError, match="move_ratio"):
        c.set_move_ratio(0.0)


def test_general_counter_sources():
    c = Counters()
    assert c.general_source == "manual"
    c.update(10, 20, 1.0)
    assert c.general == 0
    c.set_general(5, source="feedback")
    c.update(10, 30, 1.0)
    assert c.general == 15
    c.set_general(0, source="clock")
    c.update(10, 30, 1.5)
    assert c.general == round(0.5 * CLOCK_HZ)
    with pytest.raises(MotionError, match="source"):
        c.set_general(0, source="bogus")
    assert c.general_source == "clock"


@pytest.mark.parametrize("bad", [0.5, float("nan"), 2**27, -(2**27) - 1, "x"])
def test_counter_set_refuses_bad_values(bad):
    c = Counters()
    c.update(7, 7, 0.0)
    snap = c.snapshot()
    with pytest.raises(MotionError):
        c.set_command(bad)
    with pytest.raises(MotionError):
        c.reset_target(bad)
    assert c.snapshot() == snap


def test_target_recorder():
    c = Counters()
    c.add_target(100)
    c.add_target(-30)
    assert c.target == 70
    c.reset_target(5)
    assert c.target == 5


def test_reset_all_clears_counters_not_target():
    c = Counters()
    c.add_target(10)
    c.update(50, 40, 0.0)
    c.reset_all()
    assert (c.command, c.feedback, c.error, c.general) == (0, 0, 0, 0)
    assert c.target == 10


def test_state_table():
    S = AxisState
    for src in S:
        assert can_transition(src, S.ERROR_STOP)
    assert can_transition(S.DISABLED, S.STANDSTILL)
    assert not can_transition(S.DISABLED, S.DISCRETE_MOTION)
    assert not can_transition(S.STOPPING, S.DISCRETE_MOTION)
    assert not can_transition(S.ERROR_STOP, S.DISCRETE_MOTION)
    assert set(TRANSITIONS) == set(S)
    with pytest.raises(MotionError, match="Stopping -> ContinuousMotion"):
        transition(S.STOPPING, S.CONTINUOUS_MOTION)


@given(st.integers(-(2**30), 2**30), st.integers(-(2**30), 2**30),
       st.integers(-(2**30), 2**30), st.integers(-(2**30), 2**30),
       st.sampled_from(("command", "feedback", "clock", "manual")),
       st.floats(0.25, 4.0))
@settings(max_examples=100)
def test_readings_at_equal_the_counters_at_those_totals(pulses, enc, p2, e2, src, ratio):
    """readings_at(p, e, t) is what the counters would read with raw totals (p, e) at t."""
    c = Counters(ratio)
    c.update(pulses, enc, 2.0)
    c.set_command(12)
    c.set_feedback(-7)
    c.reset_error()
    c.set_general(3, source=src)
    offset = c.command_offset
    assert c.command == wrap28(pulses + offset)
    assert c.encoder_raw() == enc
    seen = c.readings_at(p2, e2, 3.5)
    c.update(p2, e2, 3.5)
    assert seen == (c.command, c.feedback, c.error, c.general)
    assert c.command_offset == offset  # moving the totals never touches the offsets
