"""The shared argument checks of openmotion.errors: what they accept, what they name."""

import math
from decimal import Decimal

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from openmotion.errors import (
    MotionError,
    check_finite,
    check_int,
    check_nonnegative,
    check_positive,
)


@given(st.integers(-(2**40), 2**40), st.integers(-100, 100), st.integers(0, 200))
def test_check_int_accepts_exactly_the_ints_in_range(v, lo, span):
    hi = lo + span
    inside = lo <= v <= hi
    if inside:
        assert check_int("n", v, lo, hi) == v
    else:
        with pytest.raises(MotionError, match=rf"^n must be an integer in \[{lo}, {hi}\], "):
            check_int("n", v, lo, hi)
    assert (v >= lo) == _accepted(lambda: check_int("n", v, lo))


def _accepted(call) -> bool:
    try:
        call()
    except MotionError:
        return False
    return True


@pytest.mark.parametrize("bad", [True, 3.0, "3", None, np.int64(3), Decimal(3)])
def test_check_int_refuses_what_is_not_a_python_int(bad):
    with pytest.raises(MotionError, match=r"^capacity must be an integer >= 1, got "):
        check_int("capacity", bad, 1)


@pytest.mark.parametrize("check", [check_finite, check_positive, check_nonnegative])
def test_strict_refuses_what_only_converts_to_a_number(check):
    assert check("x", np.int64(2)) == 2.0  # the lenient form converts a numpy number
    with pytest.raises(MotionError, match=r"^x must be a real number, got "):
        check("x", np.int64(2), strict=True)


@pytest.mark.parametrize("check", [check_finite, check_positive, check_nonnegative])
@pytest.mark.parametrize("strict", [False, True])
@pytest.mark.parametrize("bad", [True, False, "1.5", Decimal("1.5"), None, 1j,
                                 np.array([1.0]), np.array(1.0), [1.0], np.bool_(True)])
def test_what_is_not_a_real_number_is_refused(check, strict, bad):
    """#12 defects 8 and 11: "5000", Decimal and bool passed and broke later."""
    with pytest.raises(MotionError, match=r"^x must be a real number, got "):
        check("x", bad, strict=strict)


@pytest.mark.parametrize("strict", [False, True])
def test_numbers_beyond_the_float_range_are_not_finite(strict):
    with pytest.raises(MotionError, match=r"^x must be finite"):
        check_finite("x", 10**400, strict=strict)
    with pytest.raises(MotionError, match=r"^x must be finite"):
        check_positive("x", math.inf, strict=strict)
    assert check_nonnegative("x", 2, strict=strict) == 2.0
    assert check_positive("x", np.float64(0.5), strict=strict) == 0.5  # a float subclass
