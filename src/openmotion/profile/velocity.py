"""PCL6045 velocity mode (HSL tv_move / sv_move / v_change) and the two stops.

* `velocity_ramp` takes an axis from any state (p, v, a) to a signed target velocity and
  then holds it (the profile's `end.v` is the target, so sampling past the end keeps
  moving). From rest the pulse rate first jumps to StrVel (HSL §4.6 "Velocity Mode
  Motion"). T shape: constant acceleration |dv|/t. S shape: PCL ramp with jerk regions of
  VS pps (0 = pure S) and the same (A, J) algebra as `pcl.MoveSpec`; from a = 0 the ramp
  lasts exactly t. From a != 0 the ramp keeps those A and J limits but, being jerk-limited
  from a moving acceleration, does not last exactly t (the manual warns that changing
  speed during acceleration does not guarantee the ramp time, fig. 4-34).
* `decel_stop` (HSL_M_sd_stop) decelerates as the original move would: its decel rate
  (and jerk for S) down to StrVel, then the rate drops to 0. `immediate_stop`
  (HSL_M_emg_stop) drops the rate to 0 at once.
* Both stops return the FULL profile: the original up to `t`, spliced with the stop
  (`Profile.splice`), so the runtime swaps one profile for another.

A reversal (target of the other sign) is two ramps at one rate (|dv| - 2*StrVel over the
ramp time): down to StrVel, a jump through the start-stop band, up to the target. A T
reversal lasts exactly the ramp time; an S reversal has an extra pair of jerk regions.
A target of 0 ramps to StrVel and then drops to 0.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import MotionError, check_finite
from ..limits import check_pulses, check_quantity
from .pcl import MoveSpec, append_ramp
from .ramps import ramp_accel, ramp_jerk
from .segments import Profile, ProfileBuilder, State

# ------------------------------------------------------------------ helpers


def ramp_rates(dv: float, t: float, shape: str, vs: float = 0.0) -> tuple[float, float]:
    """(A, J) of a PCL ramp covering dv >= 0 in time t; J = inf for T. VS is clamped to
    [0, dv/2] (0 = pure S)."""
    if dv <= 0.0:
        return 0.0, math.inf
    if shape == "T":
        return dv / t, math.inf
    vs = dv / 2.0 if vs <= 0.0 or vs > dv / 2.0 else vs
    a = (dv + 2.0 * vs) / t
    return a, a * a / (2.0 * vs)


def ramp_from_state(b: ProfileBuilder, v1: float, accel: float, jerk: float,
                    label: str, *, j_zero: float | None = None) -> ProfileBuilder:
    """Append a ramp from b's (v, a) to (v1, 0) under limits (accel, jerk); jerk = inf is T.

    S from a != 0: `j_zero` (default `jerk`) is the jerk available to remove the present
    acceleration (the running move's own jerk); the larger of it and `jerk` is used. An
    acceleration pointing away from v1 (or over `accel`) is first brought to 0 (or to
    `accel`) at that jerk, then `ramps.ramp_jerk` finishes: zeroing at constant jerk and
    then ramping is the minimum-time ramp. An
    acceleration pointing towards v1 that `jerk` cannot remove before v1 is removed at
    the jerk that lands exactly on v1 (never above max(jerk, j_zero)); only when even
    that jerk overshoots does the speed pass v1, by the least the physics allows
    (a**2 / (2 max(jerk, j_zero))), and come back.
    """
    st = b.state
    if accel <= 0.0:  # nothing to ramp over (caller jumps the velocity)
        b.set_acceleration(0.0)
        return b
    if math.isinf(jerk):
        return ramp_accel(b, v1, accel, label=label)
    if st.a == 0.0:
        return append_ramp(b, v1, accel, jerk, label)
    j_hi = jerk if j_zero is None else max(jerk, j_zero)
    gap = v1 - st.v
    if st.a * gap > 0.0:  # accelerating towards v1
        need = st.a * st.a / 2.0  # gap * jerk needed to remove a before v1
        if need > abs(gap) * jerk:
            if need <= abs(gap) * j_hi:  # land on v1 with a = 0: no overshoot
                _jerk_out(b, st.a, need / abs(gap), label)
                b.set_velocity(v1)
                return b
            _jerk_out(b, st.a, j_hi, label)  # the least overshoot there is
            return ramp_jerk(b, v1, accel, jerk, label=label)
        if abs(st.a) > accel:
            b.segment((abs(st.a) - accel) / j_hi, -math.copysign(j_hi, st.a),
                      label=f"{label} ease")
        return ramp_jerk(b, v1, accel, jerk, label=label)
    _jerk_out(b, st.a, j_hi, label)  # away from v1 (or already on it)
    if b.state.v == v1:
        return b
    return ramp_jerk(b, v1, accel, jerk, label=label)


def _jerk_out(b: ProfileBuilder, a: float, jerk: float, label: str) -> None:
    """Bring b's acceleration `a` to 0 at `jerk` (at once for an unbounded jerk)."""
    if math.isfinite(jerk):
        b.segment(abs(a) / jerk, -math.copysign(jerk, a), label=f"{label} jerk-out")
    b.set_acceleration(0.0)


def segment_durations(profile: Profile) -> np.ndarray:
    """The profile's exact segment durations (its `dt`, else differences of t0)."""
    if profile.dt is not None:
        return profile.dt
    return np.array([profile.segment_duration(k) for k in range(profile.n_segments)])


def extend_to(profile: Profile, t: float) -> Profile:
    """`profile`, with its final constant velocity written out as a segment up to `t`.

    A velocity-mode profile keeps moving after `duration`; splicing past the end needs
    that motion as a real segment (Profile.splice clamps to `duration`).
    """
    if t <= profile.duration or profile.end.v == 0.0:
        return profile
    e = profile.end
    return Profile(
        dt=np.append(segment_durations(profile), t - profile.duration),
        t0=np.append(profile.t0, profile.duration), p0=np.append(profile.p0, e.p),
        v0=np.append(profile.v0, e.v), a0=np.append(profile.a0, 0.0),
        j=np.append(profile.j, 0.0), duration=float(t),
        start=profile.start, end=State(e.p + e.v * (t - profile.duration), e.v, 0.0),
        labels=profile.labels + ("hold",),
    )


def check_profile_time(profile: Profile, t: float) -> float:
    """Validate a (profile, t >= 0) pair for the stop and on-the-fly entry points."""
    if not isinstance(profile, Profile):
        raise MotionError(f"profile must be a Profile, got {type(profile).__name__}")
    return check_quantity("t", t, "seconds", zero=True)


# ------------------------------------------------------------------ velocity mode


def velocity_ramp(state: State, target_v: float, t_ramp: float, *, shape: str = "T",
                  vs: float = 0.0, str_vel: float = 0.0,
                  j_zero: float | None = None) -> Profile:
    """Ramp from `state` to the signed `target_v` (pps) in `t_ramp` s, then hold it.

    HSL tv_move (shape 'T') / sv_move (shape 'S', `vs` = SVacc) from rest, v_change while
    moving. From rest (v = a = 0) the rate jumps to StrVel first and the ramp covers
    |target| - StrVel. Positions are absolute (`state.p`). `j_zero` (S only): the jerk
    available to remove the present acceleration, normally the running move's own jerk
    (see `ramp_from_state`); by default the new ramp's.
    """
    if not isinstance(state, State):
        raise MotionError(f"state must be a State(p, v, a), got {type(state).__name__}")
    if not isinstance(shape, str) or shape not in ("T", "S"):
        raise MotionError(f"shape must be 'T' or 'S', got {shape!r}")
    p0 = check_pulses("state.p", state.p)
    v0 = check_quantity("state.v", state.v, "pps", zero=True, signed=True)
    a0 = check_quantity("state.a", state.a, "pps2", zero=True, signed=True)
    vt = check_quantity("target_v", target_v, "pps", zero=True, signed=True)
    t = check_quantity("t_ramp", t_ramp, "seconds")
    vs = check_quantity("vs", vs, "pps", zero=True)
    sv = check_quantity("str_vel", str_vel, "pps", zero=True)
    jz = None if j_zero is None else check_quantity("j_zero", j_zero, "pps3")
    if abs(vt) < sv and vt != 0.0:
        raise MotionError(f"target_v must be 0 or |target_v| >= str_vel ({sv:g}), got {vt!r}")
    b = ProfileBuilder(p0, v0, a0)
    if v0 == 0.0 and a0 == 0.0:
        if vt == 0.0:
            return b.build(end_v=0.0)
        b.set_velocity(math.copysign(sv, vt))
        v0 = b.state.v
    # a stop ramps to StrVel and then drops to 0; a reversal also restarts at StrVel
    v_end = math.copysign(sv, v0) if vt == 0.0 and v0 != 0.0 else vt
    if v0 * vt < 0.0:
        v_mid = math.copysign(min(sv, abs(v0)), v0)
        acc, jerk = ramp_rates(abs(v_mid - v0) + abs(vt + v_mid), t, shape, vs)
        ramp_from_state(b, v_mid, acc, jerk, "ramp down", j_zero=jz)
        b.set_velocity(-v_mid)
        append_ramp(b, vt, acc, jerk, "ramp")
    else:
        acc, jerk = ramp_rates(abs(v_end - v0), t, shape, vs)
        if b.state.a != 0.0 and (acc == 0.0 or jerk == 0.0):
            # (next to) the right speed, only the acceleration to remove
            acc, jerk = abs(a0), (4.0 * abs(a0) / t if shape == "S" else math.inf)
        ramp_from_state(b, v_end, acc, jerk, "ramp", j_zero=jz)
    b.set_velocity(vt)
    return b.build(end_v=vt)


def velocity_move(spec: MoveSpec, direction: float, *, start: float = 0.0) -> Profile:
    """HSL tv_move / sv_move from rest: StrVel, ramp to +-MaxVel in Tacc, hold."""
    if not isinstance(spec, MoveSpec):
        raise MotionError(f"spec must be a MoveSpec, got {type(spec).__name__}")
    d = check_finite("direction", direction)
    if d == 0.0:
        raise MotionError("direction must be +1 or -1, got 0")
    return velocity_ramp(State(check_pulses("start", start)),
                         math.copysign(spec.max_vel, d), spec.tacc, shape=spec.shape,
                         vs=spec.vs_acc, str_vel=spec.str_vel)


# ------------------------------------------------------------------ stops


def stop_distance(spec: MoveSpec, v: float, a: float = 0.0) -> float:
    """Distance (>= 0, along v) a `decel_stop` from (v, a) covers."""
    if not isinstance(spec, MoveSpec):
        raise MotionError(f"spec must be a MoveSpec, got {type(spec).__name__}")
    v = check_quantity("v", v, "pps", zero=True, signed=True)
    a = check_quantity("a", a, "pps2", zero=True, signed=True)
    b = ProfileBuilder(0.0, v, a)
    append_stop(b, spec)
    return abs(b.state.p)


def append_stop(b: ProfileBuilder, spec: MoveSpec, label: str = "decel") -> None:
    """Append the sd_stop deceleration (to StrVel, acceleration 0) from b's state."""
    st = b.state
    if abs(st.v) <= spec.str_vel or (st.v == 0.0 and st.a == 0.0):
        b.set_acceleration(0.0)
        return
    r = spec.rates
    sgn = 1.0 if st.v > 0.0 else -1.0
    j_zero = r.jerk_acc if st.a * sgn > 0.0 else r.jerk_dec
    ramp_from_state(b, sgn * spec.str_vel, r.decel, r.jerk_dec, label, j_zero=j_zero)


def decel_stop(profile: Profile, t: float, spec: MoveSpec) -> Profile:
    """Slow-down stop at time `t` (HSL_M_sd_stop): the full profile, spliced at `t`.

    From the state at `t` the axis decelerates at the spec's deceleration (S: its jerk)
    to StrVel and stops. If |v| <= StrVel it stops at once. An S stop issued while
    accelerating first removes the acceleration at the acceleration jerk, as the move
    itself would have.
    """
    t = check_profile_time(profile, t)
    if not isinstance(spec, MoveSpec):
        raise MotionError(f"spec must be a MoveSpec, got {type(spec).__name__}")
    base = extend_to(profile, t)
    st = base.state_at(t) if t < base.duration else base.end
    b = ProfileBuilder(st.p, st.v, st.a)
    append_stop(b, spec)
    return base.splice(t, b.build(end_v=0.0))


def immediate_stop(profile: Profile, t: float) -> Profile:
    """Emergency stop at time `t` (HSL_M_emg_stop): the rate drops to 0 at `t`."""
    t = check_profile_time(profile, t)
    base = extend_to(profile, t)
    p = base.state_at(t).p if t < base.duration else base.end.p
    return base.splice(t, ProfileBuilder(p).build(end_p=p))
