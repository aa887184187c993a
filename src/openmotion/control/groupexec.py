"""The run-time side of a `Group`: executing its queue from a controller cycle hook.

Point-to-point commands start every axis with its own T/S profile and the next command
waits for all of them. Consecutive path commands with the same feed and acceleration are
planned as one chain by the look-ahead (`path.plan_speeds`) and executed by pathexec.py:
with blending on, corners between lines and arcs are rounded (`path.blend_corner`) within
the tolerance and the chain runs through them; with blending off every corner is an exact
stop. Hold, continue, abort and the feed override re-plan the running chain from the
current path state. A group axis going to ErrorStop (the controller's fault hooks, when
present, and a check every cycle) or reaching the limit switch ahead of it stops every axis
of the group at once and puts the group in error (MCCL 2.6.3 VI: all motion commands stop).
"""

from __future__ import annotations

import math
import weakref
from collections import deque
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InfeasibleError, MotionError
from ..path import Blend, blend_corner, plan_speeds
from ..path.geometry import PathElement
from ..path.smoothing import fir_smooth, jerk_window
from ..profile.pcl import MoveSpec
from ..profile.segments import Profile, State
from . import pathexec as px
from . import planning
from .group_corners import LookaheadSettings
from .states import AxisState

if TYPE_CHECKING:
    from .axis import Axis
    from .controller import Controller


