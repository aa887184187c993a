"""Homing in virtual time on the simulated XYZU table (axis x, ideal stepper).

Geometry used throughout (command pulses): ORG placed at [2000, 5000) with 50 pulses of
hysteresis, -EL active below -5000, +EL above 305000, EZ index at every multiple of 10000
(one count wide). Home direction is negative. The expected home mark of every mode is the
exact edge the mode defines, worked out by hand below.
"""

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, MachineConfig, default_machine
from openmotion.control import AxisState, Controller
from openmotion.control.guard.safety import Safety
from openmotion.control.home.homing import HomeConfig, Homing, escape_home, home_move, home_search
from openmotion.control.home.homing_sequence import HomeSequence
from openmotion.errors import MotionError

S = AxisState
FAST = dict(str_vel=2000.0, max_vel=20000.0, tacc=0.05)

# mode -> mark (command pulses, home direction -1):
EXPECTED_MARK = {
    0: 4999,    # ORG becomes active moving down: y < 5000
    1: 1949,    # end of ORG moving down: y < 2000 - 50
    2: 0,       # the next index below ORG
    3: 0,
    4: 10000,   # stop inside ORG, reverse: first index going up
    5: 10000,   # leave ORG going up, then the index
    6: -5001,   # -EL becomes active: y < -5000
    7: 0,       # from -EL, reverse: first index going up
    8: 0,
    9: 5050,    # back up to the ORG edge: releases at 5000 + 50
    10: 0,      # index at speed, back to its edge
    11: 10000,  # ORG, reverse at MaxVel to the index, forward slowly to its edge
    12: 0,      # -EL, reverse to the index, forward slowly to its edge
}
STARTS = {"right": 20000, "on_org": 3000, "left": -2000, "on_el": -10000}


def make(start=0, org=(2000.0, 3000.0, 50.0), config=None, safety=False):
    # Homing handles the limits its modes use itself; the safety layer is tested below.
    ctl = Controller(config, safety=safety)
    ctl.enable_all()
    if org is not None:
        ctl.hardware.scenario.place_switch(0, "org", *org)
    ax = ctl.axis("x")
    if start:
        ax.move_absolute(start, max_vel=100000, tacc=0.05)
        assert ctl.wait_motion_done(timeout=10)
    return ctl, ax


def run(ctl, h, timeout=120.0):
    assert ctl.run_until(lambda: not h.running, timeout, event_driven=True)
    return h.status


@pytest.mark.parametrize("mode", range(13))
@pytest.mark.parametrize("where", STARTS)
def test_every_mode_every_start_ends_on_the_mode_edge(mode, where):
    ctl, ax = make(STARTS[where])
    target_before = ax.counters.target
    h = home_search(ctl, "x", HomeConfig(mode=mode, org_offset=300, **FAST))
    assert ax.state is S.HOMING
    st = run(ctl, h)
    assert st.state == "done", st.reason
    mark = EXPECTED_MARK[mode]
    # the mark is the count of the pulse that tripped the edge: that pulse left when the
    # planned position was half a pulse short of it (half-pulse rule), at the edge's exact
    # time (within the blend of a cycle straddling a segment boundary, see motion.py)
    assert st.mark == mark
    at = ctl.history.state_at(0, st.mark_time)
    assert st.mark - at.p == pytest.approx(0.5 if at.v > 0 else -0.5, abs=1e-2)
    # the axis rests exactly on the mark; every counter but the target recorder is cleared
    assert ctl.hardware.command_position(0) == pytest.approx(mark, abs=1e-9)
    assert ctl.hardware.motor_position(0) == mark
    c = ax.counters
    assert (c.command, c.feedback, c.error, c.general) == (0, 0, 0, 0)
    assert ax.position == pytest.approx(0.0, abs=1e-9)
    assert c.target != 0.0 or target_before == 0.0
    assert ax.state is S.STANDSTILL and st.code == 1


@pytest.mark.parametrize("mode", [0, 1, 9])
def test_repeatable_from_random_starts(mode):
    finals = set()
    for start in (150000, 7000, 4000, 2500):
        ctl, ax = make(start)
        h = home_move(ctl, "x", HomeConfig(mode=mode, **FAST))
        assert run(ctl, h).state == "done"
        finals.add(ctl.hardware.motor_position(0))
    assert finals == {EXPECTED_MARK[mode]}


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(start=st.integers(-40000, 250000), vmax=st.floats(3000.0, 40000.0),
       tacc=st.floats(0.02, 0.2), mode=st.sampled_from([0, 9, 11]))
