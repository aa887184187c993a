"""Joins planned off the real-time cycle: a worker thread re-plans, a later cycle installs.

In real-time mode a join (the running chain re-planned with the next queued commands, a
few hundred elements) takes several cycles of work. Instead of doing it inside one cycle,
`_join_async` picks a future cycle boundary t_j = t + K periods (K from `JOIN_LEAD`),
takes the commands off the queue and starts a worker thread that builds the join options,
re-plans the running plan from t_j (`pathrun.replan` is a pure function of the immutable
plan) and builds the axis profiles from the group position the running profiles reach at
t_j. At the hook of cycle t_j, `_poll_join` installs the result exactly as `_launch` does
when the running plan is still the same object and the settings are unchanged; a worker
not done by then is waited for a few cycles at most, then the cycle computes the same join
itself (joinhandoff.py: the result does not depend on who computes it, so neither does the
motion). Otherwise (failed, no feasible option, or the plan changed by a hold, an
override, a continue) the commands go back to the queue front; abort and faults drop them
(`_drop_join`). After `MAX_MISSES` misses in a row the next join is synchronous.

The worker reads only immutable values or copies taken before it starts: the plan, the
commands, the limits, the pre-blend cache (a copy), the blend settings (compared again at
install). Virtual time never uses it: joins there stay synchronous and bit for bit as they
were.
"""

from __future__ import annotations

import math
import queue
import threading
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import InfeasibleError, MotionError
from . import joinhandoff, pathaxes, pathrun

if TYPE_CHECKING:
    from ...profile.segments import Profile

#: Lead time of a join planned off the cycle (s): the worker has this long to finish.
JOIN_LEAD = 0.025
#: Misses in a row (late, failed, or the plan changed) before a join is done in the cycle.
MAX_MISSES = 2


def lead_cycles(period: float) -> int:
    """K: cycles between the decision to join and the cycle that installs it (>= 2)."""
    return max(2, math.ceil(JOIN_LEAD / period - 1e-9))


@dataclass
class _Job:
    """One join in flight: what it was planned against, and the worker's result."""

    plan: pathrun.PathPlan        # the running plan (compared by identity at install)
    run: Any                      # the running _Run
    new: list[Any]                # the commands taken off the queue
    t_j: float                    # the cycle boundary the join starts at
    key: tuple                    # the settings it was planned with
    work: Callable[[], None] | None = None
    # the join itself, a pure function of what the launch captured: compute(stop) -> result
    # (None: no feasible option, or stop() became true); the worker or the cycle runs it
    compute: Callable[[Callable[[], bool]], Any] | None = None
    queued: bool = False          # handed to the worker (not while it is stalled)
    cancelled: bool = False       # the install computed it itself: the worker drops it
    done: threading.Event = field(default_factory=threading.Event)
    result: tuple[pathrun.PathPlan, list[Profile]] | None = None
    error: BaseException | None = None


