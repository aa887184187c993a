"""The controller clock: one cycle function, paced either by the caller (virtual time) or
by a thread against the wall clock (real time), with cycle-time statistics.

Virtual time is the cycle count times the period (no float accumulation, so cycle n always
ends at exactly n * period). Real time runs the same cycle function; it records, per cycle,
how late the cycle started against its schedule (jitter) and how long it took, in a ring
buffer of fixed size, so statistics cost flat memory however long it runs.

Falling behind: motion time is never skipped. A cycle that ends after the next one was due
is an overrun; the cycles whose slot passed meanwhile are not dropped but run back to back
as soon as possible (catch-up), each counted as late (`CycleStats.late`), until the
schedule is met again; `behind` is the most slots the pacer was ever behind. So the motion
keeps its exact time (cycle n is always the motion of [(n-1)T, nT]); only its delivery to
the hardware is late. `on_overrun(count, behind)` is called at the first overrun of each
burst (the controller records an `overrun` event).
"""

from __future__ import annotations

import threading
import time as _time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...errors import MotionError, check_finite

PERIOD_MIN = 0.001
PERIOD_MAX = 1.0
_STATS_WINDOW = 65536


def check_period(period: float) -> float:
    """Interpolation period in seconds: 1 ms .. 1000 ms (the MCCL range)."""
    p = check_finite("period", period)
    if not PERIOD_MIN - 1e-15 <= p <= PERIOD_MAX:
        raise MotionError(f"period must be in [0.001, 1] s (1..1000 ms), got {period!r}")
    return p


@dataclass(frozen=True)
class CycleStats:
    """Real-time cycle statistics over the last (up to 65536) cycles, in seconds.

    jitter = start lateness against the schedule; busy = time spent inside the cycle;
    overruns = cycles that ended after the next cycle was due; late = cycles started after
    their whole slot had passed (run in catch-up, never skipped); behind = the most slots
    the pacer was behind at once; errors = cycles that raised (counted over the whole run).
    With the compiled executor (control/core/realtime.py, executor "compiled"): work = the
    Python work between cycles (landing, feeding the pieces ahead), python_cycles = cycles
    stepped in Python because nothing could be jumped (the fallback). own_overruns = cycles
    whose own busy time plus the Python work before the next one exceeded the time to the
    next cycle's slot: the overruns the controller causes by itself, with the OS's wake-up
    lateness left out (wall time: a thread preempted inside counts). The compiled executor
    counts from each cycle's planned start (its slot, or up to the landing lead earlier for
    the last cycles before a landing, which run ahead: realtime.LANDING_LEAD_S), or the
    end of the controller's own work before it if later. cpu = the real-time thread's CPU
    time for a cycle and the work after it, up to the wait for the next one (what the
    controller itself costs, preemption left out); own_cpu_overruns = the same count from
    that CPU time: the overruns the controller would cause on a machine of its own.
    """

    cycles: int
    period: float
    mean_busy: float
    p99_busy: float
    max_busy: float
    mean_jitter: float
    p99_jitter: float
    max_jitter: float
    overruns: int
    late: int = 0
    behind: int = 0
    errors: int = 0
    mean_work: float = 0.0
    p99_work: float = 0.0
    max_work: float = 0.0
    python_cycles: int = 0
    executor: str = "python"
    own_overruns: int = 0
    p99_cpu: float = 0.0
    max_cpu: float = 0.0
    own_cpu_overruns: int = 0


