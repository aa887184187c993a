"""The run-time side of a `Group`: executing its queue from a controller cycle hook.

Point-to-point commands start every axis with its own T/S profile and the next command
waits for all of them. Consecutive path commands of the same shape (T, or S with a fitting
smoothing window) and StrVel run as one chain: each element keeps its own feed and
acceleration, and with blending on the corners between lines and arcs are rounded
(`path.blend_corner`) within the tolerance; other corners stop exactly (or are taken at the
corner velocity). The look-ahead is lazy (Klipper's flush): a chain holds the queued
commands up to twice the distance it needs to brake from its feed, and joins the next ones
when it runs short, so a program of any length streams through a bounded plan; quiet
cycles blend the queued corners ahead of the join (`_preblend`). Joining,
hold, continue and the feed override are all one re-plan of the running chain from the
present state (pathrun.py); in real-time mode joins are planned on a worker thread
(groupjoin.py). A group axis going to ErrorStop (the controller's fault hooks,
when present, and a check every cycle) or reaching the limit switch ahead of it stops every
axis of the group at once and puts the group in error (MCCL 2.6.3 VI: all motion commands
stop).
"""

from __future__ import annotations

import itertools
import math
import weakref
from collections import deque
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import InfeasibleError, MotionError
from ...path import blend_corner, speed_caps
from ...path.geometry import PathElement
from ...path.lookahead import _element_limits as element_limits
from ...path.smoothing import jerk_window
from ...profile.pcl import MoveSpec
from ...profile.segments import Profile, State, delayed
from ..core import planning
from ..core.states import AxisState
from . import overlap, pathmove, pathrun, ptpblend
from . import pathexec as px
from .group_corners import LookaheadSettings
from .groupjoin import AsyncJoin

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller


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
ERR_PLANNER = -12      # run time: the group's planner failed in the cycle (the group stopped)


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
    decel: float | None = None     # path deceleration (None: follows accel)
    specs: tuple[MoveSpec, ...] = ()
    seconds: float = 0.0
    jerk: float = 0.0              # path jerk limit (0: T-curve)
    str_vel: float = 0.0           # StrVel: a path starts/ends with a jump from/to rest
    move: MoveSpec | None = None   # path run alone as one move with its own ramp shapes

    @property
    def dec(self) -> float:
        """The path deceleration (the acceleration unless set apart)."""
        return self.accel if self.decel is None else self.decel

    @property
    def window_accel(self) -> float:
        """The acceleration an S path's smoothing window is sized for (the larger one)."""
        return self.accel if self.decel is None else max(self.accel, self.decel)


@dataclass
class _Run:
    """What the group is executing now."""

    kind: str
    cmds: list[_Cmd]
    t0: float
    plan: pathrun.PathPlan | None = None   # path: the chain and the motion along it
    profiles: list[Profile] = field(default_factory=list)
    t_until: float = 0.0
    target: np.ndarray | None = None
    window_end: float | None = None        # path: the axes' profiles end here (windowed)
    blend_at: float | None = None          # when the next command may blend in (overlap)
    overlay_end: float | None = None       # a blend: the previous command's rest ends here
    deferred: str | None = None            # hold/override asked during the overlay

    @property
    def t_end(self) -> float:
        if self.kind == "delay":
            return self.t_until
        if self.plan is not None:
            return self.plan.t_end
        return self.t0 + max((p.duration for p in self.profiles), default=0.0)


#: The axes of a path get their profiles PATH_WINDOW_S seconds ahead at a time (a knot
#: every period), renewed when half of it is left: one long slow element (a 21-minute
#: circle) costs a bounded window per cycle, not its whole length (issue #12 defect 7).
PATH_WINDOW_S = 2.0
#: Most commands joined to a running chain in one re-plan (bounds one cycle's work).
MAX_JOIN = 2000
#: Queued corners blended ahead of a join per quiet cycle, and how far ahead at most.
PREBLEND_PER_CYCLE = 4
PREBLEND_AHEAD = 256