def test_same_count_from_any_start_and_speed(start, vmax, tacc, mode):
    """Property: wherever it starts (either side of ORG, on it, on -EL) and whatever MaxVel
    and Tacc, the axis ends on the mode's edge with the counters at 0."""
    ctl, ax = make(start)
    cfg = HomeConfig(mode=mode, str_vel=1500.0, max_vel=vmax, tacc=tacc, org_offset=100)
    st_ = run(ctl, home_search(ctl, "x", cfg), timeout=300)
    assert st_.state == "done", st_.reason
    assert ctl.hardware.motor_position(0) == EXPECTED_MARK[mode]
    assert ax.counters.command == 0 and ax.counters.feedback == 0


def test_el_immediate_stop_mode_6():
    ctl, ax = make(20000)
    st_ = run(ctl, home_move(ctl, "x", HomeConfig(mode=6, el_stop="immediate", **FAST)))
    assert st_.state == "done"
    assert st_.mark == -5001  # the pulse that tripped -EL
    assert ctl.hardware.motor_position(0) == -5001 and ax.counters.command == 0


def test_servo_axis_homes_the_load_onto_the_index():
    """A servo's command leads the load by the following error at the edge; the home is
    taken from the encoder, so the load (not the command) ends on the index."""
    from dataclasses import replace

    from openmotion.config import DriveConfig
    base = default_machine()
    cfg = base.with_axis(replace(base.axes[0], drive=DriveConfig(type="servo")))
    finals = set()
    for start in (20000, 3000):
        ctl, ax = make(start, config=cfg)
        h = home_move(ctl, "x", HomeConfig(mode=11, settle_s=0.05, **FAST))
        st_ = run(ctl, h)
        assert st_.state == "done", st_.reason
        assert abs(st_.mark - 10000) > 5  # the command was ahead of the load at the edge
        ctl.advance(0.2)
        finals.add(round(ctl.hardware.load_position(0), 6))
        assert abs(ax.counters.feedback) <= 1
    assert len(finals) == 1 and abs(finals.pop() - 10000) <= 1.0


def test_final_stay_counts_from_the_mark():
    ctl, ax = make(20000)
    h = home_move(ctl, "x", HomeConfig(mode=0, final="stay", **FAST))
    st = run(ctl, h)
    assert st.state == "done"
    rest = ctl.hardware.motor_position(0)
    assert rest < 4999  # decelerated past the edge, did not come back
    assert ax.counters.command == rest - 4999
    assert ax.counters.feedback == rest - 4999
    assert ax.counters.error == 0


def test_home_offset_moves_to_logical_home_and_zeroes_there():
    ctl, ax = make(20000)
    h = home_move(ctl, "x", HomeConfig(mode=0, home_offset=-1234, **FAST))
    assert run(ctl, h).state == "done"
    assert ctl.hardware.motor_position(0) == 4999 - 1234
    assert ax.counters.command == 0 and ax.counters.feedback == 0


def test_s_curve_homing_same_mark():
    ctl, ax = make(20000)
    h = home_move(ctl, "x", HomeConfig(mode=9, jerk=2e7, **FAST))
    st = run(ctl, h)
    assert st.state == "done", st.reason
    assert ctl.hardware.motor_position(0) == EXPECTED_MARK[9]


def test_ez_count_skips_index_pulses():
    ctl, ax = make(20000)
    h = home_move(ctl, "x", HomeConfig(mode=4, ez_count=2, **FAST))
    st = run(ctl, h)
    assert st.state == "done", st.reason
    assert st.mark == 30000  # third index above the reversal


