"""Pure motion-profile math: no clocks, no state. Units: pulses, pulses/s, seconds.

Entry points: `trapezoid`, `scurve` (PCL6045 semantics, `MoveSpec` for the full parameter
set), `jerk_limited` (time-optimal), `jerk_limited_sync` (all axes arrive together),
`jerk_limited_durations` (vectorized batch), `quantize` (integer counts).
"""

from .batch import jerk_limited_durations, jerk_limited_phases
from .jerk import jerk_limited, jerk_limited_duration, jerk_limited_sync
from .onthefly import Change, change_position, change_speed
from .pcl import MovePlan, MoveSpec, Rates, scurve, trapezoid
from .quantize import check_quantized, quantize
from .retarget import retarget, retarget_velocity
from .segments import Phase, Profile, ProfileBuilder, Samples, State, empty_profile
from .velocity import decel_stop, immediate_stop, stop_distance, velocity_move, velocity_ramp

__all__ = [
    "Change", "Rates", "change_position", "change_speed", "decel_stop", "immediate_stop",
    "stop_distance", "velocity_move", "velocity_ramp",
    "MovePlan", "MoveSpec", "Phase", "Profile", "ProfileBuilder", "Samples", "State",
    "check_quantized", "empty_profile", "jerk_limited", "jerk_limited_duration",
    "jerk_limited_durations", "jerk_limited_phases", "jerk_limited_sync", "quantize",
    "retarget", "retarget_velocity",
    "scurve", "trapezoid",
]
