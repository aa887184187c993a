"""A running path chain and its re-plans: start, join (streaming), override, hold.

One mechanism for T and S paths. The look-ahead gives a speed curve v**2(s) (pathexec);
that curve becomes the *raw* motion s(t), piecewise constant acceleration. A T path
executes the raw motion itself; an S path executes the raw motion smoothed by a moving
average of window tj (path/smoothing.py), which bounds the path jerk by |delta a|/tj. For
the smoothed motion to keep the raw motion's speed caps and tangential accelerations, each
cap c is held c*tj/2 beyond its element or corner (pathexec.guarded), and the raw motion
rests tj at every exact-stop corner so the smoothed one passes it at rest.

Every change while running is the same operation: take the raw state now, plan a new raw
tail from it over the (possibly longer) chain, splice it onto the raw motion, and smooth
from now on. The smoothed motion up to now depends only on the raw motion up to now, so it
continues without a jump in position, speed or acceleration. Elements the path has left
behind are dropped at each re-plan (their s is subtracted from everything), so a chain
that streams commands for hours stays as short as its look-ahead.

An S path with StrVel (`_start_strvel`) averages a raw motion that moved at the jump speed
before its start (the raw start state) and keeps its end speed after its end
(`PathPlan.v_end`): it starts with the jump and a = 0 and ends on the chain's end at the
end speed with a = 0 (path/smoothing.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ...errors import InfeasibleError
from ...path.smoothing import fir_smooth
from ...profile.pcl import MoveSpec
from ...profile.segments import Profile, ProfileBuilder, State
from . import pathexec as px


@dataclass(frozen=True)
class PathPlan:
    """What a running chain follows. Times are controller times; s is chain position."""

    chain: px.Chain
    curve: px.SpeedCurve   # the look-ahead plan the raw motion follows
    raw: Profile           # raw s(t), its time 0 at `raw_t0`
    raw_t0: float
    sprof: Profile         # executed s(t), its time 0 at `t0` (raw itself when tj == 0)
    t0: float
    tj: float              # smoothing window (0: T path)
    limits: px.Limits
    a_min: float           # tangential deceleration every remaining element allows
    v_end: float = 0.0     # S path with StrVel: the raw speed past its end (0: ends at rest)
    move: MoveSpec | None = None  # a command run alone as one move along it (pathmove.py)

    @property
    def t_end(self) -> float:
        return self.t0 + self.sprof.duration

    def s_at(self, t: float) -> float:
        return self.sprof.state_at(min(max(t - self.t0, 0.0), self.sprof.duration)).p

    def remaining(self, t: float) -> float:
        """Path length the raw motion still has before the chain's end."""
        u = t - self.raw_t0
        return self.chain.length - self.raw.state_at(min(max(u, 0.0), self.raw.duration)).p

    @property
    def stopped_short(self) -> bool:
        return self.sprof.end.p < self.chain.length


def start(chain: px.Chain, lim: px.Limits, tj: float, t: float, s0: float = 0.0) -> PathPlan:
    """A chain from rest at path position s0 (0: its start; a held chain continues),
    with the StrVel jump of its limits."""
    if tj > 0.0 and s0 >= chain.length:  # a hold that ended on the end: nothing left
        end = _still(chain.length, 0.0)
        curve = px.SpeedCurve(np.array([chain.length]), np.array([0.0]))
        return drop_travelled(PathPlan(chain, curve, end, t, end, t, tj, lim, lim.accel))
    sv = lim.str_vel  # a StrVel path starts with a jump to it
    if tj > 0.0 and sv > 0.0:
        try:
            return _start_strvel(chain, lim, tj, t, s0)
        except InfeasibleError:  # too short to jump (or not from s0): an S path from rest
            lim, sv = replace(lim, str_vel=0.0), 0.0
    curve = px.plan_curve(chain, s0, sv, lim, window=tj, jump=sv > 0.0)
    raw = px.s_profile(curve, chain.length, chain.cum[1:-1], dwell=tj)
    sprof = fir_smooth(raw, tj) if tj > 0.0 else raw
    return drop_travelled(PathPlan(chain, curve, raw, t, sprof, t, tj, lim, _amin(curve, lim)))


