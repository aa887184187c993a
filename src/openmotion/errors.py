"""Project error types and the argument checks every public entry point shares.

Every check raises before anything is computed or changed, and its message names the
parameter and the rule it broke, so a caller can fix the call without reading our code.
"""

from __future__ import annotations

import math

#: Largest magnitude a PCL6045 28-bit signed counter holds (-2**27 .. 2**27 - 1).
COUNTER28_MAX = 2**27 - 1


class MotionError(ValueError):
    """Invalid argument or infeasible request. Derives from ValueError."""


class InfeasibleError(MotionError):
    """A well-formed request that the motion cannot satisfy (e.g. too little distance left)."""


def check_finite(name: str, value: float, *, strict: bool = False) -> float:
    """Return `value` as float; refuse NaN, infinities and non-numbers.

    `strict` also refuses what only converts to a number (bool, str, Decimal, numpy
    integers): for values read from files, where "1.5" or true is a typing slip.
    """
    if strict and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise MotionError(f"{name} must be a real number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be a real number, got {value!r}") from None
    except OverflowError:  # an int beyond the float range
        x = math.inf
    if not math.isfinite(x):
        raise MotionError(f"{name} must be finite, got {value!r}")
    return x


def check_positive(name: str, value: float, *, strict: bool = False) -> float:
    """Finite and strictly greater than zero (`strict`: see check_finite)."""
    x = check_finite(name, value, strict=strict)
    if x <= 0.0:
        raise MotionError(f"{name} must be > 0, got {value!r}")
    return x


def check_nonnegative(name: str, value: float, *, strict: bool = False) -> float:
    """Finite and not below zero (`strict`: see check_finite)."""
    x = check_finite(name, value, strict=strict)
    if x < 0.0:
        raise MotionError(f"{name} must be >= 0, got {value!r}")
    return x


def check_int(name: str, value: int, lo: int, hi: int | None = None) -> int:
    """A Python int (not bool, not 3.0) in [lo, hi], or >= lo when hi is None."""
    if isinstance(value, bool) or not isinstance(value, int) or value < lo \
            or (hi is not None and value > hi):
        rule = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise MotionError(f"{name} must be an integer {rule}, got {value!r}")
    return value


def check_range(name: str, value: float, lo: float, hi: float) -> float:
    """Finite and within [lo, hi]."""
    x = check_finite(name, value)
    if not lo <= x <= hi:
        raise MotionError(f"{name} must be in [{lo:g}, {hi:g}], got {value!r}")
    return x


def check_distance(name: str, value: float, limit: float = COUNTER28_MAX) -> float:
    """A finite distance (pulses) whose magnitude a 28-bit position counter can hold."""
    x = check_finite(name, value)
    if abs(x) > limit:
        raise MotionError(
            f"{name} must satisfy |{name}| <= {limit} (28-bit counter), got {value!r}"
        )
    return x
