"""HSL-4XMO trigger comparator (4.12): single value > = <, linear function with the
after-final rule, arbitrary table, CMP pulse width and polarity, the 34,000-point scan."""

import math

import numpy as np
import pytest

from helpers import free_axes
from openmotion.control.trigger.compare import CompareEngine
from openmotion.control.trigger.hsl_trigger import HslTrigger
from openmotion.errors import MotionError


def setup(buffer_size=100_000, move_ratio=1.0):
    c = free_axes(3, move_ratio=move_ratio)
    eng = CompareEngine(c, buffer_size=buffer_size)
    return c, eng, HslTrigger(eng)


def move(c, axis, d, v=20_000.0):
    c.axes[axis].move_relative(d, max_vel=v, tacc=0.01, tdec=0.01)
    assert c.wait_motion_done(timeout=60)


def test_ccd_scan_fires_34000_times():
    # 4.12 example: table 0 -> 36000 at 6000 pps, points 1001..35000 every pulse, "="
    c, eng, h = setup()
    h.set_trigger_comparator(0, 0, 1, 0.0)
    assert h.build_compare_function(0, 1001, 35000, 1) == 34000
    h.set_auto_compare(0, 1)
    assert h.check_compare_data(0) == 1001.0
    c.axes[0].move_relative(36000, max_vel=6000, tacc=0.05, tdec=0.05)
    c.advance(1.0)
    now = h.check_compare_data(0)
    assert now == len(eng.log) + 1001  # the value block holds the next point
    assert c.wait_motion_done(timeout=10)
    a = eng.log.arrays()
    assert a["time"].size == 34000
    np.testing.assert_array_equal(a["index"], np.arange(34000))
    assert np.max(np.abs(a["positions"][:, 0] - a["value"])) < 1e-6
    # cruise at 6000 pps: one trigger every 1/6000 s
    mid = np.diff(a["time"][5000:30000])
    np.testing.assert_allclose(mid, 1 / 6000, atol=1e-9)
    # after the final point the dummy (End + Interval * count) * ratio is loaded
    assert h.check_compare_data(0) == 35000 + 34000
    assert h.check_compare_status(0)
    # default CMP: normal high, 10 us low-going pulses
    w = eng.output(0).pulse_widths(active=False)
    assert w.size == 34000
    np.testing.assert_allclose(w, 10e-6, atol=1e-12)


def test_after_final_uses_move_ratio_and_fires_if_reached():
    c, eng, h = setup(move_ratio=2.0)
    h.set_trigger_comparator(1, 0, "=", 0)
    h.build_compare_function(1, 10, 50, 10)  # 5 points, dummy (50 + 50) * 2 = 200
    h.set_auto_compare(1, 1)
    move(c, 1, 300)
    vals = eng.log.arrays()["value"]
    assert vals.tolist() == [10, 20, 30, 40, 50, 200]  # a dummy within reach fires
    assert h.check_compare_data(1) is None


def test_table_with_dummy_last_and_method_direction():
    c, eng, h = setup()
    h.set_trigger_comparator(0, 0, 2, 0)  # "=" counting up
    h.build_compare_table(0, [300, 100, 200, 1e6], 4)  # any order; 1e6 is the dummy
    h.set_auto_compare(0, 1)
    move(c, 0, 400)     # passes 300 upward, fires; 100 is next
    move(c, 0, -400)    # passes 100 downward: counting up only, nothing
    assert eng.log.arrays()["value"].tolist() == [300]
    move(c, 0, 250)     # 100 upward, then 200 upward
    assert eng.log.arrays()["value"].tolist() == [300, 100, 200]
    assert h.check_compare_data(0) == 1e6


@pytest.mark.parametrize("method,passes", [(">", 2), ("<", 1), ("=", 3), (4, 2), (5, 1)])
def test_single_value_fires_whenever_condition_comes_true(method, passes):
    c, eng, h = setup()
    h.set_trigger_comparator(0, 0, method, 500)
    for d in (1000, -1000, 1000):
        move(c, 0, d)
    assert len(eng.log) == passes
    assert h.check_compare_data(0) == 500
    np.testing.assert_allclose(eng.log.arrays()["positions"][:, 0], 500, atol=1e-9)


def test_trigger_type_and_width():
    c, eng, h = setup()
    h.set_trigger_type(1, 1)  # normal low: rising-edge pulses
    h.set_pulse_width(1, 250e-6)
    assert c.hardware.read_output(None, "do1") is False
    h.set_trigger_comparator(1, 0, "=", 100)
    move(c, 1, 200)
    line = eng.output(1)
    np.testing.assert_allclose(line.pulse_widths(active=True), [250e-6], atol=1e-12)
    assert line.edges[0][1] is True
    assert c.hardware.read_output(None, "do0") is True  # axis 0 CMP idles high


def test_feedback_source_on_a_stepper():
    c, eng, h = setup()
    h.set_trigger_comparator(0, 1, "=", 0)
    h.build_compare_function(0, 100, 900, 100)
    h.set_auto_compare(0, 1)
    move(c, 0, 1000)
    pos = eng.log.arrays()["positions"][:, 0]
    assert pos.size == 9
    assert np.max(np.abs(pos - np.arange(100, 1000, 100))) <= 1.0


def test_refusals_leave_the_running_compare_unchanged():
    c, eng, h = setup(buffer_size=100)
    h.set_trigger_comparator(0, 0, "=", 0)
    h.build_compare_function(0, 10, 50, 10)
    h.set_auto_compare(0, 1)
    bad = [
        lambda: h.build_compare_function(2, 0, 10, 1),          # axis without comparator
        lambda: h.build_compare_function(0, 0, 1000, 1),        # too long for the buffer
        lambda: h.build_compare_function(0, 0, 10, 0),
        lambda: h.build_compare_function(0, 10, 0, 1),          # interval leads away
        lambda: h.build_compare_table(0, [], 0),                # empty
        lambda: h.build_compare_table(0, [1, 2], 3),
        lambda: h.build_compare_table(0, [1, math.inf], 2),
        lambda: h.set_trigger_comparator(0, 2, "=", 0),
        lambda: h.set_trigger_comparator(0, 0, "!=", 0),
        lambda: h.set_trigger_comparator(0, 0, "=", math.nan),
        lambda: h.set_trigger_type(0, 3),
        lambda: h.check_compare_data(0, 4),
        lambda: HslTrigger(eng, cmp_outputs=(0, 99)),
    ]
    for f in bad:
        with pytest.raises(MotionError):
            f()
    assert h.check_compare_data(0) == 10.0
    move(c, 0, 99)  # the dummy (50 + 10 * 5) stays out of reach
    assert eng.log.arrays()["value"].tolist() == [10, 20, 30, 40, 50]
    h.set_auto_compare(0, 0)
    assert not h.check_compare_status(0)
