"""Position latch (LTC) and touch probes: counters captured at the exact edge time."""

import pytest

from openmotion.config import DriveConfig, default_machine
from openmotion.control import Controller
from openmotion.control.home.latch import Latch, TouchProbe
from openmotion.errors import MotionError


@pytest.fixture
def ctl():
    c = Controller()
    c.enable_all()
    return c


def move(c, axis, distance, v=80000.0):
    c.axis(axis).move_relative(distance, max_vel=v, tacc=0.05)


def test_ltc_captures_four_counters_at_speed(ctl):
    ax = ctl.axis("x")
    ax.counters.set_command(1000)
    ax.counters.set_general(0, source="command")
    latch = Latch(ctl)
    ctl.hardware.scenario.place_switch(0, "ltc", 12345.5, 500.0)
    move(ctl, "x", 40000)
    assert ctl.wait_motion_done(timeout=5)
    assert latch.latched("x")
    d = latch.data("x")
    assert not latch.latched("x")
    # the switch closes when the load reaches 12346 (first whole pulse >= 12345.5)
    assert d.command == 12346 + 1000
    assert d.feedback == 12346
    assert d.error == 0
    assert d.general == 12346
    st = ctl.history.state_at(0, d.time)
    assert abs(st.v) > 10000  # captured at speed, not at a cycle boundary
    # the planned position at the edge: pulse 12346 left at its half-pulse point
    assert d.position == pytest.approx(12345.5 + 1000, abs=1e-6)
    assert d.position == pytest.approx(st.p + 1000)


def test_ltc_off_edge_and_last_capture_wins(ctl):
    latch = Latch(ctl)
    latch.set_edge("x", "off")
    ctl.hardware.scenario.place_switch(0, "ltc", 10000.0, 2000.0)
    move(ctl, "x", 30000)
    ctl.wait_motion_done(timeout=5)
    assert latch.data("x").feedback == 12000  # released at 10000 + 2000
    move(ctl, "x", -30000)
    ctl.wait_motion_done(timeout=5)
    assert latch.data("x").feedback == 9999  # going down: released below 10000
    latch.close()


def test_ltc_shared_with_sd_pin(ctl):
    latch = Latch(ctl)
    ctl.hardware.scenario.place_switch(1, "sd", 7000.0, 100.0)
    move(ctl, "y", 20000)
    ctl.wait_motion_done(timeout=5)
    assert latch.data("y").command == 7000


def test_ltc_on_a_servo_latches_the_feedback_at_the_edge():
    cfg = default_machine()
    x = cfg.axes[0]
    from dataclasses import replace
    cfg = cfg.with_axis(replace(x, drive=DriveConfig(type="servo")))
    c = Controller(cfg)
    c.enable_all()
    latch = Latch(c)
    c.hardware.scenario.place_switch(0, "ltc", 15000.0, 500.0)
    move(c, "x", 40000, v=40000.0)
    c.wait_motion_done(timeout=5)
    d = latch.data("x")
    assert d.feedback == 15000  # the switch sits on the load: the encoder reads it there
    # the command leads the load by the following error; error counter = their difference
    assert d.command >= d.feedback and d.error == d.command - d.feedback


def test_touch_probe_on_general_input_matches_analytic_position(ctl):
    probe = TouchProbe(ctl, "x", "di0", mode="continuous")
    move(ctl, "x", 100000)
    t_hits = [ctl.time + 0.1234567, ctl.time + 0.3456789, ctl.time + 0.5]
    for k, t in enumerate(t_hits):
        ctl.hardware.scenario.set_input("di0", k % 2 == 0, at=t)
    ctl.wait_motion_done(timeout=5)
    # edges "on" only: the first and third
    assert [r.time for r in probe.records] == [t_hits[0], t_hits[2]]
    for r in probe.records:
        p = ctl.history.state_at(0, r.time).p
        assert r.position == p
        assert abs(r.command - p) < 1.0
        assert abs(r.feedback - p) < 1.0


def test_touch_probe_window_and_single(ctl):
    probe = TouchProbe(ctl, "x", (0, "ltc"), edge="both", window=(20000.0, 30000.0))
    sc = ctl.hardware.scenario
    sc.place_switch(0, "ltc", 5000.0, 10.0)
    move(ctl, "x", 24000)
    ctl.wait_motion_done(timeout=5)
    assert not probe.done  # 5000 and 5010 are outside the window
    sc.place_switch(0, "ltc", 25000.0, 1000.0)
    move(ctl, "x", 10000)
    ctl.wait_motion_done(timeout=5)
    assert probe.done and len(probe.records) == 1  # single: the 26000 release is not taken
    # pulse 25000 closes the switch; it left when the planned position passed 24999.5
    assert probe.records[0].command == 25000
    assert probe.recorded_position == pytest.approx(24999.5, abs=0.05)
    assert not probe.armed


def test_touch_probe_abort(ctl):
    probe = TouchProbe(ctl, "x", "di1")
    probe.abort()
    ctl.hardware.scenario.set_input("di1", True)
    ctl.advance(0.01)
    assert not probe.done


@pytest.mark.parametrize("kwargs,match", [
    (dict(trigger="emg"), "trigger"), (dict(trigger="di99"), "di"),
    (dict(trigger=(0, "foo")), "signal"), (dict(trigger=(9, "ltc")), "axis"),
    (dict(trigger="di0", edge="up"), "edge"), (dict(trigger="di0", mode="many"), "mode"),
    (dict(trigger="di0", window=(5.0, 1.0)), "window"),
    (dict(trigger="di0", window=(float("nan"), 1.0)), "window"),
    (dict(trigger="di0", capacity=0), "capacity"),
])
def test_touch_probe_bad_input(ctl, kwargs, match):
    with pytest.raises(MotionError, match=match):
        TouchProbe(ctl, "x", **kwargs)


def test_latch_bad_edge(ctl):
    latch = Latch(ctl)
    with pytest.raises(MotionError, match="edge"):
        latch.set_edge("x", "rising")
    assert latch.data("x") is None
