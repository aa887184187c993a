"""Homing order across axes (MCCL MCC_GoHome nXOrder..nUOrder): axes with the same order
number home together, the next order starts when all of the previous ones are done."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ...errors import MotionError, check_int
from .homing import Homing
from .homing_modes import HomeConfig

if TYPE_CHECKING:
    from ..core.controller import Controller


class HomeSequence:
    """Home several axes in order (MCC_GoHome): axes with the same order number home
    together; the next order starts when all of the previous are done. A failure stops the
    others (decelerating). `code`: -1 running, 1 all done, 0 failed / not started."""

    def __init__(self, ctl: Controller, plan: dict[int | str, tuple[HomeConfig, int]]) -> None:
        if not isinstance(plan, dict) or not plan:
            raise MotionError("plan must be a non-empty dict axis -> (HomeConfig, order)")
        self.ctl = ctl
        groups: dict[int, list[Homing]] = {}
        for key, item in plan.items():
            if not (isinstance(item, tuple) and len(item) == 2):
                raise MotionError(f"plan[{key!r}] must be (HomeConfig, order), got {item!r}")
            cfg, order = item
            check_int(f"order of axis {key!r}", order, 0)
            groups.setdefault(order, []).append(Homing(ctl, key, cfg))
        self.groups = [groups[k] for k in sorted(groups)]
        self._g = -1
        self.state = "idle"
        self.reason: str | None = None

    @property
    def code(self) -> int:
        return -1 if self.state == "running" else 1 if self.state == "done" else 0

    @property
    def homings(self) -> list[Homing]:
        return [h for g in self.groups for h in g]

    def start(self) -> None:
        self.state = "running"
        self.ctl.add_cycle_hook(self._on_cycle, due=self._due)
        self._next_group()

    def abort(self) -> None:
        """MCC_AbortGoHome: stop every axis still homing."""
        for h in self.homings:
            h.abort()
        self._end("aborted", "aborted by abort()")

    def _next_group(self) -> None:
        self._g += 1
        if self._g >= len(self.groups):
            self._end("done", None)
            return
        for h in self.groups[self._g]:
            h.start()

    def _end(self, state: str, reason: str | None) -> None:
        if self.state == "running":
            self.state = state
            self.reason = reason
            self.ctl.remove_cycle_hook(self._on_cycle)

    def _due(self, ctl: Controller) -> float:
        """Now when the running group of homings failed or is done (the homings change
        state only inside hooks, so this hook acts in the cycle after), else never."""
        if self.state != "running":
            return math.inf
        group = self.groups[self._g]
        if any(h.status.state in ("error", "aborted") for h in group) or \
                all(h.done for h in group):
            return -math.inf
        return math.inf

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        if self.state != "running":
            return
        group = self.groups[self._g]
        failed = [h for h in group if h.status.state in ("error", "aborted")]
        if failed:
            for h in group:
                h.abort()
            self._end("error", failed[0].status.reason)
        elif all(h.done for h in group):
            self._next_group()
