"""Joins planned off the real-time cycle (control/groups/groupjoin.py): a streamed program in
real-time mode ends exactly, never rests inside, keeps its limits, and its join re-plans
run on the worker thread - the same joins in every run, whatever the thread schedule;
hold, override and abort while a join is in flight keep the queue and the path
consistent; a late, stalled or failing worker falls back to joins in the cycle, and a late
or stalled one changes nothing in the motion.

Real time on a shared machine: generous timeouts, no wall-clock asserts."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups import groupjoin, pathrun
from openmotion.control.groups.group import Group, GroupState

FEED, ACC_TIME, PPU = 40.0, 0.05, 1000.0  # mm/s, s, pulses/mm (lead 10 mm, 10000 ppr)
N = 300


def _setup(n: int = N, shape: str = "") -> tuple[Controller, Group, list[tuple[float, float]],
                                                dict]:
    """n short blended segments (0.05 mm, 1.25 ms each at the feed), fed a few per cycle
    by a cycle hook; `info` counts the cycles the path rested while moving."""
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xy")
    ctl = Controller(MachineConfig(name="rtjoin", axes=axes))
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], units=True, feed=FEED, acc_time=ACC_TIME, queue_size=1024)
    g.enable_blend(0.005)
    if shape == "corner":
        g.set_corner_velocity(5.0)
    elif shape == "S":
        g.set_path_shape("S", jerk=40_000.0)  # tj = 20 ms
    pts = [(0.05 * k, 0.5 * math.sin(k / 15.0)) for k in range(1, n + 1)]
    it = iter(pts)
    info = {"rests": 0, "fed": 0, "stop": False}

    def feed(c: Controller, t: float) -> None:
        for _ in range(3):
            p = next(it, None) if g.queue_length < 256 and not info["stop"] else None
            if p is None:
                return
            g.line(p)
            info["fed"] += 1

    def watch(c: Controller, t: float) -> None:
        if g.state is GroupState.MOVING and (g.queue_length or g._job is not None) \
                and not any(a.is_moving for a in g.axes):
            info["rests"] += 1

    ctl.add_cycle_hook(feed)
    ctl.add_cycle_hook(watch)
    return ctl, g, pts, info


def _wait(ctl: Controller, cond: Callable[[], bool], timeout: float = 60.0) -> bool:
    """Poll `cond` under the controller lock while real time runs."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        with ctl.lock:
            if cond():
                return True
        time.sleep(0.001)
    return False


def _done(g: Group) -> Callable[[], bool]:
    return lambda: (g.state in (GroupState.IDLE, GroupState.ERROR) and g.queue_length == 0
                    and g._job is None and not any(a.is_moving for a in g.axes))


def _ends_exactly(g: Group, end: tuple[float, float]) -> None:
    assert [a.position for a in g.axes] == [e * PPU for e in end]  # bit for bit
    assert not any(a.is_moving for a in g.axes)


