"""The controller's hook registration: what the capabilities built on the core attach.

A mixin of `controller.Controller` (the hook lists live there and its cycle runs them):
`add_*` / `remove_*` for edge hooks (with the signals they act on), cycle and pre-advance
hooks (with `due`), jump observers, sample hooks, fault hooks, motion checks and motion
hooks, period hooks and config hooks. This is how groups, safety, homing, compare and the
servo loops reach the cycle without the core importing any of them.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from typing import TYPE_CHECKING

from ...errors import MotionError, check_int

if TYPE_CHECKING:
    from .controller import (
        ConfigHook,
        CycleHook,
        DueFn,
        EdgeHook,
        FaultHook,
        JumpObserver,
        MotionCheck,
        MotionHook,
        PeriodHook,
        PreAdvanceHook,
        SampleHook,
    )
    from .realtime import HandoverLock


class ControllerHooks:
    """Mixin of `Controller`: registering and removing every kind of hook."""

    _lock: HandoverLock
    _edge_hooks: list[EdgeHook]
    _edge_signals: dict[EdgeHook, frozenset[str]]
    _cycle_hooks: list[CycleHook]
    _cycle_dues: dict[CycleHook, DueFn]
    _pre_hooks: list[PreAdvanceHook]
    _pre_dues: dict[PreAdvanceHook, DueFn]
    _jump_observers: list[JumpObserver]
    _sample_hooks: list[tuple[SampleHook, int]]
    _samples: int
    _fault_hooks: list[FaultHook]
    _motion_checks: list[MotionCheck]
    _motion_hooks: list[MotionHook]
    _period_hooks: list[PeriodHook]
    _config_hooks: list[ConfigHook]

    def add_edge_hook(self, hook: EdgeHook, *, signals: Collection[str] | None = None
                      ) -> None:
        """Call `hook(controller, edge)` for every input edge, after the built-in hooks.

        `signals`, if given, promises the hook does nothing for edges on other signals:
        virtual time then jumps over cycles whose only edges are on signals no hook acts
        on (control/core/jump.py). Without it, every edge ends a jump.
        """
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        if signals is not None and (isinstance(signals, str) or not all(
                isinstance(x, str) for x in signals)):
            raise MotionError(f"signals must be a collection of signal names, got "
                                  f"{signals!r}")
        with self._lock:
            self._edge_hooks.append(hook)
            if signals is not None:
                self._edge_signals[hook] = frozenset(signals)

    def remove_edge_hook(self, hook: EdgeHook) -> None:
        with self._lock:
            if hook in self._edge_hooks[2:]:
                self._edge_hooks.remove(hook)
                if hook not in self._edge_hooks:
                    self._edge_signals.pop(hook, None)

    def add_cycle_hook(self, hook: CycleHook, *, due: DueFn | None = None) -> None:
        """Call `hook(controller, t)` at the end of every cycle (t = cycle end time).

        `due(controller)`, if given, returns the earliest time at which the hook may act
        (it must run in the first cycle ending at or after it; math.inf: not before the
        next input edge or motion change; the current time or less: every cycle). Virtual
        time jumps only over cycles in which every cycle hook is not due (control/core/jump.py);
        a hook without `due` runs every cycle and keeps time from jumping.
        """
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        if due is not None and not callable(due):
            raise MotionError(f"due must be callable or None, got {due!r}")
        with self._lock:
            self._cycle_hooks.append(hook)
            if due is not None:
                self._cycle_dues[hook] = due

    def remove_cycle_hook(self, hook: CycleHook) -> None:
        with self._lock:
            if hook in self._cycle_hooks:
                self._cycle_hooks.remove(hook)
                if hook not in self._cycle_hooks:
                    self._cycle_dues.pop(hook, None)

    def add_pre_advance_hook(self, hook: PreAdvanceHook, *, due: DueFn | None = None
                             ) -> None:
        """Call `hook(controller, t0, t1)` every cycle after every axis's command for
        [t0, t1] is set and before `hardware.advance(t1)`: the commanded motion of the
        coming cycle is known then (the history holds it), so a hook can schedule timed
        outputs for it (hw.interface.TimedOutputHardware).

        `due(controller)`, as for `add_cycle_hook`: the earliest time inside the first
        cycle in which the hook may act; that cycle then runs on its own (a jump lands
        before it). Without it, every cycle runs.
        """
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        if due is not None and not callable(due):
            raise MotionError(f"due must be callable or None, got {due!r}")
        with self._lock:
            self._pre_hooks.append(hook)
            if due is not None:
                self._pre_dues[hook] = due

    def remove_pre_advance_hook(self, hook: PreAdvanceHook) -> None:
        with self._lock:
            if hook in self._pre_hooks:
                self._pre_hooks.remove(hook)
                if hook not in self._pre_hooks:
                    self._pre_dues.pop(hook, None)

    def add_jump_observer(self, observer: JumpObserver) -> None:
        """Call `observer(controller, first, last, positions, actual)` when a jump
        (control/core/jump.py) crosses cycles first..last without running their hooks:
        `positions[i, a]` (float arrays, one row per crossed cycle, one column per axis)
        is axis a's command position (pulses) at the end of cycle first + i, exactly as
        those cycles would have left it, and `actual[i, a]` its `counters.actual()` (the
        feedback position in the command frame) there; valid during the call only. A hook
        that records something every cycle (a trace) fills the crossed cycles from it and
        can declare a `due`."""
        if not callable(observer):
            raise MotionError(f"observer must be callable, got {observer!r}")
        with self._lock:
            self._jump_observers.append(observer)

    def remove_jump_observer(self, observer: JumpObserver) -> None:
        with self._lock:
            if observer in self._jump_observers:
                self._jump_observers.remove(observer)

    def add_sample_hook(self, hook: SampleHook, per_cycle: int = 1) -> None:
        """Call `hook(controller, t)` `per_cycle` times per cycle, at t = t0 + k*T/per_cycle
        (k = 0..per_cycle-1), after the cycle's commands are sent and the hardware has been
        advanced to t (sampled loops: read feedback, write an output held from t)."""
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        check_int("per_cycle", per_cycle, 1, 1000)
        with self._lock:
            self._sample_hooks.append((hook, per_cycle))
            self._samples = math.lcm(*(n for _, n in self._sample_hooks))

    def remove_sample_hook(self, hook: SampleHook) -> None:
        with self._lock:
            self._sample_hooks = [(h, n) for h, n in self._sample_hooks if h != hook]
            self._samples = math.lcm(1, *(n for _, n in self._sample_hooks))

    def add_fault_hook(self, hook: FaultHook) -> None:
        """Call `hook(axis, reason)` whenever an axis goes to ErrorStop (`fault_stop`):
        limits, alarms, E-stop, safety reactions. A group engine subscribes here."""
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        with self._lock:
            self._fault_hooks.append(hook)

    def remove_fault_hook(self, hook: FaultHook) -> None:
        with self._lock:
            if hook in self._fault_hooks:
                self._fault_hooks.remove(hook)

    def add_motion_check(self, check: MotionCheck) -> None:
        """Call `check(axis, motion)` before a motion starts or is re-planned (not for
        stops); it refuses by raising MotionError, which leaves the axis unchanged."""
        if not callable(check):
            raise MotionError(f"check must be callable, got {check!r}")
        with self._lock:
            self._motion_checks.append(check)

    def remove_motion_check(self, check: MotionCheck) -> None:
        with self._lock:
            if check in self._motion_checks:
                self._motion_checks.remove(check)

    def add_motion_hook(self, hook: MotionHook) -> None:
        """Call `hook(axis, motion)` whenever an axis starts, re-plans or kills its motion
        (motion None: stopped at once, disabled, faulted). Not called when a motion ends by
        itself. A group engine subscribes to react to its axes being stopped directly."""
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        with self._lock:
            self._motion_hooks.append(hook)

    def remove_motion_hook(self, hook: MotionHook) -> None:
        with self._lock:
            if hook in self._motion_hooks:
                self._motion_hooks.remove(hook)

    def add_period_hook(self, hook: PeriodHook) -> None:
        """Call `hook(new_period, commit)` when the period changes (`set_period`): first
        with commit False for every hook (raise MotionError to refuse the change), then
        with commit True once it is made. Capabilities whose settings are per period (a
        group's per-period pulse caps) subscribe here."""
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        with self._lock:
            self._period_hooks.append(hook)

    def remove_period_hook(self, hook: PeriodHook) -> None:
        with self._lock:
            if hook in self._period_hooks:
                self._period_hooks.remove(hook)

    def add_config_hook(self, hook: ConfigHook) -> None:
        """Call `hook(axis_index, new_config, commit)` when an axis is reconfigured
        (`reconfigure_axis`): first with commit False (raise MotionError to refuse), then
        with commit True once it is made. A group whose units follow the machine
        subscribes here."""
        if not callable(hook):
            raise MotionError(f"hook must be callable, got {hook!r}")
        with self._lock:
            self._config_hooks.append(hook)

    def remove_config_hook(self, hook: ConfigHook) -> None:
        with self._lock:
            if hook in self._config_hooks:
                self._config_hooks.remove(hook)
