"""G33.1 on the machine: the rigid tap locked to the measured spindle (LinuxCNC's sequence).

`RigidTapMove` runs a `RigidTap` in phases, each a `SyncMove` (spindle.py: the tool
advances pitch per measured revolution, the group's feed override tracking it):

1. **in**: from the next index pulse, start -> end, on a line that goes on past the end by
   the spindle's possible overrun; when the tool passes the end the spindle is reversed
   (sped up by I); the tool keeps following the decelerating spindle into the overrun,
   and where the spindle turns round (its measured speed changes sign) the group stops.
2. **out**: from that turning point (no index wait: the thread is already cut) back to the
   start, following the reversed spindle; past the start the spindle is reversed again to
   its first direction and speed, the tool follows it until it turns round.
3. **home**: an unsynchronised line back to the start at K x S.

The phase errors (tool - pitch x revolutions) are kept (`errors`) for the report; the
overrun beyond the end and the start is `overrun_in` / `overrun_out` (machine units).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..control.groups.group import GroupState
from . import canon
from .rigidtap import RigidTap
from .spindle import SpindleDrive, SyncMove

if TYPE_CHECKING:
    from ..control.groups.group import Group

#: Overrun allowance: revolutions the spindle may turn while reversing, x this margin.
_MARGIN = 3.0


class RigidTapMove:
    """One G33.1 (module docstring). `spindle_cmd`: the Spindle record in force."""

    def __init__(self, drive: SpindleDrive, g: Group, tap: RigidTap, spindle_cmd: canon.Spindle,
                 vmax: float, push) -> None:
        self.drive = drive
        self.g = g
        self.tap = tap
        self.cmd = spindle_cmd
        self.vmax = vmax
        self._push = push  # push(end, feed, line) -> group index
        self.start = np.asarray(tap.start, dtype=float)
        self.end = np.asarray(tap.end, dtype=float)
        d = self.end - self.start
        self.depth = float(np.linalg.norm(d))
        self.u = d / self.depth
        rps = abs(spindle_cmd.speed) / 60.0
        # revolutions while the spindle stops from the return speed, with a margin
        stop_revs = rps * tap.return_scale * drive.acc_time * 0.5
        self.allow = _MARGIN * (stop_revs + 1.0) * tap.pitch
        self.phase = "in"
        self.overrun_in = self.overrun_out = 0.0
        self.errors: list[tuple[float, float, float]] = []
        self._reversed = False
        self._sign = 1.0 if spindle_cmd.clockwise else -1.0
        self._turn_count: float | None = None
        self._after = "out"
        self._sync = SyncMove(drive, g, [(self.start, self.end + self.u * self.allow,
                                          tap.pitch)], self._push_sync)
        self._prog_len = self.depth  # programmed length of the phase's line

    def _push_sync(self, rps: float) -> list[int]:
        s, e, p = self._sync.lines[0]
        return [self._push(e, min(p * rps, self.vmax), self.tap.line)]

    def _reverse(self, clockwise: bool, scale: float) -> None:
        self.drive.apply(replace(self.cmd, clockwise=clockwise,
                                 speed=self.cmd.speed * scale))
        self._sign = 1.0 if clockwise else -1.0

    def poll(self, ppu: np.ndarray) -> bool:
        """Per cycle; True when the tap has ended (the tool at rest at the start)."""
        if self.phase == "home":
            return self.g.state is GroupState.IDLE and self.g.queue_length == 0
        if self.phase == "stopping":
            if self.g.state is GroupState.IDLE and self.g.queue_length == 0:
                self._next_phase(ppu)
            return False
        m = self._sync
        m.poll(ppu)
        if m.speed0 == 0.0 or not m._idx:
            return False
        s, _k = m.position()
        if not self._reversed and s >= self._prog_len:
            self._reversed = True
            first = self.phase == "in"
            cw = not self.cmd.clockwise if first else self.cmd.clockwise
            self._reverse(cw, self.tap.return_scale if first else 1.0)
        if self._reversed and self.drive.revs_per_s() * self._sign > 0.0:
            # the spindle has turned round: stop the tool there
            self._turn_count = self.drive.count()
            over = s - self._prog_len
            if self.phase == "in":
                self.overrun_in = over
            else:
                self.overrun_out = over
            self.errors.extend(m.errors)
            self.g.abort()
            self.g.set_override(100.0)
            self._after = "out" if self.phase == "in" else "home"
            self.phase = "stopping"
        return False

    def _next_phase(self, ppu: np.ndarray) -> None:
        pos = np.array([a.position for a in self.g.axes], dtype=float) / ppu
        if self._after == "out":
            self.phase = "out"
            self._reversed = False
            self._prog_len = float(np.dot(pos - self.start, self.u))
            back = self.start - self.u * self.allow
            self._sync = SyncMove(self.drive, self.g, [(pos, back, self.tap.pitch)],
                                  self._push_sync)
            self._sync.close()  # no index wait: follow the spindle from where it turned
            self._sync.c0 = self._turn_count
            self._sync.t0 = self.drive.ctl.time
            return
        self.phase = "home"
        f = min(self.tap.pitch * abs(self.cmd.speed) / 60.0, self.vmax)
        if not np.allclose(pos, self.start, atol=1e-12):
            self._push(self.start, f, self.tap.line)

    def close(self) -> None:
        self._sync.close()
