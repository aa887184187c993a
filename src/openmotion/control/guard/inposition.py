"""In-position control (MCCL 2.10.2): a move is done only once the axis is in position.

Per axis: a tolerance (pulses, or user units) and a check time (s), enabled or disabled
(MCC_SetInPosTolerance, MCC_SetInPosCheckTime, MCC_EnableInPos / MCC_DisableInPos). When
the planned motion of an enabled axis ends, the axis stays "moving" (motion_done 14,
waiting) until |position error| <= tolerance at a cycle end; the position error is the
axis's error counter (planned command pulses - feedback / move ratio). If the check time
passes first, the system error `INPOS_TIMEOUT` is set (`error_code`, MCC_GetErrorCode),
that axis goes to ErrorStop ("in-position timeout") and the queued commands are dropped
("the following motion commands are stopped") until `clear_error()` (MCC_ClearError).

`queue(fn)` holds commands: each runs only when every axis is done and in position, so the
next queued command waits for the previous one to settle (MCCL's consecutive commands).

The cycle hook declares when it acts (`_due`), so virtual time jumps while in-position
control is attached: at once when a held axis was released or a queued command can start,
at a check time's end, else not before a motion change (a move's end lands a jump; an axis
waiting for in-position keeps every cycle running anyway).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from ...errors import MotionError, check_flag, check_nonnegative, check_positive
from ..core.states import MotionDone

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller

#: Our error codes (the MCCL list is not in the seed; seed-facts 5 asks us to define them).
NO_ERROR = 0
INPOS_TIMEOUT = 301
#: Default check time (s).
DEFAULT_CHECK_TIME = 1.0


class InPositionControl:
    """In-position checks of a controller's axes; attaches a cycle hook and axis gates."""

    def __init__(self, controller: Controller) -> None:
        self._ctl = controller
        n = len(controller.axes)
        self._tol = [0.0] * n
        self._check = [DEFAULT_CHECK_TIME] * n
        self._enabled = [False] * n
        self._since: list[float | None] = [None] * n
        self._error = NO_ERROR
        self._error_axis: int | None = None
        self._queue: deque[Callable[[], object]] = deque()
        #: The MotionError a queued command raised (the queue was dropped), else None.
        self.failure: MotionError | None = None
        self._gates = [self._make_gate(i) for i in range(n)]
        controller.add_cycle_hook(self._on_cycle, due=self._due)

    # ------------------------------------------------------------------ settings
    def set_tolerance(self, axis: int | str, tolerance: float, *, units: bool = False) -> None:
        """MCC_SetInPosTolerance: |error| <= tolerance counts as in position (pulses; user
        units with units=True)."""
        ax = self._ctl.axis(axis)
        tol = check_nonnegative("tolerance", tolerance)
        if check_flag("units", units):
            tol = abs(float(ax.units.to_pulses(tol)))
        with self._ctl.lock:
            self._tol[ax.index] = tol

    def tolerance(self, axis: int | str) -> float:
        """The tolerance in pulses."""
        return self._tol[self._ctl.axis(axis).index]

    def set_check_time(self, axis: int | str, seconds: float) -> None:
        """MCC_SetInPosCheckTime: how long a finished move may wait for in-position."""
        ax = self._ctl.axis(axis)
        t = check_positive("seconds", seconds)
        with self._ctl.lock:
            self._check[ax.index] = t

    def enable(self, axes: Sequence[int | str] | None = None) -> None:
        """MCC_EnableInPos for the given axes (default all)."""
        sel = self._select(axes)
        with self._ctl.lock:
            for ax in sel:
                if not self._enabled[ax.index]:
                    self._enabled[ax.index] = True
                    ax.done_gates.append(self._gates[ax.index])

    def disable(self, axes: Sequence[int | str] | None = None) -> None:
        """MCC_DisableInPos for the given axes (default all); a waiting move is done now."""
        sel = self._select(axes)
        with self._ctl.lock:
            for ax in sel:
                if self._enabled[ax.index]:
                    self._enabled[ax.index] = False
                    self._since[ax.index] = None
                    ax.done_gates.remove(self._gates[ax.index])

    def enabled(self, axis: int | str) -> bool:
        return self._enabled[self._ctl.axis(axis).index]

    def _select(self, axes: Sequence[int | str] | None) -> tuple[Axis, ...]:
        if axes is None:
            return self._ctl.axes
        if isinstance(axes, (str, int)) or not hasattr(axes, "__iter__"):
            raise MotionError(f"axes must be a sequence of names or indices, got {axes!r}")
        return tuple(self._ctl.axis(k) for k in axes)  # validates every key first

    # ------------------------------------------------------------------ status
    def position_error(self, axis: int | str) -> int:
        """The axis's error counter: planned pulses - feedback / move ratio."""
        return self._ctl.axis(axis).counters.error

    def in_position(self, axis: int | str | None = None) -> bool:
        """MCC_GetInPosStatus: |error| <= tolerance for the axis (default: every enabled
        axis)."""
        if axis is not None:
            ax = self._ctl.axis(axis)
            return abs(ax.counters.error) <= self._tol[ax.index]
        return all(abs(ax.counters.error) <= self._tol[ax.index]
                   for ax in self._ctl.axes if self._enabled[ax.index])

    @property
    def error_code(self) -> int:
        """MCC_GetErrorCode: NO_ERROR (0) or INPOS_TIMEOUT."""
        return self._error

    @property
    def error_axis(self) -> int | None:
        """Index of the axis whose check time passed (None without an error)."""
        return self._error_axis

    def clear_error(self) -> None:
        """MCC_ClearError: accept queued commands again (the axis still needs reset())."""
        with self._ctl.lock:
            self._error = NO_ERROR
            self._error_axis = None

    # ------------------------------------------------------------------ the queue
    def queue(self, command: Callable[[], object]) -> None:
        """Run `command()` once every axis is done and in position (after the commands
        queued before it). Refused while a system error is set."""
        if not callable(command):
            raise MotionError(f"command must be callable, got {command!r}")
        with self._ctl.lock:
            if self._error:
                raise MotionError(f"in-position error {self._error} is set; clear_error() "
                                  "first")
            self._queue.append(command)

    @property
    def pending(self) -> int:
        """Number of queued commands not yet started."""
        return len(self._queue)

    # ------------------------------------------------------------------ internals
    def _make_gate(self, i: int) -> Callable[[Axis], int]:
        def gate(ax: Axis) -> int:
            if abs(ax.counters.error) <= self._tol[i]:
                self._since[i] = None
                return MotionDone.STOPPED
            if self._since[i] is None:
                self._since[i] = self._ctl.time
            return MotionDone.WAITING_INP
        return gate

    def _due(self, ctl: Controller) -> float:
        """The earliest time `_on_cycle` acts (Controller.add_cycle_hook's `due`)."""
        due = math.inf
        for ax in ctl.axes:
            since = self._since[ax.index]
            if since is None:
                continue
            if ax.motion is not None or not ax.is_moving:
                return -math.inf
            due = min(due, since + self._check[ax.index] - 1e-9)  # early is safe
        if not self._error and self._queue and all(a.motion_done == 0 for a in ctl.axes):
            return -math.inf
        return due

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        for ax in ctl.axes:
            i = ax.index
            since = self._since[i]
            if since is None:
                continue
            if ax.motion is not None or not ax.is_moving:
                self._since[i] = None  # no longer held (released, faulted, new move)
            elif t - since >= self._check[i] - 1e-12:
                self._since[i] = None
                self._error, self._error_axis = INPOS_TIMEOUT, i
                self._queue.clear()
                ax.fault_stop("in-position timeout")
        if self._error:
            return
        while self._queue and all(a.motion_done == 0 for a in ctl.axes):
            try:
                self._queue.popleft()()
            except MotionError as exc:  # a refused command stops the rest, like an error
                self.failure = exc
                self._queue.clear()
