"""The handoff of a join planned off the cycle to the cycle that installs it (real time).

A join in flight (groupjoin.py) is a pure computation: the running plan re-planned from
the cycle boundary t_j with the commands taken off the queue, from inputs captured when it
was launched. Whoever computes it - the worker thread or the install cycle itself - gets
the very same plan and profiles, so the motion never depends on the thread schedule.

That is what makes the install cycle's wait safe to bound. A controller's cycle must never
wait long for another thread: while it waits, no E-stop, limit or other axis is served. So
the install cycle waits for an unfinished worker at most `JOIN_WAIT_CYCLES` periods, then
computes the join itself (the job is cancelled: the worker drops it at its next option).
A worker still busy with a job whose wait ran out is *stalled*; joins launched while it
is stalled are not queued to it, and their install cycles compute them at once, without
waiting (a worker that never finishes costs one bounded wait, not one per join). Those
joins count as `late_joins`; they are not misses, since the result is the same.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

#: How long (controller periods) the install cycle waits for a worker not yet done before it
#: computes the join itself.
JOIN_WAIT_CYCLES = 5


def worker_stalled(stuck: Any) -> bool:
    """Whether the worker still runs `stuck`, a job whose install stopped waiting for it
    (None: none did)."""
    return stuck is not None and not stuck.done.is_set()


def run_on_worker(job: Any, compute: Callable[[Callable[[], bool]], Any]) -> None:
    """The worker's part: the result (or the error) of `compute`, unless the job was
    cancelled first; `compute(stop)` gives up early (None) once `stop()` is true."""
    try:
        if not job.cancelled:
            job.result = compute(lambda: job.cancelled)
    except BaseException as exc:  # reported at install: the join is a miss
        job.error = exc
    finally:
        job.done.set()


def collect(job: Any, period: float, stalled: bool) -> tuple[str, Any]:
    """At the install cycle: the join's outcome, never waiting more than JOIN_WAIT_CYCLES
    periods. ("worker", result): the worker finished (result None: no feasible join
    option); ("failed", None): the worker raised; ("cycle", result): computed here, the
    worker being late or stalled (the same result it would have given)."""
    if not job.queued:
        return _in_cycle(job)
    if not job.done.is_set() and not stalled:
        job.done.wait(JOIN_WAIT_CYCLES * period)
    if job.done.is_set() and not job.cancelled:
        return ("failed", None) if job.error is not None else ("worker", job.result)
    job.cancelled = True  # the worker drops it (at its next option, or before it starts)
    return _in_cycle(job)


def _in_cycle(job: Any) -> tuple[str, Any]:
    try:
        return "cycle", job.compute(lambda: False)
    except Exception:  # as a worker's failure: a miss, the commands go back to the queue
        return "failed", None