def _start_strvel(chain: px.Chain, lim: px.Limits, tj: float, t: float,
                  s0: float) -> PathPlan:
    """An S path with the StrVel jump (see the smoothing module doc): the raw motion starts
    d = v*tj/2 ahead of s0 at the jump speed v, with a history at v, so the executed one
    starts on s0 at v with a = 0; it ends with tj/2 at its end speed (`_cruise_end`)."""
    room = chain.length - s0
    v = min(lim.str_vel, room / tj)  # the start and end stretches need v*tj of path
    if v > 0.0:  # the raw start must lie before the first exact stop (a barrier), with room
        ahead = px.plan_curve(chain, s0, v, lim, window=tj, jump=True)
        stop = px.stop_point(ahead)
        if stop < chain.length and ahead.at(stop) <= 0.0:  # d + v**2/(2a) <= the way
            a = ahead.a_min if math.isfinite(ahead.a_min) else lim.accel
            h = 0.5 * tj
            v = min(v, a * (math.sqrt(h * h + 2.0 * (stop - s0) / a) - h))
    for _ in range(8):  # the jump speed the look-ahead allows from s0 + d (d shrinks with v)
        if not v > 1e-12 * max(1.0, lim.str_vel) or room <= 0.0:
            break
        d = min(0.5 * v * tj, room)
        curve = px.plan_curve(chain, s0 + d, v, lim, window=tj, jump=True)
        curve, ve = _cruise_end(curve, tj, lim.str_vel, lim.accel)
        v1 = math.sqrt(curve.v2[0])
        if v1 < v * (1.0 - 1e-12):
            v = v1
            continue
        curve = replace(curve, jump=False)  # the history before the start is at v
        raw = px.s_profile(curve, chain.length, chain.cum[1:-1], dwell=tj)
        sprof = fir_smooth(raw, tj, v_after=ve)
        sprof = replace(sprof, start=State(sprof.start.p, 0.0, 0.0))  # at rest before: jump
        return drop_travelled(PathPlan(chain, curve, raw, t, sprof, t, tj, lim,
                                       _amin(curve, lim), ve))
    raise InfeasibleError("no StrVel start fits the chain")


def _cruise_end(curve: px.SpeedCurve, tj: float, sv: float,
                accel: float) -> tuple[px.SpeedCurve, float]:
    """The curve (which ends at <= StrVel `sv`) lowered so that it holds its end speed ve
    over the last ve*tj/2 before its end: the executed (averaged) motion then ends on the
    chain's end at ve with a = 0 (smoothing module doc). Lowered by a ramp at the smallest
    tangential acceleration of the curve's elements, so it keeps every limit. Raises
    InfeasibleError when that would lower the curve's start (the raw is already too fast)."""
    s, v2 = curve.s, curve.v2
    end = float(s[-1])
    a = curve.a_min if math.isfinite(curve.a_min) else accel
    h = 0.5 * tj
    near = s[(v2 <= 0.0) & (s >= end - sv * h) & (s < end)]
    if len(near):  # an exact stop within the end stretch: start it after the stop, and
        # reach its speed from rest there (v*tj/2 + v**2/(2a) <= the way to the end)
        sv = min(sv, a * (math.sqrt(h * h + 2.0 * (end - float(near[-1])) / a) - h))
    lo = max(float(s[0]), end - sv * h)
    inside = v2[(s > lo) & (s < end)]
    ve2 = min(sv * sv, curve.at(lo), float(v2[-1]), *(float(x) for x in inside))
    if not ve2 > 0.0:
        raise InfeasibleError("the path stops within its StrVel end")
    ve = math.sqrt(ve2)
    knee = end - ve * h
    if knee < float(s[0]) - 1e-9 * max(1.0, end):
        raise InfeasibleError("no room for the StrVel end")
    if knee > float(s[0]):
        cap = px.SpeedCurve(np.array([float(s[0]), knee, end]),
                            np.array([ve2 + 2.0 * a * (knee - float(s[0])), ve2, ve2]))
    else:
        cap = px.SpeedCurve(np.array([float(s[0]), end]), np.array([ve2, ve2]))
    out = px.curve_min(curve, cap)
    if out.v2[0] < curve.v2[0] * (1.0 - 1e-9):
        raise InfeasibleError("the path cannot slow down to its StrVel end in time")
    return px.SpeedCurve(out.s, out.v2, curve.a_min, curve.jump), ve


