"""Groups: logical axes of a controller moving together from a command queue (MCCL 2.5-2.6).

A `Group` maps logical axes (x, y, z, ...) onto controller axes; an axis belongs to one open
group at a time. Commands (point-to-point, line, arc, circle, helix, 3-D arc, delay) are
validated and queued; each accepted command gets the next command index (>= 0). A refused
command raises `GroupError` (a MotionError) carrying a negative `code` that vendor facades
return as their own negative value; the queue and the running motion are then unchanged.
The checks a command passes before it is queued are in group_checks.py, what the group
reports (state, command index at a time, positions) in group_status.py; the run-time side
(queue execution, hold/continue/override re-planning, faults) is in groupexec.py; the path
math in pathexec.py. Positions, speeds and accelerations are command pulses, pps and pps^2
of the controller axes, or with `units=True` the axes' user units (mm, mm/s, mm/s^2: the
MCCL mechanism parameters, openmotion.units.AxisUnits): the path is then planned in user
space, so an arc is a true arc and the feed the true tool speed even when the axes have
different pulses per unit; each axis's pulses are AxisUnits.to_pulses of its coordinate.
set_max_pulse_speed/acc stay in pulses (as their MCCL names say).
"""

from __future__ import annotations

import contextlib
import math
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from functools import wraps
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from ...errors import InfeasibleError, MotionError, check_finite, check_flags
from ...path import Arc, Arc3D, Line
from ...profile.pcl import MoveSpec
from ...units import AxisUnits
from ..core.states import AxisState
from . import pathmove, pathrun
from .group_checks import unit_names, unit_scales
from .group_settings import PERIOD_PULSES_DEFAULT, PERIOD_PULSES_MAX
from .group_status import CommandInfo, GroupStatus
from .groupexec import (
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

__all__ = [
    "PERIOD_PULSES_DEFAULT", "PERIOD_PULSES_MAX",
    "ERR_ACCEL", "ERR_ARC", "ERR_ARGUMENT", "ERR_AXIS_BUSY", "ERR_AXIS_FAULT", "ERR_AXIS_STATE",
    "ERR_GROUP", "ERR_LIMIT", "ERR_PLANNER", "ERR_QUEUE_FULL", "ERR_SPEED", "ERR_STATE", "Group",
    "CommandInfo", "GroupError", "GroupState",
]


F = TypeVar("F", bound=Callable[..., Any])


def _locked(fn: F) -> F:
    """Serialise a public call with the cycle loop (real-time mode runs it on a thread)."""

    @wraps(fn)
    def wrapper(self: Group, *args: Any, **kwargs: Any) -> Any:
        check_flags(kwargs)
        with self._ctl._lock:
            return fn(self, *args, **kwargs)

    return wrapper  # type: ignore[return-value]


class Group(GroupStatus):
    """Coordinated axes of `controller` with a command queue.

    axes: logical name -> controller axis (name or index), or a sequence of controller axes
    (logical names are then the axis names). feed: vector speed (pps); acc_time: time to
    reach the feed (path acceleration = feed / acc_time, default 20 periods as in MCCL).
    units: False (pulses), True (each axis's AxisUnits from the controller's config) or one
    AxisUnits per logical axis; positions, feed and accelerations are then in user units.
    """

    def __init__(self, controller: Controller, axes: Mapping[str, int | str] | Sequence[int | str],
                 *, feed: float = 10_000.0, acc_time: float | None = None,
                 queue_size: int = 1024,
                 units: bool | Sequence[AxisUnits] = False) -> None:
        if isinstance(axes, Mapping):
            names, keys = list(axes.keys()), list(axes.values())
        elif isinstance(axes, Sequence) and not isinstance(axes, (str, bytes)):
            keys = list(axes)
            names = [controller.axis(k).name for k in keys]
        else:
            raise MotionError(f"axes must be a mapping or a sequence of axes, got {axes!r}")
        if len(keys) < 1:
            raise MotionError("axes must name at least one axis")
        ax = [controller.axis(k) for k in keys]
        if len({a.index for a in ax}) != len(ax):
            raise MotionError("axes must be different controller axes")
        if isinstance(queue_size, bool) or not isinstance(queue_size, int) or queue_size < 1:
            raise MotionError(f"queue_size must be an integer >= 1, got {queue_size!r}")
        k_units = unit_scales(controller, ax, units)
        owners = OWNERS.setdefault(controller, {})
        for a in ax:
            if a.index in owners:
                raise GroupError(ERR_AXIS_BUSY, f"axis {a.name} already belongs to an open group")
        self._ctl = controller
        self.names = tuple(str(n) for n in names)
        self.axes: tuple[Axis, ...] = tuple(ax)
        self._k = k_units                       # signed pulses per logical unit, per axis
        self._ppu = np.abs(k_units)
        self._unit_names = unit_names(controller, ax, units)  # messages in the user's units
        self._queue: deque[_Cmd] = deque()
        self._pre: dict[int, tuple[Any, ...]] = {}  # corners blended ahead (groupexec)
        self._index_memo: tuple[Any, ...] | None = None  # (t, run, plan, index): index_at
        self._owners_memo: tuple[Any, np.ndarray] | None = None  # (chain, owners): indices_at
        self._lookup_memo: tuple[Any, ...] | None = None  # (run, plan, lookup): index_lookup
        self._pre_tail: tuple[int, Any] | None = None
        self._queue_size = queue_size
        self._next_index = 0
        self._state = GroupState.IDLE
        self._run: _Run | None = None
        self._held: _Run | None = None
        self._aborting = False
        self._own = 0          # > 0 while the group itself commands its axes
        self._foreign: tuple[Axis, float] | None = None  # last axis stopped directly
        self._error = 0
        self._error_msg = ""
        self._override = 1.0
        self._ptp_override = 1.0
        self._dry = False
        self._dry_pos = np.array([a.position for a in ax])  # pulses
        self._tail: np.ndarray | None = None   # end position of the last queued command
        self._blend_tol = 0.0
        self._blend = False
        self._feed = 0.0
        self._acc_time = 20.0 * controller.period
        self._dec_time: float | None = None  # None: deceleration follows the acceleration
        self._sys_max = float(max(a.max_speed / k for a, k in zip(ax, self._ppu, strict=True)))
        self.set_feed(feed)
        if acc_time is not None:
            try:
                self.set_acc_time(acc_time)
            except MotionError as e:  # set_acc_time names its own argument, `seconds`
                raise MotionError(f"acc_time: {e}") from None
        self._vmax_pps = np.array([a.max_speed for a in ax], dtype=float)
        # the machine file's per-axis acceleration limit (0: none) caps every command
        self._amax_pps = np.array([a.config.max_accel * a.config.pulses_per_unit
                                   if a.config.max_accel > 0.0 else math.inf for a in ax])
        self._period_pulses = np.full(len(ax), PERIOD_PULSES_DEFAULT)
        self._period_pulse_acc = np.full(len(ax), PERIOD_PULSES_DEFAULT)
        self._update_caps()
        self._refuse = True
        self._ptp_ratio = 10.0
        self._path_jerk = 0.0   # 0: T-curve path speed; > 0: S-curve with this path jerk
        self._path_sfactor = 0.0  # > 0: S-curve sized from the ramp times (MCCL)
        jmax = [a.config.max_jerk * a.config.pulses_per_unit / k
                for a, k in zip(ax, self._ppu, strict=True) if a.config.max_jerk > 0.0]
        if jmax:  # the machine file's jerk limits: S paths whose jerk stays within them
            self._path_jerk = min(jmax)
        self._str_vel = 0.0     # StrVel of the following path commands (0: from/to rest)
        self._ptp_shapes = ("T",) * len(ax)
        self._ptp_dec_shapes = ("T",) * len(ax)
        self._ptp_acc_time: float | None = None  # None: the path commands' times
        self._ptp_dec_time: float | None = None
        for a in ax:
            owners[a.index] = self
        controller.add_cycle_hook(self._on_cycle, due=self._due)
        if hasattr(controller, "add_fault_hook"):  # immediate reaction to axis faults
            controller.add_fault_hook(self._on_axis_fault)
        if hasattr(controller, "add_motion_hook"):  # ... and to axes stopped directly
            controller.add_motion_hook(self._on_axis_motion)
        if hasattr(controller, "add_period_hook"):  # per-period caps follow the period
            controller.add_period_hook(self._on_period)
        # the units each axis takes from the machine config follow its reconfiguration
        self._units = [AxisUnits.from_axis(controller.config.axes[a.index]) for a in ax] \
            if units is True else (list(units) if units is not False else None)
        self._follows: tuple[int, bool] | None = None
        self._old_max = 0.0  # (the reconfigured axis's speed before: _on_config)
        if hasattr(controller, "add_config_hook"):
            controller.add_config_hook(self._on_config)

    @_locked
    def clear_error(self) -> None:
        """MCC_ClearError: leave the error state (axes in ErrorStop still need reset())."""
        self._error, self._error_msg = 0, ""
        if self._state is GroupState.ERROR:
            self._state = GroupState.IDLE
            self._tail = None

    @_locked
    def close(self) -> None:
        """Abort everything immediately and release the axes for other groups."""
        self._stop_axes()
        self._queue.clear()
        self._stop_join_worker()
        self._run = self._held = None
        self._ctl.remove_cycle_hook(self._on_cycle)
        if hasattr(self._ctl, "remove_fault_hook"):
            self._ctl.remove_fault_hook(self._on_axis_fault)
        if hasattr(self._ctl, "remove_motion_hook"):
            self._ctl.remove_motion_hook(self._on_axis_motion)
        if hasattr(self._ctl, "remove_period_hook"):
            self._ctl.remove_period_hook(self._on_period)
        if hasattr(self._ctl, "remove_config_hook"):
            self._ctl.remove_config_hook(self._on_config)
        owners = OWNERS.get(self._ctl, {})
        for a in self.axes:
            if owners.get(a.index) is self:
                del owners[a.index]

    def _on_period(self, period: float, commit: bool) -> None:
        """Controller period hook (set_period): refused while the group holds commands
        (queued, running, held: checked against the old period's caps); then the
        per-period pulse caps (MCCL 2.6.4: speed/T, acc/T^2) follow the new period."""
        if not commit:
            self._busy_for("period")
            return
        self._update_caps()

    def _busy_for(self, what: str) -> None:
        if self._run is not None or self._queue or self._held is not None or \
                self._job is not None:
            raise GroupError(ERR_STATE, f"{what}: group {'/'.join(self.names)} has "
                                        "commands queued or running")

    def _on_config(self, index: int, cfg: Any, commit: bool) -> None:
        """Controller config hook (reconfigure_axis of one of the group's axes): refused
        while the group holds commands; then its units (when they come from the machine),
        speed and acceleration caps follow the axis's new settings."""
        k = next((i for i, a in enumerate(self.axes) if a.index == index), None)
        if k is None:
            return
        a = self.axes[k]
        if not commit:
            self._busy_for("reconfigure")
            follows = self._units is not None and \
                self._units[k] == AxisUnits.from_axis(a.config)
            self._follows = (k, follows)
            self._old_max = a.max_speed
            return
        if self._follows is not None and self._follows == (k, True) and \
                self._units is not None:
            self._units[k] = AxisUnits.from_axis(cfg)
            self._k = np.array([u.sign * u.pulses_per_unit for u in self._units])
            self._ppu = np.abs(self._k)
            names = list(self._unit_names)
            names[k] = cfg.unit
            self._unit_names = tuple(names)
        self._follows = None
        if self._vmax_pps[k] >= self._old_max * (1 - 1e-12):  # the default: the axis's
            self._vmax_pps[k] = a.max_speed
        else:
            self._vmax_pps[k] = min(self._vmax_pps[k], a.max_speed)
        self._amax_pps[k] = cfg.max_accel * cfg.pulses_per_unit if cfg.max_accel > 0.0 \
            else math.inf
        self._sys_max = float(max(x.max_speed / p for x, p in
                                  zip(self.axes, self._ppu, strict=True)))
        self._update_caps()
        self._tail = None

    # ------------------------------------------------------------------ settings
    # (feed, times, caps, blending, shapes, PtP: group_settings.py)
    @_locked
    def enable_dry_run(self, on: bool = True) -> None:
        """Plan and report positions without sending pulses (only while idle)."""
        if not isinstance(on, bool):
            raise MotionError(f"on must be a bool, got {on!r}")
        if self._run is not None or self._queue:
            raise GroupError(ERR_STATE, "dry run can only be switched while the group is idle")
        self._dry = on
        self._dry_pos = np.array([a.position for a in self.axes])
        self._tail = None

    # ------------------------------------------------------------------ commands
    @_locked
    def ptp(self, target: Sequence[float], *, relative: bool = False,
            ratio: float | None = None) -> int:
        """Point-to-point: every axis to its target with its own T/S profile at the PtP
        speed ratio (or `ratio` % for this command: a jog); the next command waits for
        all axes."""
        if ratio is not None:
            ratio = check_finite("ratio", ratio)
            if not 0.0 < ratio <= 100.0:
                raise GroupError(ERR_SPEED, f"ratio must be in (0, 100] percent, got "
                                            f"{ratio!r}")
        start = self._start_point()
        p = self._point("target", target, start if relative else None)
        if np.all(p == start):
            raise GroupError(ERR_ARGUMENT, "target must differ from the start (zero-length move)")
        self._check_soft_span(np.minimum(start, p), np.maximum(start, p), start, "move")
        specs = []
        tacc, tdec = self.ptp_times
        for k, a in enumerate(self.axes):
            v = min(a.max_speed, self._vmax[k]) * (ratio or self._ptp_ratio) / 100.0
            sa, sd = self._ptp_shapes[k], self._ptp_dec_shapes[k]
            specs.append(MoveSpec(sa, 0.0, v, self._ramp_time(k, sa, v, tacc),
                                  self._ramp_time(k, sd, v, tdec), 0.0, 0.0, sd))
        return self._push(_Cmd(-1, "ptp", target=p, specs=tuple(specs)), p)

    def _ramp_time(self, k: int, shape: str, v: float, t: float) -> float:
        """A PtP ramp time `t` of axis k lengthened, if need be, to keep the axis within
        its acceleration limit and (S ramps) jerk limit of the machine file: a T ramp
        peaks at v/t, a pure S ramp at 2v/t with jerk 4v/t^2."""
        a = self.axes[k].config
        if a.max_accel > 0.0:
            t = max(t, (2.0 if shape == "S" else 1.0) * v / (a.max_accel * a.pulses_per_unit))
        if shape == "S" and a.max_jerk > 0.0:
            t = max(t, math.sqrt(4.0 * v / (a.max_jerk * a.pulses_per_unit)))
        return t

    @_locked
    def line(self, target: Sequence[float], *, relative: bool = False) -> int:
        """Linear interpolation to `target` (all logical axes) at the feed."""
        start = self._start_point()
        p = self._point("target", target, start if relative else None)
        if p.size >= 2:  # both points checked (finite, in range, one per axis): not again
            a, b = np.array(start, dtype=float), np.array(p, dtype=float)
            a.flags.writeable = b.flags.writeable = False
            el = Line.between(a, b)  # the same line as Line(start, p), bit for bit
        else:
            el = Line(start, p)
        if el.length == 0.0:
            raise GroupError(ERR_ARGUMENT, "target must differ from the start (zero-length move)")
        return self._push_path(el, p)

    @_locked
    def arc(self, centre: Sequence[float], end: Sequence[float], *, plane: tuple[int, int] = (0, 1),
            direction: str = "CCW", relative: bool = False, turns: int = 0) -> int:
        """Circular arc in the plane of logical axes `plane` around `centre` (2 plane values)
        to `end` (all axes; other axes move linearly: a helix). relative: centre and end are
        offsets from the start point."""
        start = self._start_point()
        c = self._point2("centre", centre, start if relative else None, plane)
        e = self._point("end", end, start if relative else None)
        try:
            el = Arc(start, c, e, plane=plane, direction=direction, turns=turns)
        except MotionError as err:
            code = ERR_ARC if "arc command error" in str(err) else ERR_ARGUMENT
            raise GroupError(code, str(err)) from None
        return self._push_path(el, np.array(el.end))

    @_locked
    def circle(self, centre: Sequence[float], *, plane: tuple[int, int] = (0, 1),
               direction: str = "CCW", relative: bool = False) -> int:
        """Full circle around `centre` (MCC_CircleXY), back to the start."""
        start = self._start_point()
        c = self._point2("centre", centre, start if relative else None, plane)
        return self.arc(c, start, plane=plane, direction=direction, relative=False)

    @_locked
    def helix(self, centre: Sequence[float], end: Sequence[float], **kw: Any) -> int:
        """An arc whose other axes move linearly to their `end` values (same as arc)."""
        return self.arc(centre, end, **kw)

    @_locked
    def arc3d(self, via: Sequence[float], end: Sequence[float], *, relative: bool = False) -> int:
        """3-D arc through a reference point (MCC_ArcXYZ)."""
        start = self._start_point()
        v = self._point("via", via, start if relative else None)
        e = self._point("end", end, start if relative else None)
        try:
            el = Arc3D(start, v, e)
        except MotionError as err:
            raise GroupError(ERR_ARC, str(err)) from None
        return self._push_path(el, np.array(el.end))

    @_locked
    def delay(self, seconds: float) -> int:
        """MCC_DelayMotion: wait `seconds` after the previous command ends (its exact end
        time), then start the next one at the first cycle at or after that. Queued on an
        idle group it starts counting now, so the next command starts `seconds` from now
        (not one period later, as a queued motion command does)."""
        t = check_finite("seconds", seconds)
        if t < 0.0:
            raise GroupError(ERR_ARGUMENT, f"seconds must be >= 0, got {seconds!r}")
        idle = self._state is GroupState.IDLE and self._run is None and not self._queue \
            and self._held is None and self._job is None
        index = self._push(_Cmd(-1, "delay", seconds=t), None)
        if idle:
            self._ended_at = None
            self._start_next(self._ctl.time)
        return index

    def reset_command_index(self) -> None:
        self._next_index = 0

    # ------------------------------------------------------------------ hold / continue / abort
    @_locked
    def hold(self) -> None:
        """MCC_HoldMotion: decelerate along the path and stop; continue() resumes. In the
        error state (a fault already stopped every axis) it does nothing."""
        if self._state is GroupState.ERROR:
            return
        if self._state is not GroupState.MOVING or self._run is None:
            raise GroupError(ERR_STATE, f"hold needs a moving group (state {self._state.value})")
        r = self._run
        if r.kind == "delay":  # keep the rest of the delay for continue()
            self._held = _Run("delay", r.cmds, r.t0, t_until=max(0.0, r.t_until - self._ctl.time))
            self._run = None
            self._state = GroupState.HELD
            return
        if r.kind == "path":
            self._replan(r, hold=True)
        elif r.kind == "ptp" and not self._dry:
            with self._commanding():
                for a in self.axes:
                    a.stop()
        self._state = GroupState.HOLDING

    @_locked
    def cont(self) -> None:
        """MCC_ContiMotion: resume the remaining motion of a held group."""
        if self._state is not GroupState.HELD or self._held is None:
            raise GroupError(ERR_STATE, f"continue needs a held group (state {self._state.value})")
        r, self._held = self._held, None
        t = self._ctl.time
        if r.plan is not None:  # from rest (with the StrVel jump again)
            chain, s0 = r.plan.chain, r.plan.sprof.end.p
            lim = self._limits(chain, r.cmds[0].str_vel)
            self._launch(pathmove.start(chain, r.plan.move, lim, t, s0) if r.plan.move
                         else pathrun.start(chain, lim, r.plan.tj, t, s0=s0), r.cmds, t)
        elif r.kind == "ptp":
            self._launch_ptp(r.cmds[0], t)
        else:
            self._run = _Run("delay", r.cmds, t, t_until=t + r.t_until)
        self._state = GroupState.MOVING

    @_locked
    def abort(self) -> None:
        """MCC_AbortMotion: stop along the path (or discard a hold) and empty the queue."""
        self._queue.clear()
        self._drop_join()  # a join in flight (real time) drops its commands too
        if self._state is GroupState.HELD:
            self._held = None
            self._state = GroupState.IDLE
            self._tail = None
            return
        if self._state is GroupState.MOVING and self._run is not None:
            if self._run.kind == "delay":
                self._run = None
                self._state = GroupState.IDLE
                self._tail = None
                return
            self.hold()
        self._aborting = self._state is GroupState.HOLDING
        self._tail = None

    @_locked
    def set_override(self, percent: float) -> None:
        """MCC_SetOverSpeed: feed override in % of the programmed feed (1 .. 200). A running
        path re-plans at once: it accelerates or decelerates to the new speed (figure 11)."""
        p = check_finite("percent", percent)
        if not 0.0 < p <= 200.0:
            raise MotionError(f"percent must be in (0, 200], got {percent!r}")
        r = self._run
        old = self._override
        self._override = p / 100.0
        if r is not None and r.plan is not None and self._state is GroupState.MOVING:
            try:
                self._replan(r, hold=False)
            except Exception:
                self._override = old
                raise

    @_locked
    def set_ptp_override(self, percent: float) -> None:
        """MCC_SetPtPOverSpeed: change the speed of running point-to-point axes."""
        p = check_finite("percent", percent)
        if not 0.0 < p <= 200.0:
            raise MotionError(f"percent must be in (0, 200], got {percent!r}")
        self._ptp_override = p / 100.0
        r = self._run
        if r is not None and r.kind == "ptp" and not self._dry:
            for a, spec in zip(self.axes, r.cmds[0].specs, strict=True):
                if a.motion is not None and a.state is AxisState.DISCRETE_MOTION and \
                        a.motion.spec is not None:  # a blended PtP (ptpblend) keeps its speed
                    a.fix_speed_range(min(a.max_speed, spec.max_vel * 2.0))
                    # too close to the target: the move finishes at its speed
                    with contextlib.suppress(InfeasibleError), self._commanding():
                        a.change_speed(min(a.max_speed, spec.max_vel * self._ptp_override),
                                       spec.tacc)
