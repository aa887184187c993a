"""The representable range of every physical quantity, and the one check that enforces it.

A value outside its range is refused with a MotionError naming the parameter, the rule and
the unit, before anything is computed or changed. The ranges keep every product and
quotient the planners form (v^2/a, a^2/j, a/j, distance/v ...) far inside float64, so no
planner divides by a subnormal or overflows: a jerk of 5e-324 pps^3 or a ramp time of
1e300 s is not a motion anyone can run, and refusing it is better than a ZeroDivisionError
deep in a root finder or a profile of NaN seconds. docs/ranges.md is the table for users.

A quantity that must be > 0 (a speed, acceleration or jerk limit, a ramp time, a period:
what planners divide by) lies within [minimum, maximum]. A quantity that may be 0 (a start
speed, a dwell, an instant; `zero=True`) or negative (a position, a state's velocity or
acceleration; `signed=True`) is never a divisor, so only the maximum of its magnitude
applies and computed values of any size below it pass.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .errors import MotionError, check_finite, is_real, show


@dataclass(frozen=True)
class Range:
    """Magnitudes a quantity may take: [minimum, maximum] in `unit` (minimum 0: any)."""

    unit: str
    minimum: float
    maximum: float
    integer: bool = False


#: Largest position or distance, pulses: float64 keeps 2^-12 pulse resolution below 2^40.
PULSES_MAX = float(2**40)
#: Longest path element (line, arc, helix), pulses of its axes: a full circle through any
#: two representable points fits (2*pi*2*sqrt(2)*2^40 < 2^45), and the path coordinate s
#: keeps 2^-7 pulse resolution (an arc's angle s*sweep/length errs by at most length*2^-53).
PATH_LENGTH_MAX = float(2**45)
#: Velocity, pulses/s: 1 pulse in 11.6 days up to 1 Gpps (hardware tops out near 10 Mpps).
PPS_MIN, PPS_MAX = 1e-6, 1e9
#: Acceleration, pulses/s^2.
PPS2_MIN, PPS2_MAX = 1e-6, 1e13
#: Jerk, pulses/s^3.
PPS3_MIN, PPS3_MAX = 1e-6, 1e18
#: Durations (ramp times, dwell, timeouts), seconds: 1 ns up to 10^7 s (115 days).
SECONDS_MIN, SECONDS_MAX = 1e-9, 1e7
#: Sample and cycle periods, seconds: 1 us up to 10 s.
PERIOD_MIN, PERIOD_MAX = 1e-6, 10.0
#: Dimensionless ratios (gear and move ratios, scale factors).
RATIO_MIN, RATIO_MAX = 1e-6, 1e6
#: Whole pulse counts (step loss, offsets written to 32-bit counters).
COUNT_MAX = 2**31 - 1

RANGES: dict[str, Range] = {
    "pulses": Range("pulses", 0.0, PULSES_MAX),
    "pps": Range("pps", PPS_MIN, PPS_MAX),
    "pps2": Range("pps^2", PPS2_MIN, PPS2_MAX),
    "pps3": Range("pps^3", PPS3_MIN, PPS3_MAX),
    "seconds": Range("s", SECONDS_MIN, SECONDS_MAX),
    "period": Range("s", PERIOD_MIN, PERIOD_MAX),
    "ratio": Range("", RATIO_MIN, RATIO_MAX),
    "count": Range("pulses", 0.0, float(COUNT_MAX), integer=True),
}


def _rule(r: Range, zero: bool, signed: bool) -> str:
    unit = f" {r.unit}" if r.unit else ""
    mag = "|x|" if signed else "x"
    if r.integer:
        sign = "|n|" if signed else "n"
        return f"{'0 <= ' if zero and not signed else ''}{sign} <= {r.maximum:.0f}{unit}" \
            if zero or signed else f"1 <= n <= {r.maximum:.0f}{unit}"
    if r.minimum > 0.0 and not signed and not zero:
        return f"{r.minimum:g} <= {mag} <= {r.maximum:g}{unit}"
    if signed:
        return f"|x| <= {r.maximum:g}{unit}"
    return f"0 <= x <= {r.maximum:g}{unit}" if zero else f"0 < x <= {r.maximum:g}{unit}"


def check_quantity(name: str, value: object, kind: str, *, zero: bool = False,
                   signed: bool = False) -> float:
    """`value` as float (int for kind 'count') if it is a number within the range of `kind`.

    `zero` accepts exactly 0 below a positive minimum; `signed` accepts negative values
    (only the maximum applies, to the magnitude). The message names `name`, the rule and the unit.
    """
    r = RANGES[kind]
    if r.integer:
        rule = f"an integer with {_rule(r, zero, signed)}"
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise MotionError(f"{name} must be {rule}, got {show(value)}")
        n = int(value)
        if (n < 0 and not signed) or abs(n) > r.maximum or (n == 0 and not zero):
            raise MotionError(f"{name} must be {rule}, got {show(value)}")
        return n
    if type(value) is float:  # the common case: no abstract-class check
        x = value
    else:
        if not is_real(value):
            check_finite(name, value)  # type: ignore[arg-type]  # raises: not a real number
        try:
            x = float(value)  # type: ignore[arg-type]
        except OverflowError:  # an int beyond the float range
            x = math.inf
    m = abs(x)
    if not math.isfinite(x) or (x < 0.0 and not signed) or m > r.maximum \
            or (x == 0.0 and not zero) or (0.0 < m < r.minimum and not signed and not zero):
        raise MotionError(f"{name} must satisfy {_rule(r, zero, signed)}, got {show(value)}")
    return x if x != 0.0 else 0.0


def check_pulses(name: str, value: object) -> float:
    """A signed position or distance in pulses (|x| <= PULSES_MAX)."""
    return check_quantity(name, value, "pulses", zero=True, signed=True)


def isfinite_quantity(x: float, kind: str) -> bool:
    """Whether a computed (already float) value lies within the range of `kind`."""
    r = RANGES[kind]
    return math.isfinite(x) and abs(x) <= r.maximum


def check_quantity_array(name: str, x: Any, kind: str, *, zero: bool = False,
                         signed: bool = False) -> None:
    """check_quantity for every element of a float array (the batch planners)."""
    r = RANGES[kind]
    m = np.abs(x)
    bad = m > r.maximum
    if not signed:
        bad |= x < 0.0
    if not signed and not zero:
        bad |= m < r.minimum
    if not zero:
        bad |= x == 0.0
    if bad.any():
        k = int(np.flatnonzero(bad.reshape(-1))[0])
        raise MotionError(f"{name} must satisfy {_rule(r, zero, signed)} everywhere, "
                          f"got {float(x.reshape(-1)[k])!r} at flat index {k}")


def _flat_items(value: object) -> list[object] | None:
    """Elements of nested lists/tuples, or None for something else."""
    if isinstance(value, (list, tuple)):
        out: list[object] = []
        for v in value:
            sub = _flat_items(v)
            if sub is None:
                out.append(v)
            else:
                out.extend(sub)
        return out
    return None


def as_array(name: str, value: object, kind: str | None = "pulses", *, zero: bool = True,
             signed: bool = True) -> NDArray[np.float64]:
    """`value` (a sequence or array of real numbers) as a float64 array within `kind`
    (None: any finite values).

    Refuses bools, strings, Decimals and None as elements (numpy would convert them),
    integers beyond the float range (numpy raises OverflowError) and non-finite values,
    with a MotionError naming `name`. The caller checks the shape.
    """
    items = _flat_items(value)
    if items is not None:
        for k, v in enumerate(items):
            if not is_real(v):
                raise MotionError(f"{name} must hold real numbers, got {show(v)} "
                                  f"({type(v).__name__}) at flat index {k}")
    elif isinstance(value, np.ndarray):
        if value.dtype.kind not in "fiu":
            raise MotionError(f"{name} must be an array of real numbers, got dtype "
                              f"{value.dtype}")
    elif not is_real(value):
        raise MotionError(f"{name} must be a sequence of real numbers, got {show(value)} "
                          f"({type(value).__name__})")
    try:
        x = np.asarray(value, dtype=np.float64)
    except OverflowError:
        raise MotionError(f"{name} must be finite everywhere (an integer beyond the float "
                          "range)") from None
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be a sequence of real numbers of one shape") from None
    if not np.isfinite(x).all():
        raise MotionError(f"{name} must be finite everywhere, got {show(value)}")
    if kind is not None:
        check_quantity_array(name, x, kind, zero=zero, signed=signed)
    return x