class GroupEngine(AsyncJoin, LookaheadSettings):
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

    def _planner_failed(self, err: Exception) -> None:
        """Stop the group's path at once, put its axes in ErrorStop (one fault event each
        in ctl.events) and the group in error ERR_PLANNER; other axes carry on."""
        msg = f"planner failure: {type(err).__name__}: {err}"
        self._fault(ERR_PLANNER, msg)
        if self._dry:
            return
        with self._commanding():
            for a in self.axes:
                if a.state is not AxisState.ERROR_STOP:
                    a.fault_stop(f"group {msg}")

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

    # ------------------------------------------------------------------ streaming
    def _joins(self, tj: float, cmd: _Cmd, str_vel: float = 0.0) -> bool:
        """Whether `cmd` can join a chain smoothed with window tj (0: a T chain) that starts
        and ends at `str_vel`: a path command of the same shape and StrVel whose own window
        fits in tj (its jerk stays bounded)."""
        if cmd.kind != "path" or cmd.str_vel != str_vel or self._wait_inpos or \
                self._alone(cmd):
            return False
        if tj == 0.0 or not cmd.jerk:
            return tj == 0.0 and not cmd.jerk
        return jerk_window(cmd.window_accel, cmd.jerk) <= tj * (1.0 + 1e-12)

    def _reach(self, cmd: _Cmd, tj: float) -> float:
        """Path length a chain should keep ahead for `cmd`: twice what it takes to brake
        from its feed (override included), plus a few cycles and the smoothing window, so
        joining commands never makes the running motion brake for the chain's end."""
        f = min(cmd.feed * self._override, self._sys_max)
        ahead = 4.0 * self._ctl.period + tj
        if self._ctl.realtime:  # a join in flight (groupjoin.py) must not see the end
            ahead += (self._lead_cycles() + 2) * self._ctl.period
        return 2.0 * (f * f / (2.0 * cmd.dec) + f * ahead)

    def _take(self, tj: float, have: float, cmds: list[_Cmd]) -> list[_Cmd]:
        """Pop the queued commands that join a chain with `have` length ahead until it
        holds twice its reach (Klipper's lazy flush: the rest waits in the queue)."""
        out: list[_Cmd] = []
        reach = max(self._reach(c, tj) for c in cmds[-1:]) if cmds else 0.0
        sv = cmds[0].str_vel if cmds else 0.0
        while self._queue and len(out) < MAX_JOIN and self._joins(tj, self._queue[0], sv):
            reach = max(reach, self._reach(self._queue[0], tj))
            if have >= 2.0 * reach:
                break
            c = self._queue.popleft()
            out.append(c)
            have += c.elements[0].length
        return out

    def _join_queued(self, t: float) -> None:
        """Streaming look-ahead: when the running chain has less than its reach ahead, join
        the next queued path commands and re-plan from now. The corner with the running
        chain is blended when the path has not yet reached the blend's start; otherwise the
        corner keeps its exact stop (or junction speed). A join that cannot be followed
        from the present speed leaves the commands queued (they start after the chain).
        In real-time mode the re-plan runs on the join worker (groupjoin.py)."""
        r = self._run
        if r is None or r.plan is None or self._state is not GroupState.MOVING or \
                self._job is not None:
            return
        plan = r.plan
        if plan.move is not None or r.overlay_end is not None:
            return  # a command run alone, or a time-overlap blend: no chain to join
        if t < plan.t0 or not self._joins(plan.tj, self._queue[0], plan.limits.str_vel):
            return  # (a plan starting later in this cycle joins from the next one)
        reach = max(self._reach(self._queue[0], plan.tj), self._reach(r.cmds[-1], plan.tj))
        memo = self.__dict__.get("_have_memo")
        if memo is not None and memo[0] is plan and t >= memo[1]:
            # a lower bound of the length ahead from the last evaluation and the plan's
            # peak raw speed: no join while it holds the reach (what the evaluation would
            # say), without evaluating s(t) every cycle
            dt = t - memo[1]
            low = memo[2] - memo[3] * dt * (1.0 + 1e-9) - 1e-9 * max(1.0, plan.chain.length)
            if low >= reach:
                return
        have = plan.remaining(t)
        self._have_memo = (plan, t, have, _peak_speed(plan.raw))
        if have >= reach:
            return
        new = self._take(plan.tj, have, [r.cmds[-1]])
        if not new:
            return
        if self._use_worker(plan):
            self._join_async(r, new)
            return
        if self._ctl.realtime:
            self.sync_joins += 1
        for chain in self._join_options(plan, have, new):
            try:
                p2 = pathrun.replan(plan, t, chain=chain,
                                    limits=self._limits(chain, plan.limits.str_vel))
            except InfeasibleError:
                continue
            try:
                self._launch(p2, [*r.cmds, *new], t)
            except MotionError as err:  # refused by an axis (safety): stop the group
                self._fault(getattr(err, "code", ERR_AXIS_STATE), f"join refused: {err}")
            return
        self._queue.extendleft(reversed(new))

    def _join_options(self, plan: pathrun.PathPlan, have: float, new: list[_Cmd],
                      pre: dict[int, tuple[Any, ...]] | None = None) -> Iterator[px.Chain]:
        """The running chain joined with `new`: first with the corner between them blended
        (when the path has not reached the blend's start yet), then with that corner kept
        as it is. Lazy: the second is built only when the first is missing or refused.
        `pre`: the pre-blend cache to use (the join worker's copy; default the group's)."""
        s_raw = plan.chain.length - have
        last = plan.chain.elements[-1]
        first, els, owners = self._elements(new, last, pre)
        if first is not last and s_raw < float(plan.chain.cum[-2]) + first.length:
            yield plan.chain.joined(els, owners, *self._per(owners, new), replace_last=first)
        if first is not last:  # without the blend the new elements differ: rebuild them
            _, els, owners = self._elements(new)
        yield plan.chain.joined(els, owners, *self._per(owners, new))

    @staticmethod
    def _per(owners: list[int], cmds: list[_Cmd]
             ) -> tuple[list[float], list[float], list[float] | None]:
        """Feed, acceleration and deceleration (None when no command sets one apart) of
        each element, from the command that owns it."""
        by = {c.index: c for c in cmds}
        dec = None if all(c.decel is None for c in cmds) else [by[o].dec for o in owners]
        return [by[o].feed for o in owners], [by[o].accel for o in owners], dec

    def _chain(self, cmds: list[_Cmd]) -> px.Chain:
        """The commands' elements end to end, corners blended where that pays."""
        _, els, owners = self._elements(cmds)
        return px.Chain(els, owners, *self._per(owners, cmds))

    def _elements(self, cmds: list[_Cmd], prev: PathElement | None = None,
                  pre: dict[int, tuple[Any, ...]] | None = None
                  ) -> tuple[PathElement | None, list[PathElement], list[int]]:
        """The commands' elements (and owners), each corner blended where that pays; with
        `prev` (the last element before them) the first corner too: `prev` comes back
        trimmed by that blend (or unchanged)."""
        els: list[PathElement] = [prev] if prev is not None else []
        owners: list[int] = [-1] if prev is not None else []
        for c in cmds:
            el = c.elements[0]
            b = self._blend_pair(els[-1], el, c, pre) if els else None
            if b is not None:
                els[-1] = b[0]
                els.append(b[1])
                owners.append(c.index)
                el = b[2]
            els.append(el)
            owners.append(c.index)
        if prev is None:
            return None, els, owners
        return els[0], els[1:], owners[1:]

    def _blend_key(self) -> tuple:
        """The settings a blend depends on besides its two elements and its command."""
        vmax, amax = self._caps()
        return (self._blend, self._blend_tol, self._corner_velocity, vmax.tobytes(),
                amax.tobytes())

    def _blend_pair(self, prev: PathElement, el: PathElement, cmd: _Cmd,
                    pre: dict[int, tuple[Any, ...]] | None = None
                    ) -> tuple[PathElement, PathElement, PathElement] | None:
        """`_blend_new`, or its result from `_preblend` when computed for the same
        elements and settings (the same objects: the chain is the same bit for bit)."""
        hit = (self._pre if pre is None else pre).pop(cmd.index, None)
        if hit is not None and hit[0] is prev and hit[1] is el and hit[2] == self._blend_key():
            return hit[3]
        return self._blend_new(prev, el, cmd)

    def _preblend(self) -> None:
        """A quiet cycle of a running chain: blend the next few queued corners ahead of the
        join that will take them, starting from the chain's last element, so the join's
        work (about 40 % of it was blending) is spread over the cycles before it."""
        r = self._run
        q = self._queue
        pre = self._pre
        if r is None or r.plan is None or not q or not (self._blend and self._blend_tol > 0.0) \
                or self._state is not GroupState.MOVING:
            # (a hold or abort in progress: the queued commands start after it, from rest)
            pre.clear()
            return
        prev = r.plan.chain.elements[-1]
        head = pre.get(q[0].index)
        i = 0
        if head is not None and head[0] is prev and self._pre_tail is not None:
            # the prepared corners still follow the chain's end: continue after them
            tail, piece = self._pre_tail
            i = tail - q[0].index + 1
            if 0 < i <= len(q) and q[i - 1].index == tail:
                prev = piece
            else:
                i = 0
        if i == 0:
            pre.clear()  # nothing prepared, or stale: the chain's end changed
        key = self._blend_key()
        for c in itertools.islice(q, i, min(len(q), i + PREBLEND_PER_CYCLE, PREBLEND_AHEAD)):
            if not self._joins(r.plan.tj, c, r.plan.limits.str_vel):
                break
            el = c.elements[0]
            b = self._blend_new(prev, el, c)
            pre[c.index] = (prev, el, key, b)
            if b is not None and r.plan.tj == 0.0:
                # the trimmed prev belongs to the command before c, the blend arc to c
                self._warm_limits(b[0], q[i - 1] if i > 0 else r.cmds[-1])
                self._warm_limits(b[1], c)
            prev = b[2] if b is not None else el
            self._pre_tail = (c.index, prev)
            i += 1

    def _warm_limits(self, el: PathElement, cmd: _Cmd) -> None:
        """Have the look-ahead's per-element memo (path/lookahead.py) hold the limits of a
        new piece with the values the join's plan will ask for (a T chain's feed x
        override capped by the system maximum, the command's acceleration, the axis caps):
        the join then computes only the junctions and the passes."""
        if el.length > 0.0:
            vmax, amax = self._caps()
            # what speed_caps([el], ...) stores, without validating the group's own values
            element_limits(el, min(cmd.feed * self._override, self._sys_max), cmd.accel,
                           vmax, amax, px.ARC_TANGENTIAL_RATIO)

    def _blend_new(self, prev: PathElement, el: PathElement,
                   cmd: _Cmd) -> tuple[PathElement, PathElement, PathElement] | None:
        """The corner prev -> el (any Line/Arc/Arc3D pair) rounded within the tolerance
        (trimmed prev, the blend, the trimmed el), or None: blending off, no corner, or
        taking the corner unrounded (an exact stop, or the corner velocity when one is set)
        is faster."""
        if not (self._blend and self._blend_tol > 0.0):
            return None
        b = blend_corner(prev, el, self._blend_tol)
        if b is None:
            return None
        vmax, amax = self._caps()
        accel = min(cmd.accel, cmd.dec, float(np.min(amax)))
        v_corner = 0.0
        corner = self._corner_limits()
        if corner["square_corner_velocity"] > 0.0 and prev.length > 0.0 and el.length > 0.0:
            v_corner = speed_caps([prev, el], cmd.feed, cmd.accel, axis_vmax=vmax,
                                  axis_amax=amax,
                                  square_corner_velocity=corner["square_corner_velocity"],
                                  axis_vjump=corner["axis_vjump"])[1][1]
        trims = (float(prev.length - b.first.length), float(el.length - b.second.length))
        if not _blend_pays(b, accel, cmd.feed, v_corner, trims):
            return None
        return b.first, b.arc, b.second

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
        for a, p, kw in args:
            try:
                a.check_profile(p, **kw)
            except GroupError:
                raise
            except MotionError as exc:
                raise GroupError(ERR_LIMIT if "SL" in str(exc) or "limit" in str(exc)
                                 else ERR_AXIS_STATE, f"axis {a.name}: {exc}") from exc
        with self._commanding():
            for a, p, kw in args:
                a.run_profile(p, **kw)

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

    def _stop_point(self) -> np.ndarray:
        """Where the running motion comes to rest (pulses): each axis's profile end (the
        group's own profiles in dry run), or its position when it has no motion."""
        r = self._run
        if self._dry and r is not None and r.profiles:
            return np.array([p.end.p for p in r.profiles])
        out = []
        for a in self.axes:
            m = a.motion
            end = a.position if m is None or m.kind == "velocity" else \
                m.profile.end.p + (a.position - a.raw_position)
            out.append(end)
        return np.array(out, dtype=float)

    @contextmanager
    def _commanding(self) -> Iterator[None]:
        """The group itself changes its axes' motions (not a direct stop to react to)."""
        self._own += 1
        try:
            yield
        finally:
            self._own -= 1

    def _on_axis_motion(self, axis: Axis, motion: Any) -> None:
        """Controller motion hook: a group axis was stopped (at once: motion None; or
        decelerating: a "stop" motion) by someone else - a direct stop_immediately(),
        stop() or disable(), a fault - while the group runs. Every axis stops the same way
        at the same instant and the group goes to error, so none drives on off the path."""
        if self._own or self._dry or axis not in self.axes or self._run is None or \
                self._state not in (GroupState.MOVING, GroupState.HOLDING):
            return
        if motion is not None and motion.kind != "stop":
            return
        self._foreign = (axis, self._ctl.time)
        if motion is None:
            self._fault(ERR_AXIS_STATE, f"axis {axis.name}: stopped outside the group")
            return
        # a decelerating stop: every axis decelerates along the path (a path's own stop,
        # as hold() does), so an arc stays on its arc; a point-to-point move has no path
        if self._run.kind != "path" or not self._path_stop():
            with self._commanding():
                for a in self.axes:
                    if a is not axis and a.motion is not None and a.motion.kind != "stop":
                        a.stop()
        self._fault(ERR_AXIS_STATE, f"axis {axis.name}: stopped outside the group",
                    stop=False)

    def _path_stop(self) -> bool:
        """Replace every axis's motion from now by the running path's stop to rest (the
        hold re-plan), each as a "stop" motion of that axis; False (nothing changed) when
        the path cannot be stopped along itself (a plan starting later, a planner error)."""
        r = self._run
        assert r is not None and r.plan is not None
        t = self._ctl.time
        if t < r.plan.t0 or t >= r.plan.t_end or \
                (r.overlay_end is not None and t < r.overlay_end):
            return False
        try:
            plan = pathrun.replan(r.plan, t, limits=r.plan.limits, hold=True)
            profiles = self._pulse_profiles(px.axis_profiles(
                plan.chain, plan.sprof, self._ctl.period, self.position))
        except (MotionError, ArithmeticError, ValueError):
            return False
        with self._commanding():
            for a, p in zip(self.axes, profiles, strict=True):
                a._stop_along(p)
        return True

    def _on_axis_fault(self, axis: Axis, reason: str) -> None:
        """Controller fault hook: a group axis went to ErrorStop."""
        code = ERR_LIMIT if "EL" in reason else ERR_AXIS_FAULT
        if self._state is GroupState.ERROR and self._foreign == (axis, self._ctl.time):
            # the motion hook reacted first (the fault stopped the axis): name the fault
            self._foreign = None
            self._error, self._error_msg = code, f"axis {axis.name}: {reason}"
            if axis.motion is None:  # an immediate fault stop; a decelerating one keeps
                self._stop_axes()    # the path stop the motion hook installed
            return
        if axis in self.axes and not self._dry and self._state in (
                GroupState.MOVING, GroupState.HOLDING, GroupState.HELD):
            self._fault(code, f"axis {axis.name}: {reason}")

    def _check_faults(self) -> bool:
        for k, a in enumerate(self.axes):
            if a.state is AxisState.ERROR_STOP:
                self._fault(ERR_AXIS_FAULT, f"axis {a.name} in ErrorStop ({a.fault})")
                return True
            v = a.velocity
            pel = v > 0.0 or (self._limit_any and v != 0.0)
            mel = v < 0.0 or (self._limit_any and v != 0.0)
            if (pel and self._ctl.input_active(a.index, "pel")) or \
                    (mel and self._ctl.input_active(a.index, "mel")):
                self._fault(ERR_LIMIT, f"limit switch reached on axis {self.names[k]}")
                return True
        return False

    def _fault(self, code: int, message: str, *, stop: bool = True) -> None:
        """Stop every axis of the group at once and drop the queue (MCCL 2.6.3 VI);
        `stop=False`: the axes are already stopping."""
        if stop:
            self._stop_axes()
        self._queue.clear()
        self._drop_join()
        self._run = self._held = None
        self._error, self._error_msg = code, message
        self._state = GroupState.ERROR
        self._tail = None

    def _stop_axes(self) -> None:
        if self._dry:
            return
        with self._commanding():
            for a in self.axes:
                if a.state is not AxisState.ERROR_STOP:
                    a.stop_immediately()


