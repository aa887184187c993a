"""Real time on the compiled executor (control/core/realtime.py, _kernel_rt.c).

A real-time run takes the jumps virtual time takes (paced to the wall clock in C), so it
must give exactly what the virtual-time run of the same commands gives: counters, states,
events with their exact times (a limit edge, an E-stop: the same stop instant), histories,
every pulse. Only timing-independent facts are asserted: which path ran the cycles, never
how long anything took (the `overrun` events a loaded machine may record are left out of
the comparison).
"""

from __future__ import annotations

import threading
import time
from dataclasses import replace

import numpy as np
import pytest

from openmotion.config import MachineConfig, SwitchConfig, default_machine
from openmotion.control import Controller
from openmotion.control.core import realtime
from openmotion.control.core.realtime import RT_WAITERS, HandoverLock, RealtimeExecutor

pytestmark = pytest.mark.skipif(not realtime.AVAILABLE, reason="the kernel is not built")

WAIT = 60.0  # generous: a loaded CI machine may run the wall clock slowly for us


def _machine(servo: bool = False) -> MachineConfig:
    x = default_machine().axes[0]
    axes = []
    for i, name in enumerate("xyzu"):
        kw: dict = {}
        if i == 0:
            kw["pel"] = SwitchConfig(position=30_000.0, width=500.0)
        if servo and i == 1:
            kw["drive"] = replace(x.drive, type="servo")
        axes.append(replace(x, name=name, **kw))
    return MachineConfig(name="rt", axes=tuple(axes), digital_inputs=2)


def _setup(ctl: Controller, scenario: str) -> None:
    hw = ctl.hardware
    hw.record_pulses()
    ctl.enable_all()
    ctl.axis("x").move_relative(60_000, max_vel=80_000, tacc=0.05)  # runs into PEL
    ctl.axis("y").move_relative(-7_000, max_vel=30_000, tacc=0.02, str_vel=500.0)
    ctl.axis("z").move_relative(12_345, max_vel=50_000, tacc=0.1)
    ctl.axis("u").move_velocity(-4_000, tacc=0.03)
    if scenario == "recorder":  # the recorder rows of the crossed cycles come from C
        ctl.start_recording(capacity=700)
        hw.scenario.press_estop(at=0.4567)
    elif scenario == "estop":
        hw.scenario.press_estop(at=0.317)
    else:
        hw.scenario.inject_step_loss(2, 17, at=0.2113)
        hw.scenario.set_input("di1", True, at=0.05)


def _observe(ctl: Controller) -> tuple:
    hw = ctl.hardware
    axes = tuple((a.state, a.fault, a.position, a.velocity, a.motion_done,
                  a.counters.snapshot()) for a in ctl.axes)
    events = tuple((e.time, e.kind, e.axis, e.position, e.detail) for e in ctl.events.events()
                   if e.kind != "overrun")
    hist = tuple(tuple(np.concatenate([v.ravel() for v in ctl.history.records(i).values()])
                       .tolist()) for i in range(len(ctl.axes)))
    pulses = tuple(tuple(map(tuple, (t.tolist(), c.tolist())))
                   for t, c in (hw.pulse_record(i).pulses() for i in range(len(ctl.axes))))
    rec = ctl.recorder
    rows = None if rec is None else (len(rec), rec.total, tuple(
        (k, v.tobytes()) for k, v in rec.arrays().items()))
    return ctl.time, ctl.cycles, axes, events, tuple(ctl.safety.stops), hist, pulses, rows


def _realtime_run(ctl: Controller, cycles: int) -> None:
    with ctl.start_realtime():
        deadline = time.monotonic() + WAIT
        while ctl.cycles < cycles and time.monotonic() < deadline:
            time.sleep(0.01)
    assert ctl.cycles >= cycles, "the real-time run did not get there in time"


