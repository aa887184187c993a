"""Real-time mode on the compiled executor: cycles paced to the wall clock without Python.

`RealtimeExecutor` runs the controller against the wall clock on one thread. Whenever
virtual time could jump (control/core/jump.py: nothing needs the control layer in the
coming cycles), it feeds the back end the pieces of the next cycles (at most `HORIZON_S`
ahead) and lets it run them inside a pacing context (`openmotion._kernel.rt_paced`,
src/openmotion/_kernel_rt.c): the compiled cycle loop waits for each cycle's slot on the
wall clock with the GIL released and records its busy time, so no Python thread (the
join worker, a UI, the caller) can delay a cycle. Python is woken only where it must act,
exactly where a jump lands in virtual time: a reported input edge (its cycle runs on the
Python path and the reactions land at that cycle's end), a motion end, a hook's due time,
the end of the fed horizon, or another thread waiting for `Controller.lock` (a command:
the run returns at the next cycle boundary, the command gets the lock, the next cycle
sees it - as when stepping). When a jump is not possible (a per-cycle hook, a servo loop
closed in Python, a back end the compiled loop cannot serve: servo/DC plants, pitch
tables, armed stops) the cycle runs in Python (`Controller.step`) at its slot: the
fallback, counted in `CycleStats.python_cycles`.

The landing lead: a landing's Python work (its hooks: a path start, a join install; the
trace of the crossed cycles; planning and feeding the next run) takes several periods
where a path starts. So the last `LANDING_LEAD_S` of cycles before a planned landing (and
a Python step, a landing of its own) do not wait for their own slots: they run back to
back from the slot of the first of them, and the landing's work has the lead plus a period
before the next cycle's slot. The machine is then at most the lead ahead of the wall
clock; every cycle is the same cycle, only delivered early (as catch-up delivers late).
A run is one chunk of jump.py's feed (`RUN_CYCLES`), so all its Python work is at its
landing.

Because a real-time run takes the same jumps as virtual time (same pieces, same landing
cycles), it gives the same counters, events and histories as the virtual-time run of the
same commands (tests/test_realtime_executor.py, tests/test_realtime_lead.py).

Statistics, per cycle (rings of 65536 cycles): `late` (start against the planned start:
the OS wake-up, or Python work that overran the gap), `lead` (periods planned ahead of
its slot), `busy` (the cycle itself: compiled, or the
Python path, plus the reactions of a landing cycle), `work` (Python between the cycles:
landing, planning and feeding the next pieces; it delays nothing unless it overflows the
gap, which then shows as lateness). `clock.pacer_baseline` measures a no-op pacer the
same way, the OS part of the lateness.

While a compiled run is in progress, the controller's Python state (time, positions) is
that of the run's start (at most `HORIZON_S` old); take `Controller.lock` for current
values (that ends the run at the next cycle boundary).
"""

from __future__ import annotations

import contextlib
import gc
import math
import sys
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

# numpy imports numpy.ma lazily on the first np.unique (a path plan): 50-90 ms inside the
# first landing that plans a path. Imported here, before real time starts.
import numpy.ma  # noqa: F401

from ...errors import MotionError
from .clock import CycleStats, PacedThread
from .jump import FIRST_CHUNK_COMPILED, jump, plan_jump

try:  # the compiled inner loops (setup.py builds them)
    from openmotion import _kernel
except ImportError:  # pragma: no cover - depends on the build
    _kernel = None

if TYPE_CHECKING:
    from .controller import Controller

