"""Tests for openmotion.units: scale from mechanism parameters, sign, vectorization, limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, default_machine
from openmotion.errors import MotionError
from openmotion.units import AxisUnits, pulses_per_unit


def units(**kw) -> AxisUnits:
    return AxisUnits.from_axis(AxisConfig(name="x", **kw))


def test_mm_scale_follows_mccl_formula():
    # MCCL: distance = pulse * pitch / (PPR * gear)  =>  1 mm = 10000 * 2 / 5 pulses
    u = units(pulses_per_rev=10000, lead=5.0, gear_ratio=2.0, unit="mm")
    assert u.pulses_per_unit == 4000.0
    assert u.to_pulses(1.0) == 4000.0
    assert u.to_units(4000.0) == 1.0


def test_inch_uses_same_formula():
    u = units(pulses_per_rev=2000, lead=0.2, gear_ratio=1.0, unit="inch", max_speed=10.0)
    assert u.pulses_per_unit == pytest.approx(10000.0)


def test_degree_lead_is_degrees_per_output_revolution():
    u = units(pulses_per_rev=7200, lead=360.0, gear_ratio=5.0, unit="degree", max_speed=90.0)
    assert u.pulses_per_unit == 100.0
    assert u.to_pulses(360.0) == 7200 * 5


def test_pulse_unit_is_identity_whatever_the_mechanism():
    u = units(pulses_per_rev=1234, lead=7.0, gear_ratio=3.0, unit="pulse", max_speed=1000.0)
    assert u.pulses_per_unit == 1.0
    assert u.to_pulses(17.0) == 17.0
    assert pulses_per_unit(1234, 3.0, 7.0, "pulse") == 1.0


def test_reverse_flips_signed_quantities_not_magnitudes():
    fwd = units(reverse=False)
    rev = units(reverse=True)
    assert rev.sign == -1
    assert rev.to_pulses(2.0) == -fwd.to_pulses(2.0)
    assert rev.to_units(-2000.0) == 2.0
    assert rev.velocity_to_pps(3.0) == -3000.0
    assert rev.accel_to_pps2(4.0) == -4000.0
    assert rev.jerk_to_pps3(5.0) == -5000.0
    assert rev.scale_to_pulses(2.0) == 2000.0
    assert rev.max_speed_pps == fwd.max_speed_pps == 500.0 * 1000.0
    assert rev.validate_speed(100.0) == 100000.0


def test_vectorized_over_arrays():
    u = units(reverse=True)
    x = np.linspace(-10.0, 10.0, 101)
    p = u.to_pulses(x)
    assert isinstance(p, np.ndarray) and p.shape == x.shape
    np.testing.assert_array_equal(p, -1000.0 * x)
    np.testing.assert_allclose(u.to_units(p), x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(u.velocity_to_units(u.velocity_to_pps(x)), x, atol=1e-12)
    np.testing.assert_allclose(u.accel_to_units(u.accel_to_pps2(x)), x, atol=1e-12)
    np.testing.assert_allclose(u.jerk_to_units(u.jerk_to_pps3(x)), x, atol=1e-12)
    np.testing.assert_allclose(u.scale_to_units(u.scale_to_pulses(np.abs(x))), np.abs(x))


def test_scalar_in_scalar_out():
    u = units()
    assert isinstance(u.to_pulses(1), float)
    assert isinstance(u.to_units(1000), float)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, "1", None, True])
def test_non_finite_or_non_numbers_refused(bad):
    with pytest.raises(MotionError, match="x must"):
        units().to_pulses(bad)


def test_array_with_nan_refused():
    with pytest.raises(MotionError, match="p must contain only finite"):
        units().to_units(np.array([1.0, np.nan]))


def test_validate_speed_refuses_over_max_naming_axis():
    u = units(max_speed=200.0)
    assert u.validate_speed(200.0) == 200000.0
    with pytest.raises(MotionError, match=r"speed on axis x must be <= max_speed 200 mm/s"):
        u.validate_speed(200.001)
    with pytest.raises(MotionError, match="feed must be >= 0"):
        u.validate_speed(-1.0, name="feed")
    with pytest.raises(MotionError, match="speed must be finite"):
        u.validate_speed(math.nan)
    assert u.validate_speed_pps(200000.0) == 200000.0
    with pytest.raises(MotionError, match="axis x"):
        u.validate_speed_pps(200001.0)


def test_direct_construction_validated():
    with pytest.raises(MotionError, match="axes.q.pulses_per_unit must be > 0"):
        AxisUnits("q", "mm", 0.0)
    with pytest.raises(MotionError, match="axes.q.sign must be 1 or -1"):
        AxisUnits("q", "mm", 1.0, sign=2)
    with pytest.raises(MotionError, match="axes.q.max_speed must be > 0"):
        AxisUnits("q", "mm", 1.0, max_speed=0.0)


def test_default_machine_axes():
    m = default_machine()
    assert [AxisUnits.from_axis(a).pulses_per_unit for a in m.axes] == [1000, 2000, 4000, 100]


mech = st.fixed_dictionaries({
    "pulses_per_rev": st.integers(1, 1_000_000),
    "lead": st.floats(0.01, 1000.0),
    "gear_ratio": st.floats(0.01, 100.0),
    "unit": st.sampled_from(["mm", "inch", "degree", "pulse"]),
    "reverse": st.booleans(),
})


@settings(max_examples=200, deadline=None)
@given(mech, st.floats(-1e4, 1e4))
def test_round_trip_units_pulses(kw, x):
    u = AxisUnits("x", kw["unit"], pulses_per_unit(kw["pulses_per_rev"], kw["gear_ratio"],
                                                  kw["lead"], kw["unit"]),
                  -1 if kw["reverse"] else 1)
    assert u.to_units(u.to_pulses(x)) == pytest.approx(x, rel=1e-12, abs=1e-12)
    assert u.velocity_to_units(u.velocity_to_pps(x)) == pytest.approx(x, rel=1e-12, abs=1e-12)
    # the sign of the pulse displacement follows the direction setting
    if x != 0:
        assert math.copysign(1, u.to_pulses(x)) == math.copysign(1, x) * u.sign


@settings(max_examples=100, deadline=None)
@given(mech, st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=50))
def test_array_matches_scalar(kw, xs):
    u = AxisUnits("x", kw["unit"], pulses_per_unit(kw["pulses_per_rev"], kw["gear_ratio"],
                                                  kw["lead"], kw["unit"]),
                  -1 if kw["reverse"] else 1)
    arr = u.to_pulses(np.array(xs))
    assert list(arr) == [u.to_pulses(x) for x in xs]
