"""The group engine's shared types: its error and error codes, its state, a queued command
and what the group runs (groupexec.py and its mixins groupstream.py, groupfaults.py)."""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import MotionError
from ...path.geometry import PathElement
from ...profile.pcl import MoveSpec
from ...profile.segments import Profile

if TYPE_CHECKING:
    from . import pathrun
    from .groupexec import GroupEngine


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
