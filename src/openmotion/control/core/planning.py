"""Thin adapters from axis commands to the profile planners (openmotion.profile).

All the motion math lives in `profile`; this module only picks the planner for a command,
passes the running motion's profile and local time, and hands back a Profile anchored like
the running one (time 0 = the motion's t_start). Each function raises MotionError /
InfeasibleError before anything is changed when the planner refuses.
"""

from __future__ import annotations

from dataclasses import replace

from ...profile import onthefly, velocity
from ...profile.jerk import jerk_limited
from ...profile.pcl import MoveSpec
from ...profile.retarget import retarget_velocity
from ...profile.segments import Profile, State
from .motion import ActiveMotion


def position_move(spec: MoveSpec, start: float, target: float) -> Profile:
    """PCL6045 T/S move from rest at `start` to exactly `target` (raw pulse frame)."""
    return _ending_on(spec.plan(target - start, start).profile, target)


def _ending_on(profile: Profile, target: float) -> Profile:
    """The profile with its end state pinned to `target`: start + (target - start) need
    not round back to target in floating point when start is fractional."""
    if profile.end.p == target:
        return profile
    return replace(profile, end=State(target, 0.0, 0.0))


def jerk_move(start: float, target: float, v_max: float, a_max: float, j_max: float,
              d_max: float | None) -> Profile:
    """Time-optimal jerk-limited rest-to-rest move to exactly `target`."""
    return _ending_on(jerk_limited(target - start, v_max, a_max, j_max, d_max=d_max,
                                   start=start), target)


def velocity_move(spec: MoveSpec, direction: float, start: float) -> Profile:
    """Velocity mode from rest: StrVel jump, ramp to MaxVel in Tacc, hold (tv/sv_move)."""
    return velocity.velocity_move(spec, direction, start=start)


def change_speed(m: ActiveMotion, t: float, new_vel: float, tacc: float,
                 v_limit: float) -> tuple[Profile, MoveSpec]:
    """v_change at absolute time t; returns the spliced profile and the spec it now runs."""
    ch = onthefly.change_speed(m.profile, t - m.t_start, m.spec, new_vel, tacc,
                               target=m.target, v_limit=v_limit)
    return ch.profile, ch.spec


def change_position(m: ActiveMotion, t: float, new_target: float) -> tuple[Profile, MoveSpec]:
    """p_change at absolute time t to `new_target` (raw pulse frame)."""
    ch = onthefly.change_position(m.profile, t - m.t_start, m.spec, new_target)
    return _ending_on(ch.profile, new_target), ch.spec


def decel_stop(m: ActiveMotion, t: float, tdec: float | None) -> Profile:
    """sd_stop at absolute time t (deceleration of the move's spec, or `tdec`)."""
    if m.limits is not None:  # jerk-limited or external: fastest jerk-limited ramp to rest
        u = t - m.t_start
        _, a_max, j_max = m.limits
        st = m.profile.state_at(u)
        # never refuse a stop: an external profile may be accelerating harder than a_max
        tail = retarget_velocity(st, 0.0, max(a_max, abs(st.a)), j_max)
        return m.profile.splice(u, tail)
    spec = m.spec if tdec is None else replace(m.spec, tdec=tdec)
    return velocity.decel_stop(m.profile, t - m.t_start, spec)
