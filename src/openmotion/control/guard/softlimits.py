"""Soft limits (HSL-4XMO 4.14, comparators 1 and 2): the command position never passes them.

Two limits per axis in the command-counter frame, enabled with a stop action: "immediate"
or "decel" (the running move's deceleration to StrVel, then stop). The HSL board compares
the command counter pulse by pulse; this controller works per cycle, so it *predicts*:

- a motion (start or re-plan) is refused when its plan goes past an enabled limit (a target
  beyond it), or, for an open-ended motion (velocity mode, jog), when one more cycle of it
  could no longer be stopped before the limit;
- at the end of every cycle (time t, period T) for an open-ended plan that crosses a limit:
  decel action - if a stop started at t + T would end past the limit, the stop starts now
  (from t it ends inside: the previous cycle checked exactly that); immediate action - if
  the plan is past the limit anywhere in [t, t + T], the axis stops now at once.

So the axis stops at most one cycle's travel (immediate) or one cycle's worth of stopping
distance (decel) before the limit, never after. The axis goes to ErrorStop "+SL" / "-SL".
Suspend with `safety.suspend(axis, "soft")` (homing).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import MotionError, check_finite
from ...profile.velocity import stop_distance
from ..core import planning
from ..core.states import AxisState

if TYPE_CHECKING:
    from ...profile.segments import Profile
    from ..core.axis import Axis
    from ..core.controller import Controller
    from ..core.motion import ActiveMotion

_TOL = 1e-9
OPEN_ENDED = ("velocity",)


@dataclass
class SoftLimit:
    """Soft limits of one axis, command-counter frame."""

    plimit: float = math.inf
    nlimit: float = -math.inf
    enabled: bool = False
    decelerate: bool = False


def working_interval(high: float, low: float, high_offset: float = 0.0,
                     low_offset: float = 0.0) -> tuple[float, float]:
    """MCCL 2.4 working interval [low + low_offset, high - high_offset] (any one unit).

    `high` (dfHighLimit) must be > 0 and `low` (dfLowLimit) < 0, relative to the logical
    home; the offsets (dfHighLimitOffset / dfLowLimitOffset) must be >= 0 and at most
    `high` / |low|. MotionError naming the parameter otherwise."""
    hi = check_finite("high", high)
    lo = check_finite("low", low)
    ho = check_finite("high_offset", high_offset)
    lo_off = check_finite("low_offset", low_offset)
    if not hi > 0.0:
        raise MotionError(f"high (dfHighLimit) must be > 0, got {high!r}")
    if not lo < 0.0:
        raise MotionError(f"low (dfLowLimit) must be negative, got {low!r}")
    if not 0.0 <= ho <= hi:
        raise MotionError(f"high_offset (dfHighLimitOffset) must be in [0, dfHighLimit = "
                          f"{hi!r}], got {high_offset!r}")
    if not 0.0 <= lo_off <= -lo:
        raise MotionError(f"low_offset (dfLowLimitOffset) must be in [0, |dfLowLimit| = "
                          f"{-lo!r}], got {low_offset!r}")
    return lo + lo_off, hi - ho


def profile_extent(profile: Profile, u0: float, u1: float) -> tuple[float, float]:
    """(min, max) position of `profile` over local times [u0, u1] (u1 may be inf; past the
    end the end state continues at its velocity). Exact: segment ends and velocity zeros."""
    dur = profile.duration
    pts = []
    if u1 > dur:
        end = profile.end
        if end.v == 0.0:
            pts.append(end.p)
        elif math.isinf(u1):
            pts.append(math.copysign(math.inf, end.v))
        else:
            pts.append(end.p + end.v * (u1 - dur))
        pts.append(end.p + end.v * max(u0 - dur, 0.0))
    n = profile.n_segments
    if n and u0 < dur:
        t0 = profile.t0
        t_next = np.append(t0[1:], dur)
        lo = np.maximum(t0, u0)
        hi = np.minimum(t_next, u1)
        ok = hi >= lo
        p0, v0, a0, j = profile.p0[ok], profile.v0[ok], profile.a0[ok], profile.j[ok]
        s_lo, s_hi = (lo - t0)[ok], (hi - t0)[ok]
        cand = [s_lo, s_hi]
        # velocity zeros: v0 + a0 s + j s^2 / 2 = 0
        qa, qb, qc = j / 2.0, a0, v0
        with np.errstate(divide="ignore", invalid="ignore"):
            disc = np.sqrt(np.maximum(qb * qb - 4.0 * qa * qc, 0.0))
            r1 = np.where(qa != 0.0, (-qb + disc) / (2.0 * qa),
                          np.where(qb != 0.0, -qc / qb, s_lo))
            r2 = np.where(qa != 0.0, (-qb - disc) / (2.0 * qa), s_lo)
        for r in (r1, r2):
            r = np.nan_to_num(r, nan=0.0)
            cand.append(np.clip(r, s_lo, s_hi))
        s = np.stack(cand)
        p = p0 + s * (v0 + s * (a0 / 2.0 + s * j / 6.0))
        if p.size:
            pts += [float(p.min()), float(p.max())]
    if not pts:
        st = profile.state_at(min(max(u0, 0.0), dur))
        pts.append(st.p)
    return min(pts), max(pts)


class SoftLimits:
    """Soft limits of every axis of a controller (used through `Safety.soft`)."""

    def __init__(self, controller: Controller,
                 suspended: Callable[[int, str], bool] = lambda a, s: False) -> None:
        self.ctl = controller
        self._lim = [SoftLimit() for _ in controller.axes]
        self._suspended = suspended
        self._safe: dict[int, tuple[int, float, float]] = {}  # axis -> (id, lo, hi) cache
        self._memo: dict[int, tuple] = {}  # motion id -> (spec, v, a, stop distance)

    def set(self, axis: int | str, plimit: float, nlimit: float) -> None:
        """HSL_M_set_soft_limit(PLimit, NLimit), command-counter positions, nlimit < plimit."""
        i = self.ctl.axis(axis).index
        p = check_finite("plimit", plimit)
        n = check_finite("nlimit", nlimit)
        if not n < p:
            raise MotionError(f"nlimit must be < plimit, got nlimit={nlimit!r}, "
                              f"plimit={plimit!r}")
        self._lim[i].plimit, self._lim[i].nlimit = p, n
        self._safe.pop(i, None)

    def enable(self, axis: int | str, action: str | int = "immediate") -> None:
        """HSL_M_enable_soft_limit(Action): "immediate" (0) or "decel" (1) stop."""
        i = self.ctl.axis(axis).index
        lim = self._lim[i]
        if action in ("immediate", 0) and not isinstance(action, bool):
            dec = False
        elif action in ("decel", 1) and not isinstance(action, bool):
            dec = True
        else:
            raise MotionError(f"action must be 'immediate' (0) or 'decel' (1), got {action!r}")
        if math.isinf(lim.plimit):
            raise MotionError("soft limits are not set; call set(axis, plimit, nlimit) first")
        lim.enabled, lim.decelerate = True, dec
        self._safe.pop(i, None)

    def disable(self, axis: int | str) -> None:
        """HSL_M_disable_soft_limit."""
        i = self.ctl.axis(axis).index
        self._lim[i].enabled = False

    def get(self, axis: int | str) -> SoftLimit:
        lim = self._lim[self.ctl.axis(axis).index]
        return SoftLimit(lim.plimit, lim.nlimit, lim.enabled, lim.decelerate)

    def enabled_of(self, indices: tuple[int, ...]) -> list[tuple[int, float, float]]:
        """(k, plimit, nlimit) of every enabled limit among the controller axes `indices`
        (k: the position in `indices`), as `get` reports them now: a group's push path
        compares each queued point against these (plain floats, no copies)."""
        lims = self._lim
        out = []
        for k, i in enumerate(indices):
            lim = lims[i]
            if lim.enabled:
                out.append((k, lim.plimit, lim.nlimit))
        return out

    # ------------------------------------------------------------------ internals
    def _raw(self, ax: Axis) -> tuple[float, float] | None:
        """(nlimit, plimit) in the raw pulse frame, or None when not active."""
        lim = self._lim[ax.index]
        if not lim.enabled or self._suspended(ax.index, "soft"):
            return None
        c = ax.counters
        return c.pulses_from_command(lim.nlimit), c.pulses_from_command(lim.plimit)

    def _over(self, lo: float, hi: float, lim: tuple[float, float], here: float) -> int:
        """+1 / -1 when [lo, hi] goes past the plus / minus limit (further than `here`)."""
        n, p = lim
        if hi > max(p, here) + _TOL * max(1.0, abs(p)):
            return 1
        if lo < min(n, here) - _TOL * max(1.0, abs(n)):
            return -1
        return 0

    def _stop_extent(self, m: ActiveMotion, now: float, t: float,
                     decel: bool) -> tuple[float, float]:
        """Extent of the plan from `now` to a stop begun at absolute time t (decel or
        immediate) and through that stop."""
        u = t - m.t_start
        lo, hi = profile_extent(m.profile, now - m.t_start, u)
        if decel and m.kind != "stop":
            pr = planning.decel_stop(m, t, None)
            a, b = profile_extent(pr, u, pr.duration)
            lo, hi = min(lo, a), max(hi, b)
        return lo, hi

    def check_motion(self, ax: Axis, m: ActiveMotion) -> None:
        """Refuse (MotionError) a motion that would pass an enabled soft limit."""
        lim = self._raw(ax)
        if lim is None:
            return
        t = self.ctl.time
        u = t - m.t_start
        here = m.state(t)[0]
        lo, hi = profile_extent(m.profile, u, math.inf)
        side = self._over(lo, hi, lim, here)
        if side == 0:
            return
        name = "+" if side > 0 else "-"
        value = self._lim[ax.index].plimit if side > 0 else self._lim[ax.index].nlimit
        if m.kind not in OPEN_ENDED:
            raise MotionError(f"axis {ax.name}: the motion passes the {name} soft limit "
                              f"{value!r}")
        T = self.ctl.period
        a, b = self._stop_extent(m, t, t + T, self._lim[ax.index].decelerate)
        a, b = min(a, here), max(b, here)
        if self._over(a, b, lim, here):
            raise MotionError(f"axis {ax.name}: too close to the {name} soft limit {value!r} "
                              "to start this motion")

    def _fast_extent(self, m: ActiveMotion, now: float, t: float,
                     decel: bool) -> tuple[float, float] | None:
        """`_stop_extent` for a velocity-mode plan that keeps its direction over [now, t]
        (monotone there, so its ends bound it), with the stop distance computed alone;
        None when that shortcut does not apply."""
        p0, v0, _ = m.state(now)
        p1, v1, a1 = m.state(t)
        if v0 * v1 < 0.0 or m.spec is None:
            return None
        lo, hi = min(p0, p1), max(p0, p1)
        if decel and v1 != 0.0:
            # constant speed: the same stop every cycle (the memo holds the spec itself)
            memo = self._memo.get(id(m))
            if memo is None or memo[0] is not m.spec or memo[1:3] != (v1, a1):
                if len(self._memo) > 64:
                    self._memo.clear()
                memo = (m.spec, v1, a1, stop_distance(m.spec, v1, a1))
                self._memo[id(m)] = memo
            e = p1 + math.copysign(memo[3], v1)
            lo, hi = min(lo, e), max(hi, e)
        return lo, hi

    def due(self) -> float:
        """When `on_cycle` may next act: every cycle while an axis under active limits runs
        a velocity move or a discrete move not yet found inside them, else math.inf."""
        for ax in self.ctl.axes:
            m = ax.motion
            if m is None or ax.state is AxisState.ERROR_STOP and ax.fault in ("+SL", "-SL"):
                continue
            lim = self._raw(ax)
            if lim is None:
                continue
            cached = self._safe.get(ax.index)
            if m.kind == "velocity" or cached is None or cached[0] != id(m) \
                    or cached[1:] != lim:
                return -math.inf
        return math.inf

    def on_cycle(self, t: float) -> None:
        """The per-cycle prediction (see the module docstring)."""
        T = self.ctl.period
        for ax in self.ctl.axes:
            m = ax.motion
            if m is None or ax.state is AxisState.ERROR_STOP and ax.fault in ("+SL", "-SL"):
                continue  # (another fault's decelerating stop is watched like any motion)
            lim = self._raw(ax)
            if lim is None:
                continue
            i = ax.index
            here = m.state(t)[0]
            decel = self._lim[i].decelerate and m.kind != "stop"
            if m.kind == "velocity":  # open-ended: checked every cycle, cheaply
                ext = self._fast_extent(m, t, t + T, decel) or \
                    self._stop_extent(m, t, t + T, decel)
                side = self._over(min(ext[0], here), max(ext[1], here), lim, here)
                if side == 0:
                    continue
            else:
                key = id(m)
                cached = self._safe.get(i)
                if cached is not None and cached[0] == key and cached[1:] == lim:
                    continue
                lo, hi = profile_extent(m.profile, t - m.t_start, math.inf)
                side = self._over(lo, hi, lim, here)
                if side == 0:
                    self._safe[i] = (key, *lim)
                    continue
                a, b = self._stop_extent(m, t, t + T, decel)
                if not self._over(min(a, here), max(b, here), lim, here):
                    continue
            reason = "+SL" if side > 0 else "-SL"
            if decel:
                a, b = self._fast_extent(m, t, t, True) or self._stop_extent(m, t, t, True)
                if not self._over(min(a, here), max(b, here), lim, here):
                    ax.fault_stop(reason, decelerate=True)
                    continue
            ax.fault_stop(reason)
