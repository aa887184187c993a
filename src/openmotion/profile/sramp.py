"""A ramp given as acceleration and smoothing time, in PCL6045 move parameters.

Controllers like ZMotion set an acceleration A (units/s^2) and an S-ramp time Ts (SRAMP):
the acceleration rises from 0 to A in Ts, holds, and falls back in Ts (jerk A / Ts). The
same ramp as a PCL6045 S-curve (profile.pcl.MoveSpec): the time to reach v is v/A + Ts and
each curved part spans A Ts / 2 of speed. When v < A Ts the ramp never reaches A: it is a
pure S (span 0) of time 2 sqrt(v Ts / A) at the same jerk. Ts = 0 is the T-curve v / A.
"""

from __future__ import annotations

import math

from ..errors import check_nonnegative, check_positive


def ramp_spec(speed: float, accel: float, ramp_s: float) -> tuple[str, float, float]:
    """(shape, ramp time, S span) of a ramp from rest to `speed` at `accel` smoothed over
    `ramp_s` seconds (see the module docstring)."""
    v = check_positive("speed", speed)
    a = check_positive("accel", accel)
    ts = check_nonnegative("ramp_s", ramp_s)
    if ts == 0.0:
        return "T", v / a, 0.0
    if v >= a * ts:
        return "S", v / a + ts, a * ts / 2.0
    return "S", 2.0 * math.sqrt(v * ts / a), 0.0
