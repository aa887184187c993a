"""Every worked example of the HSL-4XMO manual, through the HSL library facade.

Each test names the manual section and uses the manual's numbers; the network charges
every call its wire time (Table 6-2), so the polling loops below advance virtual time.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from openmotion.compat.hsl import HslLibrary, HslSim
from openmotion.compat.hsl import errors as E
from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.config_network import ModuleConfig, NetworkConfig
from openmotion.control.cards.network import GET_U32
from openmotion.profile.onthefly import change_speed


def library(modules: int = 1) -> HslLibrary:
    hsl = HslLibrary.simulated(modules)
    assert hsl.HSL_initial(0) == 0
    return hsl


def wait_command(hsl: HslLibrary, axis: int, position: float) -> None:
    """Poll the command counter until it reaches `position` (a legacy busy loop)."""
    for _ in range(10**6):
        if hsl.HSL_M_get_command(axis) >= position:
            return
    raise AssertionError("position never reached")


def reach(hsl: HslLibrary, axis: int, position: float) -> None:
    """Run the network until the commanded position is `position` (the tables' "at
    CurrentPos the function is applied": the call then acts at exactly that position)."""
    ax = hsl.controller(axis // 4).axes[axis % 4]
    assert hsl.network.run_until(lambda: ax.position >= position - 1e-6, 60.0)


def wait_done(hsl: HslLibrary, axis: int) -> int:
    n = 0
    while hsl.HSL_M_motion_done(axis):
        n += 1
        assert n < 10**6
    return n


# 4.11, Table 4-6: start_tr_move(0, 10000, 0, 1000, 0.1, 0.1); v_change(0, NewVel, Tacc)
# at 5000 pulses. Necessary remaining pulses: acceleration, deceleration, OK / Error.
TABLE_4_6 = [(5000, 0.1, 300, 313, True), (5000, 1.0, 3000, 3125, False),
             (10000, 0.1, 550, 556, True), (50000, 0.1, 2550, 2551, False)]


def half_up(x: float) -> int:
    return math.floor(x + 0.5)


@pytest.mark.parametrize("new_vel,tacc,need_acc,need_dec,ok", TABLE_4_6)
def test_table_4_6_v_change(new_vel, tacc, need_acc, need_dec, ok):
    hsl = library()
    assert hsl.HSL_M_fix_speed_range(0, 50000) == 0   # needed for v_change above MaxVel
    assert hsl.HSL_M_start_tr_move(0, 10000, 0, 1000, 0.1, 0.1) == 0
    reach(hsl, 0, 5000)
    ax = hsl.controller(0).axes[0]
    m = ax.motion
    probe = change_speed(m.profile, ax._ctl.time - m.t_start, m.spec, new_vel, tacc,
                         target=m.target) if ok else None
    before = (m.t_start, m.profile.duration)
    r = hsl.HSL_M_v_change(0, new_vel, tacc)
    if ok:
        assert r == 0
        assert (half_up(probe.needed_accel), half_up(probe.needed_decel)) == (need_acc, need_dec)
        top = 0.0
        while hsl.HSL_M_motion_done(0):
            top = max(top, hsl.HSL_M_get_current_speed(0))
        assert top == pytest.approx(new_vel, rel=1e-6)
    else:
        assert r == E.ERR_Infeasible
        msg = hsl.HSL_M_get_error_message(r)
        got = re.search(r"\(([\d.]+) to change, ([\d.]+) to decelerate\)", msg)
        assert (half_up(float(got[1])), half_up(float(got[2]))) == (need_acc, need_dec)
        assert (ax.motion.t_start, ax.motion.profile.duration) == before  # unchanged
        wait_done(hsl, 0)
    assert hsl.HSL_M_get_command(0) == 10000


# 4.11, Table 4-7: start_ta_move(0, 10000, 0, 1000, 0.5, 1); p_change(0, 5000) at
# CurrentPos. Deceleration needs 0.5 * 1000 * 1 = 500 pulses.
TABLE_4_7 = [(4000, True, False), (4501, False, False), (5000, False, False),
             (5499, False, False), (6000, True, True), (9499, True, True),
             (9500, False, False), (9999, False, False)]


@pytest.mark.parametrize("current,ok,go_back", TABLE_4_7)
def test_table_4_7_p_change(current, ok, go_back):
    hsl = library()
    assert hsl.HSL_M_start_ta_move(0, 10000, 0, 1000, 0.5, 1) == 0
    reach(hsl, 0, current)
    assert hsl.controller(0).axes[0].counters.command == current
    r = hsl.HSL_M_p_change(0, 5000)
    if not ok:
        assert r == E.ERR_Infeasible
        wait_done(hsl, 0)
        assert hsl.HSL_M_get_command(0) == 10000
        return
    assert r == 0
    highest = current
    while hsl.HSL_M_motion_done(0):
        highest = max(highest, hsl.HSL_M_get_command(0))
    assert hsl.HSL_M_get_command(0) == 5000
    assert hsl.HSL_M_get_target_pos(0) == 5000
    assert (highest > max(current, 5000)) == go_back


def test_table_4_7_deceleration_starts_500_pulses_before_the_target():
    hsl = library()
    hsl.HSL_M_start_ta_move(0, 10000, 0, 1000, 0.5, 1)
    reach(hsl, 0, 9499)
    assert hsl.HSL_M_motion_done(0) == 12          # at MaxVel
    reach(hsl, 0, 9501)
    assert hsl.HSL_M_motion_done(0) == 13          # decelerating


# 4.6 "Trapezoidal Motion": command 80 pulses/mm, table encoder 200 pulses/mm, ratio 2.5.
def geared_library() -> HslLibrary:
    ax = AxisConfig(name="x", unit="pulse", pulses_per_rev=8000, move_ratio=2.5,
                    max_speed=1e6, drive=DriveConfig(type="ideal_stepper"))
    cfg = NetworkConfig((ModuleConfig(0, 1, MachineConfig("geared", (ax,))),))
    hsl = HslLibrary.from_config(cfg)
    hsl.HSL_initial(0)
    return hsl


def test_move_ratio_2_5_makes_absolute_moves_right():
    hsl = geared_library()
    assert hsl.HSL_M_set_move_ratio(0, 200 / 80) == 0
    for mm in (100, 200, 50):       # 100 mm/round: 8000 command pulses, 20000 counts
        assert hsl.HSL_M_start_ta_move(0, 80 * mm, 0, 40000, 0.05, 0.05) == 0
        wait_done(hsl, 0)
        assert hsl.HSL_M_get_command(0) == 80 * mm
        assert hsl.HSL_M_get_position(0) == 200 * mm
        assert hsl.HSL_M_get_error_counter(0) == 0


def test_without_the_move_ratio_absolute_moves_go_wrong():
    hsl = geared_library()
    hsl.HSL_M_start_ta_move(0, 8000, 0, 40000, 0.05, 0.05)
    wait_done(hsl, 0)
    hsl.HSL_M_start_ta_move(0, 16000, 0, 40000, 0.05, 0.05)
    wait_done(hsl, 0)
    # the distance was measured from the feedback 20000 read as command pulses
    assert hsl.HSL_M_get_command(0) == 8000 + (16000 - 20000)


# 4.6: encoder 2000 counts per phase (x4), 3600 rpm -> MaxVel = 3600/60*2000*4 = 480000.
def test_rpm_to_pps_conversion():
    ax = AxisConfig(name="x", unit="pulse", pulses_per_rev=8000, encoder_lines_per_rev=2000,
                    max_speed=1e6, drive=DriveConfig(type="ideal_stepper"))
    hsl = HslLibrary.from_config(NetworkConfig((ModuleConfig(0, 1, MachineConfig(
        "servo", (ax,))),)))
    hsl.HSL_initial(0)
    max_vel = 3600 / 60 * 2000 * 4
    assert max_vel == 480000
    assert hsl.HSL_M_tv_move(0, 0, max_vel, 0.1) == 0
    hsl.network.advance(0.2)
    assert hsl.HSL_M_get_current_speed(0) == pytest.approx(480000)
    p0, t0 = hsl.HSL_M_get_position(0), hsl.network.time
    hsl.network.advance(1.0)
    counts = hsl.HSL_M_get_position(0) - p0
    dt = hsl.network.time - t0 - hsl.network.command_time(GET_U32)
    rpm = counts / dt / (2000 * 4) * 60
    assert rpm == pytest.approx(3600, rel=1e-3)


# 4.6 "Relationship between Velocity and Acceleration Time": 0 -> 5000 pps.
def test_verify_speed_examples():
    hsl = library()
    v, t_min, t_max = hsl.HSL_M_verify_speed(0, 0, 5000, 5000)
    assert t_min == pytest.approx(0.0267, rel=5e-3)
    assert t_max == pytest.approx(873.587, rel=5e-3)
    v2, t_min2, t_max2 = hsl.HSL_M_verify_speed(0, 0, 5000, 140000)
    assert round(t_min2, 6) == 0.000948           # as printed
    assert round(t_max2, 2) == 31.08
    assert t_max / t_min == pytest.approx(32768)
    assert 3.0 <= v2 < 3.0 + 140000 / 65535 * 2   # "3 pps more than the 0 pps setting"
    assert hsl.HSL_M_verify_speed(0, 0, 5000) == hsl.HSL_M_verify_speed(0, 0, 5000, 5000)


def accel_time(hsl: HslLibrary, axis: int, top: float) -> float:
    t0 = hsl.network.time
    while hsl.HSL_M_get_current_speed(axis) < top * (1 - 1e-9):
        pass
    return hsl.network.time - t0


def test_fix_speed_range_gives_the_1ms_acceleration():
    hsl = library()
    # without a fixed range the 1 ms ramp is slowed to the range's shortest, 0.0267 s
    assert hsl.HSL_M_start_tr_move(0, 5000, 0, 5000, 0.001, 0.001) == 0
    spec = hsl.controller(0).axes[0].motion.spec
    assert spec.tacc == pytest.approx(0.0267, rel=5e-3)
    wait_done(hsl, 0)
    assert hsl.HSL_M_fix_speed_range(1, 140000) == 0
    assert hsl.HSL_M_start_tr_move(1, 5000, 0, 5000, 0.001, 0.001) == 0
    spec = hsl.controller(0).axes[1].motion.spec
    assert spec.tacc == 0.001                      # meets the 1 ms requirement
    assert spec.max_vel == pytest.approx(5000, abs=140000 / 65535)  # on the coarse grid
    wait_done(hsl, 1)
    assert hsl.HSL_M_get_command(1) == 5000


def test_fixed_range_refuses_faster_moves_and_v_changes():
    hsl = library()
    hsl.HSL_M_fix_speed_range(0, 20000)
    snap = hsl.controller(0).axes[0].snapshot()
    assert hsl.HSL_M_start_tr_move(0, 50000, 0, 30000, 0.1, 0.1) == E.ERR_SpeedRange
    assert hsl.controller(0).axes[0].snapshot() == snap
    assert hsl.HSL_M_start_tr_move(0, 50000, 0, 10000, 0.1, 0.1) == 0
    hsl.network.advance(0.5)
    assert hsl.HSL_M_v_change(0, 25000, 0.1) == E.ERR_SpeedRange
    assert hsl.HSL_M_v_change(0, 20000, 0.1) == 0
    assert hsl.HSL_M_unfix_speed_range(0) == 0
    wait_done(hsl, 0)
    assert hsl.HSL_M_get_command(0) == 50000


# 4.10, Table 4-5: module 1 -> axes 0..3, module 2 -> 4..7, module 3 -> 8..11;
# CM3 of module 2 accelerates 0 -> 10000 pps in 0.5 s: HSL_M_start_tv_move(6, 0, 10000, 0.5).
def test_table_4_5_axis_numbering():
    hsl = library(3)
    for module in (1, 2, 3):
        for cm in range(4):
            axis = hsl.HSL_M_get_axis_no(module - 1, cm)
            assert axis == 4 * (module - 1) + cm
            assert hsl.HSL_M_get_axis_location(axis) == (module - 1, cm)
    assert hsl.HSL_M_start_tv_move(6, 0, 10000, 0.5) == 0
    hsl.network.advance(0.6)
    moving = [a for a in range(12) if hsl.HSL_M_get_current_speed(a) > 0]
    assert moving == [6]
    assert hsl.controller(1).axes[2].speed == 10000
    assert hsl.HSL_M_get_current_speed(6) == 10000


def test_63_axes_on_16_modules():
    hsl = library(16)
    assert hsl.HSL_get_module_count(0) == 16
    assert hsl.HSL_M_get_axis_location(62) == (15, 2)
    assert hsl.HSL_M_motion_done(63) == E.ERR_InvalidAxis
    assert hsl.HSL_M_start_tr_move(62, 1000, 0, 10000, 0.01, 0.01) == 0
    wait_done(hsl, 62)
    assert hsl.HSL_M_get_command(62) == 1000
    assert hsl.HSL_M_get_command(61) == 0


# 4.6 "Circular interpolation": from (0, 0) around (1000, 0) to (1800, 600) at 1000 pps.
def test_arc_example():
    hsl = library()
    ctl = hsl.controller(0)
    rec = ctl.start_recording(channels=("cmd_pos", "cmd_vel"))
    assert hsl.HSL_M_start_a_arc_xy(0, 1000.0, 0, 1800.0, 600.0, 1000.0) == 0
    t0 = hsl.network.time
    wait_done(hsl, 0)
    assert (hsl.HSL_M_get_command(0), hsl.HSL_M_get_command(1)) == (1800, 600)
    data = rec.arrays()
    xy = data["cmd_pos"][:, :2]
    r = np.hypot(xy[:, 0] - 1000.0, xy[:, 1])
    np.testing.assert_allclose(r, 1000.0, atol=1e-6)
    assert np.max(xy[:, 1]) == pytest.approx(1000.0, abs=1e-3)   # CW over the top
    speed = np.hypot(data["cmd_vel"][:, 0], data["cmd_vel"][:, 1])
    assert np.max(speed) == pytest.approx(1000.0, rel=1e-9)
    sweep = math.pi - math.atan2(600, 800)               # 180 deg -> 36.87 deg, clockwise
    assert hsl.network.time - t0 == pytest.approx(sweep * 1000 / 1000, abs=2e-3)


def test_arc_with_direction_and_relative():
    hsl = library()
    assert hsl.HSL_M_start_r_arc_xy(0, 1000.0, 0.0, 1800.0, 600.0, 1, 1000.0) == 0  # CCW
    ctl = hsl.controller(0)
    low = 0.0
    while hsl.HSL_M_motion_done(0):
        low = min(low, ctl.axes[1].position)
    assert low == pytest.approx(-1000.0, abs=1.0)   # under the centre
    assert (hsl.HSL_M_get_command(0), hsl.HSL_M_get_command(1)) == (1800, 600)


# 4.6 "2 Axes Linear Interpolation": start_tr_move_xy(0, 30000, 40000, 1000, 5000, 0.1, 0.2)
def test_tr_move_xy_example():
    hsl = library()
    ctl = hsl.controller(0)
    rec = ctl.start_recording(channels=("cmd_vel",))
    assert hsl.HSL_M_start_tr_move_xy(0, 30000.0, 40000.0, 1000.0, 5000.0, 0.1, 0.2) == 0
    wait_done(hsl, 0)
    assert (hsl.HSL_M_get_command(0), hsl.HSL_M_get_command(1)) == (30000, 40000)
    v = rec.arrays()["cmd_vel"]
    vec = np.hypot(v[:, 0], v[:, 1])
    assert np.max(vec) == pytest.approx(5000.0, rel=1e-9)
    assert np.max(v[:, 0]) == pytest.approx(3000.0) and np.max(v[:, 1]) == pytest.approx(4000)
    # accel 1000 -> 5000 in 0.1 s, decel in 0.2 s: 300 + 600 pulses of ramps
    duration = 0.1 + 0.2 + (50000 - 300 - 600) / 5000
    moving = vec > 0
    t = rec.arrays()["t"][moving]
    # samples at cycle ends: the first after the start, the last before the end
    assert duration - 2.001e-3 <= t[-1] - t[0] <= duration + 1e-9
    first = vec[moving]
    up = np.argmax(first >= 5000 * (1 - 1e-9))
    assert (t[up] - t[0]) == pytest.approx(0.1, abs=2e-3)
    down = len(first) - np.argmax(first[::-1] >= 5000 * (1 - 1e-9))
    assert (t[-1] - t[down]) == pytest.approx(0.2, abs=2e-3)


# 4.12 "Continuously Comparison with Trigger Output": table 0 -> 36000 at 6000 pps,
# compare points 1001..35000 every pulse ("="), 34000 triggers for the CCD camera.
def test_ccd_compare_table():
    hsl = library()
    assert hsl.HSL_M_set_trigger_comparator(0, 1, 1, 0.0) == 0
    assert hsl.HSL_M_build_comp_function(0, 1001, 35000, 1) == 0
    assert hsl.HSL_M_set_auto_compare(0, 1) == 0
    assert hsl.HSL_M_check_compare_data(0, 5) == 1001.0
    assert hsl.HSL_M_start_ta_move(0, 36000, 0, 6000, 0.05, 0.05) == 0
    hsl.network.advance(1.0)
    current = hsl.HSL_M_check_compare_data(0, 5)
    assert 1001 < current < 35000
    assert hsl.HSL_M_check_compare_status(0) == 1
    wait_done(hsl, 0)
    log = hsl._modules[0].trigger.eng.log.arrays()
    assert log["time"].size == 34000
    np.testing.assert_allclose(np.diff(log["time"][5000:30000]), 1 / 6000, atol=1e-9)
    # the after-final dummy: (End + Interval x Total) x ratio
    assert hsl.HSL_M_check_compare_data(0, 5) == 35000 + 1 * 34000


# 4.11 Figure 4-35: an absolute move of 200000 pulses at 10000 pps; sensors 1, 2, 3 change
# the speed to 25000, 50000 and 100000 pps (Tacc 0.02).
def test_sensor_driven_v_change():
    hsl = library()
    sim = HslSim(hsl)
    ctl = hsl.controller(0)
    for ch, (on, off) in enumerate(((40000, 60000), (80000, 100000), (120000, 140000)),
                                   start=1):
        sim.sensor_at(0, ch, 0, on, True)
        sim.sensor_at(0, ch, 0, off, False)
    rec = ctl.start_recording(channels=("cmd_vel", "cmd_pos"))
    axis = 0
    assert hsl.HSL_M_fix_speed_range(axis, 100000) == 0
    assert hsl.HSL_M_start_ta_move(axis, 200000, 0, 10000, 0.02, 0.02) == 0
    while hsl.HSL_M_motion_done(axis):
        s1, s2, s3 = (sim.read_input(0, ch) for ch in (1, 2, 3))
        if s1 and not s2 and not s3:
            hsl.HSL_M_v_change(axis, 25000, 0.02)
        elif not s1 and s2 and not s3:
            hsl.HSL_M_v_change(axis, 50000, 0.02)
        elif not s1 and not s2 and s3:
            hsl.HSL_M_v_change(axis, 100000, 0.02)
    assert hsl.HSL_M_get_command(axis) == 200000
    d = rec.arrays()
    v, p = d["cmd_vel"][:, 0], d["cmd_pos"][:, 0]
    for lo, hi, speed in ((5000, 40000, 10000), (45000, 80000, 25000),
                          (85000, 120000, 50000), (125000, 195000, 100000)):
        sel = (p > lo) & (p < hi)
        # the speeds run on the fixed range's grid: 300/196 = 1.53 pps a step
        assert np.max(v[sel]) == pytest.approx(speed, abs=300 / 196 / 2)
        assert np.median(v[sel]) == np.max(v[sel])


# 4.3: one module (ID 1, 3, 5, 7) at 6M full duplex: 8 x 30.4 us = 243.2 us; 1.2 spec:
# half duplex one module and full duplex two modules: about 240 us. 6.1: command times.
def test_scan_time_examples():
    hsl = library(1)
    assert hsl.HSL_get_scan_time(0) == pytest.approx(243.2e-6)
    assert library(2).HSL_get_scan_time(0) == pytest.approx(243.2e-6)
    from openmotion.control.cards.network import NetworkTiming

    half = HslLibrary.simulated(1, timing=NetworkTiming(duplex="half"))
    half.HSL_initial(0)
    assert half.HSL_get_scan_time(0) == pytest.approx(236e-6)  # "240 us for one module"
    assert [hsl.HSL_connect_status(0, i) for i in range(1, 9)] == [1, 0, 1, 0, 1, 0, 1, 0]


# 4.6 "Home Search Example (Home mode=1)", figure 4-29: 1 search (-), 2 -EL: slow down and
# reverse (+), 3 ORG: slow down, 4 escape ORG by the ORG offset, 5 search again (-),
# 6-7 ORG found at search speed: the end of ORG is home.
def test_home_search_example():
    hsl = library()
    sim = HslSim(hsl)
    sim.place_switch(0, "mel", -10000, -1e9)
    sim.place_switch(0, "org", 20000, 500)
    assert hsl.HSL_M_set_home_config(0, 1, 0, 0, 0, 0) == 0
    assert hsl.HSL_M_home_search(0, 500, -20000, 0.1, 1000) == 0
    ax = hsl.controller(0).axes[0]
    low = high = 0.0
    while hsl.HSL_M_motion_done(0):
        low, high = min(low, ax.position), max(high, ax.position)
    steps = hsl._modules[0].homing[0].status.history
    assert steps[:2] == ["search ORG", "MEL hit: reverse"]
    assert "back off by org_offset" in steps and steps[-1] == "end of ORG"
    assert steps.index("back off by org_offset") < len(steps) - 2   # searched again
    assert low <= -10000 and high >= 20500 + 1000 - 1               # the offset escape
    assert hsl.HSL_M_get_command(0) == 0                            # counters cleared
    assert hsl.HSL_M_get_target_pos(0) != 0                         # the recorder is not
    assert hsl.HSL_M_reset_target_pos(0, 0) == 0
