"""The run-time side of a `Group`: executing its queue from a controller cycle hook.

Point-to-point commands start every axis with its own T/S profile and the next command
waits for all of them. Consecutive path commands of the same shape (T, or S with a fitting
smoothing window) and StrVel run as one chain: each element keeps its own feed and
acceleration, and with blending on the corners between lines and arcs are rounded
(`path.blend_corner`) within the tolerance; other corners stop exactly (or are taken at the
corner velocity). The look-ahead is lazy (Klipper's flush, groupstream.py): a chain holds
the queued commands up to twice the distance it needs to brake from its feed, and joins
the next ones when it runs short, so a program of any length streams through a bounded
plan. Joining, hold, continue and the feed override are all one re-plan of the running
chain from the present state (pathrun.py); in real-time mode joins are planned on a worker
thread (groupjoin.py). Faults stop every axis of the group at once (groupfaults.py). The
group's types (errors, states, commands, runs) are in grouptypes.py; this module has the
cycle hook, the starts, launches and windows of the runs, and the re-plans of hold and
override.
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import MotionError
from ...path.smoothing import jerk_window
from ...profile.segments import Profile, State, delayed
from ..core import planning
from . import overlap, pathmove, pathrun, ptpblend
from . import pathexec as px
from .group_corners import LookaheadSettings
from .groupfaults import GroupFaults
from .groupjoin import AsyncJoin
from .groupstream import ChainStream, _blend_pays, _peak_speed  # noqa: F401 - re-exported
from .grouptypes import (  # noqa: F401 - re-exported: the group's types live there
    ERR_ACCEL,
    ERR_ARC,
    ERR_ARGUMENT,
    ERR_AXIS_BUSY,
    ERR_AXIS_FAULT,
    ERR_AXIS_STATE,
    ERR_GROUP,
    ERR_LIMIT,
    ERR_PLANNER,
    ERR_QUEUE_FULL,
    ERR_SPEED,
    ERR_STATE,
    OWNERS,
    GroupError,
    GroupState,
    _Cmd,
    _Run,
)

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller

#: The axes of a path get their profiles PATH_WINDOW_S seconds ahead at a time (a knot
#: every period), renewed when half of it is left: one long slow element (a 21-minute
#: circle) costs a bounded window per cycle, not its whole length (issue #12 defect 7).
PATH_WINDOW_S = 2.0
#: Most commands joined to a running chain in one re-plan (bounds one cycle's work).
MAX_JOIN = 2000
#: Queued corners blended ahead of a join per quiet cycle, and how far ahead at most.
PREBLEND_PER_CYCLE = 4
PREBLEND_AHEAD = 256


class GroupEngine(ChainStream, GroupFaults, AsyncJoin, LookaheadSettings):
    """Queue execution and re-planning; `Group` adds the commands and settings."""

    _ctl: Controller
    axes: tuple[Axis, ...]
    names: tuple[str, ...]
    _queue: deque[_Cmd]
    _pre: dict[int, tuple[Any, ...]]   # cmd index -> (prev, el, settings, blend): _preblend
    _pre_tail: tuple[int, Any] | None  # last prepared command and its final piece
    _state: GroupState
    _run: _Run | None
    _held: _Run | None
    _aborting: bool
    _own: int
    _foreign: tuple[Axis, float] | None
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
    _ended_at: float | None = None  # when the last finished run ended (a delay counts from it)
    _wait_inpos: bool = False       # every command ends alone: in-position between commands
    _limit_any: bool = False        # any engaged limit switch stops a moving group
    _ppu: np.ndarray

    def _units_of(self, pulses: np.ndarray) -> np.ndarray:
        """Pulse positions -> logical coordinates."""
        return np.asarray(pulses, dtype=float) / self._k

    def _pulses_of(self, coords: np.ndarray) -> np.ndarray:
        """Logical coordinates -> pulse positions (AxisUnits.to_pulses per axis)."""
        return np.asarray(coords, dtype=float) * self._k

    def _caps(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-axis speed and acceleration caps in logical units (from the pulse caps);
        kept while the three arrays are the same objects (settings replace them, never
        write into them), as every corner and element asks."""
        memo = self.__dict__.get("_caps_memo")
        vm, am, ppu = self._vmax, self._amax, self._ppu
        if memo is not None and memo[0] is vm and memo[1] is am and memo[2] is ppu:
            return memo[3]
        out = (vm / ppu, am / ppu)
        self._caps_memo = (vm, am, ppu, out)
        return out

    def _pulse_profiles(self, profiles: list[Profile]) -> list[Profile]:
        """Axis profiles planned in logical units -> command pulses."""
        if np.all(self._k == 1.0):
            return profiles
        return [px.scaled(p, float(k)) for p, k in zip(profiles, self._k, strict=True)]

    @property
    def position(self) -> np.ndarray:  # defined by Group
        raise NotImplementedError

    # ------------------------------------------------------------------ execution
    def _limits(self, chain: px.Chain, str_vel: float = 0.0) -> px.Limits:
        """Limits of a chain: its elements' own feeds times the override, capped by the
        system maximum; per-axis caps in logical units; the chain's StrVel."""
        vmax, amax = self._caps()
        acc = float(np.max(chain.accels)) if chain.accels is not None else 1.0
        return px.Limits(self._sys_max, acc, vmax, amax, scale=self._override,
                         str_vel=str_vel, **self._corner_limits())

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        """The group's cycle hook. A failure in it (a planner bug) never escapes the cycle:
        it becomes a fault of this group alone (`_planner_failed`)."""
        try:
            self._cycle_step(t)
        except Exception as err:
            self._planner_failed(err)


    def _cycle_step(self, t: float) -> None:
        if self._state is GroupState.ERROR:
            return
        if self._run is not None and not self._dry and self._check_faults():
            return
        r = self._run
        if r is not None and r.window_end is not None and \
                t >= r.window_end - 0.5 * PATH_WINDOW_S:
            self._extend(r, t)
        if self._job is not None and self._poll_join(t):
            return  # a join in flight (real time), or installed this cycle
        r = self._run
        if r is not None and r.kind == "delay" and self._queue and \
                self._state is GroupState.MOVING and \
                1e-12 < r.t_until - t < self._ctl.period - 1e-12 and \
                self._queue[0].kind in ("path", "ptp") and not self._queue[0].str_vel:
            # the delay ends inside the coming cycle: start the command now, at rest until
            # the delay's exact end (MCC_DelayMotion is exact, not rounded to a cycle)
            self._run = None
            self._ended_at = r.t_until
            self._start_next(t, start=r.t_until)
            return
        if r is not None and r.deferred is not None and r.overlay_end is not None and \
                t >= r.overlay_end - 1e-12:  # a hold or override asked during the overlay
            what, r.deferred = r.deferred, None
            self._replan(r, hold=what == "hold")
        if r is not None and r.blend_at is not None and self._queue and \
                r.blend_at < t + self._ctl.period - 1e-12 and self._blend_next(r, t):
            return
        if r is not None and t >= r.t_end - 1e-12 and (self._dry or not any(
                a.is_moving for a in self.axes)):
            self._run = None
            self._ended_at = self._exact_end(r)
            if r.kind in ("path", "ptp") and r.target is not None and self._dry:
                self._dry_pos = self._pulses_of(r.target) if r.kind == "path" \
                    else r.target.copy()
            if self._state is GroupState.HOLDING:
                if self._dry and r.profiles:
                    self._dry_pos = np.array([p.end.p for p in r.profiles])
                if self._aborting:
                    self._aborting = False
                    self._state = GroupState.IDLE
                    if not self._queue:  # commands queued during the stop keep their tail
                        self._tail = None
                    return
                self._held = r
                self._state = GroupState.HELD
                return
            if r.plan is not None and r.plan.stopped_short:
                # a run that stopped short (should not happen) is kept as held
                self._held, self._state = r, GroupState.HELD
                return
        if self._run is None and self._state in (GroupState.MOVING, GroupState.IDLE):
            if self._queue:
                self._start_next(t)
            else:
                self._state = GroupState.IDLE
        elif self._queue:
            n = len(self._queue)
            self._join_queued(t)
            if len(self._queue) == n:  # no join this cycle
                self._preblend()

    def _blend_next(self, r: _Run, t: float) -> bool:
        """Velocity blending (MCCL 2.6.3 II): the next command starts while the running one
        decelerates, each axis following the sum of both motions: a PtP after a PtP
        (any blend mode, control.groups.ptpblend), any pair with the time-overlap blend
        (control.groups.overlap)."""
        cmd = self._queue[0]
        overlap_on = self._overlap  # type: ignore[attr-defined]
        if self._wait_inpos or self._dry or self._state is not GroupState.MOVING:
            return False
        if cmd.kind == "ptp":
            if not (overlap_on or (self._blend and r.kind == "ptp")):
                return False
        elif cmd.kind != "path" or not overlap_on or cmd.str_vel:
            return False
        start, r.blend_at = r.blend_at, None  # one try: a refused blend runs them apart
        if start is None:
            return False
        if cmd.kind == "path":
            if not overlap.start_path(self, r, cmd, t, max(start, t)):
                return False
            self._queue.popleft()
            return True
        if not ptpblend.start_blend(self, cmd, t, max(start, t)):
            return False
        self._queue.popleft()
        assert cmd.target is not None
        self._run = _Run("ptp", [cmd], t, target=self._pulses_of(cmd.target),
                         blend_at=ptpblend.blend_at(self))
        return True

    def _exact_end(self, r: _Run) -> float:
        """When run `r` ended: a PtP when its last axis came to rest (inside a cycle)."""
        if r.kind != "ptp" or self._dry:
            return r.t_end
        ends = [e for a in self.axes if (e := a.motion_ended_at) is not None and e >= r.t0]
        return max(ends, default=r.t_end)

    def _start_next(self, t: float, start: float | None = None) -> None:
        try:
            self._start_queued(t, start)
        except MotionError as err:  # an axis refused (safety check, state): stop the group
            self._fault(getattr(err, "code", ERR_AXIS_STATE), f"command refused at start: {err}")

    def _start_queued(self, t: float, start: float | None = None) -> None:
        """Start the next queued command now (a path: from `start` >= t within this
        cycle, at rest until then)."""
        cmd = self._queue.popleft()
        if cmd.kind == "delay":
            # counted from the exact end of the command before it when that ended within
            # this cycle (MCCL 2.6.3 V: "after finishing A, it will delay"), else from now
            end = self._ended_at
            base = end if end is not None and 0.0 <= t - end < self._ctl.period else t
            self._run = _Run("delay", [cmd], base, t_until=base + cmd.seconds)
        elif cmd.kind == "ptp":
            self._launch_ptp(cmd, t, 0.0 if start is None else start - t)
        else:
            plan, cmds = self._plan_path(cmd, t if start is None else start)
            self._launch(plan, cmds, t)
        self._state = GroupState.MOVING

    def _alone(self, cmd: _Cmd) -> bool:
        """Whether a path command is planned on its own (no chain): a 1-D move with its
        own ramp shapes, or any path with the time-overlap blend on."""
        return cmd.move is not None or self._overlap  # type: ignore[attr-defined]

    def plan_alone(self, cmd: _Cmd, t: float, s0: float = 0.0) -> pathrun.PathPlan:
        """`cmd` alone from rest at path position s0, starting at time t."""
        chain = self._chain([cmd])
        lim = self._limits(chain, cmd.str_vel)
        if cmd.move is not None:
            return pathmove.start(chain, cmd.move, lim, t, s0)
        tj = jerk_window(cmd.window_accel, cmd.jerk) if cmd.jerk else 0.0
        return pathrun.start(chain, lim, tj, t, s0)

    def _plan_path(self, cmd: _Cmd, t: float) -> tuple[pathrun.PathPlan, list[_Cmd]]:
        """The plan starting with `cmd` at time t, and the commands it holds: `cmd` alone,
        or with the queued commands that join its chain."""
        if self._alone(cmd):
            return self.plan_alone(cmd, t), [cmd]
        tj = jerk_window(cmd.window_accel, cmd.jerk) if cmd.jerk else 0.0
        cmds = [cmd, *self._take(tj, cmd.elements[0].length, [cmd])]
        chain = self._chain(cmds)
        return pathrun.start(chain, self._limits(chain, cmd.str_vel), tj, t), cmds

    # ------------------------------------------------------------------ launching
    def _launch_ptp(self, cmd: _Cmd, t: float, lead: float = 0.0) -> None:
        """Every axis its own move to the target, `lead` seconds after t (an exact delay)."""
        assert cmd.target is not None
        profiles = []
        start = self._pulses_of(self.position)
        target = self._pulses_of(cmd.target)
        for k, a in enumerate(self.axes):
            spec = cmd.specs[k]
            if self._ptp_override != 1.0:
                spec = spec.derived(
                    max_vel=min(a.max_speed, spec.max_vel * self._ptp_override))
            if self._dry:
                prof = planning.position_move(spec, float(start[k]), float(target[k]))
                profiles.append(delayed(prof, lead) if lead > 1e-12 else prof)
            elif target[k] != a.position:
                with self._commanding():
                    a.move_absolute(float(target[k]), max_vel=spec.max_vel, tacc=spec.tacc,
                                    tdec=spec.tdec, shape=spec.shape,
                                    start_in=lead if lead > 1e-12 else 0.0,
                                    dec_shape=spec.dec_shape)
        self._run = _Run("ptp", [cmd], t, profiles=profiles, target=target,
                         blend_at=None if self._dry else ptpblend.blend_at(self))

    def _launch(self, plan: pathrun.PathPlan, cmds: list[_Cmd], t: float) -> None:
        """Run `plan` from now: per-axis profiles along the chain, started all or none;
        a plan longer than 1.5 windows gets its first window only (`_extend` renews it)."""
        sp = plan.sprof
        window = not self._dry and sp.duration > 1.5 * PATH_WINDOW_S
        sp_w = _section(sp, 0.0, PATH_WINDOW_S) if window else sp
        profiles = self._pulse_profiles(px.axis_profiles(plan.chain, sp_w,
                                                         self._ctl.period, self.position))
        lead = plan.t0 - t
        if lead > 1e-12:  # the plan starts later in this cycle (an exact delay)
            profiles = [delayed(p, lead) for p in profiles]
        self._install(plan, profiles, cmds, t)
        if window and self._run is not None:
            self._run.window_end = plan.t0 + sp_w.duration  # t + the lead of a delay

    def _extend(self, r: _Run, t: float) -> None:
        """The next window of a windowed path, from now (a cycle boundary, so the knots
        stay on the cycle grid): every axis's profile is replaced by the path's next
        PATH_WINDOW_S seconds, continuing exactly from where the axes are."""
        plan = r.plan
        assert plan is not None
        u = t - plan.t0
        sp_w = _section(plan.sprof, u, PATH_WINDOW_S)
        profiles = self._pulse_profiles(px.axis_profiles(plan.chain, sp_w,
                                                         self._ctl.period, self.position))
        self._run_profiles(profiles, plan.limits.str_vel)
        r.window_end = t + sp_w.duration if u + sp_w.duration < plan.sprof.duration \
            - 1e-9 else None

    def _install(self, plan: pathrun.PathPlan, profiles: list[Profile], cmds: list[_Cmd],
                 t: float) -> None:
        """Start `plan`'s axis profiles (all or none) and make it the running chain."""
        if not self._dry:
            self._run_profiles(profiles, plan.limits.str_vel)
        first = plan.chain.owners[0]
        cmds = [c for c in cmds if c.index >= first] or cmds[-1:]
        self._run = _Run("path", cmds, t, plan, profiles,
                         target=np.array(plan.chain.elements[-1].end))
        if self._overlap and not self._dry:  # type: ignore[attr-defined]
            self._run.blend_at = overlap.path_blend_at(self._run)

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
        vetted = []
        with self._ctl._lock:  # the vetted motions start in the cycle they were vetted in
            for a, p, kw in args:
                try:
                    vetted.append((a, a._vet_profile(p, **kw)))
                except GroupError:
                    raise
                except MotionError as exc:
                    raise GroupError(ERR_LIMIT if "SL" in str(exc) or "limit" in str(exc)
                                     else ERR_AXIS_STATE, f"axis {a.name}: {exc}") from exc
            with self._commanding():
                for a, (motion, start_p) in vetted:
                    a._start_vetted(motion, start_p)

    def _replan(self, r: _Run, *, hold: bool) -> None:
        """Re-plan the running chain from now: a hold (to rest) or a new override."""
        assert r.plan is not None
        now = self._ctl.time
        if r.overlay_end is not None and now < r.overlay_end - 1e-12:
            # a time-overlap blend: the earlier command's rest still runs on every axis;
            # the re-plan waits until it is over (at most its deceleration time)
            r.deferred = "hold" if hold or r.deferred == "hold" else "override"
            return
        t = max(now, r.plan.t0)  # (a plan that starts later in this cycle)
        if t >= r.plan.t_end:
            return
        lim = r.plan.limits if hold else self._limits(r.plan.chain, r.plan.limits.str_vel)
        self._launch(pathrun.replan(r.plan, t, limits=lim, hold=hold), r.cmds, now)


