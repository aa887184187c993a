"""The compare engine's re-plan rollback: a pre-advance scan undone and run again.

A mixin of `compare.CompareEngine` (the state lives there). On timed hardware the
command-position jobs are scanned before the hardware runs the cycle; when the motion of
that cycle changed afterwards (an edge stop, a re-plan from an edge time), `_snapshot`'s
record of the scan's effects lets `_rollback` undo them so the engine can scan the motion
as executed (compare.py's `_on_cycle` decides when).
"""

from __future__ import annotations

from typing import Any

from . import compare_math as _cm
from .compare_io import OutputLine
from .compare_jobs import Action, CompareJob, VectorSource, WindowJob


class CompareReplan:
    """Mixin of `CompareEngine`: snapshot, change check and rollback of a pre-advance scan."""

    ctl: Any
    _jobs: dict[int, CompareJob]
    _next_id: int
    _jobs_ver: int
    _lines: dict[int, OutputLine]
    _vectors: dict[VectorSource, float]
    _pwms: list[Any]
    _win: tuple[float, float]
    _plan: bytes | None
    _plan_hists: list[Any]
    _plan_key: tuple[int, int, int] | None
    _plan_axes: list[int]
    _timers: dict[int, Any]
    _pre_rows: list[Any]

    # A stop the hardware makes by itself at an input edge (hw.interface.EdgeStopHardware)
    # or a re-plan from an edge time changes (t0, t1] after the pre-advance scan. The
    # history record in force at the end of the cycle is kept; if it changed after the cycle,
    # the scan's effects (job state, waveforms, vector lengths, PWM duties, log rows) are
    # undone and the scan is run again on the motion as executed. Edges already handed to
    # the hardware cannot be taken back: the line is corrected at the cycle end.
    def _snapshot(self, ta: float, t1: float) -> None:
        if not (self._jobs or self._pwms or self._vectors):
            self._plan = None
            return
        # the compared axes and the pulse timers change only with the jobs and vectors
        key = (self._next_id, len(self._jobs), len(self._vectors))
        if key != self._plan_key:
            axes: set[int] = set()
            for j in self._jobs.values():
                src = getattr(j, "source", None)
                axes.update(j.axes if isinstance(j, WindowJob) else
                            src.axes if isinstance(src, VectorSource) else (src.axis,))
            for v in self._vectors:
                axes.update(v.axes)
            self._plan_axes = sorted(axes)
            self._plan_hists = [self.ctl.history._tracks[a] for a in self._plan_axes]
            self._timers = {id(x): x for x in (_timer_of(j.action)
                                               for j in self._jobs.values()) if x is not None}
            self._plan_key = key
        # the history record in force just before t1 of every compared axis (a re-plan
        # or cut inside the cycle starts a new one there; a motion starting exactly at t1
        # does not count), read in place from the history's record stores
        solvers = _cm._solvers()
        self._plan = solvers.plan_records(self._plan_hists, t1)
        timers = self._timers
        lines = self._lines
        self._snap = (
            dict(self._jobs),
            {k: (j.index, j.hits, j.active) for k, j in self._jobs.items()},
            {k: (x.busy_until, x.overruns, x.ignored) for k, x in timers.items()}, timers,
            dict(zip(lines, solvers.lines_snapshot(list(lines.values()), ta), strict=True)),
            dict(self._vectors), [len(p.duties) for p in self._pwms])

    def _moved_off_plan(self) -> bool:
        if self._plan is None:
            return False
        return not _cm._solvers().plan_records(self._plan_hists, self._win[1], self._plan)

    def _rollback(self, ta: float) -> None:
        jobs, state, tstate, timers, lines, vectors, duties = self._snap
        for k, (idx, hits, active) in state.items():
            j = jobs[k]
            if k in self._jobs or j.done:  # not removed by the user meanwhile
                j.index, j.hits, j.active = idx, hits, active
                if active:
                    self._jobs[k] = j
        self._jobs_ver += 1
        for k, (busy, over, ign) in tstate.items():
            timers[k].busy_until, timers[k].overruns, timers[k].ignored = busy, over, ign
        for n_, snap in lines.items():
            self._lines[n_].restore(ta, snap)
        self._vectors.update(vectors)
        for p, n_ in zip(self._pwms, duties, strict=False):
            del p.duties[n_:]
        self._pre_rows = []


def _timer_of(action: Action) -> Any:
    """The pulse timer an action drives (itself, or a trigger's `timer`), or None."""
    tm = getattr(action, "timer", action)
    return tm if hasattr(tm, "busy_until") else None
