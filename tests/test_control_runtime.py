"""Controller runtime: clock, cycle, edges and hooks, E-stop, alarms, refusals change nothing."""

from dataclasses import replace

import pytest

from openmotion.config import DriveConfig, default_machine
from openmotion.control import AxisState, Controller, MotionDone
from openmotion.errors import MotionError

S = AxisState


@pytest.fixture
def ctl():
    c = Controller()
    c.enable_all()
    return c


def all_snapshots(c):
    return [ax.snapshot() for ax in c.axes], c.time


def test_period_and_virtual_time():
    c = Controller(period=0.004)
    assert c.period == 0.004
    c.advance(0.01)  # rounded up to whole cycles
    assert c.cycles == 3 and c.time == pytest.approx(0.012)
    c.advance(0)
    assert c.cycles == 3
    for bad in (0.0005, 2.0, float("nan"), "x"):
        with pytest.raises(MotionError, match="period"):
            Controller(period=bad)


def test_time_is_cycle_count_times_period():
    c = Controller()
    c.advance(1.0)
    assert c.cycles == 1000 and c.time == 1000 * 0.001


def test_run_until_condition_and_timeout(ctl):
    ax = ctl.axis("x")
    ax.move_relative(1000, max_vel=10_000, tacc=0.01)
    assert ctl.run_until(lambda: ax.counters.command >= 500, 1.0)
    assert 500 <= ax.counters.command < 1000
    t = ctl.time
    assert ctl.run_until(lambda: False, 0.05) is False
    assert ctl.time == pytest.approx(t + 0.05)
    with pytest.raises(MotionError, match="condition"):
        ctl.run_until(None, 1.0)
    with pytest.raises(MotionError, match="timeout"):
        ctl.run_until(lambda: True, -1)


def test_unknown_axis_refused(ctl):
    for key in ("w", 7, -1, 1.5, True):
        with pytest.raises(MotionError, match="axis"):
            ctl.axis(key)


def test_axes_start_disabled_and_refuse_motion():
    c = Controller()
    ax = c.axis("x")
    assert ax.state is S.DISABLED
    before = ax.snapshot()
    with pytest.raises(MotionError, match="disabled"):
        ax.move_relative(100, max_vel=1000)
    assert ax.snapshot() == before
    ax.enable()
    assert ax.state is S.STANDSTILL
    ax.disable()
    assert ax.state is S.DISABLED


BAD_CALLS = [
    ("move_relative", (float("nan"),), {"max_vel": 1000}),
    ("move_relative", (100,), {"max_vel": -5}),
    ("move_relative", (100,), {"max_vel": 1000, "str_vel": 2000}),
    ("move_relative", (100,), {"max_vel": 1000, "tacc": 0}),
    ("move_relative", (100,), {"max_vel": 1000, "shape": "Q"}),
    ("move_relative", (100,), {"max_vel": 1000, "shape": "S", "vs_acc": 600}),
    ("move_relative", (2**28,), {"max_vel": 1000}),
    ("move_relative", (100,), {"max_vel": 1e9}),  # above the axis's safe speed
    ("move_absolute", (2**27,), {"max_vel": 1000}),
    ("move_absolute", ("a",), {"max_vel": 1000}),
    ("move_velocity", (0.0,), {}),
    ("move_velocity", (float("inf"),), {}),
    ("move_jerk_limited", (100,), {"v_max": 1000, "a_max": -1, "j_max": 1e6}),
    ("change_speed", (float("nan"), 0.1), {}),
    ("change_speed", (100, 0), {}),
    ("change_speed", (1e9, 0.1), {}),
    ("change_position", (float("inf"),), {}),
    ("stop", (-1.0,), {}),
    ("fix_speed_range", (0,), {}),
    ("set_move_ratio", (0,), {}),
    ("set_inp", ("yes",), {}),
]


@pytest.mark.parametrize("name,args,kwargs", BAD_CALLS)
def test_bad_input_changes_nothing(ctl, name, args, kwargs):
    ax = ctl.axis("x")
    ax.move_relative(5000, max_vel=20_000, tacc=0.05)
    ctl.advance(0.1)
    y = ctl.axis("y")
    for target in (ax, y):  # while moving and at rest
        before = all_snapshots(ctl)
        with pytest.raises(MotionError):
            getattr(target, name)(*args, **kwargs)
        assert all_snapshots(ctl) == before