class GroupError(MotionError):
    """A refused group command or a group fault; `code` is the negative error code."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


#: Negative error codes (returned by facades on rejection; `Group.error_code` at run time).
ERR_ARGUMENT = -1      # NaN, zero-length move, bad shape/plane/direction, ...
ERR_QUEUE_FULL = -2
ERR_AXIS_BUSY = -3     # axis in another group or moving outside the group
ERR_AXIS_STATE = -4    # axis disabled or in ErrorStop
ERR_SPEED = -5         # feed beyond the system maximum or an axis's maximum pulse speed
ERR_ACCEL = -6         # acceleration beyond an axis's maximum pulse acceleration
ERR_ARC = -7           # arc command error (end not on the circle, collinear 3-D arc)
ERR_GROUP = -8         # the group is in error: clear_error() first
ERR_LIMIT = -9         # run time: limit switch reached by a group axis
ERR_AXIS_FAULT = -10   # run time: a group axis went to ErrorStop
ERR_STATE = -11        # command not allowed in the group's state (e.g. continue when not held)


class GroupState(Enum):
    IDLE = "idle"
    MOVING = "moving"
    HOLDING = "holding"   # decelerating along the path after hold()
    HELD = "held"
    ERROR = "error"


OWNERS: weakref.WeakKeyDictionary[Any, dict[int, GroupEngine]] = weakref.WeakKeyDictionary()


@dataclass
class _Cmd:
    index: int
    kind: str                      # ptp, path, delay
    target: np.ndarray | None = None
    elements: tuple[PathElement, ...] = ()
    feed: float = 0.0
    accel: float = 0.0
    specs: tuple[MoveSpec, ...] = ()
    seconds: float = 0.0
    jerk: float = 0.0              # path jerk limit (0: T-curve)
    str_vel: float = 0.0           # StrVel: a path starts/ends with a jump from/to rest


@dataclass
class _Run:
    """What the group is executing now."""

    kind: str
    cmds: list[_Cmd]
    t0: float
    chain: px.Chain | None = None
    curve: px.SpeedCurve | None = None
    sprof: Profile | None = None
    profiles: list[Profile] = field(default_factory=list)
    limits: px.Limits | None = None
    a_min: float = 0.0
    t_until: float = 0.0
    target: np.ndarray | None = None
    raw: Profile | None = None     # S-curve: the T-curve s(t) the filter smooths
    tj: float = 0.0                # S-curve: the filter window

    @property
    def t_end(self) -> float:
        if self.kind == "delay":
            return self.t_until
        if self.sprof is not None:
            return self.t0 + self.sprof.duration
        return self.t0 + max((p.duration for p in self.profiles), default=0.0)


class GroupEngine(LookaheadSettings):
    """Queue execution and re-planning; `Group` adds the commands and settings."""

    _ctl: Controller
    axes: tuple[Axis, ...]
    names: tuple[str, ...]
    _queue: deque[_Cmd]
    _state: GroupState
    _run: _Run | None
    _held: _Run | None
    _aborting: bool
    _error: int
    _error_msg: str
    _override: float
    _ptp_override: float
    _dry: bool
    _dry_pos: np.ndarray
    _tail: np.ndarray | None
    _blend: bool
    _blend_tol: float
    _sys_max: float
    _vmax: np.ndarray
    _amax: np.ndarray
    _k: np.ndarray      # signed pulses per logical unit (1.0: the group works in pulses)
    _ppu: np.ndarray

    def _units_of(self, pulses: np.ndarray) -> np.ndarray:
        """Pulse positions -> logical coordinates."""
        return np.asarray(pulses, dtype=float) / self._k

    def _pulses_of(self, coords: np.ndarray) -> np.ndarray:
        """Logical coordinates -> pulse positions (AxisUnits.to_pulses per axis)."""
        return np.asarray(coords, dtype=float) * self._k

    def _caps(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-axis speed and acceleration caps in logical units (from the pulse caps)."""
        return self._vmax / self._ppu, self._amax / self._ppu

    def _pulse_profiles(self, profiles: list[Profile]) -> list[Profile]:
        """Axis profiles planned in logical units -> command pulses."""
        if np.all(self._k == 1.0):
            return profiles
        return [px.scaled(p, float(k)) for p, k in zip(profiles, self._k, strict=True)]

    @property
    def position(self) -> np.ndarray:  # defined by Group
        raise NotImplementedError

    # ------------------------------------------------------------------ execution
    def _limits(self, cmd: _Cmd) -> px.Limits:
        vmax, amax = self._caps()
        return px.Limits(min(cmd.feed * self._override, self._sys_max), cmd.accel, vmax, amax,
                         str_vel=cmd.str_vel, **self._corner_limits())

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        if self._state is GroupState.ERROR:
            return
        if self._run is not None and not self._dry and self._check_faults():
            return
        r = self._run
        if r is not None and t >= r.t_end - 1e-12 and (self._dry or not any(
                a.is_moving for a in self.axes)):
            self._run = None
            if r.kind in ("path", "ptp") and r.target is not None and self._dry:
                self._dry_pos = self._pulses_of(r.target) if r.kind == "path" \
                    else r.target.copy()
            if self._state is GroupState.HOLDING:
                if self._aborting:
                    self._aborting = False
                    self._state = GroupState.IDLE
                    self._tail = None
                    if self._dry and r.profiles:
                        self._dry_pos = np.array([p.end.p for p in r.profiles])
                    return
                self._held = r
                if self._dry and r.profiles:
                    self._dry_pos = np.array([p.end.p for p in r.profiles])
                self._state = GroupState.HELD
                return
            if r.kind == "path" and r.sprof is not None and r.chain is not None \
                    and r.sprof.end.p < r.chain.length:
                # a run that stopped short (should not happen) is kept as held
                self._held, self._state = r, GroupState.HELD
                return
        if self._run is None and self._state in (GroupState.MOVING, GroupState.IDLE):
            if self._queue:
                self._start_next(t)
            else:
                self._state = GroupState.IDLE

    def _start_next(self, t: float) -> None:
        try:
            self._start_queued(t)
        except MotionError as err:  # an axis refused (safety check, state): stop the group
            self._fault(getattr(err, "code", ERR_AXIS_STATE), f"command refused at start: {err}")

    def _start_queued(self, t: float) -> None:
        cmd = self._queue.popleft()
        if cmd.kind == "delay":
            self._run = _Run("delay", [cmd], t, t_until=t + cmd.seconds)
        elif cmd.kind == "ptp":
            self._launch_ptp(cmd, t)
        else:
            cmds = [cmd]
            while self._queue and self._queue[0].kind == "path" and not cmd.jerk \
                    and not self._queue[0].jerk \
                    and self._queue[0].feed == cmd.feed and self._queue[0].accel == cmd.accel \
                    and self._queue[0].str_vel == cmd.str_vel:
                cmds.append(self._queue.popleft())
            chain = self._chain(cmds)
            lim = self._limits(cmd)
            curve = px.plan_curve(chain, 0.0, lim.str_vel, lim, jump=True)
            self._launch_path(chain, curve, cmds, lim, t)
        self._state = GroupState.MOVING

    def _chain(self, cmds: list[_Cmd]) -> px.Chain:
        els: list[PathElement] = []
        owners: list[int] = []
        for c in cmds:
            el = c.elements[0]
            b = self._corner_blend(els[-1], el, c) if els else None
            if b is not None:
                els[-1] = b.first
                els.append(b.arc)
                owners.append(c.index)
                el = b.second
            els.append(el)
            owners.append(c.index)
        return px.Chain(els, owners)

    def _corner_blend(self, prev: PathElement, el: PathElement, cmd: _Cmd) -> Blend | None:
        """The blend of the corner prev -> el (any Line/Arc/Arc3D pair) when blending is on
        and rounding it pays; None: an exact stop (or a tangent corner)."""
        if not (self._blend and self._blend_tol > 0.0):
            return None
        b = blend_corner(prev, el, self._blend_tol)
        if b is None or not _blend_pays(b, min(cmd.accel, float(np.min(self._caps()[1]))),
                                        cmd.feed):
            return None
        return b

    def _launch_ptp(self, cmd: _Cmd, t: float) -> None:
        assert cmd.target is not None
        profiles = []
        start = self._pulses_of(self.position)
        target = self._pulses_of(cmd.target)
        for k, a in enumerate(self.axes):
            spec = cmd.specs[k]
            if self._ptp_override != 1.0:
                spec = MoveSpec(spec.shape, spec.str_vel,
                                min(a._max_speed, spec.max_vel * self._ptp_override),
                                spec.tacc, spec.tdec, spec.vs_acc, spec.vs_dec)
            if self._dry:
                profiles.append(planning.position_move(spec, float(start[k]),
                                                       float(target[k])))
            elif target[k] != a.position:
                a.move_absolute(float(target[k]), max_vel=spec.max_vel, tacc=spec.tacc,
                                shape=spec.shape)
        self._run = _Run("ptp", [cmd], t, profiles=profiles, target=target)

    def _extend_running(self, cmd: _Cmd) -> bool:
        """Streaming look-ahead: join a path command queued while a chain runs (nothing
        else waiting, same feed and acceleration) to that chain and re-plan from now. The
        corner with the running chain is blended when the path has not yet reached the
        blend's start; when the new plan cannot start at the current speed (the path is
        already braking), the corner becomes an exact stop; failing that, the command
        just waits in the queue."""
        r = self._run
        if (r is None or r.kind != "path" or self._state is not GroupState.MOVING
                or self._queue or cmd.kind != "path" or r.chain is None or r.sprof is None
                or cmd.feed != r.cmds[0].feed or cmd.accel != r.cmds[0].accel
                or cmd.jerk or r.cmds[0].jerk or cmd.str_vel != r.cmds[0].str_vel):
            return False
        t = self._ctl.time
        u = t - r.t0
        if u >= r.sprof.duration:
            return False
        st = r.sprof.state_at(u)
        s0, v0 = st.p, max(0.0, st.v)
        old, owners = list(r.chain.elements), list(r.chain.owners)
        el = cmd.elements[0]
        options = []
        b = self._corner_blend(old[-1], el, cmd)
        if b is not None and s0 < float(r.chain.cum[-2]) + float(b.first.length):
            options.append((old[:-1] + [b.first, b.arc, b.second],
                            owners + [cmd.index, cmd.index]))
        options.append((old + [el], owners + [cmd.index]))
        lim = self._limits(cmd)
        for els, own in options:
            chain = px.Chain(els, own)
            try:
                curve = px.plan_curve(chain, s0, v0, lim)
            except InfeasibleError:
                continue
            self._launch_path(chain, curve, [*r.cmds, cmd], lim, t)
            return True
        return False

    def _launch_path(self, chain: px.Chain, curve: px.SpeedCurve, cmds: list[_Cmd],
                     lim: px.Limits, t: float) -> None:
        s_end = chain.length
        sprof = px.s_profile(curve, s_end, chain.cum[1:-1].tolist())
        raw, tj = None, 0.0
        if cmds[0].jerk:  # S-curve: smooth s(t) (one element, from rest; see path/smoothing)
            raw = sprof
            amax = float(np.max(np.abs(raw.a0))) if raw.n_segments else lim.accel
            tj = jerk_window(amax, cmds[0].jerk)
            sprof = fir_smooth(raw, tj)
        starts = self.position
        profiles = self._pulse_profiles(px.axis_profiles(chain, sprof, self._ctl.period,
                                                         starts))
        if not self._dry:
            self._run_profiles(profiles, lim.str_vel)
        a_min = min((lim.accel,) + tuple(
            x for x in _accels(chain, lim)))
        self._run = _Run("path", cmds, t, chain, curve, sprof, profiles, lim, a_min,
                         target=np.array(chain.elements[-1].end), raw=raw, tj=tj)

    def _run_profiles(self, profiles: list[Profile], str_vel: float = 0.0) -> None:
        """Start every axis's profile, or none: each is checked (soft limits, states)
        before any starts, so a refusal never leaves the group off its path. An axis may
        jump by at most the path's StrVel (in its pulses) at the start and the end."""
        args = []
        for a, p, ppu in zip(self.axes, profiles, self._ppu, strict=True):
            acc = max(1.0, float(np.max(np.abs(p.a0)))) if p.n_segments else 1.0
            args.append((a, p, {"stop_accel": acc, "stop_jerk": acc * 1000.0,
                                "replace_running": a.motion is not None,
                                "str_vel": str_vel * float(ppu)}))
        for a, p, kw in args:
            try:
                a.check_profile(p, **kw)
            except GroupError:
                raise
            except MotionError as exc:
                raise GroupError(ERR_LIMIT if "SL" in str(exc) or "limit" in str(exc)
                                 else ERR_AXIS_STATE, f"axis {a.name}: {exc}") from exc
        for a, p, kw in args:
            a.run_profile(p, **kw)

    def _replan(self, r: _Run, *, hold: bool) -> None:
        """Re-plan the running chain from now: a hold (to rest) or a new override."""
        assert r.chain is not None and r.sprof is not None and r.curve is not None
        t = self._ctl.time
        u = t - r.t0
        st = r.sprof.state_at(min(max(u, 0.0), r.sprof.duration))
        s0, v0 = st.p, max(0.0, st.v)
        if u >= r.sprof.duration:
            return
        if r.raw is not None:
            self._hold_scurve(r, t, u)
            return
        if hold:
            curve = px.hold_curve(r.curve, s0, v0, r.a_min)
            lim = r.limits
        else:
            lim = self._limits(r.cmds[0])
            curve = px.plan_curve(r.chain, s0, v0, lim, old=r.curve.tail(s0))
        if v0 == 0.0 and hold:
            curve = px.SpeedCurve(np.array([s0, s0]), np.array([0.0, 0.0]))
        s_end = r.chain.length
        if curve.s[-1] <= s0:
            s_end = s0
        elif hold:
            s_end = px.stop_point(curve)
        if s_end <= s0:
            sprof = px.s_profile(px.SpeedCurve(np.array([s0]), np.array([0.0])), s0, [])
            profiles = [Profile(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0),
                                np.zeros(0), 0.0, p_state, p_state) for p_state in
                        [_rest(x) for x in self._pulses_of(self.position)]]
        else:
            sprof = px.s_profile(curve, s_end, r.chain.cum[1:-1].tolist())
            profiles = self._pulse_profiles(px.axis_profiles(r.chain, sprof, self._ctl.period,
                                                             self.position))
        assert lim is not None
        if not self._dry:
            self._run_profiles(profiles, lim.str_vel)
        self._run = _Run("path", r.cmds, t, r.chain, curve, sprof, profiles, lim, r.a_min,
                         target=r.target)

    def _hold_scurve(self, r: _Run, t: float, u: float) -> None:
        """Hold an S-curve path: the T-curve under the filter decelerates from its own state
        now, and the filter (same window) keeps running over old + new, so acceleration stays
        continuous and the jerk within the limit."""
        assert r.raw is not None and r.curve is not None and r.chain is not None
        rs = r.raw.state_at(u)
        s0, v0 = rs.p, max(0.0, rs.v)
        tail: Profile
        if v0 > 0.0 and u < r.raw.duration:
            curve = px.hold_curve(r.curve, s0, v0, r.a_min)
            s_end = px.stop_point(curve)
            tail = px.s_profile(curve, s_end, []) if s_end > s0 else _still(s0)
        else:
            curve, tail = r.curve, _still(r.raw.end.p if u >= r.raw.duration else s0)
        raw = r.raw.splice(u, tail)
        sprof = fir_smooth(raw, r.tj, t_out=u)
        profiles = self._pulse_profiles(px.axis_profiles(r.chain, sprof, self._ctl.period,
                                                         self.position))
        if not self._dry:
            self._run_profiles(profiles)
        self._run = _Run("path", r.cmds, t, r.chain, curve, sprof, profiles, r.limits, r.a_min,
                         target=r.target, raw=_rebased(raw, u), tj=r.tj)

    def _on_axis_fault(self, axis: Axis, reason: str) -> None:
        """Controller fault hook: a group axis went to ErrorStop."""
        if axis in self.axes and not self._dry and self._state in (
                GroupState.MOVING, GroupState.HOLDING, GroupState.HELD):
            code = ERR_LIMIT if "EL" in reason else ERR_AXIS_FAULT
            self._fault(code, f"axis {axis.name}: {reason}")

    def _check_faults(self) -> bool:
        for k, a in enumerate(self.axes):
            if a.state is AxisState.ERROR_STOP:
                self._fault(ERR_AXIS_FAULT, f"axis {a.name} in ErrorStop ({a.fault})")
                return True
            v = a.velocity
            if (v > 0.0 and self._ctl.input_active(a.index, "pel")) or \
                    (v < 0.0 and self._ctl.input_active(a.index, "mel")):
                self._fault(ERR_LIMIT, f"limit switch reached on axis {self.names[k]}")
                return True
        return False

    def _fault(self, code: int, message: str) -> None:
        """Stop every axis of the group at once and drop the queue (MCCL 2.6.3 VI)."""
        self._stop_axes()
        self._queue.clear()
        self._run = self._held = None
        self._error, self._error_msg = code, message
        self._state = GroupState.ERROR
        self._tail = None

    def _stop_axes(self) -> None:
        if self._dry:
            return
        for a in self.axes:
            if a.state is not AxisState.ERROR_STOP:
                a.stop_immediately()