# -- MCCL phased homing ----------------------------------------------------------------------
@pytest.mark.parametrize("kind,same,mark", [
    ("mccl_normal", False, 10000),    # leave ORG upwards (5050), nearest index above
    ("mccl_home_only", False, 5050),  # the sensor's release edge is the origin
    ("mccl_normal", True, 0),         # leave ORG downwards (1949), nearest index below
    ("mccl_index_only", True, 0),     # from 3000 in wPhase1Dir (down): the first index
    ("mccl_index_only", False, 10000),  # from 3000 in wPhase1Dir (up): the first index
])
def test_mccl_phases(kind, same, mark):
    ctl, ax = make(20000 if kind != "mccl_index_only" else 3000)
    cfg = HomeConfig(mode=kind, phase1_same_direction=same, home_offset=500, max_vel=20000,
                     str_vel=2000, tacc=0.05)
    st = run(ctl, home_move(ctl, "x", cfg))
    assert st.state == "done", st.reason
    assert st.mark == mark
    assert ctl.hardware.motor_position(0) == mark + 500
    assert ax.counters.command == 0


def test_mccl_phase0_overrun_is_reported():
    ctl, ax = make(20000, org=(2000.0, 100.0, 0.0))  # a 100-pulse sensor
    cfg = HomeConfig(mode="mccl_normal", max_vel=20000, str_vel=2000, tacc=0.05)
    st = run(ctl, home_move(ctl, "x", cfg))
    assert st.state == "error" and "lower the homing speed" in st.reason
    assert ax.state is S.ERROR_STOP


def test_home_sequence_orders_axes():
    ctl = Controller()
    ctl.enable_all()
    for i in (0, 1):
        ctl.hardware.scenario.place_switch(i, "org", 2000.0, 3000.0, 50.0)
        ctl.axes[i].move_absolute(20000, max_vel=100000, tacc=0.05)
    ctl.wait_motion_done(timeout=10)
    cfg = HomeConfig(mode=0, **FAST)
    seq = HomeSequence(ctl, {"x": (cfg, 1), "y": (cfg, 0)})
    seq.start()
    assert seq.code == -1
    assert ctl.axis("y").state is S.HOMING and ctl.axis("x").state is S.STANDSTILL
    assert ctl.run_until(lambda: seq.code != -1, 60, event_driven=True)
    assert seq.state == "done"
    hx, hy = seq.groups[1][0], seq.groups[0][0]
    assert hx.status.mark_time > hy.status.mark_time
    assert ctl.hardware.motor_position(0) == ctl.hardware.motor_position(1) == 4999


# -- abort paths ------------------------------------------------------------------------------
def test_stop_aborts_homing():
    ctl, ax = make(200000)
    h = home_move(ctl, "x", HomeConfig(mode=0, **FAST))
    ctl.advance(0.2)
    ax.stop()
    st = run(ctl, h)
    assert st.state == "aborted"
    assert ctl.wait_motion_done(timeout=5) and ax.state is S.STANDSTILL


def test_abort_method_and_counters_untouched():
    ctl, ax = make(200000)
    before = ax.counters.command
    h = home_move(ctl, "x", HomeConfig(mode=0, **FAST))
    ctl.advance(0.2)
    h.abort()
    assert h.status.state == "aborted"
    ctl.wait_motion_done(timeout=5)
    assert ax.state is S.STANDSTILL and ax.counters.command != 0 and before == 200000


def test_estop_aborts_homing():
    ctl, ax = make(200000)
    h = home_move(ctl, "x", HomeConfig(mode=0, **FAST))
    ctl.hardware.scenario.press_estop(at=ctl.time + 0.1)
    st = run(ctl, h)
    assert st.state == "aborted" and "emergency stop" in st.reason
    assert ax.state is S.ERROR_STOP


def test_limit_not_part_of_mode_faults_without_auto_search():
    ctl, ax = make(-2000)  # below ORG: searching down meets -EL
    st = run(ctl, home_move(ctl, "x", HomeConfig(mode=0, **FAST)))
    assert st.state == "error" and "MEL" in st.reason
    assert ax.state is S.ERROR_STOP


def test_starting_on_limit_faults_without_auto_search():
    ctl, ax = make(-10000)
    st = home_move(ctl, "x", HomeConfig(mode=0, **FAST)).status
    assert st.state == "error" and "limit" in st.reason


