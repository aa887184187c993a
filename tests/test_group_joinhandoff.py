"""The bounded handoff of a join planned off the cycle (control/groups/joinhandoff.py): the
install cycle never waits more than JOIN_WAIT_CYCLES periods, then computes the join
itself; a stalled worker is not waited for at all; a cancelled job is dropped by the
worker. Fake jobs, no threads, no real time."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any

from openmotion.control.groups import joinhandoff


class _Done(threading.Event):
    """An event that records the waits (and never becomes set by itself)."""

    def __init__(self) -> None:
        super().__init__()
        self.waits: list[float] = []

    def wait(self, timeout: float | None = None) -> bool:
        self.waits.append(timeout)  # type: ignore[arg-type]
        return self.is_set()


@dataclass
class _Job:
    compute: Any = None
    queued: bool = True
    cancelled: bool = False
    done: _Done = field(default_factory=_Done)
    result: Any = None
    error: BaseException | None = None


def _job(value: Any = "plan") -> _Job:
    calls: list[bool] = []

    def compute(stop):  # noqa: ANN001, ANN202
        calls.append(stop())
        return value

    job = _Job(compute=compute)
    job.calls = calls  # type: ignore[attr-defined]
    return job


def test_a_finished_worker_is_taken_as_it_is():
    job = _job()
    job.done.set()
    job.result = "worker plan"
    assert joinhandoff.collect(job, 0.001, False) == ("worker", "worker plan")
    assert job.calls == [] and not job.cancelled


def test_a_worker_not_done_is_waited_for_a_few_cycles_then_the_cycle_computes():
    job = _job()
    assert joinhandoff.collect(job, 0.001, False) == ("cycle", "plan")
    assert job.done.waits == [joinhandoff.JOIN_WAIT_CYCLES * 0.001]  # one bounded wait
    assert job.cancelled and job.calls == [False]  # computed to the end, here


def test_a_stalled_worker_is_not_waited_for():
    job = _job()
    assert joinhandoff.collect(job, 0.001, True) == ("cycle", "plan")
    assert job.done.waits == [] and job.cancelled
    unqueued = _job()
    unqueued.queued = False
    assert joinhandoff.collect(unqueued, 0.001, False) == ("cycle", "plan")
    assert unqueued.done.waits == []
    assert joinhandoff.worker_stalled(job) and not joinhandoff.worker_stalled(None)
    job.done.set()
    assert not joinhandoff.worker_stalled(job)


def test_failures_are_reported_not_raised():
    job = _job()
    job.done.set()
    job.error = RuntimeError("worker bug")
    assert joinhandoff.collect(job, 0.001, False) == ("failed", None)
    bad = _job()
    bad.queued = False

    def broken(stop):  # noqa: ANN001, ANN202
        raise ValueError("planner bug")

    bad.compute = broken
    assert joinhandoff.collect(bad, 0.001, False) == ("failed", None)


def test_the_worker_drops_a_cancelled_job_and_reports_errors():
    job = _job()
    job.cancelled = True
    joinhandoff.run_on_worker(job, job.compute)
    assert job.done.is_set() and job.result is None and job.calls == []
    job = _job()
    joinhandoff.run_on_worker(job, job.compute)
    assert job.done.is_set() and job.result == "plan"
    job = _job()

    def broken(stop):  # noqa: ANN001, ANN202
        raise RuntimeError("worker bug")

    joinhandoff.run_on_worker(job, broken)
    assert job.done.is_set() and isinstance(job.error, RuntimeError)