def _rest(p: float) -> State:
    return State(float(p), 0.0, 0.0)


def _still(p: float) -> Profile:
    return Profile(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), 0.0,
                   _rest(p), _rest(p), (), np.zeros(0))


def _rebased(p: Profile, u: float) -> Profile:
    """A constant-acceleration profile with time u as its new zero (the past dropped)."""
    dts = p.dt if p.dt is not None else np.diff(np.append(p.t0, p.duration))
    keep = p.t0 + dts > u
    st = p.state_at(u)
    t0 = np.maximum(p.t0[keep] - u, 0.0)
    dt = dts[keep].copy()
    p0, v0 = p.p0[keep].copy(), p.v0[keep].copy()
    if len(t0):
        dt[0] = float(p.t0[keep][0]) + float(dt[0]) - u if p.t0[keep][0] < u else dt[0]
        if p.t0[keep][0] < u:
            p0[0], v0[0] = st.p, st.v
    labels = tuple(lb for lb, k in zip(p.labels, keep, strict=False) if k)
    return Profile(t0, p0, v0, p.a0[keep].copy(), p.j[keep].copy(), max(0.0, p.duration - u),
                   State(st.p, st.v, st.a), p.end, labels, dt)


def _accels(chain: px.Chain, lim: px.Limits) -> list[float]:
    sp = plan_speeds(chain.elements, lim.feed, lim.accel, axis_vmax=lim.axis_vmax,
                     axis_amax=lim.axis_amax)
    return [x.accel for x in sp if x.length > 0.0]


