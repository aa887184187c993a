"""Comparators 3 and 4 of the HSL-4XMO (4.12): step-loss check and the general comparator.

- Comparator 3, `set_error_counter_check(axis, tolerance, on)`: at every cycle end the
  position error counter (command - feedback / move ratio) is compared with the tolerance;
  beyond it the axis stops at once and goes to ErrorStop "step loss" (a stepper that lost
  pulses, a servo whose following error ran away). It re-arms once the error is back within
  the tolerance (e.g. after `counters.reset_error()`).
- Comparator 4, `set_general_comparator(axis, source, method, action, data)`: source
  "command", "feedback", "error" or "general" counter; method "=" (the value reaches data,
  either way), ">" (becomes greater), "<" (becomes less); action "event" (recorded only),
  "stop" (immediate stop), "slow_stop" (decelerating stop), "change_speed" (HSL
  cmp_v_change: arm the speed with `cmp_v_change(axis, new_vel, tacc)` first). One-shot: it
  fires once, then is off until set again. For the command source the event time is the
  exact crossing time of the planned command position (history); the action itself, and
  every other source, act at the end of the cycle that saw the condition (one cycle late at
  most).

Every firing is appended to `comparators.events` (and given to `on_event` callbacks).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import InfeasibleError, MotionError, check_finite, check_int, check_nonnegative
from ..core.states import AxisState

if TYPE_CHECKING:
    from ..core.controller import Controller

SOURCES = ("command", "feedback", "error", "general")
METHODS = ("=", ">", "<", "=+", "=-")  # "=+" / "=-": equal while counting up / down
ACTIONS = ("event", "stop", "slow_stop", "change_speed")


@dataclass(frozen=True)
class CompareEvent:
    """A comparator fired."""

    axis: int
    comparator: str   # "error_check" or "general"
    time: float       # exact crossing time (command source) or the cycle end
    value: float      # the counter value that met the condition
    action: str
    note: str = ""    # e.g. why a change of speed could not be made


@dataclass
class _General:
    source: str
    method: str
    action: str
    data: float
    prev: float | None = None


class Comparators:
    """Comparators 3 and 4 of every axis (used through `Safety.cmp`)."""

    def __init__(self, controller: Controller) -> None:
        self.ctl = controller
        n = len(controller.axes)
        self._err: list[tuple[int, bool] | None] = [None] * n   # (tolerance, armed)
        self._gen: list[_General | None] = [None] * n
        self._vchange: list[tuple[float, float] | None] = [None] * n
        self._last_t = controller.time
        self.events: list[CompareEvent] = []
        self._callbacks: list[Callable[[CompareEvent], None]] = []

    def on_event(self, fn: Callable[[CompareEvent], None]) -> None:
        """Call `fn(event)` whenever a comparator fires (the seed's interrupt)."""
        if not callable(fn):
            raise MotionError(f"fn must be callable, got {fn!r}")
        self._callbacks.append(fn)

    # ------------------------------------------------------------------ settings
    def set_error_counter_check(self, axis: int | str, tolerance: int, on: bool) -> None:
        """HSL_M_set_error_counter_check(Tolerance, On_Off)."""
        i = self.ctl.axis(axis).index
        check_int("tolerance", tolerance, 0)
        if not isinstance(on, bool):
            raise MotionError(f"on must be a bool, got {on!r}")
        self._err[i] = (tolerance, True) if on else None

    def set_general_comparator(self, axis: int | str, source: str, method: str,
                               action: str, data: float) -> None:
        """HSL_M_set_general_comparator(CmpSrc, CmpMethod, CmpAction, Data)."""
        i = self.ctl.axis(axis).index
        if source not in SOURCES:
            raise MotionError(f"source must be one of {SOURCES}, got {source!r}")
        if method not in METHODS:
            raise MotionError(f"method must be one of {METHODS}, got {method!r}")
        if action not in ACTIONS:
            raise MotionError(f"action must be one of {ACTIONS}, got {action!r}")
        d = check_finite("data", data)
        if action == "change_speed" and self._vchange[i] is None:
            raise MotionError("action 'change_speed' needs cmp_v_change(axis, new_vel, tacc) "
                              "first")
        g = _General(source, method, action, d)
        g.prev = self._value(i, source)
        self._gen[i] = g

    def clear_general_comparator(self, axis: int | str) -> None:
        self._gen[self.ctl.axis(axis).index] = None

    def cmp_v_change(self, axis: int | str, new_vel: float, tacc: float) -> None:
        """HSL_M_cmp_v_change: the speed (pps) and ramp time the general comparator's
        "change_speed" action applies (as Axis.change_speed)."""
        i = self.ctl.axis(axis).index
        v = check_finite("new_vel", new_vel)
        if v <= 0.0:
            raise MotionError(f"new_vel must be > 0, got {new_vel!r}")
        ta = check_nonnegative("tacc", tacc)
        if ta <= 0.0:
            raise MotionError(f"tacc must be > 0, got {tacc!r}")
        self._vchange[i] = (v, ta)

    def error_counter_check(self, axis: int | str) -> int | None:
        """The step-loss tolerance armed on `axis` (comparator 3), or None when off."""
        e = self._err[self.ctl.axis(axis).index]
        return None if e is None else e[0]

    def general_comparator(self, axis: int | str) -> tuple[str, str, str, float] | None:
        """(source, method, action, data) of the armed general comparator, or None."""
        g = self._gen[self.ctl.axis(axis).index]
        return None if g is None else (g.source, g.method, g.action, g.data)

    # ------------------------------------------------------------------ cycle
    def _value(self, i: int, source: str) -> float:
        c = self.ctl.axes[i].counters
        if source == "command":
            return self.ctl.axes[i].position
        if source == "feedback":
            return float(c.feedback_unwrapped())
        if source == "error":
            return float(c.error)
        return float(c.general)

    def due(self) -> float:
        """When `on_cycle` may next act: every cycle while an error-counter check or a
        general comparator is set, else math.inf."""
        if any(e is not None for e in self._err) or any(g is not None for g in self._gen):
            return -math.inf
        return math.inf

    def on_cycle(self, t: float) -> None:
        t_prev, self._last_t = self._last_t, t
        for ax in self.ctl.axes:
            i = ax.index
            e = self._err[i]
            if e is not None:
                err = ax.counters.error
                tol, armed = e
                if armed and abs(err) > tol:
                    self._err[i] = (tol, False)
                    if ax.state is not AxisState.ERROR_STOP:
                        ax.fault_stop("step loss")
                    self._fire(CompareEvent(i, "error_check", t, float(err), "stop"))
                elif not armed and abs(err) <= tol:
                    self._err[i] = (tol, True)
            g = self._gen[i]
            if g is not None:
                self._general(i, g, t_prev, t)

    def _general(self, i: int, g: _General, t_prev: float, t: float) -> None:
        ax = self.ctl.axes[i]
        val = self._value(i, g.source)
        prev = val if g.prev is None else g.prev
        g.prev = val
        d = g.data
        if g.method == "=":
            hit = (prev < d <= val) or (prev > d >= val) or val == d != prev
        elif g.method == "=+":
            hit = prev < d <= val
        elif g.method == "=-":
            hit = prev > d >= val
        elif g.method == ">":
            hit = val > d
        else:
            hit = val < d
        if not hit:
            return
        self._gen[i] = None
        t_hit = t
        if g.source == "command" and prev != val:
            off = ax.position - ax.counters.pulses_from_command(ax.position)
            direction = {"=": 0, ">": 1, "=+": 1}.get(g.method, -1)
            times = self.ctl.history.crossings(i, d - off, t_prev, t, direction)
            if len(times):
                t_hit = float(times[0])
        note = ""
        if g.action == "stop":
            ax.stop_immediately()
        elif g.action == "slow_stop":
            ax.stop()
        elif g.action == "change_speed":
            vc = self._vchange[i]
            assert vc is not None
            try:
                ax.change_speed(vc[0], vc[1])
            except (InfeasibleError, MotionError) as exc:
                note = f"change_speed refused: {exc}"
        self._fire(CompareEvent(i, "general", t_hit, val, g.action, note))

    def _fire(self, ev: CompareEvent) -> None:
        self.events.append(ev)
        for fn in tuple(self._callbacks):
            fn(ev)