@pytest.mark.parametrize("scenario", ["estop", "limit", "recorder"])
def test_a_realtime_run_gives_the_virtual_time_result(scenario):
    rt = Controller(_machine())
    _setup(rt, scenario)
    _realtime_run(rt, 600)
    ex = rt._pacer
    assert isinstance(ex, RealtimeExecutor)
    assert ex.compiled_runs > 0  # the cycles ran compiled, paced in C
    vt = Controller(_machine())
    _setup(vt, scenario)
    vt.advance(rt.cycles * vt.period)
    assert vt.cycles == rt.cycles
    assert _observe(rt) == _observe(vt)
    kinds = {e.kind for e in rt.events.events()}
    assert ("fault" in kinds or "limit" in kinds or "estop" in kinds) or rt.axes[0].fault


def test_stats_count_every_cycle_once():
    ctl = Controller(_machine())
    _setup(ctl, "limit")
    _realtime_run(ctl, 300)
    s = ctl.cycle_stats()
    assert s.executor == "compiled"
    assert s.cycles == ctl.cycles
    assert s.python_cycles < s.cycles
    assert s.p99_busy <= s.max_busy and s.p99_work <= s.max_work
    assert 0 <= s.overruns <= s.cycles and s.errors == 0
    assert 0 <= s.own_overruns <= s.cycles
    samples = ctl.cycle_samples()
    assert len(samples["busy"]) == len(samples["cpu"]) == s.cycles
    assert np.all(samples["late"] >= 0.0) and np.all(samples["busy"] >= 0.0)
    # the thread's CPU time per cycle (and the work after it): measured, never negative
    assert np.all(samples["cpu"] >= 0.0) and samples["cpu"].sum() > 0.0
    assert s.p99_cpu <= s.max_cpu and 0 <= s.own_cpu_overruns <= s.cycles


def test_a_per_cycle_hook_falls_back_to_python_steps():
    ctl = Controller(_machine())
    seen: list[float] = []
    ctl.add_cycle_hook(lambda c, t: seen.append(t))  # no due: every cycle needs Python
    _setup(ctl, "limit")
    _realtime_run(ctl, 200)
    s = ctl.cycle_stats()
    assert ctl._pacer.compiled_runs == 0
    assert s.python_cycles == s.cycles == ctl.cycles == len(seen)


def test_a_servo_machine_steps_in_python_with_the_same_result():
    rt = Controller(_machine(servo=True))
    assert not rt.hardware.paced_cycles()
    _setup(rt, "limit")
    _realtime_run(rt, 200)
    assert rt._pacer.compiled_runs == 0
    assert rt.cycle_stats().python_cycles == rt.cycles
    vt = Controller(_machine(servo=True))
    _setup(vt, "limit")
    vt.advance(rt.cycles * vt.period)
    assert _observe(rt) == _observe(vt)


def test_commands_from_another_thread_take_effect_and_end_exactly():
    ctl = Controller(_machine())
    ctl.enable_all()
    ax = ctl.axis("z")
    with ctl.start_realtime():
        with ctl.lock:
            ax.move_velocity(20_000, tacc=0.01)
        time.sleep(0.05)
        with ctl.lock:
            ax.stop()
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            with ctl.lock:  # each look hands the lock over at a cycle boundary
                if ax.motion_done == 0:
                    break
            time.sleep(0.005)
        with ctl.lock:
            ax.move_absolute(5_000, max_vel=40_000, tacc=0.02)
        while time.monotonic() < deadline:
            with ctl.lock:
                if ax.motion_done == 0:
                    break
            time.sleep(0.005)
    assert ax.motion_done == 0
    assert ax.counters.command == ax.counters.feedback == 5_000
    assert ctl.cycle_stats().errors == 0