#: Compiled cycles fed ahead per run (s); a run lands at the latest after this long (each
#: landing costs Python work between two cycles, so few of them). A jump longer than one
#: chunk of pieces (jump.py) is safe to interrupt: the C loop never returns at the first
#: cycle of a kernel run, so a run always lands on a cycle it ran.
HORIZON_S = 1.0
#: Most cycles per compiled run: one chunk of jump.py's feed, so all the Python work of a
#: run (hooks, the trace of the crossed cycles, planning and feeding the next run) is at
#: its landing, which the landing lead (`LANDING_LEAD_S`) covers. None: `HORIZON_S` alone.
RUN_CYCLES: int | None = FIRST_CHUNK_COMPILED
#: How long before its planned landing a compiled run stops waiting for each cycle's slot
#: (s): those last cycles run back to back from the slot of the first of them, so the
#: Python work of the landing (hooks: a path start, a join install) has this long plus a
#: period before the next cycle's slot. The machine then runs at most this far ahead of
#: the wall clock; every cycle is the same, only its delivery is early.
LANDING_LEAD_S = 0.008
#: The landing lead of the first landing after `start_realtime` (s): the first cycle's
#: slot is this long after the start, so the Python work of a start (a program's first
#: feed, its first path) has that time before the cycles that follow.
START_LEAD_S = 0.025
#: Interpreter switch interval while real time runs (s): the executor thread gets the GIL
#: back this soon for the Python work between cycles (CPython's default is 5 ms).
SWITCH_INTERVAL_S = 0.0005
_WINDOW = 65536
# st fields, as in _kernel_rt.c (the C side checks the array's length)
(RT_WALL0, RT_PERIOD, RT_COUNT, RT_WAITERS, RT_STOPPING, RT_PENDING, RT_START, RT_LASTEND,
 RT_OVERRUNS, RT_LATECYC, RT_BEHIND, RT_BURSTS, RT_INBURST, RT_INTERRUPTED, RT_LASTK,
 RT_LASTSTART, RT_LASTOVER, RT_EXTEND, RT_CPU0, RT_LAND, RT_LEAD, RT_DUE,
 RT_NFIELDS) = range(23)
#: The per-cycle rings of the pacing context, in its argument order (after st).
RINGS = ("busy", "late", "work", "cpu", "lead")



def _built_to_match() -> bool:
    """Whether the built extension has the pacing functions this module calls, with its
    context layout (an extension built from older sources would refuse every run): a
    stale build falls back to the Python pacer instead."""
    if _kernel is None or not hasattr(_kernel, "rt_paced"):
        return False
    st = np.zeros(RT_NFIELDS)
    st[RT_PENDING] = -1.0  # nothing pending, no cycle counted: rt_close changes nothing
    try:
        _kernel.rt_close(st, *(np.zeros(1) for _ in RINGS))
    except (TypeError, ValueError):
        return False
    return True


AVAILABLE = _built_to_match()


class HandoverLock:
    """The controller's re-entrant lock. A thread that has to wait for it is counted in
    `st[RT_WAITERS]`, the real-time executor's context, so a compiled run in progress
    returns at the next cycle boundary and hands the lock over."""

    __slots__ = ("_lock", "_count", "_waiting", "st")

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._count = threading.Lock()
        self._waiting = 0
        self.st = np.zeros(RT_NFIELDS)

    def acquire(self, blocking: bool = True, timeout: float = -1) -> bool:
        if self._lock.acquire(False):
            return True
        if not blocking:
            return False
        with self._count:
            self._waiting += 1
            self.st[RT_WAITERS] = self._waiting
        try:
            return self._lock.acquire(True, timeout)
        finally:
            with self._count:
                self._waiting -= 1
                self.st[RT_WAITERS] = self._waiting

    def release(self) -> None:
        self._lock.release()

    def __enter__(self) -> bool:
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self._lock.release()