def replan(plan: PathPlan, t: float, *, chain: px.Chain | None = None,
           limits: px.Limits | None = None, hold: bool = False) -> PathPlan:
    """Re-plan `plan` from time t: over `chain` (the same chain extended; default the
    chain itself) with `limits` (default the plan's), or decelerating to rest (`hold`).
    Raises InfeasibleError when the new chain cannot be followed from the present speed
    (a join that comes too late); the caller then keeps the old plan."""
    if plan.move is not None:  # a command run alone: its own 1-D re-plan (joins none)
        from . import pathmove

        return pathmove.replan(plan, t, limits=limits, hold=hold)
    chain = chain or plan.chain
    lim = limits or plan.limits
    tj = plan.tj
    u = t - plan.raw_t0
    if plan.v_end > 0.0:
        return _replan_strvel(plan, t, chain, lim, hold)
    raw = _rest_until(plan.raw, u)
    rs = raw.state_at(u)
    s0, v0 = rs.p, max(0.0, rs.v)
    lead = 0.0
    if hold:
        curve = px.hold_curve(plan.curve, s0, v0, plan.a_min)
        s_end = px.stop_point(curve) if v0 > 0.0 else s0
    else:
        old = plan.curve.tail(s0) if chain is plan.chain else None
        curve = px.plan_curve(chain, s0, v0, lim, old, window=tj)
        s_end = chain.length
        if v0 == 0.0 and tj > 0.0:  # at rest at a stop (an exact-stop corner, or the end
            # a join continues from): rest out the tj the executed motion needs to pass it
            # at rest, whatever the re-plan (an override in the dwell used to cut it short)
            lead = max(0.0, tj - _rested(raw, u))
    if s_end > s0:
        tail = px.s_profile(curve, s_end, chain.cum[1:-1], dwell=tj, lead=lead)
    else:
        tail = _still(s0, 0.0)
    spliced = raw.splice(u, tail)
    if tj > 0.0:
        sprof = fir_smooth(spliced, tj, t_out=u)
        cut = max(0.0, u - tj)  # keep a window of raw history for the next re-plan
        new_raw, raw_t0 = (spliced, plan.raw_t0) if cut <= 0.0 else \
            (_rebased(spliced, cut), plan.raw_t0 + cut)
    else:
        sprof, new_raw, raw_t0 = tail, tail, t
    new = PathPlan(chain, curve, new_raw, raw_t0, sprof, t, tj, lim,
                   plan.a_min if hold else _amin(curve, lim))
    return drop_travelled(new)


def _replan_strvel(plan: PathPlan, t: float, chain: px.Chain, lim: px.Limits,
                   hold: bool) -> PathPlan:
    """`replan` for an S path that ends with the StrVel jump (plan.v_end > 0): the new raw
    tail ends the same way (`_cruise_end`), or at rest for a hold. Once the raw motion
    cruises into its end (its last tj/2) or cannot slow down in time, a hold or an
    override leaves it unchanged (the path finishes with its end jump within tj) and a join
    raises InfeasibleError (the joined commands start after the chain)."""
    tj, u, raw = plan.tj, t - plan.raw_t0, plan.raw
    joined = chain is not plan.chain
    keep = u >= raw.duration - 0.5 * tj
    if not keep:
        rs = raw.state_at(u)
        s0, v0 = rs.p, max(0.0, rs.v)
        lead = 0.0
        try:
            if hold:
                curve = px.hold_curve(plan.curve, s0, v0, plan.a_min)
                s_end = px.stop_point(curve) if v0 > 0.0 else s0
                if curve.at(s_end) > 0.0:
                    raise InfeasibleError("cannot stop before the StrVel end")
                ve = 0.0
            else:
                old = None if joined else plan.curve.tail(s0)
                curve = px.plan_curve(chain, s0, v0, lim, old, window=tj)
                curve, ve = _cruise_end(curve, tj, lim.str_vel, lim.accel)
                s_end = chain.length
                if v0 == 0.0:  # resting at an exact stop: complete the rest to tj
                    lead = max(0.0, tj - _rested(raw, u))
        except InfeasibleError:
            if joined:
                raise
            keep = True
    if keep:
        if joined:
            raise InfeasibleError("the chain already cruises into its StrVel end")
        chain, curve, ve, spliced = plan.chain, plan.curve, plan.v_end, raw
    else:
        tail = px.s_profile(curve, s_end, chain.cum[1:-1], dwell=tj, lead=lead) \
            if s_end > s0 else _still(s0, 0.0)
        spliced = raw.splice(u, tail)
    sprof = fir_smooth(spliced, tj, t_out=u, v_after=ve)
    cut = max(0.0, u - tj)  # keep a window of raw history for the next re-plan
    new_raw, raw_t0 = (spliced, plan.raw_t0) if cut <= 0.0 else \
        (_rebased(spliced, cut), plan.raw_t0 + cut)
    a_min = plan.a_min if hold or keep else _amin(curve, lim)
    return drop_travelled(PathPlan(chain, curve, new_raw, raw_t0, sprof, t, tj, lim, a_min,
                                   ve))


