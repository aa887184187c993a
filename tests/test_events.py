"""The controller's event log: faults with exact times, reading, waiting, callbacks."""

import pytest

from openmotion.control import Controller
from openmotion.control.core.events import EventLog, classify_fault
from openmotion.errors import MotionError


def _ctl():
    ctl = Controller()
    ctl.enable_all()
    return ctl


def test_limit_hit_is_an_event_at_the_edge_time():
    ctl = _ctl()
    x = ctl["x"]
    pel = ctl.config.axes[0].pel
    seen = []
    ctl.events.on_event(seen.append)
    x.move_velocity(50_000, tacc=0.05)
    ev = ctl.events.wait("limit", "x", timeout=30.0)
    assert ev is not None and ev.detail == "+EL" and ev.axis == 0
    assert seen and seen[-1] is ev
    # the edge lies between two cycle ends, and the position is the planned one then
    assert ev.time < ctl.time
    assert ev.position == pytest.approx(ctl.history.state_at(0, ev.time).p)
    assert ev.position == pytest.approx(pel.position, abs=1.0)
    assert ctl.events.last("limit") is ev
    assert ctl.events.events(axis="y") == []


def test_estop_events_for_every_axis():
    ctl = _ctl()
    for ax in ctl.axes:
        ax.move_velocity(1000, tacc=0.05)
    ctl.advance(0.1)
    ctl.emergency_stop()
    kinds = {e.kind for e in ctl.events.events()}
    assert kinds == {"estop"}
    assert len(ctl.events.events(kind="estop")) == len(ctl.axes)


def test_wait_times_out_and_record_validates():
    ctl = _ctl()
    t0 = ctl.time
    assert ctl.events.wait("latch", timeout=0.05) is None
    assert ctl.time == pytest.approx(t0 + 0.05)
    ev = ctl.events.record("home_done", 1, ctl.time, 0.0, "mode 1")
    assert ctl.events.events(kind="home_done") == [ev]
    with pytest.raises(MotionError, match="kind"):
        ctl.events.record("not a kind", 0, 0.0)
    with pytest.raises(MotionError, match="axis"):
        ctl.events.record("latch", 9, 0.0)
    with pytest.raises(MotionError, match="time"):
        ctl.events.record("latch", 0, float("nan"))
    assert len(ctl.events) == 1
    with pytest.raises(MotionError, match="capacity"):
        EventLog(ctl, capacity=0)


def test_capacity_bounds_memory():
    ctl = Controller()
    log = EventLog(ctl, capacity=3)
    for k in range(10):
        log.record("compare", 0, float(k))
    assert [e.time for e in log.events()] == [7.0, 8.0, 9.0]


def test_classify_fault():
    assert classify_fault("+EL") == "limit"
    assert classify_fault("-SL") == "soft_limit"
    assert classify_fault("servo alarm") == "alarm"
    assert classify_fault("emergency stop") == "estop"
    assert classify_fault("step loss") == "fault"


def test_latch_and_home_completion_are_events():
    from openmotion.control.home.homing import Homing
    from openmotion.control.home.homing_modes import HomeConfig
    from openmotion.control.home.latch import Latch

    ctl = _ctl()
    latch = Latch(ctl)
    ctl.hardware.scenario.place_switch(1, "ltc", 3000.0, width=50.0)
    ctl["y"].move_relative(6000, max_vel=20_000, tacc=0.05)
    ev = ctl.events.wait("latch", "y", timeout=5.0)
    assert ev is not None and ev.position == pytest.approx(latch.data("y").position)
    assert ev.position == pytest.approx(3000.0, abs=1.0)
    ctl.wait_motion_done()

    home = Homing(ctl, "x", HomeConfig(mode=0, str_vel=100, max_vel=20_000, tacc=0.05))
    home.start()
    done = ctl.events.wait("home_done", "x", timeout=60.0)
    assert done is not None and home.status.state == "done"