class AsyncJoin:
    """The real-time join worker of `GroupEngine` (see the module doc)."""

    _job: _Job | None = None
    _last_job: _Job | None = None
    _jobs: queue.SimpleQueue | None = None   # the worker's input (None: no worker yet)
    _stuck: _Job | None = None  # a job whose install stopped waiting for the worker
    _join_misses: int = 0
    async_joins: int = 0     # joins installed from the worker (for tests and figures)
    late_joins: int = 0      # joins launched for the worker, computed by the install cycle
    sync_joins: int = 0      # joins done in the cycle in real-time mode (fallbacks)

    def _join_key(self) -> tuple:
        """Everything besides the plan and the commands a join's result depends on."""
        # the blend key holds the blend and corner settings and the axis caps
        return (self._blend_key(), self._override, self._sys_max,  # type: ignore[attr-defined]
                self._cruise_ratio)  # type: ignore[attr-defined]

    def _lead_cycles(self) -> int:
        return lead_cycles(self._ctl.period)  # type: ignore[attr-defined]

    def _use_worker(self, plan: pathrun.PathPlan) -> bool:
        """Whether a due join goes to the worker (real-time mode) or is done in the cycle:
        virtual time, dry run, after MAX_MISSES misses in a row, a chain that ends before
        the worker's cycle. Only the controller's state decides (not whether the worker is
        still busy: jobs queue up, and the install waits for its job), so the same cycles
        give the same joins on the worker."""
        ctl = self._ctl  # type: ignore[attr-defined]
        if not ctl.realtime or self._dry:  # type: ignore[attr-defined]
            return False
        if self._join_misses >= MAX_MISSES:
            self._join_misses = 0
            return False
        return plan.t_end > ctl.time + (self._lead_cycles() + 1) * ctl.period

    def _join_async(self, r: Any, new: list[Any]) -> None:
        """Start the worker on a join of `new` to the running chain at t + K cycles."""
        ctl = self._ctl  # type: ignore[attr-defined]
        plan = r.plan
        t_j = ctl._t_origin + (ctl._n + lead_cycles(ctl.period)) * ctl.period
        u = t_j - r.t0
        starts = np.array([p.state_at(min(max(u, 0.0), p.duration)).p for p in r.profiles])
        starts = self._units_of(starts)  # type: ignore[attr-defined]
        lim0 = self._limits(plan.chain, plan.limits.str_vel)  # type: ignore[attr-defined]
        pre = dict(self._pre)  # type: ignore[attr-defined]
        have = plan.remaining(t_j)
        job = _Job(plan, r, new, t_j, self._join_key())
        k = self._k.copy()  # type: ignore[attr-defined]

        def compute(stop: Callable[[], bool]) -> tuple | None:
            for chain in self._join_options(plan, have, new, dict(pre)):  # type: ignore[attr-defined]
                if stop():
                    return None
                lim = replace(lim0, accel=float(np.max(chain.accels))) \
                    if chain.accels is not None else lim0
                try:
                    p2 = pathrun.replan(plan, t_j, chain=chain, limits=lim)
                except InfeasibleError:
                    continue
                prof = pathaxes.axis_profiles(p2.chain, p2.sprof, ctl.period, starts)
                if not np.all(k == 1.0):
                    prof = [pathaxes.scaled(p, float(s)) for p, s in zip(prof, k,
                                                                          strict=True)]
                return p2, prof
            return None

        job.compute = compute
        job.work = lambda: joinhandoff.run_on_worker(job, compute)
        self._job = self._last_job = job
        if joinhandoff.worker_stalled(self._stuck):
            return  # the install cycle computes it (joinhandoff.py)
        self._stuck = None
        if self._jobs is None:  # one worker per group, started once: a thread start
            # per join would hand the new thread the GIL in the middle of the cycle
            self._jobs = queue.SimpleQueue()
            threading.Thread(target=_serve, args=(self._jobs,), name="openmotion-join",
                             daemon=True).start()
        job.queued = True
        self._jobs.put(job)

    def _poll_join(self, t: float) -> bool:
        """Each cycle while a join is in flight: install it at its cycle, or give it up
        when the plan changed. True while the join still owns the queue's front."""
        job = self._job
        if job is None:
            return False
        r = self._run  # type: ignore[attr-defined]
        same = (r is job.run and r.plan is job.plan and self._join_key() == job.key
                and self._state.value == "moving")  # type: ignore[attr-defined]
        if same and t < job.t_j - 0.5 * self._ctl.period:  # type: ignore[attr-defined]
            return True
        self._job = None
        how, result = "late", None
        if same and t < job.t_j + 0.5 * self._ctl.period:  # type: ignore[attr-defined]
            how, result = joinhandoff.collect(job, self._ctl.period,  # type: ignore[attr-defined]
                                              joinhandoff.worker_stalled(self._stuck))
            if job.cancelled and job.queued:
                self._stuck = job  # the worker is still on it
        if result is not None:
            p2, profiles = result
            for c in job.new:
                self._pre.pop(c.index, None)  # type: ignore[attr-defined]
            try:
                self._install(p2, profiles, [*r.cmds, *job.new], t)  # type: ignore[attr-defined]
            except MotionError as err:  # refused by an axis (safety): stop the group
                self._fault(getattr(err, "code", -4), f"join refused: {err}")  # type: ignore[attr-defined]
                return True
            self._join_misses = 0
            if how == "worker":
                self.async_joins += 1
            else:
                self.late_joins += 1
            return True
        if same:  # failed, infeasible or late (a changed plan is nobody's miss)
            self._join_misses += 1
        job.cancelled = True  # given up: a worker still on it drops it at its next option
        self._queue.extendleft(reversed(job.new))  # type: ignore[attr-defined]
        return False

    def _drop_join(self) -> None:
        """Abort, fault, close: forget a join in flight with its commands."""
        if self._job is not None:
            self._job.cancelled = True
        self._job = None

    def _stop_join_worker(self) -> None:
        """Close: end the worker thread (after the job it runs, if any)."""
        self._job = None
        if self._jobs is not None:
            self._jobs.put(None)
            self._jobs = None


def _serve(jobs: queue.SimpleQueue) -> None:
    """The worker thread: run the jobs one at a time until a None arrives."""
    while True:
        job = jobs.get()
        if job is None:
            return
        job.work()
