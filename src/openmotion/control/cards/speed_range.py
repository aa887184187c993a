"""PCL6045 speed-range model: the register grid behind HSL fix_speed_range / verify_speed.

The PCL6045 holds speeds in 16-bit registers (1..65535) scaled by a multiplier chosen from
the speed range (HSL-4XMO 4.6 "Relationship between Velocity and Acceleration Time"; the
model is seed-facts 1.3, with the register details of the PCL6045B datasheet):

* reference clock CLK = 19.6608 MHz; multiplier m = 300 / (RMG + 1) pps per register step,
  RMG + 1 an integer in [3, 4096]; the range top R chooses the finest multiplier whose grid
  reaches it: RMG + 1 = floor(300 * 65535 / R). Default R = the move's own MaxVel;
  `fix_speed_range(R)` fixes it (the "OverVelocity");
* StrVel register RFL = max(round(StrVel / m), ceil(MIN_START_PPS / m)): the lowest start
  speed is 3 pps (the manual: verify_speed's "minimum velocity ... 3 pps more than the 0 pps
  setting"; the exact rule is NOT FOUND, this one is our documented assumption);
  MaxVel register RFH = round(MaxVel / m);
* a linear ramp steps the speed register once every (RUR + 1) * 4 / CLK s, RUR in
  [1, 65535]: the acceleration time (StrVel -> MaxVel) lies in
  [steps * 2 * 4 / CLK, steps * 65536 * 4 / CLK], steps = RFH - RFL.
* a StrVel of 0 stays 0 in the motion (the 3 pps floor only shortens the step count):
  the manual's p_change table (4-7) needs the deceleration of exactly 0.5 * 1000 * 1.

This reproduces the manual's worked examples: range 140000, 0 -> 5000 pps: 0.000948 s and
31.08 s (as printed); range 5000: 0.02665 s and 873.24 s (printed 0.0267 and 873.587:
within 0.2 %).

`SpeedModel` applies the grid to the moves of an axis (`attach_speed_model`): with a fixed
range, speeds run at their register value (MaxVel = RFH * m: "the more OverVelocity is
used, the coarser the speed interval"; unfixed, the DLL picks the multiplier per move and
we keep the speed exact - the manual's tables are computed that way); an acceleration
time shorter than the range allows is *slowed* to the shortest one, a MaxVel above the
fixed range or a time longer than the register can count is *refused* (InfeasibleError,
nothing changes). Axes without the model stay exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import InfeasibleError, MotionError, check_finite, check_nonnegative
from ...profile.pcl import MoveSpec

if TYPE_CHECKING:
    from ..core.axis import Axis

#: PCL6045 reference clock (Hz), "19.66MHz" in the manual's specifications.
CLOCK_HZ = 19_660_800.0
#: Largest value of a 16-bit speed or rate register.
REGISTER_MAX = 65_535
#: Numerator of the multiplier m = MULT_BASE / (RMG + 1) (RMG = 299 gives 1 pps per step).
MULT_BASE = 300
#: Range of RMG + 1 (12-bit RMG; 3 gives the 6.55 Mpps top speed).
DIVIDER_RANGE = (3, 4096)
#: Lowest start speed the ASIC runs (pps) - our reading of the manual's "3 pps" note.
MIN_START_PPS = 3.0
#: Time of one rate-register tick: 4 clocks.
TICK_S = 4.0 / CLOCK_HZ
#: Top of the speed range: 65535 steps at the coarsest multiplier (6.5535 Mpps).
MAX_RANGE_PPS = REGISTER_MAX * MULT_BASE / DIVIDER_RANGE[0]


@dataclass(frozen=True)
class SpeedRange:
    """One speed range: the multiplier divider RMG + 1 chosen for a range top (pps)."""

    top: float
    divider: int

    @classmethod
    def for_speed(cls, top: float) -> SpeedRange:
        """The range whose grid reaches `top` pps with the finest multiplier."""
        r = check_finite("range", top)
        if not 0.0 < r <= MAX_RANGE_PPS:
            raise MotionError(f"range must be in (0, {MAX_RANGE_PPS:g}] pps, got {top!r}")
        lo, hi = DIVIDER_RANGE
        div = min(hi, max(lo, math.floor(MULT_BASE * REGISTER_MAX / r * (1 + 1e-12))))
        return cls(r, div)

    @property
    def multiplier(self) -> float:
        """pps per speed-register step."""
        return MULT_BASE / self.divider

    @property
    def max_speed(self) -> float:
        """The highest speed the grid holds (65535 steps)."""
        return REGISTER_MAX * self.multiplier

    def speed_register(self, v: float) -> int:
        """RFH for a speed (round to the grid; 0 for 0)."""
        return round(abs(v) / self.multiplier)

    def start_register(self, str_vel: float) -> int:
        """RFL: StrVel on the grid, never below MIN_START_PPS."""
        m = self.multiplier
        return max(round(str_vel / m), math.ceil(MIN_START_PPS / m - 1e-9))

    def grid(self, v: float) -> float:
        """The speed the ASIC really runs for `v` (pps, sign kept)."""
        return math.copysign(self.speed_register(v) * self.multiplier, v)

    def acc_time_range(self, str_vel: float, max_vel: float) -> tuple[float, float]:
        """(shortest, longest) linear ramp time StrVel -> MaxVel on this range (s)."""
        steps = max(self.speed_register(max_vel) - self.start_register(str_vel), 0)
        return steps * 2 * TICK_S, steps * (REGISTER_MAX + 1) * TICK_S

    def ramp_time(self, name: str, str_vel: float, max_vel: float, t: float) -> float:
        """The ramp time the ASIC runs for a requested time `t`: slowed up to the shortest
        time the range allows; InfeasibleError above the longest. (Not put on the tick
        grid: the manual's own tables are computed with the exact times.)"""
        t_min, t_max = self.acc_time_range(str_vel, max_vel)
        if t_max == 0.0:
            return t
        if t > t_max * (1 + 1e-9):
            raise InfeasibleError(
                f"{name} must be <= {t_max:.6g} s on the speed range {self.top:g} pps "
                f"(shortest {t_min:.6g} s), got {t!r}")
        return max(t, t_min)


def verify_speed(str_vel: float, max_vel: float,
                 over_speed: float = 0.0) -> tuple[float, float, float]:
    """HSL_M_verify_speed: (minimum start velocity, min acc time, max acc time) of a ramp
    StrVel -> MaxVel on the range `over_speed` (0: the move's own MaxVel)."""
    sv = check_nonnegative("str_vel", str_vel)
    mv = check_finite("max_vel", max_vel)
    if mv <= 0.0 or mv < sv:
        raise MotionError(f"max_vel must be > 0 and >= str_vel ({sv:g}), got {max_vel!r}")
    ov = check_nonnegative("over_speed", over_speed)
    rng = SpeedRange.for_speed(ov if ov > 0.0 else mv)
    if mv > rng.max_speed * (1 + 1e-12):
        raise InfeasibleError(f"max_vel must be <= the range {rng.top:g} pps, got {max_vel!r}")
    t_min, t_max = rng.acc_time_range(sv, mv)
    return rng.start_register(sv) * rng.multiplier, t_min, t_max


def on_range(spec: MoveSpec, fixed: float | None = None) -> MoveSpec:
    """The spec the ASIC runs for `spec` on the fixed range `fixed` (None: the move's own
    MaxVel): InfeasibleError above the range or for a ramp longer than the registers
    count, a too short ramp slowed, speeds on a fixed range's grid. Single-axis moves
    (SpeedModel) and the vector profile of interpolations use it alike."""
    rng = SpeedRange.for_speed(fixed if fixed is not None else spec.max_vel)
    if spec.max_vel > rng.max_speed * (1 + 1e-12):
        raise InfeasibleError(
            f"max_vel must be <= the fixed speed range {rng.top:g} pps "
            f"(fix_speed_range to allow more), got {spec.max_vel!r}")
    sv, mv = spec.str_vel, spec.max_vel
    if fixed is not None:  # the fixed range's grid
        sv, mv = rng.grid(sv), max(rng.grid(mv), rng.grid(sv))
    ta = rng.ramp_time("tacc", spec.str_vel, spec.max_vel, spec.tacc)
    td = rng.ramp_time("tdec", spec.str_vel, spec.max_vel, spec.tdec)
    half = (mv - sv) / 2.0
    return spec.derived(str_vel=sv, max_vel=mv, tacc=ta, tdec=td,
                        vs_acc=min(spec.vs_acc, half), vs_dec=min(spec.vs_dec, half))


class SpeedModel:
    """The register grid applied to one axis's T/S moves and speed changes."""

    def __init__(self, axis: Axis) -> None:
        self.axis = axis

    def range_for(self, max_vel: float) -> SpeedRange:
        fixed = self.axis.speed_range
        return SpeedRange.for_speed(fixed if fixed is not None else max_vel)

    def move(self, spec: MoveSpec) -> MoveSpec:
        """The spec the ASIC runs for `spec` (InfeasibleError when it cannot)."""
        return on_range(spec, self.axis.speed_range)

    def change(self, new_vel: float, current_range: float) -> float:
        """The speed a v_change to `new_vel` really runs (on a fixed range's grid)."""
        if self.axis.speed_range is None:
            return abs(new_vel)
        return abs(self.range_for(current_range).grid(new_vel))


def attach_speed_model(axis: Axis) -> SpeedModel:
    """Give `axis` the PCL6045 register grid (HSL modules do); returns the model."""
    model = SpeedModel(axis)
    axis.speed_model = model
    return model
