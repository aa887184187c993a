"""Deadman jogs and repeats in virtual time with a controlled clock (no server): exact
stop conditions, ids that stay dead, refusals that change nothing."""

from __future__ import annotations

import pytest

from openmotion.control import Controller
from openmotion.control.core.states import AxisState
from openmotion.errors import MotionError
from openmotion.remote.deadman import DEADMAN_S, JogRegistry
from openmotion.remote.repeat import RepeatRegistry


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


@pytest.fixture
def rig():
    ctl = Controller()
    ctl.enable_all()
    clock = Clock()
    jogs = JogRegistry(ctl, clock=clock)
    ctl.add_cycle_hook(lambda c, t: jogs.check())
    return ctl, clock, jogs


def _run(ctl, clock, seconds, step=0.001):
    for _ in range(round(seconds / step)):
        clock.t += step
        ctl.step()


def test_confirmed_jog_runs_unconfirmed_stops_after_the_deadman(rig):
    ctl, clock, jogs = rig
    x = ctl.axis("x")
    jog = jogs.start("x", 1, 10.0, 0.05, owner="tab")
    for _ in range(10):                 # a second of confirmations every 100 ms
        _run(ctl, clock, 0.1)
        assert jogs.confirm(jog.id) == (True, None)
    assert x.state is AxisState.CONTINUOUS_MOTION
    _run(ctl, clock, DEADMAN_S - 0.02)  # not yet
    assert x.state is AxisState.CONTINUOUS_MOTION
    _run(ctl, clock, 0.04)              # past 250 ms: stopping
    assert x.state is AxisState.STOPPING
    active, reason = jogs.confirm(jog.id)
    assert not active and "deadman" in reason
    _run(ctl, clock, 0.5)
    assert x.state is AxisState.STANDSTILL
    assert jogs.confirm(jog.id)[0] is False and x.motion is None   # never restarts


def test_release_and_lost_owner_stop_at_once(rig):
    ctl, clock, jogs = rig
    a = jogs.start("x", 1, 10.0, 0.05, owner="tab-a")
    b = jogs.start("y", -1, 10.0, 0.05, owner="tab-b")
    _run(ctl, clock, 0.05)
    jogs.stop(a.id)
    assert ctl.axis("x").state is AxisState.STOPPING
    jogs.stop(a.id)                                  # idempotent
    jogs.drop_owner("tab-b")
    assert ctl.axis("y").state is AxisState.STOPPING
    assert jogs.confirm(b.id) == (False, "connection lost")
    with pytest.raises(MotionError, match="unknown"):
        jogs.confirm("jog-nope")


def test_one_jog_per_axis_and_bad_direction(rig):
    ctl, clock, jogs = rig
    jogs.start("x", 1, 10.0, 0.05, owner=None)
    with pytest.raises(MotionError, match="already jogging"):
        jogs.start("x", -1, 10.0, 0.05, owner=None)
    with pytest.raises(MotionError, match="direction"):
        jogs.start("y", 0, 10.0, 0.05, owner=None)
    assert ctl.axis("y").motion is None


def test_jog_ends_at_the_limit_ahead_and_confirming_cannot_restart_it(rig):
    ctl, clock, jogs = rig
    z = ctl.axis("z")
    jog = jogs.start("z", -1, 50.0, 0.05, owner=None)   # -EL of z at -5 mm
    active = True
    for _ in range(400):
        _run(ctl, clock, 0.01)
        active, reason = jogs.confirm(jog.id)
        if not active:
            break
    assert not active and "stopped" in reason
    assert z.state is AxisState.ERROR_STOP and z.fault == "-EL"   # the limit's reaction
    assert z.position < -4.9 * 4000


def test_repeat_runs_count_moves_with_the_dwell():
    ctl = Controller()
    ctl.enable_all()
    reps = RepeatRegistry(ctl)
    ctl.add_cycle_hook(lambda c, t: reps.step(t))
    starts = []
    ctl.add_motion_hook(lambda ax, m: starts.append(ctl.time) if m is not None
                        and ax.name == "x" and m.kind == "absolute" else None)
    reps.start("x", 1.0, 2.0, 0.25, 3, {"max_vel": 20.0, "tacc": 0.05})
    ctl.advance(5.0)
    assert not reps.active(0) and reps.last_reason[0] == "done: 3 moves"
    assert ctl.axis("x").counters.command == 1000
    # each move (0.1 s: 1 mm at 20 mm/s, 0.05 s ramps) starts after the 0.25 s dwell
    assert len(starts) == 3
    gaps = [b - a for a, b in zip(starts, starts[1:], strict=False)]
    assert all(0.35 - 1e-9 <= g <= 0.35 + 0.0021 for g in gaps), gaps
    with pytest.raises(MotionError, match="p1 and p2 must differ"):
        reps.start("x", 1.0, 1.0, 0.1, 0, {"max_vel": 20.0})
    with pytest.raises(MotionError, match="max_vel"):
        reps.start("x", 1.0, 5.0, 0.1, 0, {"max_vel": -20.0})
    assert not reps.active(0)


def test_path_firings_come_once_when_reading_on():
    from openmotion.remote.programs import ProgramSession

    ctl = Controller()
    ctl.enable_all()
    prog = ProgramSession(ctl)
    ctl.add_cycle_hook(lambda c, t: prog.path.sample(t))
    prog.load("G21 G90\nG0 X0 Y0\nM62 P0\nG1 F900 X6\nM63 P0\nG1 Y6\nM62 P0\nG1 X0\n"
              "M63 P0\nM30\n", "laser.ngc")
    prog.run(feed_override=100.0, single_block=False, optional_stop=False, repeat=1,
             acc_time=0.05)
    got, nxt = [], 0
    for _ in range(400):
        ctl.advance(0.007)
        d = prog.path.path(nxt, 10_000)
        got += d["firings"]
        nxt = d["next"]
        if prog.status()["state"] == "done":
            break
    assert prog.status()["state"] == "done"
    got += prog.path.path(nxt, 10_000)["firings"]   # after the end: nothing twice
    assert [f["level"] for f in got] == [True, False, True, False]
    assert [round(f["point"][0] - 150.0, 2) for f in got] == [0.0, 6.0, 6.0, 0.0]
    assert len(prog.path.path(0, 10_000)["firings"]) == 4
