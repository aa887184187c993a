"""A path command run as one move along its own length, each ramp with its own shape.

MCCL sets the acceleration and the deceleration type of general motion apart (2.6.3 I,
MCC_SetAccType / MCC_SetDecType: 'T' trapezoid or 'S' with s-factor 1, a triangular
acceleration lasting the ramp time). A chained path (pathrun.py) has one shape: its S is a
moving average over the whole plan, which cannot leave one ramp straight. A command whose
two shapes differ is therefore planned alone, as the point-to-point axes are: its path
position s(t) is a PCL move (`MoveSpec` with `dec_shape`) from rest at its start to rest
at its end, at its feed times the override, capped by the element's own speed limits (the
look-ahead's: axis speeds, centripetal acceleration on arcs). Its ramps keep the
command's rates (feed / acceleration time), so a slower cap gives shorter ramps, as on a
chain. Hold, override and continue are 1-D operations as on an axis move: a hold is
`velocity.decel_stop` with the deceleration shape; an override a ramp to the new speed at
the command's rate (the acceleration shape up, the deceleration shape down), a cruise and
the final deceleration with its shape; continue a new move from the held position. It
joins no chain: it ends at rest, or blends into the next command in time (overlap.py).

The result is a `PathPlan` with `move` set (tj = 0, raw = the executed s(t)), so the
executor (axis profiles, windows, in-position, the time-overlap blend) treats it as any
other path.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...errors import MotionError
from ...path import speed_caps
from ...profile import velocity
from ...profile.pcl import MoveSpec
from ...profile.segments import Profile, ProfileBuilder, State
from ..core import planning
from . import pathexec as px
from .pathrun import PathPlan


def _cap(chain: px.Chain, spec: MoveSpec, lim: px.Limits) -> float:
    """The speed the command may run at: feed x override, the system maximum, the
    elements' caps (axis speeds, centripetal limit on arcs)."""
    feed = min(spec.max_vel * lim.scale, lim.feed)
    accel = spec.max_vel / min(spec.tacc, spec.tdec)
    caps, _ = speed_caps(list(chain.elements), feed, accel, axis_vmax=lim.axis_vmax,
                         axis_amax=lim.axis_amax)
    return float(min(feed, *caps))


def _at_speed(spec: MoveSpec, v: float) -> MoveSpec:
    """The command's spec cruising at v with its own ramp rates (feed / ramp time)."""
    k = v / spec.max_vel
    return spec.derived(max_vel=v, tacc=spec.tacc * k, tdec=spec.tdec * k)


def _plan(chain: px.Chain, sprof: Profile, t: float, lim: px.Limits, spec: MoveSpec
          ) -> PathPlan:
    curve = px.SpeedCurve(np.array([sprof.start.p, chain.length]), np.zeros(2))
    return PathPlan(chain, curve, sprof, t, sprof, t, 0.0, lim,
                    spec.max_vel / spec.tdec, move=spec)


def start(chain: px.Chain, spec: MoveSpec, lim: px.Limits, t: float,
          s0: float = 0.0) -> PathPlan:
    """The command from rest at path position s0 (0: its start; a held one continues)."""
    if not isinstance(spec, MoveSpec):
        raise MotionError(f"spec must be a MoveSpec, got {type(spec).__name__}")
    length = chain.length
    if s0 >= length:
        return _plan(chain, ProfileBuilder(length).build(end_p=length), t, lim, spec)
    sprof = planning.position_move(_at_speed(spec, _cap(chain, spec, lim)), s0, length)
    return _plan(chain, sprof, t, lim, spec)


def replan(plan: PathPlan, t: float, *, limits: px.Limits | None = None,
           hold: bool = False) -> PathPlan:
    """From time t: to rest with the deceleration shape (`hold`), or to the speed of new
    limits (an override: a ramp at the command's rate, then on to its end). An override
    too close to the end to change the speed leaves the plan as it is."""
    spec = plan.move
    assert spec is not None
    lim = limits or plan.limits
    u = t - plan.t0
    sp = plan.sprof
    if u >= sp.duration:
        return replace(plan, limits=lim)
    st = sp.state_at(max(u, 0.0))
    v = abs(st.v)
    if hold:
        if v == 0.0 and st.a == 0.0:
            full = sp.splice(u, ProfileBuilder(st.p).build(end_p=st.p))
        else:
            full = velocity.decel_stop(sp, u, _at_speed(spec, max(v, 1e-12 * spec.max_vel)))
    else:
        v_new = _cap(plan.chain, spec, lim)
        if v == 0.0 or abs(v_new - v) <= 1e-12 * spec.max_vel:
            return replace(plan, limits=lim)
        rest = _to_speed(st, v_new, spec, plan.chain.length)
        if rest is None:  # too close to the end: it finishes at its speed
            return replace(plan, limits=lim)
        return _plan(plan.chain, rest, t, lim, spec)
    return _plan(plan.chain, tail(full, u), t, lim, spec)


def _to_speed(st: State, v_new: float, spec: MoveSpec, length: float) -> Profile | None:
    """From state `st` (time 0): a ramp to v_new at the command's rate with its shape (the
    acceleration's when faster, the deceleration's when slower), a cruise, the final
    deceleration with the deceleration shape ending exactly on `length`; None when the
    ramp and the final deceleration do not fit in what is left."""
    up = v_new > abs(st.v)
    shape = spec.shape if up else (spec.dec_shape or spec.shape)
    t_ramp = (spec.tacc if up else spec.tdec) * abs(v_new - abs(st.v)) / spec.max_vel
    ramp = velocity.velocity_ramp(st, v_new, max(t_ramp, 1e-9), shape=shape)
    at = _at_speed(spec, v_new)
    cruise = length - ramp.end.p - velocity.stop_distance(at, v_new)
    if cruise < -1e-9 * max(1.0, length):
        return None
    b = ProfileBuilder(ramp.end.p, v_new, 0.0)
    if cruise > 0.0:
        b.segment(cruise / v_new, 0.0, accel=0.0, label="cruise")
    velocity.append_stop(b, at)
    return ramp.splice(ramp.duration, b.build(end_p=length, end_v=0.0))


def tail(p: Profile, u: float) -> Profile:
    """p from time u on, its time 0 at u (an executor section, exact at the cut)."""
    from .groupexec import _section  # (the executor's own cut; groupexec imports us)

    return _section(p, u, math.inf)