def _check_limits(ctl: Controller, g: Group) -> None:
    """The recorded motion keeps the path feed and a bounded acceleration on every axis."""
    t = np.linspace(0.0, ctl.time, 40_001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    assert np.hypot(sx.v, sy.v).max() <= FEED * PPU * (1.0 + 1e-6)
    a_max = FEED / ACC_TIME * PPU
    assert max(np.abs(sx.a).max(), np.abs(sy.a).max()) <= math.sqrt(1.75) * a_max * 1.01


def _replan_threads(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Names of the threads each join re-plan (one that gets a longer chain) ran on."""
    names: list[str] = []
    orig = pathrun.replan

    def replan(plan, t, *, chain=None, limits=None, hold=False):  # noqa: ANN001, ANN202
        if chain is not None and chain is not plan.chain:
            names.append(threading.current_thread().name)
        return orig(plan, t, chain=chain, limits=limits, hold=hold)

    monkeypatch.setattr(pathrun, "replan", replan)
    return names


#: A stream's joins go to the worker whenever its chain does not end within the worker's
#: lead: only the controller's state decides. The install cycle waits a few cycles for a
#: worker not yet done, then computes the same join itself (joinhandoff.py), so the same
#: stream gives the same motion however the threads are scheduled; only who computed a
#: join (async_joins / late_joins) may differ.


def _positions(ctl: Controller, g: Group, t_end: float) -> np.ndarray:
    t = np.linspace(0.0, t_end, 4001)
    return np.stack([ctl.history.sample(a.index, t).p for a in g.axes])


@pytest.mark.parametrize("shape", ["", "corner", "S"])
def test_streamed_program_joins_on_the_worker(monkeypatch, shape):
    names = _replan_threads(monkeypatch)
    ctl, g, pts, info = _setup(shape=shape)
    with ctl.start_realtime():
        assert _wait(ctl, lambda: info["fed"] == N and _done(g)())
    assert g.state is GroupState.IDLE and g.error_code == 0
    _ends_exactly(g, pts[-1])
    assert info["rests"] == 0  # the path never stopped inside
    # every join but those of the first short chain (it ends within the lead) and of a
    # miss (no feasible join option) was launched for the worker
    assert g.async_joins + g.late_joins >= 3 and g.sync_joins <= 2
    assert "openmotion-join" in names and names.count("openmotion-join") >= g.async_joins
    _check_limits(ctl, g)
    g.close()


def test_the_worker_carries_the_same_joins_in_every_run():
    runs = []
    for _ in range(2):
        ctl, g, pts, info = _setup()
        with ctl.start_realtime():
            assert _wait(ctl, lambda g=g, info=info: info["fed"] == N and _done(g)())
        _ends_exactly(g, pts[-1])
        runs.append((ctl, g, g.async_joins + g.late_joins, g.sync_joins, g._join_misses))
        g.close()
    (c1, g1, *n1), (c2, g2, *n2) = runs
    assert n1 == n2 and n1[0] >= 3
    t_end = min(c1.time, c2.time)
    np.testing.assert_array_equal(_positions(c1, g1, t_end), _positions(c2, g2, t_end))


def test_virtual_time_never_uses_the_worker(monkeypatch):
    names = _replan_threads(monkeypatch)
    ctl, g, pts, info = _setup(150)
    assert ctl.run_until(lambda: info["fed"] == 150 and _done(g)(), 30.0)
    _ends_exactly(g, pts[-1])
    assert names and set(names) == {threading.current_thread().name}
    assert g.async_joins == 0 and g._jobs is None


def _in_flight(ctl: Controller, g: Group, info: dict, action: Callable[[], object]) -> object:
    """Run `action()` in the first cycle with a join in flight once the stream is well under
    way, and return its result. A cycle hook, not a poll from this thread: a join is in
    flight for a few cycles only, and a loaded machine could let a poll miss every one."""
    box: dict = {}

    def catch(c: Controller, t: float) -> None:
        if "result" not in box and g._job is not None and g.current_index > 50:
            box["result"] = action()

    ctl.add_cycle_hook(catch)
    assert _wait(ctl, lambda: "result" in box or (info["fed"] == N and _done(g)()))
    assert "result" in box, "the stream ended without a join in flight"
    return box["result"]


def _indices(g: Group) -> list[int]:
    """Command indices of the running or held chain and the queue, in order."""
    r = g._run or g._held
    run = [c.index for c in r.cmds] if r is not None else []
    return run + [c.index for c in g._queue]


def test_hold_and_continue_while_a_join_is_in_flight():
    ctl, g, pts, info = _setup()

    def hold(g: Group = g) -> list[int]:
        taken = [c.index for c in g._job.new]
        g.hold()
        return taken

    with ctl.start_realtime():
        taken = _in_flight(ctl, g, info, hold)
        assert _wait(ctl, lambda g=g: g.state is GroupState.HELD)
        with ctl.lock:
            assert g._job is None
            order = _indices(g)
            # the commands the join had taken are back at the queue front, in order
            assert [c.index for c in list(g._queue)[:len(taken)]] == taken
            assert order == sorted(order) and len(set(order)) == len(order)
            g.cont()
        assert _wait(ctl, lambda g=g, info=info: info["fed"] == N and _done(g)())
    assert g.state is GroupState.IDLE
    _ends_exactly(g, pts[-1])
    _check_limits(ctl, g)


@pytest.mark.parametrize("change", ["override", "corner velocity"])
def test_override_or_settings_while_a_join_is_in_flight(change):
    ctl, g, pts, info = _setup()

    def change_it(g: Group = g) -> object:
        job = g._job
        if change == "override":
            g.set_override(60.0)
        else:  # the join was planned with other corners: it is planned again
            g.set_corner_velocity(5.0)
        return job

    with ctl.start_realtime():
        job = _in_flight(ctl, g, info, change_it)
        assert _wait(ctl, lambda g=g, job=job: g._job is not job)
        assert _wait(ctl, lambda g=g, info=info: info["fed"] == N and _done(g)())
    assert g.state is GroupState.IDLE and g.error_code == 0
    _ends_exactly(g, pts[-1])
    assert info["rests"] == 0


def test_abort_while_a_join_is_in_flight_drops_its_commands():
    ctl, g, _pts, info = _setup()
    seen: set[int] = set()
    aborted = {"yes": False}
    ctl.add_cycle_hook(lambda c, t, g=g, seen=seen, aborted=aborted:
                       seen.add(g.current_index) if aborted["yes"] else None)

    def abort(g: Group = g, info: dict = info, aborted: dict = aborted) -> set[int]:
        taken = {c.index for c in g._job.new}
        g.abort()
        info["stop"] = True  # the program is given up: the feeder stops too
        aborted["yes"] = True
        return taken

    with ctl.start_realtime():
        taken = _in_flight(ctl, g, info, abort)
        assert _wait(ctl, lambda g=g: g.state is GroupState.IDLE
                     and not any(a.is_moving for a in g.axes))
        n0 = ctl.cycles  # more cycles: nothing the join had taken comes back
        assert _wait(ctl, lambda n0=n0: ctl.cycles >= n0 + 50)
        with ctl.lock:
            assert g._job is None and g.queue_length == 0
            assert g.state is GroupState.IDLE and not any(a.is_moving for a in g.axes)
    assert taken and not seen & taken  # no command the join had taken ever ran
    assert g.error_code == 0


def _stream(g: Group, ctl: Controller, pts: list, info: dict) -> None:
    """Run the stream to its end in real time."""
    with ctl.start_realtime():
        assert _wait(ctl, lambda: info["fed"] == N and _done(g)())
    assert g.state is GroupState.IDLE and g.error_code == 0
    _ends_exactly(g, pts[-1])


@pytest.fixture(scope="module")
def normal_stream() -> tuple[Controller, Group]:
    """The stream with a working worker (its motion is the same in every run)."""
    ctl, g, pts, info = _setup()
    _stream(g, ctl, pts, info)
    g.close()
    return ctl, g


@pytest.mark.parametrize("fault", ["late", "stalled"])
def test_a_late_or_stalled_worker_changes_nothing_in_the_motion(monkeypatch, fault,
                                                                 normal_stream):
    """The install cycle waits a few cycles at most, then computes the join itself: the
    same motion as when the worker carries every join. A worker that never finishes is
    handed one job only (its install is the only one that waits); the cycle goes on."""
    c1, g1 = normal_stream
    orig = groupjoin.pathaxes.axis_profiles
    release = threading.Event()
    box: dict = {"worker": 0}

    def slow(*a):  # noqa: ANN002, ANN202
        if threading.current_thread().name == "openmotion-join":
            box["worker"] += 1
            if fault == "stalled":
                release.wait(120.0)  # never finishes while the stream runs
            else:
                # late in controller cycles, not wall time: the install cycle waits on
                # the wall clock and no cycle runs meanwhile, so this is late whatever
                # the load
                ctl = box["ctl"]
                until = ctl.cycles + 3 * groupjoin.lead_cycles(ctl.period)
                end = time.monotonic() + 30.0
                while ctl.cycles < until and time.monotonic() < end:
                    time.sleep(0.0005)
        return orig(*a)

    monkeypatch.setattr(groupjoin.pathaxes, "axis_profiles", slow)
    ctl, g, pts, info = _setup()
    box["ctl"] = ctl
    try:
        _stream(g, ctl, pts, info)
    finally:
        release.set()
    assert g.async_joins == 0 and g.late_joins >= 3 and g.sync_joins <= 2
    if fault == "stalled":
        assert box["worker"] == 1  # later joins were never queued to it
    t_end = min(c1.time, ctl.time)
    np.testing.assert_array_equal(_positions(ctl, g, t_end), _positions(c1, g1, t_end))
    g.close()


def test_a_failing_worker_falls_back_to_joins_in_the_cycle(monkeypatch):
    orig = groupjoin.pathaxes.axis_profiles

    def failing(*a):  # noqa: ANN002, ANN202
        if threading.current_thread().name == "openmotion-join":
            raise RuntimeError("worker failure (test)")
        return orig(*a)

    monkeypatch.setattr(groupjoin.pathaxes, "axis_profiles", failing)
    ctl, g, pts, info = _setup()
    _stream(g, ctl, pts, info)
    assert g.async_joins == 0 and g.sync_joins >= 1
    assert g._join_misses <= groupjoin.MAX_MISSES


def test_lead_cycles():
    assert groupjoin.lead_cycles(0.001) == 25
    assert groupjoin.lead_cycles(0.1) == 2
