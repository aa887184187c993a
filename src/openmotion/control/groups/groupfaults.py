"""A group's faults: its axes' faults and stops from outside, limit switches, planner
failures (a mixin of `GroupEngine`). A group axis going to ErrorStop (the controller's
fault hooks, when present, and a check every cycle) or reaching the limit switch ahead of
it stops every axis of the group at once and puts the group in error (MCCL 2.6.3 VI: all
motion commands stop); a direct stop of one axis stops all of them along the path.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import MotionError
from ..core.states import AxisState
from . import pathexec as px
from . import pathrun
from .grouptypes import (
    ERR_AXIS_FAULT,
    ERR_AXIS_STATE,
    ERR_LIMIT,
    ERR_PLANNER,
    GroupState,
    _Cmd,
    _Run,
)

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller


class GroupFaults:
    """Mixin of `GroupEngine`: stopping the group on faults (see the module doc)."""

    _ctl: Controller
    axes: tuple[Axis, ...]
    names: tuple[str, ...]
    _queue: deque[_Cmd]
    _state: GroupState
    _run: _Run | None
    _held: _Run | None
    _own: int
    _foreign: tuple[Axis, float] | None
    _error: int
    _error_msg: str
    _dry: bool
    _tail: np.ndarray | None
    _limit_any: bool

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
