"""M62/M63 for the program runner: an output switched where the next motion starts.

An M62/M63 read by the runner waits (`pending`) until the next line/arc is queued; it is
then bound to that move (`bind`). "Where the next motion starts" is the instant the group
starts executing that command: the first instant `Group.index_at` reports it, found on the
chain position of the command's first element (`Group.start_time`). Never a point of the
path: a move that ends where it began (a full circle, a helix back over its XY start, a
move along axes outside the plane) passes its end point at its start as well, so a
position window on the corner fired when the move before it began.

While the move before the bound one runs, a `_StartJob` is armed in the compare engine
(control/trigger/compare.py): the engine scans command-position jobs before the hardware
advances over a cycle, so on timed hardware the output switches at the exact instant inside
the cycle, and a re-plan inside the cycle re-runs the scan. The start time of the coming
cycle is taken once, before the hardware runs (`ahead`, a pre-advance hook: the group's
plan then covers the cycle; after the cycle the group may already have re-planned from its
end). A start the job did not report (a move that began from rest in the group's hook at a
cycle end, or an engine whose cycle hook runs after the runner's) is set by `fire` at the
recorded exact time.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..control.trigger.compare import WindowJob
from .convert import Op

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from ..control.trigger.compare import CompareEngine
    from ..control.trigger.compare_jobs import Action

#: start_time(index, t0, t1): Group.start_time of the runner's group
StartTime = Callable[[int, float, float], "float | None"]
#: start_of(index): Group.start_of of the runner's group (the present run's start of it)
StartOf = Callable[[int], "float | None"]


def _before(t: float | None, ctl: Controller) -> float:
    """A due time half a cycle before the instant `t` a command starts (inf: the present
    run does not hold it), so the cycle its start falls in is never jumped over, even
    when a bisection from that cycle's ends finds the instant a hair earlier."""
    return math.inf if t is None else t - 0.5 * ctl.period


@dataclass
class _Armed:
    """An M62/M63 bound to the move `index` (starting at `corner`, pulses) after `prev`."""

    index: int
    op: Op
    corner: np.ndarray
    prev: int | None
    t_start: float | None = None  # the exact start of `index`, once a cycle covered it
    job: _StartJob | None = None


class _StartJob(WindowJob):
    """A compare job that fires once, when the group starts a command (`when(ta, t1)`:
    its start time in (ta, t1], or None). A dpos WindowJob on the program's axes to the
    engine (scanned before the hardware advances, undone and re-run on a re-plan) whose
    window never excludes: the engine's due bound never lets a cycle be jumped."""

    def __init__(self, axes: Sequence[int], corner: np.ndarray, action: Action,
                 when: Callable[[float, float], float | None], name: str) -> None:
        super().__init__(axes, corner[None, :], 1e300, action, name=name)
        self._when = when

    def scan(self, eng: CompareEngine, ta: float, t1: float) -> list[tuple[float, int, float]]:
        ta = max(ta, self.t_armed)
        if ta > t1 or self.index >= self.size:
            return []
        t = self._when(ta, t1)
        if t is None:
            return []
        self.index += 1
        return [(max(t, ta), 0, 0.0)]


#: set_output(op, index, level, kind, t): the runner writes the output now and logs it at t.
SetOutput = Callable[[Op, int, bool, str, float], None]
#: record(t, op, index, level): the engine switched the output at time t; the runner logs it.
Record = Callable[[float, Op, int, bool], None]


