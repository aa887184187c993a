"""Velocity ramps appended to a `ProfileBuilder`: the building block of every planner.

`ramp_jerk` takes the builder's current (v, a) to (v1, 0) in minimum time under an
acceleration limit and a jerk limit; `ramp_accel` does the same at constant acceleration
(jerk unbounded, the T-curve case). Both work in the builder's direction frame.

Minimum-time jerk ramp (the three-phase "S"): ramping the acceleration straight to zero
would end at v_stop = v0 + a0*|a0|/(2J). The ramp therefore pushes acceleration towards
s = sign(v1 - v_stop): with a0' = s*a0 and dv = s*(v1 - v0), raising the acceleration to a
peak ap and back to zero gains (2*ap**2 - a0'**2)/(2J) of velocity. If that is not more than
dv at ap = a_max, a constant-acceleration phase covers the rest; otherwise
ap = sqrt((2*J*dv + a0'**2)/2) and there is no constant phase.
"""

from __future__ import annotations

import math

from .segments import ProfileBuilder


def ramp_jerk_phases(v0: float, a0: float, v1: float, a_max: float,
                     j_max: float) -> list[tuple[float, float]]:
    """(duration, jerk) phases taking (v0, a0) to (v1, 0) in minimum time."""
    a0 = max(-a_max, min(a_max, a0))
    v_stop = v0 + a0 * abs(a0) / (2.0 * j_max)
    diff = v1 - v_stop
    if abs(diff) <= 1e-12 * max(1.0, abs(v1), abs(v0)):
        if a0 == 0.0:
            return []
        return [(abs(a0) / j_max, -math.copysign(j_max, a0))]
    s = 1.0 if diff > 0.0 else -1.0
    a0n = s * a0
    dv = s * (v1 - v0)
    needed = (2.0 * a_max * a_max - a0n * a0n) / (2.0 * j_max)
    if needed <= dv:
        ap = a_max
        t_const = (dv - needed) / a_max
    else:
        ap = math.sqrt(max(0.0, (2.0 * j_max * dv + a0n * a0n) / 2.0))
        t_const = 0.0
    return [((ap - a0n) / j_max, s * j_max), (t_const, 0.0), (ap / j_max, -s * j_max)]


def ramp_jerk(b: ProfileBuilder, v1: float, a_max: float, j_max: float,
              label: str = "ramp") -> ProfileBuilder:
    """Append the minimum-time jerk-limited ramp from b's (v, a) to (v1, 0)."""
    st = b.state
    names = (f"{label} jerk-in", f"{label} const-acc", f"{label} jerk-out")
    for (dt, jerk), name in zip(ramp_jerk_phases(st.v, st.a, v1, a_max, j_max), names,
                                strict=False):
        b.segment(dt, jerk, label=name)
    b.set_acceleration(0.0)
    return b


def ramp_jerk_duration(v0: float, a0: float, v1: float, a_max: float, j_max: float) -> float:
    """Duration of `ramp_jerk` without building it."""
    return sum(dt for dt, _ in ramp_jerk_phases(v0, a0, v1, a_max, j_max))


def ramp_accel(b: ProfileBuilder, v1: float, accel: float,
               label: str = "ramp") -> ProfileBuilder:
    """Append a constant-acceleration ramp from b's velocity to v1, then zero acceleration."""
    v0 = b.state.v
    if v1 != v0:
        b.segment(abs(v1 - v0) / accel, 0.0, accel=math.copysign(accel, v1 - v0), label=label)
    b.set_acceleration(0.0)
    return b