def _section(sp: Profile, u: float, w: float) -> Profile:
    """s(t) over [u, u + w] (clipped to its end), its time 0 at u."""
    dur = sp.duration
    t_end = min(u + w, dur)
    if u <= 0.0 and t_end >= dur:
        return sp
    t0 = sp.t0
    k0 = max(int(np.searchsorted(t0, u, side="right")) - 1, 0)
    k1 = max(int(np.searchsorted(t0, t_end, side="left")), k0 + 1)
    st = sp.state_at(u) if u > 0.0 else None
    nt0 = t0[k0:k1] - u
    p0, v0, a0 = sp.p0[k0:k1].copy(), sp.v0[k0:k1].copy(), sp.a0[k0:k1].copy()
    if st is not None:
        nt0[0] = 0.0
        p0[0], v0[0], a0[0] = st.p, st.v, st.a
    dt = np.diff(np.append(nt0, t_end - u))
    start = sp.start if st is None else State(st.p, st.v, st.a)
    end = sp.end if t_end >= dur else sp.state_at(t_end)
    n = k1 - k0
    labels = sp.labels[k0:k1] if len(sp.labels) == sp.n_segments else ()
    return Profile(nt0, p0, v0, a0, sp.j[k0:k1].copy(), t_end - u, start, end,
                   labels if len(labels) == n else (), dt)
