"""Project error types and the argument checks every public entry point shares.

Every check raises before anything is computed or changed, and its message names the
parameter and the rule it broke, so a caller can fix the call without reading our code.
"""

from __future__ import annotations

import math
import numbers

#: Largest magnitude a PCL6045 28-bit signed counter holds (-2**27 .. 2**27 - 1).
COUNTER28_MAX = 2**27 - 1


class MotionError(ValueError):
    """Invalid argument or infeasible request. Derives from ValueError."""


class InfeasibleError(MotionError):
    """A well-formed request that the motion cannot satisfy (e.g. too little distance left)."""


def show(value: object, limit: int = 60) -> str:
    """repr of a refused value, cut to `limit` characters (10**400, long arrays)."""
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001 - a broken __repr__ must not hide the refusal
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def is_real(value: object) -> bool:
    """A real number: int, float, Fraction, numpy scalars; not bool, str, Decimal, arrays."""
    t = type(value)
    if t is float or t is int:  # the common case, without the ABC check
        return True
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def check_finite(name: str, value: float, *, strict: bool = False) -> float:
    """Return `value` as float; refuse NaN, infinities and non-numbers.

    A number is a real number (`is_real`): bool, str, Decimal, None, complex and arrays
    (even of one element) are refused, so a typing slip fails here and not deep in a
    planner. `strict` accepts only Python int and float (values read from files).
    """
    if type(value) is float and math.isfinite(value):  # the common case, decided at once
        return value
    if strict and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise MotionError(f"{name} must be a real number, got {show(value)}")
    if not is_real(value):
        raise MotionError(f"{name} must be a real number, got {show(value)} "
                          f"({type(value).__name__})")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be a real number, got {show(value)}") from None
    except OverflowError:  # an int beyond the float range
        x = math.inf
    if not math.isfinite(x):
        raise MotionError(f"{name} must be finite, got {show(value)}")
    return x


def check_positive(name: str, value: float, *, strict: bool = False) -> float:
    """Finite and strictly greater than zero (`strict`: see check_finite)."""
    x = check_finite(name, value, strict=strict)
    if x <= 0.0:
        raise MotionError(f"{name} must be > 0, got {show(value)}")
    return x


def check_nonnegative(name: str, value: float, *, strict: bool = False) -> float:
    """Finite and not below zero (`strict`: see check_finite)."""
    x = check_finite(name, value, strict=strict)
    if x < 0.0:
        raise MotionError(f"{name} must be >= 0, got {show(value)}")
    return x


def check_int(name: str, value: int, lo: int, hi: int | None = None) -> int:
    """A Python int (not bool, not 3.0) in [lo, hi], or >= lo when hi is None."""
    if isinstance(value, bool) or not isinstance(value, int) or value < lo \
            or (hi is not None and value > hi):
        rule = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise MotionError(f"{name} must be an integer {rule}, got {show(value)}")
    return value


def check_range(name: str, value: float, lo: float, hi: float) -> float:
    """Finite and within [lo, hi]."""
    x = check_finite(name, value)
    if not lo <= x <= hi:
        raise MotionError(f"{name} must be in [{lo:g}, {hi:g}], got {show(value)}")
    return x


def check_distance(name: str, value: float, limit: float = COUNTER28_MAX) -> float:
    """A finite distance (pulses) whose magnitude a 28-bit position counter can hold."""
    x = check_finite(name, value)
    if abs(x) > limit:
        raise MotionError(
            f"{name} must satisfy |{name}| <= {limit} (28-bit counter), got {show(value)}"
        )
    return x


#: Keyword arguments that are on/off flags wherever a public call takes them.
FLAG_ARGS = frozenset({"units", "relative", "absolute", "replace_running", "on", "quantize",
                       "repeat", "monotonic", "escape_only", "enabled"})


def check_flag(name: str, value: object) -> bool:
    """True or False (numpy's bool too); 1, "yes" or None are typing slips, refused."""
    if isinstance(value, bool):
        return value
    if type(value).__name__ == "bool" and type(value).__module__ == "numpy":
        return bool(value)
    raise MotionError(f"{name} must be True or False, got {show(value)}")


def check_flags(kwargs: dict[str, object]) -> None:
    """check_flag for every keyword argument named in FLAG_ARGS (the public call wrappers)."""
    if kwargs:
        for k in FLAG_ARGS.intersection(kwargs):
            check_flag(k, kwargs[k])
