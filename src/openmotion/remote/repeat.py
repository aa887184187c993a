"""Repeat moves (Motion Creator "repeat"): an axis runs between two absolute positions,
dwelling `delay_s` of control time at each end, `count` moves or until stopped.

Runs inside the control cycle (`RepeatRegistry.step`): when the axis rests at an end and its
dwell has passed, the next move starts with the parameters given. A fault, a stop command
or a refused move ends the repeat (the reason is kept for the status).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..control.core.states import AxisState
from ..errors import MotionError

if TYPE_CHECKING:
    from ..control.core.controller import Controller

MAX_DELAY_S = 60.0


@dataclass
class Repeat:
    axis: int
    ends: tuple[float, float]        # user units
    delay_s: float
    count: int                       # moves; 0 = until stopped
    move: dict[str, Any] = field(default_factory=dict)   # max_vel, tacc, ... (user units)
    done: int = 0
    next_end: int = 0
    rest_since: float | None = None
    reason: str | None = None


class RepeatRegistry:
    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self._active: dict[int, Repeat] = {}
        self.last_reason: dict[int, str] = {}

    def start(self, axis: int | str, p1: float, p2: float, delay_s: float, count: int,
              move: dict[str, Any]) -> None:
        ax = self.ctl.axis(axis)
        if not 0.0 <= delay_s <= MAX_DELAY_S:
            raise MotionError(f"delay_s must be in [0, {MAX_DELAY_S:g}] s, got {delay_s!r}")
        if p1 == p2:
            raise MotionError(f"p1 and p2 must differ, both are {p1!r}")
        with self.ctl.lock:
            if ax.index in self._active:
                raise MotionError(f"axis {ax.name} is already repeating; stop it first")
            # the first move starts now, so a bad parameter is refused to the caller
            ax.move_absolute(p1, units=True, **move)
            self._active[ax.index] = Repeat(ax.index, (p1, p2), delay_s, count, dict(move),
                                            done=1, next_end=1)
            self.last_reason.pop(ax.index, None)

    def active(self, axis: int) -> bool:
        return axis in self._active

    def stop(self, axis: int, reason: str = "stopped") -> None:
        rep = self._active.pop(axis, None)
        if rep is not None:
            self.last_reason[axis] = reason

    def stop_all(self, reason: str) -> None:
        for a in list(self._active):
            self.stop(a, reason)

    def step(self, t: float) -> None:
        """Control cycle: start the next move of every repeat whose dwell has passed."""
        for idx, rep in list(self._active.items()):
            ax = self.ctl.axes[idx]
            if ax.state is AxisState.ERROR_STOP or ax.state is AxisState.DISABLED:
                self.stop(idx, f"axis {ax.name}: {ax.fault or ax.state.value}")
                continue
            if ax.is_moving or ax.motion_done != 0:
                rep.rest_since = None
                continue
            if rep.count and rep.done >= rep.count:
                self.stop(idx, f"done: {rep.done} moves")
                continue
            if rep.rest_since is None:
                rep.rest_since = t
            if t - rep.rest_since + 1e-12 < rep.delay_s:
                continue
            try:
                ax.move_absolute(rep.ends[rep.next_end], units=True, **rep.move)
            except MotionError as exc:
                self.stop(idx, f"refused: {exc}")
                continue
            rep.done += 1
            rep.next_end ^= 1
            rep.rest_since = None
