"""Re-planning from any state: to rest at a new target, or to a new velocity.

`retarget` takes an axis that is moving (p, v, a) to rest exactly on `target`. Planning
happens in the frame of motion m, the sign of v_stop = v + a*|a|/(2J) (the velocity
reached by bringing the acceleration to zero at once). With L = m*(target - p) and d_stop
the distance of the fastest stop (a ramp to v = 0):

  L >= d_stop (target ahead of the stopping point, the common case), one of
    F1  ramp (v, a) -> V, cruise at V, ramp V -> 0, with V in [v_stop, v_max]. The
        distance d(V) increases with V, so V = v_max with a cruise if it fits, otherwise
        the root of d(V) = L (bracketed secant).
    F2  if a < 0 and even F1 at V = v_stop overshoots: brake softer. Jerk +J for t1,
        then the fastest stop; the distance grows with t1 in [0, -a/J] (t1 = 0 is the
        fastest stop, t1 = -a/J is F1 at V = v_stop).
    If v_stop > v_max, F1 ramps down to V <= v_max; if even V = v_max overshoots, V is
    searched in [0, v_max] (a braking dip at V; d(0) is the fastest stop).
  A state outside the limits (|v| > v_max, a swinging v past it, a beyond its limit) is
  first braked at full jerk until it is within them, ruckig's rule (`brake`): the axis is
  back under its speed limit as early as the jerk allows (safety first, even where a
  plan that stays above v_max longer would arrive sooner); F1/F2 continue from there.
  L < d_stop: reverse through v = 0. Planned in the opposite frame, where the target now
    lies ahead of the stopping point (F1 with V > 0 from a negative velocity).
Limits are in the frame of the final approach: a_max towards it, d_max against it (as
ruckig's max/min acceleration; for a rest-to-rest move, d_max is the deceleration). With
a_max > d_max a target may lie behind the stop point braking at d_max but ahead of it
braking at a_max; then neither frame fits and we stop (at d_max) and move back.

The fastest ramp (v0, a0) -> (v1, 0) with separate limits up/down, see `ramps.py` for the
symmetric derivation; if a0 already exceeds the limit in the ramp's direction, the first
phase brings it down to the limit instead (velocity gain (a0**2 - lim**2)/(2J) there).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..errors import COUNTER28_MAX, MotionError
from ..limits import check_pulses, check_quantity
from .jerk import PHASE_LABELS, phase_times
from .ramps import ramp_jerk
from .segments import Profile, ProfileBuilder, State

# Relative slack under which two velocities or distances count as equal. Near such a tie a
# ramp's duration depends on the difference through a square root, so rounding noise of
# 1e-16 would otherwise add spurious ~1e-8 s micro-phases (or a micro-reversal).
SNAP = 1e-12

# (duration, jerk, acceleration pinned at the phase start or None)
Phase = tuple[float, float, float | None]


# ---------------------------------------------------------------- phase algebra
def ramp_phases(v0: float, a0: float, v1: float, a_up: float, a_dn: float,
                j: float) -> list[Phase]:
    """Fastest (v0, a0) -> (v1, 0) with acceleration in [-a_dn, a_up] (see module notes)."""
    v_stop = v0 + a0 * abs(a0) / (2.0 * j)
    diff = v1 - v_stop
    if abs(diff) <= SNAP * max(abs(v0), abs(v1), a0 * a0 / j):
        return [(abs(a0) / j, -math.copysign(j, a0), None)] if a0 else []
    s = 1.0 if diff > 0.0 else -1.0
    lim = a_up if s > 0.0 else a_dn
    a0n, dv = s * a0, s * (v1 - v0)
    if a0n > lim:
        t_c = max(0.0, (dv - a0n * a0n / (2.0 * j)) / lim)
        return [((a0n - lim) / j, -s * j, None), (t_c, 0.0, s * lim), (lim / j, -s * j, s * lim)]
    needed = (2.0 * lim * lim - a0n * a0n) / (2.0 * j)
    if needed <= dv:
        ap, t_c = lim, (dv - needed) / lim
    else:
        ap, t_c = math.sqrt(max(0.0, (2.0 * j * dv + a0n * a0n) / 2.0)), 0.0
    return [(max(0.0, (ap - a0n) / j), s * j, None), (t_c, 0.0, s * ap), (ap / j, -s * j, s * ap)]


def advance(v: float, a: float, phases: list[Phase]) -> tuple[float, float, float]:
    """(distance, v, a) after running `phases` from (v, a); exact polynomial steps."""
    d = 0.0
    for dt, jk, pin in phases:
        if pin is not None:
            a = pin
        if dt <= 0.0:
            continue
        d += dt * (v + dt * (a / 2.0 + dt * jk / 6.0))
        v += dt * (a + dt * jk / 2.0)
        a += dt * jk
    return d, v, a


def _solve(f: Callable[[float], float], lo: float, hi: float) -> float:
    """x in [lo, hi] with f(x) = 0 for f(lo) <= 0 <= f(hi) (Illinois secant + bisection)."""
    flo, fhi = f(lo), f(hi)
    if flo >= 0.0:
        return lo
    if fhi <= 0.0:
        return hi
    side = 0
    for _ in range(200):
        x = hi - fhi * (hi - lo) / (fhi - flo)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        fx = f(x)
        if fx == 0.0:
            return x
        if fx < 0.0:
            lo, flo = x, fx
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = x, fx
            if side == 1:
                flo *= 0.5
            side = 1
        if hi - lo <= 4e-16 * max(abs(lo), abs(hi)) or abs(hi - lo) < 1e-300:
            break
    return lo if -flo <= fhi else hi  # keeps the root side that undershoots least


def _velocity_brake(v: float, a: float, v_hi: float, v_lo: float, a_lo: float,
                    j: float) -> list[Phase]:
    """Jerk -j from (v, a) until v = v_hi, or shorter where releasing at once would swing
    below v_lo; a held at a_lo (< 0) if it gets there first."""
    t_a = (a - a_lo) / j
    t_hi = a / j + math.sqrt(max(0.0, a * a + 2.0 * j * (v - v_hi))) / j
    t_lo = a / j + math.sqrt(max(0.0, a * a / 2.0 + j * (v - v_lo))) / j
    t_v = min(t_hi, t_lo)
    if t_a < t_v:
        v_a = v + t_a * (a - j * t_a / 2.0)
        t_c = max(min(-(v_a - v_hi) / a_lo, a_lo / (2.0 * j) - (v_a - v_lo) / a_lo), 0.0)
        return [(max(t_a, 0.0), -j, None), (t_c, 0.0, a_lo)]
    return [(max(t_v, 0.0), -j, None)]


def _brake_up(v: float, a: float, v_hi: float, v_lo: float, a_hi: float, a_lo: float,
              j: float) -> list[Phase]:
    """The brake of a state above the limits on the high side (see `brake`)."""
    if a > a_hi:  # acceleration beyond its limit: bring it down at full jerk first
        t_a = (a - a_hi) / j
        if v + a * a / (2.0 * j) > v_hi:
            return _velocity_brake(v, a, v_hi, v_lo, a_lo, j)
        v_a = v + t_a * (a - j * t_a / 2.0)
        if v_a < v_lo:
            t_c = max(min(-(v_a - v_lo) / a_hi, -a_hi / (2.0 * j) - (v_a - v_hi) / a_hi), 0.0)
            return [(t_a, -j, None), (t_c, 0.0, a_hi)]
        return [(t_a, -j, None)]
    return _velocity_brake(v, a, v_hi, v_lo, a_lo, j)


def _mirror(phases: list[Phase]) -> list[Phase]:
    return [(dt, -jk, None if pin is None else -pin) for dt, jk, pin in phases]


def brake(v: float, a: float, v_max: float, a_max: float, d_max: float,
          j: float) -> list[Phase]:
    """The pre-brake of a state outside the limits (|v| > v_max, or a swinging v past it,
    or a beyond [-d_max, a_max]), ruckig's rule: full jerk until the state is within
    them, so the axis is back under its limits as early as the jerk allows; [] if it is
    within. The plan to the target continues from the braked state."""
    v_up, v_dn = v + a * a / (2.0 * j), v - a * a / (2.0 * j)  # v where a reaches 0
    if a > a_max:
        return _brake_up(v, a, v_max, -v_max, a_max, -d_max, j)
    if a < -d_max:
        return _mirror(_brake_up(-v, -a, v_max, -v_max, d_max, -a_max, j))
    if (v > v_max and v_dn > -v_max) or (a > 0.0 and v_up > v_max):
        return _velocity_brake(v, a, v_max, -v_max, -d_max, j)
    if (v < -v_max and v_up < v_max) or (a < 0.0 and v_dn < -v_max):
        return _mirror(_velocity_brake(-v, -a, v_max, -v_max, -a_max, j))
    return []


def _duration(phases: list[Phase]) -> float:
    return math.fsum(max(dt, 0.0) for dt, _, _ in phases)


def plan_ahead(v: float, a: float, length: float, v_max: float, a_max: float, d_max: float,
               j: float, *, pos_scale: float = 0.0, reversal: bool = False
               ) -> list[Phase] | None:
    """Phases to rest after exactly `length` ahead (in this frame), or None if the target
    lies behind the stopping point. `pos_scale` (|absolute position|) sets the rounding
    slack; with `reversal` the target must lie strictly beyond the stopping point (the
    approach must really come from this frame's direction).

    A state outside the limits is first braked by ruckig's rule (`brake`) and the plan
    continues from there; if no plan continues (the target lies behind the braked
    state's stopping point) the plan without the brake is taken."""
    direct = _plan(v, a, length, v_max, a_max, d_max, j, pos_scale, reversal)
    if direct is None:
        return None
    pre = brake(v, a, v_max, a_max, d_max, j)
    if not pre:
        return direct
    d_b, v_b, a_b = advance(v, a, pre)
    rest = _plan(v_b, a_b, length - d_b, v_max, a_max, d_max, j, pos_scale, reversal)
    return None if rest is None else pre + rest


def _plan(v: float, a: float, length: float, v_max: float, a_max: float, d_max: float,
          j: float, pos_scale: float, reversal: bool) -> list[Phase] | None:
    """`plan_ahead` without the ruckig-style brake candidate."""
    stop = ramp_phases(v, a, 0.0, a_max, d_max, j)
    d_stop = advance(v, a, stop)[0]
    tol = SNAP * max(abs(length), abs(d_stop), pos_scale)
    if length < d_stop - tol or (reversal and length <= d_stop + tol):
        return None
    if length <= d_stop + tol:
        return stop  # the fastest stop ends on the target (end_p makes it exact)
    v_stop = v + a * abs(a) / (2.0 * j)

    def f1(vc: float) -> list[Phase]:
        return ramp_phases(v, a, vc, a_max, d_max, j) + ramp_phases(vc, 0.0, 0.0, a_max,
                                                                    d_max, j)

    def d1(vc: float) -> float:
        return advance(v, a, f1(vc))[0] - length

    # Above v_max the ramp to V brakes (with a dip at V): d(V) is continuous but not
    # monotone there, so search all of [0, v_max]; d(0) is the fastest stop.
    v_lo = max(v_stop, 0.0) if v_stop <= v_max else 0.0
    if d1(v_max) <= 0.0:
        up = ramp_phases(v, a, v_max, a_max, d_max, j)
        down = ramp_phases(v_max, 0.0, 0.0, a_max, d_max, j)
        cruise = -d1(v_max) / v_max
        return up + [(cruise, 0.0, 0.0)] + down
    if abs(d1(v_lo)) <= tol:
        return f1(v_lo)
    if d1(v_lo) <= 0.0:
        return f1(_solve(d1, v_lo, v_max))
    if a < 0.0:
        def f2(t1: float) -> list[Phase]:
            _, v1, a1 = advance(v, a, [(t1, j, None)])
            return [(t1, j, None)] + ramp_phases(v1, a1, 0.0, a_max, d_max, j)

        t1 = _solve(lambda t: advance(v, a, f2(t))[0] - length, 0.0, -a / j)
        return f2(t1)
    # not reached for a >= 0 (then d1(v_stop) is the stopping distance); kept for safety
    return ramp_phases(v, a, 0.0, a_max, d_max, j) + _rest_to_rest(
        length - advance(v, a, ramp_phases(v, a, 0.0, a_max, d_max, j))[0],
        v_max, a_max, d_max, j)


def _rest_to_rest(length: float, v_max: float, a_max: float, d_max: float,
                  j: float) -> list[Phase]:
    """The seven phases of the time-optimal rest-to-rest move (length may be < 0)."""
    s = 1.0 if length >= 0.0 else -1.0
    tj1, ta, _, tv, tj2, td, _ = phase_times(abs(length), v_max, a_max, d_max, j)
    ap, dp = min(a_max, j * tj1), min(d_max, j * tj2)
    return [(tj1, s * j, 0.0), (ta, 0.0, s * ap), (tj1, -s * j, s * ap), (tv, 0.0, 0.0),
            (tj2, -s * j, 0.0), (td, 0.0, -s * dp), (tj2, s * j, -s * dp)]


# ------------------------------------------------------------------- public API
def _check_state(state: State) -> tuple[float, float, float]:
    if not isinstance(state, State):
        raise MotionError(f"state must be a State(p, v, a), got {type(state).__name__}")
    return (check_pulses("state.p", state.p),
            check_quantity("state.v", state.v, "pps", zero=True, signed=True),
            check_quantity("state.a", state.a, "pps2", zero=True, signed=True))


def retarget(state: State, target: float, v_max: float, a_max: float, j_max: float, *,
             d_max: float | None = None) -> Profile:
    """From any state (p, v, a) to rest exactly on `target`, within the limits.

    a_max limits acceleration towards the final approach direction, d_max (default
    a_max) against it, so d_max is the final deceleration. |v| may exceed v_max (the
    profile brakes below it first); |a| must be within max(a_max, d_max). Reverses
    through zero velocity only when the target lies behind the stopping point.
    """
    p, v, a = _check_state(state)
    tgt = check_pulses("target", target)
    if abs(tgt - p) > COUNTER28_MAX:
        raise MotionError(f"target must satisfy |target - state.p| <= {COUNTER28_MAX} "
                          f"(28-bit counter), got {target!r}")
    vm = check_quantity("v_max", v_max, "pps")
    am = check_quantity("a_max", a_max, "pps2")
    jm = check_quantity("j_max", j_max, "pps3")
    dm = am if d_max is None else check_quantity("d_max", d_max, "pps2")
    if abs(a) > max(am, dm) * (1.0 + 1e-9):
        raise MotionError(f"state.a must satisfy |state.a| <= max(a_max, d_max), got {a!r}")

    v_stop = v + a * abs(a) / (2.0 * jm)
    m = 1.0 if v_stop > 0.0 or (v_stop == 0.0 and tgt >= p) else -1.0
    vf, af, length = m * v, m * a, m * (tgt - p)
    labels: list[str] = []
    scale = max(abs(p), abs(tgt))
    phases = plan_ahead(vf, af, length, vm, am, dm, jm, pos_scale=scale)
    if phases is None:  # reverse through zero velocity, planned in the frame of approach
        m, vf, af, length = -m, -vf, -af, -length
        phases = plan_ahead(vf, af, length, vm, am, dm, jm, pos_scale=scale, reversal=True)
    if phases is None:
        # Only with a_max > d_max: the target is behind the stopping point braking at d_max
        # but ahead of it braking at a_max. Stop (at d_max), then move back rest-to-rest.
        m, vf, af, length = -m, -vf, -af, -length
        stop = ramp_phases(vf, af, 0.0, am, dm, jm)
        phases = stop + _rest_to_rest(length - advance(vf, af, stop)[0], vm, am, dm, jm)
        labels = ["stop"] * len(stop) + [f"back {lb}" for lb in PHASE_LABELS]
    b = ProfileBuilder(p, vf, af, direction=m)
    for k, (dt, jk, pin) in enumerate(phases):
        b.segment(dt, jk, accel=pin, label=labels[k] if labels else "")
    b.set_acceleration(0.0)
    return b.build(end_p=tgt)


def retarget_velocity(state: State, v_target: float, a_max: float, j_max: float) -> Profile:
    """Fastest jerk-limited ramp from (p, v, a) to v_target; v_target is held afterwards."""
    p, v, a = _check_state(state)
    vt = check_quantity("v_target", v_target, "pps", zero=True, signed=True)
    am = check_quantity("a_max", a_max, "pps2")
    jm = check_quantity("j_max", j_max, "pps3")
    if abs(a) > am * (1.0 + 1e-9):
        raise MotionError(f"state.a must satisfy |state.a| <= a_max, got {a!r}")
    b = ProfileBuilder(p, v, a)
    ramp_jerk(b, vt, am, jm, label="velocity")
    return b.build(end_v=vt)
