"""Deadman jogs: a continuous jog runs only while its client keeps confirming it.

`JogRegistry.start` begins a continuous jog (control.manual.jog.jog_conti: it also stops at the end
limit ahead) and returns an id. The client confirms the id at least every CONFIRM_MS; the
registry's `check`, run inside the control cycle, stops a jog whose last confirmation is
older than DEADMAN_S of wall clock, so neither a stalled network nor a stalled server event
loop can keep an axis moving. `stop` (key up) and `drop_owner` (connection lost) stop at once.
A stopped jog's id stays dead: confirming it never restarts motion.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..control.core.states import AxisState
from ..control.manual.jog import jog_conti
from ..errors import MotionError

if TYPE_CHECKING:
    from ..control.core.controller import Controller

CONFIRM_MS = 100
DEADMAN_S = 0.25
#: the cycle checks the jogs every this many seconds of wall clock
CHECK_S = 0.01
_DEAD_KEEP = 256


@dataclass
class Jog:
    id: str
    axis: int
    owner: object
    last_confirm: float
    reason: str | None = None   # why it stopped; None while active


class JogRegistry:
    """The jogs of one controller (one per axis at most)."""

    def __init__(self, ctl: Controller, clock=time.monotonic) -> None:
        self.ctl = ctl
        self._clock = clock
        self._active: dict[str, Jog] = {}
        self._dead: dict[str, str] = {}
        self._ids = itertools.count(1)
        self._next_check = 0.0

    def start(self, axis: int | str, direction: int, ratio: float, tacc: float,
              owner: object) -> Jog:
        ax = self.ctl.axis(axis)
        if direction not in (1, -1) or isinstance(direction, bool):
            raise MotionError(f"direction must be +1 or -1, got {direction!r}")
        with self.ctl.lock:
            if any(j.axis == ax.index for j in self._active.values()):
                raise MotionError(f"axis {ax.name} is already jogging; stop that jog first")
            jog_conti(self.ctl, ax.index, 0 if direction > 0 else 1, ratio, tacc=tacc)
            jog = Jog(f"jog-{next(self._ids)}", ax.index, owner, self._clock())
            self._active[jog.id] = jog
        return jog

    def confirm(self, jog_id: str) -> tuple[bool, str | None]:
        """Refresh a jog's deadman; (active, reason it stopped)."""
        with self.ctl.lock:
            jog = self._active.get(jog_id)
            if jog is None:
                if jog_id in self._dead:
                    return False, self._dead[jog_id]
                raise MotionError(f"jog {jog_id!r} is unknown")
            if not self._still_moving(jog):
                self._end(jog, "the axis stopped (limit, fault or stop command)")
                return False, jog.reason
            jog.last_confirm = self._clock()
            return True, None

    def stop(self, jog_id: str, reason: str = "released") -> None:
        with self.ctl.lock:
            jog = self._active.get(jog_id)
            if jog is None:
                if jog_id in self._dead:
                    return
                raise MotionError(f"jog {jog_id!r} is unknown")
            self._halt(jog, reason)

    def drop_owner(self, owner: object) -> None:
        """The connection `owner` closed: stop its jogs."""
        with self.ctl.lock:
            for jog in [j for j in self._active.values() if j.owner is owner]:
                self._halt(jog, "connection lost")

    def stop_all(self, reason: str) -> None:
        with self.ctl.lock:
            for jog in list(self._active.values()):
                self._halt(jog, reason)

    def jog_of(self, axis: int) -> str | None:
        for j in self._active.values():
            if j.axis == axis:
                return j.id
        return None

    def check(self) -> None:
        """Control cycle: stop the jogs whose confirmation is older than DEADMAN_S."""
        if not self._active:
            return
        now = self._clock()
        if now < self._next_check:
            return
        self._next_check = now + CHECK_S
        for jog in list(self._active.values()):
            if not self._still_moving(jog):
                self._end(jog, "the axis stopped (limit, fault or stop command)")
            elif now - jog.last_confirm > DEADMAN_S:
                self._halt(jog, f"deadman: no confirmation for {DEADMAN_S * 1e3:.0f} ms")

    # ------------------------------------------------------------------ internals
    def _still_moving(self, jog: Jog) -> bool:
        ax = self.ctl.axes[jog.axis]
        return ax.motion is not None and ax.state is AxisState.CONTINUOUS_MOTION

    def _halt(self, jog: Jog, reason: str) -> None:
        if self._still_moving(jog):
            self.ctl.axes[jog.axis].stop()
        self._end(jog, reason)

    def _end(self, jog: Jog, reason: str) -> None:
        jog.reason = reason
        self._active.pop(jog.id, None)
        self._dead[jog.id] = reason
        while len(self._dead) > _DEAD_KEEP:
            self._dead.pop(next(iter(self._dead)))