class SyncedOutputs:
    """The runner's M62/M63 bookkeeping (see the module docstring)."""

    def __init__(self, ctl: Controller, axis_indices: Sequence[int],
                 compare: CompareEngine | None, set_output: SetOutput,
                 record: Record) -> None:
        self._ctl = ctl
        self._axes = list(axis_indices)
        self._compare = compare
        self._set_output = set_output
        self._record = record
        self._start_time: StartTime | None = None
        self._start_of: StartOf | None = None
        self.pending: list[Op] = []      # read, waiting for the next move to be queued
        self.armed: list[_Armed] = []    # bound to a queued move that has not started
        self.levels: dict[int, bool] = {}  # the runner's view of every output it wrote
        self._prev: int | None = None    # group index of the last queued line/arc

    def attach(self, start_time: StartTime, start_of: StartOf | None = None) -> None:
        """The run starts: `start_time` (and `start_of`) are its group's; the pre-advance
        hook is added."""
        self._start_time = start_time
        self._start_of = start_of
        self._ctl.add_pre_advance_hook(self.ahead, due=self._ahead_due)

    def detach(self) -> None:
        self._ctl.remove_pre_advance_hook(self.ahead)

    def _ahead_due(self, ctl: Controller) -> float:
        """`ahead` acts in the cycle an armed move starts in (and nowhere else: its start
        is None in every other cycle), so that cycle runs on its own."""
        start_of = self._start_of
        due = math.inf
        for a in self.armed:
            if a.t_start is None:
                if start_of is None:
                    return -math.inf
                due = min(due, _before(start_of(a.index), ctl))
        return due

    def due(self, current: int) -> float:
        """When `fire` may next act (`current`: the command executing now): now while a
        compare job is armed (the engine scans it every cycle anyway) or one is to be
        armed; else the start of the move before an armed one (where its job is armed)."""
        start_of = self._start_of
        due = math.inf
        for a in self.armed:
            if a.job is not None or a.prev is None or current >= a.prev or start_of is None:
                return -math.inf
            due = min(due, _before(start_of(a.prev), self._ctl))
        return due

    def ahead(self, ctl: Controller, t0: float, t1: float) -> None:
        """Before the hardware runs (t0, t1]: the start time of each armed move the
        group's plan starts in that cycle."""
        for a in self.armed:
            if a.t_start is None:
                a.t_start = self._start_in(a, t0, t1)

    def _start_in(self, a: _Armed, t0: float, t1: float) -> float | None:
        return None if self._start_time is None else self._start_time(a.index, t0, t1)

    def _when(self, a: _Armed) -> Callable[[float, float], float | None]:
        def when(ta: float, t1: float) -> float | None:
            if a.t_start is None and self._ctl.time < t1:  # the engine's pre-advance ran first
                a.t_start = self._start_in(a, ta, t1)
            t = a.t_start
            return t if t is not None and t <= t1 else None
        return when

    def bind(self, index: int, start: np.ndarray) -> None:
        """A line/arc with group index `index` starting at `start` (pulses) was queued:
        the pending M62/M63 switch when it starts."""
        for op in self.pending:
            self.armed.append(_Armed(index, op, start, self._prev))
        self.pending.clear()
        self._prev = index

    def flush(self) -> None:
        """End of a pass: M62/M63 with no motion after them are set now."""
        for op in self.pending:
            self._set_output(op, op.index, op.level, "sync_output", self._ctl.time)
        self.pending.clear()

    def fire(self, current: int, idle_past: Callable[[int], bool]) -> None:
        """Once per cycle: `current` is the group command executing (-1: none);
        `idle_past(i)`: the group rests and command i already ran."""
        for a in list(self.armed):
            started = 0 <= a.index <= current or (current < 0 and idle_past(a.index))
            job = a.job
            if job is not None and job.hits > 0:
                self._fired(a)
                continue
            if started:  # the job has not reported it (see the module docstring)
                if job is not None:
                    self._engine().remove(job.id)
                self.armed.remove(a)
                t = self._ctl.time if a.t_start is None else a.t_start
                self._set_output(a.op, a.op.index, a.op.level, "sync_output", t)
                if job is not None:  # keep the engine's waveform in step
                    self._engine().output(a.op.index).set(t, a.op.level)
                continue
            if job is None and (a.prev is None or current >= a.prev):
                self._arm(a)

    def _engine(self) -> CompareEngine:
        from ..control.trigger.compare import CompareEngine

        if self._compare is None:
            self._compare = CompareEngine(self._ctl)
        return self._compare

    def _arm(self, a: _Armed) -> None:
        from ..control.trigger.compare import SetLevel

        eng = self._engine()
        n = a.op.index
        line = eng.output(n)
        known = self.levels.get(n, False)
        if line.level_at(self._ctl.time) != known:  # an M64/M65 written around the engine
            line.set(self._ctl.time, known)
        job = _StartJob(self._axes, a.corner, SetLevel(n, a.op.level), self._when(a),
                        name=f"M6{2 if a.op.level else 3} line {a.op.line}")
        eng.add(job)
        a.job = job

    def _fired(self, a: _Armed) -> None:
        n, level = a.op.index, a.op.level
        assert a.job is not None
        edges = [t for t, lv in self._engine().output(n).edges if lv == level]
        t = edges[-1] if edges else self._ctl.time
        self._engine().remove(a.job.id)
        self.armed.remove(a)
        self.levels[n] = level
        self._record(t, a.op, n, level)


class SyncedAnalog:
    """The runner's M67 bookkeeping: an analog write bound to the next queued move, made
    in the cycle that move starts (LinuxCNC applies synchronised outputs at the start of
    the next motion segment, at its servo-cycle resolution; `write(op)` does the write)."""

    def __init__(self, write: Callable[[Op], None]) -> None:
        self._write = write
        self.pending: list[Op] = []
        self.armed: list[tuple[int, Op]] = []

    def due(self, ctl: Controller, current: int, start_of: StartOf) -> float:
        """When `fire` may next act: the start of the first armed write's move."""
        due = math.inf
        for index, _ in self.armed:
            if 0 <= index <= current:
                return -math.inf
            due = min(due, _before(start_of(index), ctl))
        return due

    def bind(self, index: int) -> None:
        """The move with group index `index` was queued: pending writes wait for it."""
        self.armed.extend((index, op) for op in self.pending)
        self.pending.clear()

    def fire(self, current: int, idle_past: Callable[[int], bool]) -> None:
        """Once per cycle (see SyncedOutputs.fire): write those whose move started."""
        for item in list(self.armed):
            index, op = item
            if 0 <= index <= current or (current < 0 and idle_past(index)):
                self.armed.remove(item)
                self._write(op)

    def flush(self) -> None:
        """End of a pass: M67 with no motion after them are written now."""
        for op in self.pending:
            self._write(op)
        self.pending.clear()