def test_second_move_refused_while_running(ctl):
    ax = ctl.axis("x")
    ax.move_relative(5000, max_vel=20_000, tacc=0.05)
    ctl.advance(0.05)
    before = all_snapshots(ctl)
    for call in (lambda: ax.move_relative(10, max_vel=100),
                 lambda: ax.move_absolute(10, max_vel=100),
                 lambda: ax.move_velocity(100),
                 lambda: ax.move_jerk_limited(10, v_max=100, a_max=1e4, j_max=1e6)):
        with pytest.raises(MotionError, match="running"):
            call()
    assert all_snapshots(ctl) == before
    assert ctl.wait_motion_done(timeout=2)
    assert ax.counters.command == 5000


def test_change_position_refused_for_relative_moves(ctl):
    ax = ctl.axis("x")
    ax.move_relative(5000, max_vel=20_000, tacc=0.05)
    ctl.advance(0.05)
    before = all_snapshots(ctl)
    with pytest.raises(MotionError, match="absolute"):
        ax.change_position(100)
    assert all_snapshots(ctl) == before


def test_estop_stops_everything_and_needs_release_and_reset(ctl):
    for name in ("x", "y"):
        ctl.axis(name).move_relative(50_000, max_vel=20_000, tacc=0.05)
    ctl.axis("z").move_velocity(-5000, tacc=0.05)
    ctl.hardware.scenario.press_estop(at=ctl.time + 0.1)
    ctl.advance(0.2)
    assert ctl.estop_active
    for ax in ctl.axes:
        assert ax.state is S.ERROR_STOP and ax.fault == "emergency stop"
        assert ax.motion_done == 0 and ax.speed == 0
    pos = [ax.counters.command for ax in ctl.axes]
    ctl.advance(0.1)
    assert [ax.counters.command for ax in ctl.axes] == pos  # nothing moves any more
    x = ctl.axis("x")
    before = all_snapshots(ctl)
    with pytest.raises(MotionError, match="ErrorStop"):
        x.move_relative(100, max_vel=1000)
    with pytest.raises(MotionError, match="emergency stop"):
        x.reset()
    assert all_snapshots(ctl) == before
    ctl.hardware.scenario.release_estop()
    ctl.step()
    assert not ctl.estop_active
    x.reset()
    assert x.state is S.STANDSTILL
    x.move_relative(100, max_vel=10_000, tacc=0.01)
    assert ctl.wait_motion_done(["x"], timeout=1)
    assert x.counters.command == pos[0] + 100


def test_servo_alarm_faults_one_axis():
    m = default_machine()
    x = replace(m.axes[0], drive=DriveConfig(type="servo"))
    c = Controller(m.with_axis(x))
    c.enable_all()
    assert c.hardware.read_output(0, "svon")
    ax, y = c.axis("x"), c.axis("y")
    ax.move_relative(50_000, max_vel=20_000, tacc=0.05)
    y.move_relative(5_000, max_vel=20_000, tacc=0.05)
    c.hardware.scenario.trip_alarm(0, at=0.1)
    c.advance(0.15)
    assert ax.state is S.ERROR_STOP and ax.fault == "servo alarm"
    assert y.state is S.DISCRETE_MOTION
    with pytest.raises(MotionError, match="alarm"):
        ax.reset()
    c.hardware.scenario.clear_alarm(0)
    c.step()
    ax.reset()
    assert ax.state is S.STANDSTILL
    ax.disable()
    assert not c.hardware.read_output(0, "svon")


def test_edge_hooks_see_switch_edges(ctl):
    seen = []
    hook = lambda c, e: seen.append((e.axis, e.signal, e.level, e.time))  # noqa: E731
    ctl.add_edge_hook(hook)
    ax = ctl.axis("x")  # ORG switch spans 0..3 mm = 0..3000 pulses
    ax.move_relative(-2000, max_vel=100_000, tacc=0.01)
    ctl.wait_motion_done(timeout=1)
    ax.move_relative(6000, max_vel=100_000, tacc=0.01)
    ctl.wait_motion_done(timeout=1)
    org = [s for s in seen if s[1] == "org"]
    assert len(org) >= 2
    assert all(0 < s[3] <= ctl.time for s in org)
    ctl.remove_edge_hook(hook)
    n = len(seen)
    ax.move_relative(-6000, max_vel=100_000, tacc=0.01)
    ctl.wait_motion_done(timeout=1)
    assert len(seen) == n
    with pytest.raises(MotionError, match="callable"):
        ctl.add_edge_hook(3)


def test_cycle_hook_runs_every_cycle(ctl):
    times = []
    ctl.add_cycle_hook(lambda c, t: times.append(t))
    ctl.advance(0.005)
    assert times == pytest.approx([0.001, 0.002, 0.003, 0.004, 0.005])