def _peak_speed(p: Profile) -> float:
    """The largest |speed| a profile reaches (at a segment's ends: its pieces have constant
    jerk at most, so also at a zero of the acceleration inside one, bounded here by
    |v0| + |a0|*dt + |j|*dt**2/2), and its end speed."""
    if not p.n_segments:
        return abs(p.end.v)
    dts = p.dt if p.dt is not None else np.diff(np.append(p.t0, p.duration))
    top = np.abs(p.v0) + np.abs(p.a0) * dts + 0.5 * np.abs(p.j) * dts * dts
    return max(float(np.max(top)), abs(p.end.v), abs(p.start.v))


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


def _blend_pays(b: Any, accel: float, feed: float, v_corner: float = 0.0,
                trims: tuple[float, float] | None = None) -> bool:
    """Whether rounding a corner is faster than taking it unrounded: stopping exactly at it
    or, with a corner velocity, passing it at `v_corner` (an estimate).

    The blend arc (radius R = 1/kappa, sweep phi = L/R) starts d = R*tan(phi/2) before the
    corner and is crossed at v_c = min(F, sqrt(a_n*R)), a_n = sqrt(3)/2*A (the look-ahead's
    split of A on arcs). On each side, over the distance D from the corner in which the
    exact stop accelerates to the feed (or the shorter line ends), the exact stop takes
    time(D from rest) and the blend time(D - d from v_c); the blend pays when
    L/v_c + 2*time(D - d, v_c) < 2*time(D, 0); F is capped by the centripetal speed of
    an arc next to the corner. A sharp corner with a small tolerance gets an
    arc so tight that it would crawl: it stops exactly instead. A blend that turns half a
    circle or more (a line into an arc that starts back along it) has no finite
    R*tan(phi/2): d is then the mean of what the blend trimmed off the two elements
    (`trims`), never negative (a negative d made a square root of a negative number).
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
    phi = length / radius
    d = radius * math.tan(0.5 * phi) if phi < math.pi * (1.0 - 1e-9) else math.nan
    if not (math.isfinite(d) and d >= 0.0):
        d = max(0.0, 0.5 * (trims[0] + trims[1])) if trims is not None else 0.0
    v_c = min(feed, math.sqrt(math.sqrt(0.75) * accel * radius))
    reach = min(float(b.first.length), float(b.second.length)) + d
    span = min(d + feed * feed / (2.0 * accel), reach)

    def time(dist: float, v0: float) -> float:
        dist = max(0.0, dist)
        d_acc = (feed * feed - v0 * v0) / (2.0 * accel)
        if dist <= d_acc:
            return (math.sqrt(v0 * v0 + 2.0 * accel * dist) - v0) / accel
        return (feed - v0) / accel + (dist - d_acc) / feed

    v_corner = min(v_corner, feed)
    return length / v_c + 2.0 * time(max(0.0, span - d), v_c) < 2.0 * time(span, v_corner)