def _blend_pays(b: Any, accel: float, feed: float) -> bool:
    """Whether rounding a corner is faster than stopping exactly at it (an estimate).

    The blend arc (radius R = 1/kappa, sweep phi = L/R) starts d = R*tan(phi/2) before the
    corner and is crossed at v_c = min(F, sqrt(a_n*R)), a_n = sqrt(3)/2*A (the look-ahead's
    split of A on arcs). On each side, over the distance D from the corner in which the
    exact stop accelerates to the feed (or the shorter line ends), the exact stop takes
    time(D from rest) and the blend time(D - d from v_c); the blend pays when
    L/v_c + 2*time(D - d, v_c) < 2*time(D, 0); F is capped by the centripetal speed of
    an arc next to the corner. A sharp corner with a small tolerance gets an
    arc so tight that it would crawl: it stops exactly instead.
    """
    length = float(b.arc.length)
    kappa = float(b.arc.max_curvature)
    if kappa <= 0.0 or length <= 0.0:
        return True
    for el in (b.first, b.second):  # an arc next to the corner caps the speed there too
        k_el = float(el.max_curvature)
        if k_el > 0.0:
            feed = min(feed, math.sqrt(math.sqrt(0.75) * accel / k_el))
    radius = 1.0 / kappa
    d = radius * math.tan(0.5 * length / radius)
    v_c = min(feed, math.sqrt(math.sqrt(0.75) * accel * radius))
    reach = min(float(b.first.length), float(b.second.length)) + d
    span = min(d + feed * feed / (2.0 * accel), reach)

    def time(dist: float, v0: float) -> float:
        d_acc = (feed * feed - v0 * v0) / (2.0 * accel)
        if dist <= d_acc:
            return (math.sqrt(v0 * v0 + 2.0 * accel * dist) - v0) / accel
        return (feed - v0) / accel + (dist - d_acc) / feed

    return length / v_c + 2.0 * time(max(0.0, span - d), v_c) < 2.0 * time(span, 0.0)
