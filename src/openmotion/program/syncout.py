"""M62/M63 for the program runner: an output switched where the next motion starts.

An M62/M63 read by the runner waits (`pending`) until the next line/arc is queued; it is
then bound to that move (`bind`). While the move before it runs, a compare-engine window job
(control/trigger/compare.py, `WindowJob` on the command positions of the program's axes) is armed on
the corner where the bound move starts, +-1e-6 pulse, or +-the blend tolerance in pulses
with G64 P (`set_blend`); the engine switches the output at the exact crossing time, inside
the cycle (timed hardware). A move that starts from rest starts on a cycle boundary and the
output is set in that cycle (`fire`, also exact); a corner the window missed (or G64
without P, which has no bound) falls back to the cycle in which the move starts.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .convert import Op

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from ..control.trigger.compare import CompareEngine


@dataclass
class _Armed:
    """An M62/M63 bound to the move `index` that starts at `corner` (pulses) after `prev`."""

    index: int
    op: Op
    corner: np.ndarray
    prev: int | None
    tol: float | None
    job: object = None


#: set_output(op, index, level, kind): the runner writes the output now and logs it.
SetOutput = Callable[[Op, int, bool, str], None]
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
        self.pending: list[Op] = []      # read, waiting for the next move to be queued
        self.armed: list[_Armed] = []    # bound to a queued move that has not started
        self.levels: dict[int, bool] = {}  # the runner's view of every output it wrote
        self._prev: int | None = None    # group index of the last queued line/arc
        self._tol: float | None = 1e-6   # window half-width, pulses; None: no window

    def set_blend(self, tolerance: float | None, ppu_max: float) -> None:
        """G61 (None) or G64 P tolerance (machine units; >= 1e9: G64 without P). A corner
        rounded within tol is within tol * |pulses/unit| pulses on each axis: the window
        uses the largest scale `ppu_max`."""
        if tolerance is None:
            self._tol = 1e-6
        else:
            self._tol = float(tolerance) * ppu_max + 1e-6 if tolerance < 1e9 else None

    def bind(self, index: int, start: np.ndarray) -> None:
        """A line/arc with group index `index` starting at `start` (pulses) was queued:
        the pending M62/M63 switch where it starts."""
        for op in self.pending:
            self.armed.append(_Armed(index, op, start, self._prev, self._tol))
        self.pending.clear()
        self._prev = index

    def flush(self) -> None:
        """End of a pass: M62/M63 with no motion after them are set now."""
        for op in self.pending:
            self._set_output(op, op.index, op.level, "sync_output")
        self.pending.clear()

    def fire(self, current: int, idle_past: Callable[[int], bool]) -> None:
        """Once per cycle: `current` is the group command executing (-1: none);
        `idle_past(i)`: the group rests and command i already ran."""
        for a in list(self.armed):
            started = 0 <= a.index <= current or (current < 0 and idle_past(a.index))
            job = a.job
            if job is not None and job.hits > 0:  # type: ignore[attr-defined]
                self._fired(a)
                continue
            if started:  # from rest (cycle boundary) or the window was missed
                if job is not None:
                    self._engine().remove(job.id)  # type: ignore[attr-defined]
                self.armed.remove(a)
                self._set_output(a.op, a.op.index, a.op.level, "sync_output")
                continue
            if job is None and a.prev is not None and a.tol is not None and current >= a.prev:
                self._arm_window(a)

    def _engine(self) -> CompareEngine:
        from ..control.trigger.compare import CompareEngine

        if self._compare is None:
            self._compare = CompareEngine(self._ctl)
        return self._compare

    def _arm_window(self, a: _Armed) -> None:
        from ..control.trigger.compare import SetLevel, WindowJob

        eng = self._engine()
        n = a.op.index
        line = eng.output(n)
        known = self.levels.get(n, False)
        if line.level_at(self._ctl.time) != known:  # an M64/M65 written around the engine
            line.set(self._ctl.time, known)
        assert a.tol is not None
        job = WindowJob(self._axes, a.corner[None, :], a.tol, SetLevel(n, a.op.level),
                        name=f"M6{2 if a.op.level else 3} line {a.op.line}")
        eng.add(job)
        a.job = job

    def _fired(self, a: _Armed) -> None:
        n, level = a.op.index, a.op.level
        edges = [t for t, lv in self._engine().output(n).edges if lv == level]
        t = edges[-1] if edges else self._ctl.time
        self._engine().remove(a.job.id)  # type: ignore[attr-defined]
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