class PacedThread:
    """The life cycle both real-time executors share (`RealtimePacer` here, the compiled
    `realtime.RealtimeExecutor`): one daemon thread named "openmotion-rt" runs `_run`
    until `stop()`; `error` keeps what ended it (surfaced by the caller, never dropped).
    `_begin` runs before the thread starts, `_end` after it has ended."""

    def __init__(self) -> None:
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.error: BaseException | None = None

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> None:
        if self.running:
            raise MotionError("real-time mode is already running")
        self._stop.clear()
        self.error = None
        self._begin()
        self._thread = threading.Thread(target=self._run, name="openmotion-rt", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
            self._end()

    def _begin(self) -> None:
        """Reset the statistics and settings of a new run (before the thread starts)."""

    def _wake(self) -> None:
        """Make a thread waiting for its next slot see the stop request at once."""

    def _end(self) -> None:
        """Undo what `_begin` set (the thread has ended)."""

    def _run(self) -> None:  # pragma: no cover - each executor has its own
        raise NotImplementedError


class RealtimePacer(PacedThread):
    """Runs `cycle()` every `period` seconds of wall clock on a daemon thread."""

    def __init__(self, cycle: Callable[[], None], period: float,
                 on_overrun: Callable[[int, int], None] | None = None) -> None:
        super().__init__()
        self._cycle = cycle
        self._period = period
        self._on_overrun = on_overrun
        self._late_cycles = 0
        self._behind = 0
        self._errors = 0
        self._busy = np.zeros(_STATS_WINDOW)
        self._late = np.zeros(_STATS_WINDOW)
        self._cpu = np.zeros(_STATS_WINDOW)
        self._n = 0
        self._overruns = 0

    def _run(self) -> None:
        clock, cpu = _time.perf_counter, _time.thread_time
        period = self._period
        t_next = clock()
        in_burst = False
        try:
            while not self._stop.is_set():
                now = clock()
                if now < t_next:
                    # Plain sleep, no spinning: a spin would hold the GIL against the
                    # threads that issue commands. Linux wakes within ~0.1 ms.
                    _time.sleep(t_next - now)
                    now = clock()
                start, cpu0 = now, cpu()
                if start - t_next >= period:  # this cycle's slot passed: catch-up
                    self._late_cycles += 1
                try:
                    self._cycle()
                except Exception as exc:  # the cycle guards itself; never let it die
                    self.error = exc
                    self._errors += 1
                end = clock()
                i = self._n % _STATS_WINDOW
                self._cpu[i] = cpu() - cpu0
                self._late[i] = start - t_next
                self._busy[i] = end - start
                self._n += 1
                t_next += period  # never skip a slot: motion time stays exact
                if end > t_next:
                    self._overruns += 1
                    behind = int((end - t_next) // period) + 1
                    self._behind = max(self._behind, behind)
                    if not in_burst and self._on_overrun is not None:
                        self._on_overrun(self._overruns, behind)
                    in_burst = True
                else:
                    in_burst = False
        except BaseException as exc:  # surfaced by stop()/stats, never silently dropped
            self.error = exc

    def samples(self) -> dict[str, np.ndarray]:
        """The per-cycle rings in cycle order (s): busy, late (start lateness) and cpu
        (the thread's CPU time in the cycle)."""
        return {"busy": _ring(self._busy, self._n), "late": _ring(self._late, self._n),
                "cpu": _ring(self._cpu, self._n)}

    def stats(self) -> CycleStats:
        n = min(self._n, _STATS_WINDOW)
        if n == 0:
            return CycleStats(0, self._period, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0,
                              0, 0, self._errors)
        busy = self._busy[:n]
        late = self._late[:n]
        cpu = self._cpu[:n]
        return CycleStats(
            cycles=self._n,
            period=self._period,
            mean_busy=float(busy.mean()),
            p99_busy=float(np.percentile(busy, 99)),
            max_busy=float(busy.max()),
            mean_jitter=float(late.mean()),
            p99_jitter=float(np.percentile(late, 99)),
            max_jitter=float(late.max()),
            overruns=self._overruns,
            late=self._late_cycles,
            behind=self._behind,
            errors=self._errors,
            python_cycles=self._n,
            own_overruns=int(np.count_nonzero(busy > self._period)),
            p99_cpu=float(np.percentile(cpu, 99)),
            max_cpu=float(cpu.max()),
            own_cpu_overruns=int(np.count_nonzero(cpu > self._period)),
        )


def _ring(buf: np.ndarray, count: int) -> np.ndarray:
    """A stats ring's last min(count, len) values in the order they were written."""
    n = min(count, len(buf))
    return buf[np.arange(count - n, count) % len(buf)].copy()


def pacer_baseline(period: float, seconds: float) -> CycleStats:
    """Statistics of a pacer running a no-op cycle for `seconds` of wall clock at `period`:
    the operating system's own wake-up lateness on this machine, measured the same way as
    the controller's real-time cycle. Compare its jitter with `Controller.cycle_stats()`
    to tell OS lateness from the controller's busy time (the busy figures here are the
    pacer's bookkeeping floor)."""
    period = check_period(period)
    seconds = check_finite("seconds", seconds)
    if not 0.0 < seconds <= 3600.0:
        raise MotionError(f"seconds must be in (0, 3600], got {seconds!r}")
    pacer = RealtimePacer(lambda: None, period)
    pacer.start()
    _time.sleep(seconds)
    pacer.stop()
    return pacer.stats()
