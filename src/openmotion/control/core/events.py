"""Motion events: faults, limit hits, latches, home completion, compare hits — with exact
times and positions, readable and waitable (the seed's INT signal, as a Python API).

Every `Controller` owns one `EventLog` (`ctl.events`). It records axis faults by itself
(through the controller's fault hook: limits, soft limits, alarms, E-stop, step loss,
following error), stamped with the fault's exact time (the input edge's time when the
reaction came from an edge) and the axis's planned position at that time. Other engines
(latch, homing, compare) call `record`.

Reading: `events(kind=, axis=, since=)`. Waiting: `wait(kind, axis=, timeout=)` runs
virtual time until a matching event arrives (or, while the controller runs in real time,
blocks on a condition variable), like waiting for the card's interrupt. `on_event(fn)`
registers an interrupt-style callback. Memory is bounded (`capacity`, oldest dropped).
"""

from __future__ import annotations

import threading
import time as _time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import MotionError, check_finite, check_int, check_nonnegative

if TYPE_CHECKING:
    from .axis import Axis
    from .controller import Controller

#: Event kinds recorded by the core. Engines may add their own (any identifier).
KINDS = ("fault", "limit", "soft_limit", "alarm", "estop", "latch", "home_done", "compare")

_LIMIT_REASONS = {"+EL": "limit", "-EL": "limit", "+SL": "soft_limit", "-SL": "soft_limit"}


@dataclass(frozen=True)
class MotionEvent:
    """One event. `position` is the planned command position (pulses) at `time`;
    `seq` orders events recorded at the same time."""

    seq: int
    time: float
    kind: str
    axis: int | None
    position: float | None
    detail: str = ""


EventCallback = Callable[[MotionEvent], None]


def classify_fault(reason: str) -> str:
    """The event kind of an axis fault reason."""
    if reason in _LIMIT_REASONS:
        return _LIMIT_REASONS[reason]
    low = reason.lower()
    if "alarm" in low:
        return "alarm"
    if "emergency" in low:
        return "estop"
    return "fault"


class EventLog:
    """Bounded, time-stamped log of motion events of one controller."""

    def __init__(self, ctl: Controller, capacity: int = 10_000) -> None:
        check_int("capacity", capacity, 1)
        self._ctl = ctl
        self._events: deque[MotionEvent] = deque(maxlen=capacity)
        self._seq = 0
        self._callbacks: list[EventCallback] = []
        self._cond = threading.Condition()
        ctl.add_fault_hook(self._on_fault)

    # ------------------------------------------------------------------ recording
    def record(self, kind: str, axis: int | None, time: float, position: float | None = None,
               detail: str = "") -> MotionEvent:
        """Add an event (engines call this); returns it. Callbacks run at once."""
        if not isinstance(kind, str) or not kind.isidentifier():
            raise MotionError(f"kind must be an identifier string, got {kind!r}")
        if axis is not None and not 0 <= axis < len(self._ctl.axes):
            raise MotionError(f"axis must be None or in [0, {len(self._ctl.axes) - 1}], "
                              f"got {axis!r}")
        t = check_finite("time", time)
        with self._cond:
            ev = MotionEvent(self._seq, t, kind, axis, position, detail)
            self._seq += 1
            self._events.append(ev)
            self._cond.notify_all()
        for cb in tuple(self._callbacks):
            cb(ev)
        return ev

    def _on_fault(self, axis: Axis, reason: str) -> None:
        t = getattr(axis, "fault_time", None)
        t = self._ctl.time if t is None else t
        pos = self._ctl.history.state_at(axis.index, t).p
        self.record(classify_fault(reason), axis.index, t, pos, reason)

    # ------------------------------------------------------------------ reading
    def events(self, kind: str | None = None, axis: int | str | None = None,
               since: float | None = None) -> list[MotionEvent]:
        """Events in order, filtered by kind, axis (index or name) and time >= since."""
        ax = None if axis is None else self._ctl.axis(axis).index
        with self._cond:
            evs = list(self._events)
        return [e for e in evs
                if (kind is None or e.kind == kind) and (ax is None or e.axis == ax)
                and (since is None or e.time >= since)]

    def last(self, kind: str | None = None, axis: int | str | None = None
             ) -> MotionEvent | None:
        """The newest matching event, or None."""
        evs = self.events(kind, axis)
        return evs[-1] if evs else None

    def clear(self) -> None:
        with self._cond:
            self._events.clear()

    def __len__(self) -> int:
        return len(self._events)

    def on_event(self, callback: EventCallback) -> None:
        """Call `callback(event)` for every new event (interrupt style)."""
        if not callable(callback):
            raise MotionError(f"callback must be callable, got {callback!r}")
        self._callbacks.append(callback)

    def remove_callback(self, callback: EventCallback) -> None:
        if callback in self._callbacks:
            self._callbacks.remove(callback)

    def wait(self, kind: str | None = None, axis: int | str | None = None, *,
             timeout: float = 10.0) -> MotionEvent | None:
        """Wait for the next matching event after now; None after `timeout` seconds.

        Virtual time: runs the controller's cycles. Real time: blocks the calling thread.
        """
        timeout = check_nonnegative("timeout", timeout)
        ax = None if axis is None else self._ctl.axis(axis).index
        start_seq = self._seq

        if self._ctl.realtime:
            deadline = _time.monotonic() + timeout
            with self._cond:
                while True:
                    ev = self._first_match(start_seq, kind, ax)
                    remaining = deadline - _time.monotonic()
                    if ev is not None or remaining <= 0:
                        return ev
                    self._cond.wait(remaining)
        self._ctl.run_until(lambda: self._first_match(start_seq, kind, ax) is not None,
                            timeout)
        return self._first_match(start_seq, kind, ax)

    def _first_match(self, start_seq: int, kind: str | None, ax: int | None
                     ) -> MotionEvent | None:
        with self._cond:
            evs = list(self._events)
        for e in evs:
            if e.seq >= start_seq and (kind is None or e.kind == kind) \
                    and (ax is None or e.axis == ax):
                return e
        return None