class RealtimeExecutor(PacedThread):
    """Real time for one controller: compiled cycles paced in C where virtual time would
    jump, `Controller.step` at its slot otherwise (see the module docstring)."""

    def __init__(self, ctl: Controller, on_overrun: Callable[[int, int], None] | None = None
                 ) -> None:
        if not AVAILABLE:
            raise MotionError("the compiled real-time executor is not built "
                              "(python setup.py build_ext --inplace)")
        super().__init__()
        self._ctl = ctl
        self._period = ctl.period
        self._on_overrun = on_overrun
        self.st = ctl._lock.st
        self._busy = np.zeros(_WINDOW)
        self._late = np.zeros(_WINDOW)
        self._work = np.zeros(_WINDOW)
        self._cpu = np.zeros(_WINDOW)
        self._lead = np.zeros(_WINDOW)
        self._errors = 0
        self.python_cycles = 0
        self.compiled_runs = 0
        self._switch = sys.getswitchinterval()

    def _begin(self) -> None:
        st = self.st
        waiting = st[RT_WAITERS]
        st[:] = 0.0
        st[RT_WAITERS] = waiting
        st[RT_PENDING] = -1.0
        st[RT_PERIOD] = self._period
        self._errors = 0
        self.python_cycles = 0
        self.compiled_runs = 0
        self._switch = sys.getswitchinterval()
        sys.setswitchinterval(min(self._switch, SWITCH_INTERVAL_S))
        # the objects alive now (the program, plans, the machine) are never scanned again
        # by a garbage collection, which otherwise runs inside some landing
        gc.collect()
        gc.freeze()

    def _wake(self) -> None:
        self.st[RT_STOPPING] = 1.0  # the C wait returns within 1 ms

    def _end(self) -> None:
        sys.setswitchinterval(self._switch)
        gc.unfreeze()

    def _compiled(self) -> bool:
        paced = getattr(self._ctl.hardware, "paced_cycles", None)
        return paced is not None and bool(paced())

    def _run(self) -> None:
        ctl = self._ctl
        k = _kernel
        assert k is not None
        ctx = (self.st, self._busy, self._late, self._work, self._cpu, self._lead)
        st = self.st
        horizon = math.ceil(HORIZON_S / self._period - 1e-9)
        horizon = max(2, horizon if RUN_CYCLES is None else min(horizon, RUN_CYCLES))
        lead = max(0, math.ceil(LANDING_LEAD_S / self._period - 1e-9))
        # the first landing (a program's first feed and path start) may use START_LEAD_S
        first = st[RT_LEAD] = max(lead, math.ceil(START_LEAD_S / self._period - 1e-9))
        # cycle j's slot starts at wall0 + j * period; cycle n + 1 may start now: its slot
        # is `first` periods on (the first landing's lead)
        st[RT_WALL0] = k.rt_now() - (ctl._n + 1 - first) * self._period
        bursts = 0.0
        try:
            while not self._stop.is_set():
                st[RT_INTERRUPTED] = 0.0
                with ctl._lock:
                    n1 = ctl._n + 1
                    if not (self._compiled() and self._guarded(ctx, horizon, n1)) \
                            and not self._slot(ctx, n1):
                        self.python_cycles += 1
                        ctl.step()
                    k.rt_close(*ctx)  # a landing cycle's reactions count in its busy time
                    st[RT_LEAD] = lead  # the first landing is over
                    if st[RT_BURSTS] > bursts:
                        bursts = st[RT_BURSTS]
                        if self._on_overrun is not None:
                            self._on_overrun(int(st[RT_OVERRUNS]), int(st[RT_BEHIND]))
                if st[RT_INTERRUPTED] or st[RT_WAITERS] > 0:
                    k.rt_yield(*ctx)  # another thread waits for the lock: let it in
        except BaseException as exc:  # surfaced by stop_realtime, never silently dropped
            self.error = exc

    def _slot(self, ctx: tuple, n1: int) -> bool:
        """Wait for the slot of cycle n1, a Python step (a landing of its own: it may start
        up to RT_LEAD periods ahead); True when interrupted instead (rt_wait)."""
        st = self.st
        st[RT_LAND] = n1
        try:
            return bool(_kernel.rt_wait(*ctx, n1))  # type: ignore[union-attr]
        finally:
            st[RT_LAND] = 0.0

    def _guarded(self, ctx: tuple, horizon: int, n1: int) -> bool:
        """A compiled run to the cycle where the jump lands (at most `horizon` ahead);
        False when the next cycle must run on its own. Nothing escapes it (as
        `Controller._run_cycles`)."""
        ctl = self._ctl
        try:
            land = plan_jump(ctl, horizon)
            if land <= n1:
                return False
            self.compiled_runs += 1
            self.st[RT_LAND] = land  # its last RT_LEAD cycles run ahead (the module doc)
            try:
                _kernel.rt_paced(*ctx, jump, (ctl, land))  # type: ignore[union-attr]
            finally:
                self.st[RT_LAND] = 0.0
        except Exception as err:  # the cycle must go on: safety reactions run in it
            self._errors += 1
            for ax in ctl.axes:  # nothing half-queued stays behind
                with contextlib.suppress(Exception):
                    ctl.hardware.clear_queue(ax.index)  # type: ignore[attr-defined]
            ctl._cycle_failed(max(n1, ctl._n + 1), err)
        return True

    def stats(self) -> CycleStats:
        st = self.st
        count = int(st[RT_COUNT])
        n = min(count, _WINDOW)
        if n == 0:
            return CycleStats(0, self._period, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0,
                              0, 0, self._errors,
                              executor="compiled")
        busy, late, work, cpu = self._busy[:n], self._late[:n], self._work[:n], self._cpu[:n]
        rings = self.samples()
        return CycleStats(
            cycles=count,
            period=self._period,
            mean_busy=float(busy.mean()),
            p99_busy=float(np.percentile(busy, 99)),
            max_busy=float(busy.max()),
            mean_jitter=float(late.mean()),
            p99_jitter=float(np.percentile(late, 99)),
            max_jitter=float(late.max()),
            overruns=int(st[RT_OVERRUNS]),
            late=int(st[RT_LATECYC]),
            behind=int(st[RT_BEHIND]),
            errors=self._errors,
            mean_work=float(work.mean()),
            p99_work=float(np.percentile(work, 99)),
            max_work=float(work.max()),
            python_cycles=self.python_cycles,
            executor="compiled",
            own_overruns=_own_overruns(rings, self._period),
            p99_cpu=float(np.percentile(cpu, 99)),
            max_cpu=float(cpu.max()),
            own_cpu_overruns=_own_overruns(rings, self._period, "cpu"),
        )

    def samples(self) -> dict[str, np.ndarray]:
        """The per-cycle rings in cycle order (the last 65536 cycles at most): busy, late,
        work, cpu (seconds) and lead (periods the cycle ran ahead of its slot: the last
        cycles before a landing, `LANDING_LEAD_S`)."""
        count = int(self.st[RT_COUNT])
        n = min(count, _WINDOW)
        order = np.arange(count - n, count) % _WINDOW
        return {"busy": self._busy[order].copy(), "late": self._late[order].copy(),
                "work": self._work[order].copy(), "cpu": self._cpu[order].copy(),
                "lead": self._lead[order].copy()}


def _own_overruns(rings: dict[str, np.ndarray], period: float, by: str = "busy") -> int:
    """Cycles after which the controller alone started the next cycle after its slot: each
    cycle started when planned (its slot, or up to `lead` periods earlier: the last
    cycles before a landing), or when the controller's own work before it ended, if later
    - no OS lateness - and took its busy time plus the Python work before the next cycle
    (by="cpu": the thread's CPU time for both). The first cycle of the rings starts when
    planned."""
    own = rings[by].copy()
    m = len(own)
    if not m:
        return 0
    if by == "busy":
        own[:-1] += rings["work"][1:]
    k = np.arange(m, dtype=float)
    due = (k - rings["lead"]) * period  # from the first cycle's slot
    # start[k] = max(due[k], start[k-1] + own[k-1]), in closed form (max-plus prefix)
    spent = np.concatenate(([0.0], np.cumsum(own[:-1])))
    start = spent + np.maximum.accumulate(due - spent)
    return int(np.count_nonzero(start + own > (k + 1.0) * period * (1.0 + 1e-12)))
