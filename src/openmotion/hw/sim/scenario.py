"""Scenario API: things that happen to the simulated machine at chosen times.

Every action is scheduled at a time (default: now) and fires inside `SimMachine.advance`
at exactly that time: motion up to it is simulated first, then the action applies, and any
input that changes level because of it is reported as an InputEdge at that time.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable
from typing import TYPE_CHECKING

from openmotion.errors import MotionError, check_finite, check_nonnegative
from openmotion.limits import check_quantity

if TYPE_CHECKING:
    from .machine import SimMachine

Action = Callable[[list], None]
PLACEABLE = ("pel", "mel", "org", "sd", "ltc")


class Scenario:
    """Timed actions on a SimMachine (reach it as `machine.scenario`)."""

    def __init__(self, machine: SimMachine) -> None:
        self._m = machine
        self._heap: list[tuple[float, int, Action]] = []
        self._seq = itertools.count()

    # -- scheduling -----------------------------------------------------------------------
    def _at(self, at: float | None) -> float:
        if at is None:
            return self._m.time
        t = check_finite("at", at)
        if t < self._m.time:
            raise MotionError(f"at must be >= the current time {self._m.time!r}, got {at!r}")
        return t

    def _push(self, t: float, action: Action) -> None:
        heapq.heappush(self._heap, (t, next(self._seq), action))

    def pop_due(self, t: float) -> list[tuple[float, Action]]:
        """Actions due at or before t, in time order (same time: scheduling order)."""
        out = []
        while self._heap and self._heap[0][0] <= t:
            tk, _, a = heapq.heappop(self._heap)
            out.append((tk, a))
        return out

    @property
    def pending(self) -> int:
        """Number of actions not fired yet."""
        return len(self._heap)

    # -- actions ----------------------------------------------------------------------------
    def place_switch(self, axis: int, signal: str, position: float, width: float = 100.0,
                     hysteresis: float = 0.0, at: float | None = None) -> None:
        """Place (or move) switch `signal` of `axis` over [position, position + width).

        `signal` is one of pel, mel, org, sd, ltc; placing `ltc` gives the latch its own
        switch instead of sharing the SD input. Positions are in command pulses.
        """
        self._m._axis(axis)
        if signal not in PLACEABLE:
            raise MotionError(f"signal must be one of {PLACEABLE}, got {signal!r}")
        position = check_finite("position", position)
        width = check_finite("width", width)
        if width == 0.0:
            raise MotionError("width must be non-zero")
        hysteresis = check_nonnegative("hysteresis", hysteresis)
        t = self._at(at)
        self._push(t, lambda raw: self._m._place(axis, signal, (position, width, hysteresis), raw))

    def remove_switch(self, axis: int, signal: str, at: float | None = None) -> None:
        """Take switch `signal` off `axis` (its input becomes inactive)."""
        self._m._axis(axis)
        if signal not in PLACEABLE:
            raise MotionError(f"signal must be one of {PLACEABLE}, got {signal!r}")
        t = self._at(at)
        self._push(t, lambda raw: self._m._place(axis, signal, None, raw))

    def trip_alarm(self, axis: int, at: float | None = None) -> None:
        """The drive of `axis` raises ALM (servo goes off, RDY false; a stepper stops)."""
        self._m._axis(axis)
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_alarm(axis, True, raw))

    def clear_alarm(self, axis: int, at: float | None = None) -> None:
        """The drive of `axis` clears its alarm."""
        self._m._axis(axis)
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_alarm(axis, False, raw))

    def press_estop(self, at: float | None = None) -> None:
        """Press the emergency-stop button (EMG input active)."""
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_emg(True, raw))

    def release_estop(self, at: float | None = None) -> None:
        """Release the emergency-stop button."""
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_emg(False, raw))

    def inject_step_loss(self, axis: int, pulses: int, at: float | None = None) -> None:
        """The stepper of `axis` slips: its motor falls back by `pulses` (signed; positive
        = the motor ends `pulses` below the command). Stepper axes only."""
        ax = self._m._axis(axis)
        if ax.is_servo:
            raise MotionError(f"axis {axis} is a servo; step loss applies to stepper axes")
        pulses = check_quantity("pulses", pulses, "count", zero=True, signed=True)
        t = self._at(at)
        self._push(t, lambda raw: self._m._step_loss(axis, pulses, raw))

    def set_drive_ready(self, axis: int, ready: bool, at: float | None = None) -> None:
        """The drive of `axis` drops (False) or restores (True) its RDY output without an
        alarm (a lost enable chain, an undervoltage): RDY reads inactive meanwhile."""
        self._m._axis(axis)
        if not isinstance(ready, bool):
            raise MotionError(f"ready must be a bool, got {ready!r}")
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_ready(axis, ready, raw))

    def inject_following_error(self, axis: int, counts: float, at: float | None = None
                               ) -> None:
        """The motor of closed-loop (dc_servo) `axis` is knocked `counts` motor pulses (the
        encoder counts at move ratio 1) off its command (signed; positive = behind it), as
        a crash or a load step would: the
        controller's loop sees the error and, beyond its following_error limit, trips the
        axis to ErrorStop "following error". Closed-loop axes only."""
        ax = self._m._axis(axis)
        if not ax.is_dc:
            raise MotionError(f"axis {axis} has no closed loop (drive type dc_servo); "
                              "a following error applies to closed-loop servo axes")
        c = check_finite("counts", counts)
        if abs(c) > 1e9:
            raise MotionError(f"counts must be within +-1e9, got {counts!r}")
        t = self._at(at)
        self._push(t, lambda raw: self._m._knock(axis, c, raw))

    def set_analog_input(self, channel: int, value: float, at: float | None = None) -> None:
        """Set analog input `ai<channel>` to `value` (what M66 E reads from then on)."""
        k, v = self._m._check_ai(channel, value)
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_ai(k, v))

    def set_input(self, signal: str, level: bool, at: float | None = None) -> None:
        """Drive general input `di<n>` to an electrical level."""
        n = len(self._m._di)
        self._m._board_index(signal, "di", n)
        if not isinstance(level, bool):
            raise MotionError(f"level must be a bool, got {level!r}")
        t = self._at(at)
        self._push(t, lambda raw: self._m._set_di(signal, level, raw))