def test_stepper_step_loss_shows_in_error_counter():
    m = default_machine()
    x = replace(m.axes[0], drive=DriveConfig(type="stepper", pullout_speed=30_000,
                                             pullout_accel=1e9))
    c = Controller(m.with_axis(x))
    c.enable_all()
    ax = c.axis("x")
    ax.move_relative(20_000, max_vel=20_000, tacc=0.05)
    c.wait_motion_done(timeout=5)
    assert ax.counters.error == 0
    ax.move_relative(40_000, max_vel=60_000, tacc=0.05)  # above the pull-out speed
    c.wait_motion_done(timeout=5)
    assert ax.counters.command == 60_000
    assert ax.counters.error > 0
    assert ax.counters.error == ax.counters.command - ax.counters.feedback
    ax.counters.reset_error()
    assert ax.counters.error == 0


def test_history_follows_the_executed_motion(ctl):
    ax = ctl.axis("y")
    ax.move_relative(4000, max_vel=20_000, tacc=0.05)
    ctl.wait_motion_done(timeout=2)
    h = ctl.history
    assert h.state_at(1, ctl.time).p == 4000
    assert 0 < h.state_at(1, 0.1).p < 4000


def test_recording(ctl):
    ctl.start_recording(capacity=100)
    ax = ctl.axis("x")
    ax.move_relative(1000, max_vel=20_000, tacc=0.01)
    ctl.advance(0.2)
    arr = ctl.recorder.arrays()
    assert arr["cmd_pos"].shape[1] == 4
    assert arr["cmd_pos"][-1, 0] == 1000
    assert arr["t"][-1] == pytest.approx(ctl.time)
    ctl.stop_recording()
    ctl.advance(0.01)
    assert ctl.recorder is None


def test_servo_waits_for_inp_after_the_profile_ends():
    m = default_machine()
    x = replace(m.axes[0], drive=DriveConfig(type="servo", bandwidth_hz=20.0, inp_band=2.0))
    c = Controller(m.with_axis(x))
    c.enable_all()
    ax = c.axis("x")
    ax.set_inp(True)
    ax.move_relative(20_000, max_vel=100_000, tacc=0.05)
    end = ax.motion.t_end
    codes = set()
    while ax.motion_done:
        codes.add(ax.motion_done)
        c.step()
        assert c.time < end + 2.0
    assert MotionDone.WAITING_INP in codes
    assert c.time > end + c.period  # the servo lags the command
    assert ax.state is S.STANDSTILL
    assert abs(ax.counters.error) <= 2


def test_estop_input_level_follows_the_emg_contact_logic():
    """EMG high means E-stop on a normally open contact, low on a normally closed one."""
    assert Controller().estop_input_level is True
    cfg = default_machine()
    nc = cfg.with_axis(replace(cfg.axis("x"), logic={**cfg.axis("x").logic, "emg": "nc"}))
    c = Controller(nc)
    assert c.estop_input_level is False
    assert c.estop_active == (c.hardware.read_input("emg") == c.estop_input_level)


def test_lock_is_the_cycle_lock_and_reentrant(ctl):
    """Holding `lock` around several calls (another thread's view) never deadlocks its own
    cycle: it is the re-entrant lock each cycle takes."""
    with ctl.lock:
        ctl.axes[0].move_relative(100, max_vel=10_000)
        ctl.advance(0.05)
        assert ctl.lock.acquire(blocking=False)  # re-entrant in the holding thread
        ctl.lock.release()
    ctl.advance(0.1)
    assert ctl.axes[0].position == 100


def test_axis_accessors_raw_position_powered_max_speed_check_speed():
    c = Controller()
    x = c["x"]
    assert not x.powered
    c.enable_all()
    assert x.powered
    assert x.max_speed == min(c.config.axes[0].max_speed_pps, 6.55e6)
    x.counters.set_command(1000)  # moves the counter frame, not the raw pulse frame
    assert x.raw_position == 0.0 and x.position == 1000.0
    x.move_relative(250, max_vel=5000, tacc=0.01)
    c.wait_motion_done()
    assert x.raw_position == 250.0 and x.position == 1250.0
    assert x.check_speed("v", -x.max_speed) == -x.max_speed
    ppu = x.units.pulses_per_unit
    assert x.check_speed("v", 2.0, units=True) == pytest.approx(2.0 * ppu)
    before = x.snapshot()
    for bad in (x.max_speed * 1.01, float("nan"), float("inf")):
        with pytest.raises(MotionError, match="v "):
            x.check_speed("v", bad)
    assert x.snapshot() == before
    x.disable()
    assert not x.powered