def test_the_lock_counts_the_threads_waiting_for_it():
    lock = HandoverLock()
    held, go = threading.Event(), threading.Event()

    def holder() -> None:
        with lock:
            held.set()
            go.wait(WAIT)

    t = threading.Thread(target=holder)
    t.start()
    held.wait(WAIT)
    w = threading.Thread(target=lambda: lock.acquire() and lock.release())
    w.start()
    deadline = time.monotonic() + WAIT
    while lock.st[RT_WAITERS] < 1 and time.monotonic() < deadline:
        time.sleep(0.001)
    assert lock.st[RT_WAITERS] == 1
    assert not lock.acquire(blocking=False)
    go.set()
    t.join()
    w.join()
    assert lock.st[RT_WAITERS] == 0
    with lock, lock:  # re-entrant
        pass


def test_the_python_pacer_is_still_there_on_request():
    ctl = Controller(_machine())
    ctl.compiled_realtime = False
    _setup(ctl, "limit")
    _realtime_run(ctl, 100)
    s = ctl.cycle_stats()
    assert s.executor == "python" and s.python_cycles == s.cycles == ctl.cycles
    rings = ctl.cycle_samples()
    assert len(rings["busy"]) == len(rings["cpu"]) == s.cycles and rings["cpu"].sum() > 0.0
    assert 0 <= s.own_cpu_overruns <= s.cycles


def test_a_failure_inside_a_compiled_run_faults_and_real_time_goes_on():
    ctl = Controller(_machine())
    ctl.enable_all()
    hw = ctl.hardware
    real = hw.run_cycles
    calls = [0]

    def failing(*a, **k):  # noqa: ANN002, ANN003, ANN202
        calls[0] += 1
        if calls[0] == 1:
            raise RuntimeError("back end failed")
        return real(*a, **k)

    hw.run_cycles = failing
    ctl.axis("z").move_relative(50_000, max_vel=40_000, tacc=0.05)
    _realtime_run(ctl, 100)
    z = ctl.axis("z")
    assert z.fault is not None and "cycle error" in z.fault
    assert ctl.cycle_errors == 1 and ctl.cycle_stats().errors == 1
    assert [e.kind for e in ctl.events.events()].count("cycle_error") == 1
    assert hw.queued(2) == 0  # nothing half-queued stays behind


def test_a_request_at_the_first_cycle_of_a_later_chunk_lands_on_a_cycle_run(monkeypatch):
    """A compiled run over the horizon is fed in chunks (jump.py); the C loop never returns
    at the first cycle of a kernel run, so a lock request arriving just as a later chunk
    starts lands after that chunk's first cycle, with the virtual-time result. (Runs are
    one chunk by default, `realtime.RUN_CYCLES`; here they span the whole horizon.)"""
    monkeypatch.setattr(realtime, "RUN_CYCLES", None)
    def setup(ctl: Controller) -> None:
        ctl.hardware.record_pulses()
        ctl.enable_all()
        ctl.axis("z").move_relative(150_000, max_vel=60_000, tacc=0.05)  # 2.5 s: no end
        ctl.axis("u").move_velocity(-4_000, tacc=0.03)

    rt = Controller(_machine())
    setup(rt)
    hw, st = rt.hardware, rt._lock.st
    real = hw.run_cycles
    forced: list[tuple[int, int]] = []

    def waiter_at_later_chunks(origin, period, n, stop, *a, **k):  # noqa: ANN001, ANN002, ANN003, ANN202
        later = n > rt._n  # not the first chunk of this jump
        if later:
            st[RT_WAITERS] = 1.0  # a thread waits for the lock from this chunk's start on
        try:
            run = real(origin, period, n, stop, *a, **k)
        finally:
            st[RT_WAITERS] = 0.0
        if later:
            forced.append((n, run.cycle))
        return run

    hw.run_cycles = waiter_at_later_chunks
    _realtime_run(rt, 900)
    assert forced and all(c == n + 1 for n, c in forced)  # the chunk's first cycle ran
    vt = Controller(_machine())
    setup(vt)
    vt.advance(rt.cycles * vt.period)
    assert _observe(rt) == _observe(vt)