def test_not_found_and_timeout():
    ctl, ax = make(20000, org=None)
    ctl.hardware.scenario.remove_switch(0, "org")
    ctl.hardware.scenario.remove_switch(0, "mel")
    st = run(ctl, home_move(ctl, "x", HomeConfig(mode=0, search_range=5000, **FAST)))
    assert st.state == "error" and "not found" in st.reason
    ax.reset()
    st = run(ctl, home_move(ctl, "x", HomeConfig(mode=0, timeout_s=0.5, **FAST)))
    assert st.state == "error" and "timeout" in st.reason


def test_budget_refused_before_anything_changes():
    ctl, ax = make(20000)
    snap = ax.snapshot()
    h = Homing(ctl, "x", HomeConfig(mode=0, max_overrun=100.0, **FAST))
    assert h.overrun(20000.0) == pytest.approx(20000 * 0.001 + 20000**2 / (2 * 360000))
    with pytest.raises(MotionError, match="max_overrun"):
        h.start()
    assert ax.snapshot() == snap and h.status.state == "idle"


@pytest.mark.parametrize("kwargs,match", [
    (dict(mode=13), "mode"), (dict(mode="linuxcnc"), "mode"), (dict(direction=0), "direction"),
    (dict(str_vel=-1.0), "str_vel"), (dict(str_vel=6000.0, max_vel=5000.0), "str_vel"),
    (dict(tacc=0.0), "tacc"), (dict(ez_count=16), "ez_count"), (dict(ez_count=1.5), "ez_count"),
    (dict(org_offset=float("nan")), "org_offset"), (dict(final="x"), "final"),
    (dict(el_stop="maybe"), "el_stop"), (dict(home_offset=0.5), "home_offset"),
    (dict(max_vel=float("inf")), "max_vel"), (dict(jerk=0.0), "jerk"),
])
def test_bad_config_refused(kwargs, match):
    with pytest.raises(MotionError, match=match):
        HomeConfig(**kwargs)


def test_ez_mode_refused_without_index_and_when_disabled():
    base = default_machine()
    x = base.axes[0]
    cfg = MachineConfig(name="m", axes=(AxisConfig(**{**x.__dict__, "encoder_mode": "pulse_dir",
                                                      "encoder_lines_per_rev": 10000}),))
    ctl = Controller(cfg, safety=False)
    with pytest.raises(MotionError, match="EZ index"):
        Homing(ctl, "x", HomeConfig(mode=3))
    h = Homing(ctl, "x", HomeConfig(mode=0))
    with pytest.raises(MotionError, match="disabled"):
        h.start()
    assert ctl.axis("x").state is S.DISABLED and h.status.state == "idle"


def test_motion_commands_refused_while_homing():
    ctl, ax = make(20000)
    h = home_move(ctl, "x", HomeConfig(mode=0, **FAST))
    with pytest.raises(MotionError, match="homing"):
        ax.move_relative(100, max_vel=1000)
    run(ctl, h)


# -- with the safety layer attached -----------------------------------------------------------
def test_el_mode_with_safety_suspends_and_resumes_the_limit():
    ctl, ax = make(20000, safety=True)
    safety = Safety.of(ctl)
    safety.set_erc(0, 0.005)
    st = run(ctl, home_move(ctl, "x", HomeConfig(mode=6, **FAST)))
    assert st.state == "done", st.reason
    assert ctl.hardware.motor_position(0) == -5001
    assert safety.settings(0).suspended == set()
    assert ctl.hardware.read_output(0, "erc")  # ERC one-shot on home completion
    # back in service: the limit reacts again
    with pytest.raises(MotionError, match="EL"):
        ax.move_relative(-100, max_vel=1000)


def test_orgless_limit_hit_with_safety_stops_homing():
    ctl, ax = make(-2000, safety=True)
    assert Safety.of(ctl) is not None
    st = run(ctl, home_move(ctl, "x", HomeConfig(mode=0, **FAST)))
    assert st.state in ("error", "aborted") and "EL" in st.reason
    assert ax.state is S.ERROR_STOP


def test_escape_home_leaves_org_and_keeps_counters():
    ctl, ax = make(3000)
    h = escape_home(ctl, "x", HomeConfig(mode=0, org_offset=200, **FAST))
    st = run(ctl, h)
    assert st.state == "done"
    assert not ctl.input_active(0, "org")
    assert ctl.hardware.motor_position(0) == 5050 + 200
    assert ax.counters.command == 5250
