"""Change speed and position on the fly (HSL_M_v_change, HSL_M_p_change; HSL-4XMO §4.11).

Both take the running profile, the instant `t` of the change and the spec the axis runs
under, and return a `Change`: the new FULL profile (the old one up to `t`, spliced with
the re-planned motion) and the spec the axis runs under afterwards. A refused change
raises InfeasibleError and changes nothing; the caller keeps its motion.

change_speed, preset mode (Table 4-6): the new rate a = |NewVel - v|/Tacc is used both for
the change and for the final deceleration from NewVel to StrVel; the remaining pulses must
hold both (1000 -> 5000 pps in 0.1 s: a = 40000, 300 + 312.5 = 612.5 <= 5000: OK). The S
shape uses the same (A, J) algebra as the move with the spec's VSacc (clamped to dv/2).

change_position (Table 4-7): refused during the final deceleration and when the new target
is closer to the current position than the stopping distance from the current speed
(|new - current| < stop distance, in either direction: the seed refuses a "go back" of 499
pulses against a 500-pulse stop even though a reversal could reach it). Otherwise the axis
continues to the new target (MaxVel lowered if the distance left is short), or, if the
target is behind, decelerates to a stop, reverses and moves there with the same spec.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InfeasibleError, MotionError, check_distance
from ..limits import check_quantity
from .pcl import MoveSpec, Rates, append_ramp, ramp_distance, ramp_time
from .segments import Profile, ProfileBuilder, State
from .velocity import (
    append_stop,
    check_profile_time,
    extend_to,
    ramp_from_state,
    ramp_rates,
    segment_durations,
    stop_distance,
    velocity_ramp,
)


@dataclass(frozen=True)
class Change:
    """Result of an on-the-fly change.

    `profile` is the full new profile (old motion up to `t`, then the new one); `spec` the
    parameters now in force (for a later stop or change); `target` the absolute target
    (None in velocity mode); `needed_accel`/`needed_decel` the pulses the change and the
    final deceleration take (preset change_speed; Table 4-6 columns) and `remaining` the
    pulses that were left; `reverse` tells that change_position goes back.
    """

    profile: Profile
    spec: MoveSpec
    target: float | None
    needed_accel: float = 0.0
    needed_decel: float = 0.0
    remaining: float = math.nan
    reverse: bool = False


def _check_spec(spec: MoveSpec) -> MoveSpec:
    if not isinstance(spec, MoveSpec):
        raise MotionError(f"spec must be a MoveSpec, got {type(spec).__name__}")
    return spec


def _state(profile: Profile, t: float) -> tuple[Profile, State]:
    base = extend_to(profile, t)
    return base, (base.state_at(t) if t < base.duration else base.end)


def _direction(st: State, profile: Profile) -> float:
    for x in (st.v, st.a):
        if x != 0.0:
            return 1.0 if x > 0.0 else -1.0
    raise InfeasibleError("the axis is not moving at t: nothing to change on the fly")


def _spec_from_rates(spec: MoveSpec, v: float, accel: float, jerk: float,
                     t_fallback: float) -> MoveSpec:
    """A spec cruising at v whose ramps (both) run at (accel, jerk)."""
    s = spec.str_vel
    x = v - s
    if x <= 0.0 or accel <= 0.0:
        return spec.derived(max_vel=max(v, s), tacc=t_fallback, tdec=t_fallback,
                            vs_acc=0.0, vs_dec=0.0)
    t = ramp_time(x, accel, jerk)
    vs = 0.0
    if spec.shape == "S":
        vs = accel * accel / (2.0 * jerk)
        vs = x / 2.0 if vs > x / 2.0 else vs
    return spec.derived(max_vel=v, tacc=t, tdec=t, vs_acc=vs, vs_dec=vs)


def change_speed(profile: Profile, t: float, spec: MoveSpec, new_vel: float, tacc: float,
                 *, target: float | None = None, v_limit: float | None = None) -> Change:
    """HSL_M_v_change at time `t`: ramp to speed `new_vel` (pps, > 0) in `tacc` s.

    Preset mode (`target` = the move's absolute target): the remaining distance must hold
    the change and the deceleration from `new_vel` to StrVel, both at the new rate, else
    InfeasibleError. Velocity mode (`target` None): a velocity ramp that then holds.
    `v_limit` (HSL_M_fix_speed_range) caps `new_vel`. The direction stays that of motion.
    """
    t = check_profile_time(profile, t)
    spec = _check_spec(spec)
    new = check_quantity("new_vel", new_vel, "pps")
    tacc = check_quantity("tacc", tacc, "seconds")
    if v_limit is not None:
        new = min(new, check_quantity("v_limit", v_limit, "pps"))
    if new < spec.str_vel:
        raise MotionError(f"new_vel must be >= str_vel ({spec.str_vel:g}), got {new_vel!r}")
    tgt = None if target is None else check_distance("target", target)
    base, st = _state(profile, t)
    sgn = _direction(st, profile)
    jz = _jerk_now(spec, sgn * st.a)
    if tgt is None:
        tail = velocity_ramp(st, sgn * new, tacc, shape=spec.shape, vs=spec.vs_acc,
                             str_vel=spec.str_vel, j_zero=jz)
        acc, jerk = ramp_rates(abs(new - abs(st.v)), tacc, spec.shape, spec.vs_acc)
        new_spec = _spec_from_rates(spec, new, acc, jerk, tacc) if acc > 0 else spec
        return Change(base.splice(t, tail), new_spec, None)
    remaining = sgn * (tgt - st.p)
    speed = abs(st.v)
    acc, jerk = ramp_rates(abs(new - speed), tacc, spec.shape, spec.vs_acc)
    if acc == 0.0:  # no speed change: keep the move's own deceleration
        r = spec.rates
        acc, jerk = r.decel, r.jerk_dec
        if acc == 0.0 or st.a != 0.0:
            acc, jerk = ramp_rates(max(new - spec.str_vel, 1e-300), tacc, spec.shape, 0.0)
    b = ProfileBuilder(st.p, sgn * st.v, sgn * st.a, direction=sgn)
    ramp_from_state(b, new, acc, jerk, "change", j_zero=jz)
    need_acc = sgn * (b.state.p - st.p)
    need_dec = ramp_distance(spec.str_vel, new, acc, jerk)
    if need_acc + need_dec > remaining * (1 + 1e-12) + 1e-9:
        raise InfeasibleError(
            f"new_vel {new:g} needs {need_acc + need_dec:.6g} pulses "
            f"({need_acc:.6g} to change, {need_dec:.6g} to decelerate), "
            f"only {remaining:.6g} remain"
        )
    b.set_velocity(new)
    b.segment(max(0.0, remaining - need_acc - need_dec) / new, 0.0, accel=0.0, label="cruise")
    append_ramp(b, spec.str_vel, acc, jerk, "decel")
    tail = b.build(end_p=tgt, end_v=0.0)
    return Change(base.splice(t, tail), _spec_from_rates(spec, new, acc, jerk, tacc), tgt,
                  need_acc, need_dec, remaining)


def _jerk_now(spec: MoveSpec, a_along: float) -> float | None:
    """The running move's own jerk for its present acceleration (along the motion):
    what a change may use to remove that acceleration. None for T (no jerk limit)."""
    if spec.shape != "S" or a_along == 0.0:
        return None
    r = spec.rates
    return r.jerk_acc if a_along > 0.0 else r.jerk_dec


def final_decel_start(profile: Profile) -> float:
    """Start time of the trailing run of 'decel' segments (the final deceleration)."""
    t_dec = profile.duration
    for k in range(profile.n_segments - 1, -1, -1):
        if not profile.labels[k].startswith("decel"):
            break
        t_dec = float(profile.t0[k])
    return t_dec


def _rates_for(spec: MoveSpec, up: bool) -> tuple[float, float]:
    r: Rates = spec.rates
    return (r.accel, r.jerk_acc) if up else (r.decel, r.jerk_dec)


def _continue(st: State, sgn: float, target: float, spec: MoveSpec) -> Profile:
    """From a moving state, go on (sgn direction) to the absolute `target` and stop."""
    dist = abs(target - st.p)
    s, vmax = spec.str_vel, spec.max_vel
    ra = spec.rates

    def build(v: float, cruise: float) -> ProfileBuilder:
        b = ProfileBuilder(st.p, sgn * st.v, sgn * st.a, direction=sgn)
        cur = b.state
        jz = ra.jerk_acc if cur.a > 0.0 else ra.jerk_dec
        v_stop = cur.v + cur.a * abs(cur.a) / (2.0 * jz) if math.isfinite(jz) else cur.v
        acc, jerk = _rates_for(spec, v > v_stop)
        ramp_from_state(b, v, acc, jerk, "accel" if v > v_stop else "slow", j_zero=jz)
        b.set_velocity(v)
        b.segment(cruise, 0.0, accel=0.0, label="cruise")
        append_ramp(b, s, ra.decel, ra.jerk_dec, "decel")
        return b

    def covered(v: float) -> float:
        b = build(v, 0.0)
        return sgn * (b.state.p - st.p)

    d_hi = covered(vmax)
    if d_hi <= dist:
        v, cruise = vmax, (dist - d_hi) / vmax
    else:  # lowered peak: bisection, keeping the side that does not overshoot
        lo, hi = s, vmax
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            if covered(mid) <= dist:
                lo = mid
            else:
                hi = mid
        v = lo
        cruise = max(0.0, dist - covered(v)) / v if v > 0.0 else 0.0
    return build(v, cruise).build(end_p=target, end_v=0.0)


def _concat(a: Profile, b: Profile) -> Profile:
    """`a` then `b` (b's time 0 at a's end)."""
    return Profile(
        dt=np.concatenate([segment_durations(a), segment_durations(b)]),
        t0=np.concatenate([a.t0, b.t0 + a.duration]), p0=np.concatenate([a.p0, b.p0]),
        v0=np.concatenate([a.v0, b.v0]), a0=np.concatenate([a.a0, b.a0]),
        j=np.concatenate([a.j, b.j]), duration=a.duration + b.duration,
        start=a.start, end=b.end, labels=a.labels + b.labels,
    )


def change_position(profile: Profile, t: float, spec: MoveSpec, new_target: float) -> Change:
    """HSL_M_p_change at time `t`: move to the absolute `new_target` instead.

    Refused (InfeasibleError) during the final deceleration, when the move is over, and
    when |new_target - position(t)| is less than the stop distance from the state at t.
    """
    t = check_profile_time(profile, t)
    spec = _check_spec(spec)
    new = check_distance("new_target", new_target)
    if t >= profile.duration:
        raise InfeasibleError("the move is over: change_position needs a running move")
    t_dec = final_decel_start(profile)
    if t >= t_dec - 1e-12 * max(1.0, t_dec):
        raise InfeasibleError("position change during the deceleration period is not allowed")
    st = profile.state_at(t)
    if st.v == 0.0 and st.a == 0.0:  # not yet moving (S move from StrVel 0 at t=0)
        fresh = replace(spec.plan(new - st.p, start=st.p).profile, end=State(new, 0.0, 0.0))
        return Change(profile.splice(t, fresh), spec, new)
    sgn = _direction(st, profile)
    stop = stop_distance(spec, st.v, st.a)
    gap = new - st.p
    if abs(gap) < stop:
        raise InfeasibleError(
            f"new_target {new:g} is {abs(gap):.6g} pulses from the current position "
            f"{st.p:.6g}; stopping from the current speed needs {stop:.6g}"
        )
    if gap * sgn >= 0.0:
        tail = _continue(st, sgn, new, spec)
        return Change(profile.splice(t, tail), spec, new)
    b = ProfileBuilder(st.p, sgn * st.v, sgn * st.a, direction=sgn)
    append_stop(b, spec, label="stop")
    halt = b.build(end_v=0.0)
    p_stop = halt.end.p
    back = spec.plan(new - p_stop, start=p_stop).profile
    back = replace(back, end=State(new, 0.0, 0.0))  # exactly on the new target
    return Change(profile.splice(t, _concat(halt, back)), spec, new, reverse=True)