def drop_travelled(plan: PathPlan) -> PathPlan:
    """Drop the elements the raw motion (and so the executed one) has fully left."""
    s_keep = min(plan.raw.start.p, plan.sprof.start.p)
    k = plan.chain.locate(s_keep)
    if k < 1:
        return plan
    chain, off = plan.chain.dropped(k)
    curve = replace(plan.curve, s=plan.curve.s - off)
    return replace(plan, chain=chain, curve=curve, raw=plan.raw.shifted(-off),
                   sprof=_pinned_shift(plan.sprof, off, plan.chain.length, chain.length))


def _pinned_shift(p: Profile, off: float, old_len: float, new_len: float) -> Profile:
    """p shifted by -off, its end exactly at the new chain length when it ended at the
    old one (so the last knot lands on the chain's end point bit for bit)."""
    out = p.shifted(-off)
    if p.end.p >= old_len:
        out = replace(out, end=out.end._replace(p=new_len))
    return out


def _amin(curve: px.SpeedCurve, lim: px.Limits) -> float:
    return curve.a_min if math.isfinite(curve.a_min) else lim.accel


def _still(p: float, d: float) -> Profile:
    b = ProfileBuilder(p)
    if d > 0.0:
        b.segment(d, 0.0, accel=0.0, label="rest")
    return b.build(end_p=p)


def _rest_until(raw: Profile, u: float) -> Profile:
    """The raw motion, resting at its end until at least time u."""
    if u <= raw.duration:
        return raw
    return raw.splice(raw.duration, _still(raw.end.p, u - raw.duration))


def _rested(raw: Profile, u: float) -> float:
    """How long the raw motion has been at rest up to time u (0 if it moves at u)."""
    if raw.state_at(u).v != 0.0:
        return 0.0
    rest = max(0.0, u - raw.duration)  # resting after its end
    t_end = min(u, raw.duration)
    k = int(np.searchsorted(raw.t0, t_end, side="left")) - 1  # the segment before t_end
    while k >= 0 and raw.v0[k] == 0.0 and raw.a0[k] == 0.0:
        rest += t_end - float(raw.t0[k])
        t_end = float(raw.t0[k])
        k -= 1
    return rest


def _rebased(p: Profile, u: float) -> Profile:
    """A constant-acceleration profile with time u as its new zero (the past dropped)."""
    dts = p.dt if p.dt is not None else np.diff(np.append(p.t0, p.duration))
    keep = p.t0 + dts > u
    st = p.state_at(u)
    t0 = np.maximum(p.t0[keep] - u, 0.0)
    dt = dts[keep].copy()
    p0, v0 = p.p0[keep].copy(), p.v0[keep].copy()
    if len(t0):
        first = float(p.t0[keep][0])
        if first < u:
            dt[0] = first + float(dt[0]) - u
            p0[0], v0[0] = st.p, st.v
    labels = tuple(lb for lb, k in zip(p.labels, keep, strict=False) if k)
    return Profile(t0, p0, v0, p.a0[keep].copy(), p.j[keep].copy(), max(0.0, p.duration - u),
                   st, p.end, labels, dt)
