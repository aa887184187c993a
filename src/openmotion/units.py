"""Conversion between an axis's user units (mm, inch, degree, pulse) and command pulses.

Inside openmotion everything runs in command pulses and seconds; user units exist only at
the API edge. The scale follows the MCCL mechanism parameters (MCCL manual, SYS_MACH_PARAM):

    distance = pulses * pitch / (PPR * gear_ratio)    =>  pulses_per_unit = PPR * gear / lead

- mm / inch: `lead` is the ball-screw pitch, user units of travel per screw revolution.
- degree: the same formula; `lead` is the degrees of output rotation per revolution of the
  gearbox output shaft, normally 360 (a rotary table on a gear_ratio:1 reducer).
- pulse: the user unit *is* the command pulse (pulses_per_unit = 1); lead/gear are ignored.

`reverse` (MCCL wPosToEncoderDir) flips the sign: +1 user unit is -pulses_per_unit pulses.
Positions, velocities, accelerations and jerks are signed and flip with it; speeds and
limits (magnitudes) do not. Every conversion accepts a float or a numpy array.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, overload

import numpy as np

from openmotion.errors import MotionError, check_finite, check_nonnegative, check_positive

if TYPE_CHECKING:
    from openmotion.config import AxisConfig

#: Highest pulse output frequency (pps) of the HSL-4XMO line driver (HSL manual 1.2).
MAX_PULSE_RATE = 6.55e6

ArrayLike = float | np.ndarray


def pulses_per_unit(pulses_per_rev: float, gear_ratio: float, lead: float, unit: str) -> float:
    """Command pulses per user unit for the given mechanism (see the module docstring)."""
    if unit == "pulse":
        return 1.0
    return pulses_per_rev * gear_ratio / lead


def _finite(name: str, x: ArrayLike) -> ArrayLike:
    if isinstance(x, np.ndarray):
        if not np.issubdtype(x.dtype, np.number) or not np.all(np.isfinite(x)):
            raise MotionError(f"{name} must contain only finite numbers")
        return x.astype(float, copy=False)
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise MotionError(f"{name} must be a real number, got {x!r}")
    return check_finite(name, x)


@dataclass(frozen=True)
class AxisUnits:
    """Unit conversion for one axis. Build it with `AxisUnits.from_axis(axis_config)`."""

    axis: str
    unit: str
    pulses_per_unit: float
    sign: int = 1
    max_speed: float = math.inf  # user units/s

    def __post_init__(self) -> None:
        check_positive(f"axes.{self.axis}.pulses_per_unit", self.pulses_per_unit)
        if isinstance(self.sign, bool) or not isinstance(self.sign, int) \
                or self.sign not in (1, -1):
            raise MotionError(f"axes.{self.axis}.sign must be 1 or -1, got {self.sign!r}")
        if not isinstance(self.max_speed, int | float) or isinstance(self.max_speed, bool) \
                or math.isnan(self.max_speed) or not self.max_speed > 0:
            raise MotionError(f"axes.{self.axis}.max_speed must be > 0, got {self.max_speed!r}")

    @classmethod
    def from_axis(cls, axis: AxisConfig) -> AxisUnits:
        """Conversion for a (validated) AxisConfig."""
        ppu = pulses_per_unit(axis.pulses_per_rev, axis.gear_ratio, axis.lead, axis.unit)
        return cls(axis.name, axis.unit, ppu, -1 if axis.reverse else 1, float(axis.max_speed))

    # -- derived figures --------------------------------------------------------------
    @property
    def max_speed_pps(self) -> float:
        """Maximum safe speed in command pulses per second."""
        return self.max_speed * self.pulses_per_unit

    @property
    def units_per_pulse(self) -> float:
        return 1.0 / self.pulses_per_unit

    # -- signed quantities (positions and their derivatives) ---------------------------
    @overload
    def to_pulses(self, x: float) -> float: ...
    @overload
    def to_pulses(self, x: np.ndarray) -> np.ndarray: ...
    def to_pulses(self, x: ArrayLike) -> ArrayLike:
        """Position or displacement: user units -> command pulses (float, not rounded)."""
        return _finite("x", x) * (self.sign * self.pulses_per_unit)

    @overload
    def to_units(self, p: float) -> float: ...
    @overload
    def to_units(self, p: np.ndarray) -> np.ndarray: ...
    def to_units(self, p: ArrayLike) -> ArrayLike:
        """Position or displacement: command pulses -> user units."""
        # Divide rather than multiply by the reciprocal: exact whenever p = x * ppu was.
        return _finite("p", p) / (self.sign * self.pulses_per_unit)

    def velocity_to_pps(self, v: ArrayLike) -> ArrayLike:
        """Signed velocity: user units/s -> pulses/s."""
        return _finite("v", v) * (self.sign * self.pulses_per_unit)

    def velocity_to_units(self, v_pps: ArrayLike) -> ArrayLike:
        """Signed velocity: pulses/s -> user units/s."""
        return _finite("v_pps", v_pps) / (self.sign * self.pulses_per_unit)

    def accel_to_pps2(self, a: ArrayLike) -> ArrayLike:
        """Signed acceleration: user units/s^2 -> pulses/s^2."""
        return _finite("a", a) * (self.sign * self.pulses_per_unit)

    def accel_to_units(self, a_pps2: ArrayLike) -> ArrayLike:
        """Signed acceleration: pulses/s^2 -> user units/s^2."""
        return _finite("a_pps2", a_pps2) / (self.sign * self.pulses_per_unit)

    def jerk_to_pps3(self, j: ArrayLike) -> ArrayLike:
        """Signed jerk: user units/s^3 -> pulses/s^3."""
        return _finite("j", j) * (self.sign * self.pulses_per_unit)

    def jerk_to_units(self, j_pps3: ArrayLike) -> ArrayLike:
        """Signed jerk: pulses/s^3 -> user units/s^3."""
        return _finite("j_pps3", j_pps3) / (self.sign * self.pulses_per_unit)

    # -- magnitudes (speeds, limits, lengths) -------------------------------------------
    def scale_to_pulses(self, d: ArrayLike) -> ArrayLike:
        """A magnitude (length, speed, acceleration limit): user -> pulse based, no sign."""
        return _finite("d", d) * self.pulses_per_unit

    def scale_to_units(self, d_p: ArrayLike) -> ArrayLike:
        """A magnitude: pulse based -> user units, no sign."""
        return _finite("d_p", d_p) / self.pulses_per_unit

    def validate_speed(self, speed: float, name: str = "speed") -> float:
        """Check a speed magnitude in user units/s against max_speed; return it in pps.

        Refuses negative, non-finite, and speeds above the axis's maximum safe speed
        (1e-9 relative tolerance), naming the axis.
        """
        s = check_nonnegative(name, _finite(name, speed))
        if s > self.max_speed * (1.0 + 1e-9):
            raise MotionError(
                f"{name} on axis {self.axis} must be <= max_speed {self.max_speed:g} "
                f"{self.unit}/s, got {speed!r}"
            )
        return s * self.pulses_per_unit

    def validate_speed_pps(self, speed_pps: float, name: str = "speed_pps") -> float:
        """Check a speed magnitude in pulses/s against max_speed_pps; return it."""
        s = check_nonnegative(name, _finite(name, speed_pps))
        if s > self.max_speed_pps * (1.0 + 1e-9):
            raise MotionError(
                f"{name} on axis {self.axis} must be <= max_speed {self.max_speed_pps:g} pps, "
                f"got {speed_pps!r}"
            )
        return s
