"""The HSL network: files with one machine section per module, 16 modules / 63 axes,
scan and command times (Tables 4-1, 6-1, 6-2), polling loops in virtual time, the
scenario helper and the ported example program."""

from __future__ import annotations

import math
import runpy
from pathlib import Path

import pytest

from openmotion.compat.hsl import HslLibrary, HslSim
from openmotion.compat.hsl import errors as E
from openmotion.config_network import (
    ModuleConfig,
    NetworkConfig,
    default_module,
    loads_network,
)
from openmotion.control.cards import network as N
from openmotion.errors import MotionError

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "hsl"

FILE = """
[network]
rate = "6M"
duplex = "half"

[modules.0]
slave_id = 1
name = "a"
[modules.0.axes.x]
unit = "pulse"
max_speed = 100000.0

[modules.3]
slave_id = 9
name = "b"
cycle_s = 0.001
[modules.3.axes.p]
unit = "pulse"
max_speed = 1000.0
[modules.3.axes.q]
unit = "mm"
"""


def test_network_file_one_machine_section_per_module():
    cfg = loads_network(FILE)
    assert [m.index for m in cfg.modules] == [0, 3]
    assert cfg.modules[1].machine.axis_names == ("p", "q")
    hsl = HslLibrary.from_config(cfg)
    hsl.HSL_initial(0)
    assert hsl.HSL_M_get_axis_no(3, 1) == 13
    assert hsl.HSL_M_get_axis_location(12) == (3, 0)
    assert hsl.HSL_M_motion_done(1) == E.ERR_InvalidAxis     # module 0 has one axis
    assert hsl.HSL_M_motion_done(4) == E.ERR_InvalidAxis     # no module 1
    # module 3's own section: axis p's safe speed is 1000 pps
    assert hsl.HSL_M_start_tv_move(12, 0, 5000, 0.1) == E.ERR_InvalidParameter
    assert "1000" in hsl.last_error.message
    assert hsl.HSL_get_scan_time(0) == pytest.approx(59e-6 * 10)   # half duplex, IDs 1, 9, 10


@pytest.mark.parametrize("text,words", [
    ("[modules.0]\nname='a'\n[modules.0.axes.x]\n", "slave_id is required"),
    ("[modules.x]\nslave_id=1\n[modules.x.axes.x]\n", "connect index"),
    ("[network]\nrate='5M'\n[modules.0]\nslave_id=1\n[modules.0.axes.x]\n", "rate"),
    ("[network]\nspeed=1\n", "unknown key"),
    ("[modules.0]\nslave_id=1\n[modules.0.axes.x]\n[modules.0.axes.w]\n[modules.1]\n"
     "slave_id=3\n[modules.1.axes.y]\n", "already used by module 0"),
    ("[modules.0]\nslave_id=1\n[modules.0.axes.x]\nlead=-1\n", "modules.0: axes.x.lead"),
    ("[modules.0]\nslave_id=1\n[modules.0.axes]\n", "1..4 axes"),
])
def test_network_file_errors_name_the_key(text, words):
    with pytest.raises(MotionError, match=words):
        loads_network(text)


def test_at_most_16_modules_and_63_axes():
    mods = [ModuleConfig(k, 1 + k * 4, default_module(f"m{k}")) for k in range(16)]
    with pytest.raises(MotionError, match="63"):
        NetworkConfig(tuple(mods), duplex="half")       # 64 axes (and ID 64)
    mods[-1] = ModuleConfig(15, 61, default_module("m15", 3))
    cfg = NetworkConfig(tuple(mods), duplex="half")
    assert sum(len(m.machine.axes) for m in cfg.modules) == 63
    with pytest.raises(MotionError, match="connect index"):
        ModuleConfig(16, 1, default_module())


def test_table_4_1_and_the_scan_formula():
    t = N.NetworkTiming
    assert t("6M", "full").scan_time([1, 3, 5, 7]) == pytest.approx(243.2e-6)
    assert t("3M", "half").scan_time([1, 2, 3, 4]) == pytest.approx(4 * 118e-6)
    assert t("12M", "full").scan_time(range(1, 33)) == pytest.approx(32 * 15.2e-6)
    assert t("3M", "full").base_scan_s == 60.7e-6 and t("12M", "half").base_scan_s == 29.5e-6


def test_table_6_2_command_times_and_the_recommended_formula():
    t = N.NetworkTiming()
    for kind, ms in N.COMMAND_MS.items():
        for n, value in ms.items():
            assert t.command_time(kind, n) == pytest.approx(value * 1e-3)
    # other module counts: deliveries x (0.5 ms, or 0.5 + (N(+1) - 4)/2 x 0.24 ms)
    assert N.delivery_ms(2) == 0.5
    assert N.delivery_ms(5) == pytest.approx(0.74) and N.delivery_ms(6) == pytest.approx(0.74)
    assert N.delivery_ms(8) == pytest.approx(0.98)     # Table 6-2 measured 1.000
    assert t.command_time(N.ONE_AXIS, 6) == pytest.approx(6 * 0.74e-3)
    assert t.command_time(N.SHORT, 16) == pytest.approx(2 * (0.5 + 12 / 2 * 0.24) * 1e-3)
    assert N.NetworkTiming(rate="12M").command_time(N.SIMPLE, 1) == \
        pytest.approx(0.413e-3 * 15.2 / 30.4)
    assert N.NetworkTiming(scale=0.0).command_time(N.ONE_AXIS, 1) == 0.0


def test_each_call_costs_its_table_time():
    hsl = HslLibrary.simulated(1)
    hsl.HSL_initial(0)
    t = hsl.network.time
    hsl.HSL_M_set_pls_outmode(0, 1)
    assert hsl.network.time - t == pytest.approx(0.429e-3)   # a U16 setting
    t = hsl.network.time
    hsl.HSL_M_start_tr_move(0, 1000, 0, 10000, 0.01, 0.01)
    assert hsl.network.time - t == pytest.approx(2.588e-3)    # one-axis motion
    t = hsl.network.time
    hsl.HSL_M_start_tr_move(0, 1, 0, 1, 1, 1)                 # busy: the module answers
    assert hsl.network.time - t == pytest.approx(2.588e-3)
    t = hsl.network.time
    hsl.HSL_M_start_tr_move(99, 1, 0, 1, 1, 1)                # the DLL refuses: no packet
    assert hsl.network.time == t
    hsl.HSL_M_verify_speed(0, 0, 5000)                        # computed on the host
    assert hsl.network.time == t


def test_a_polling_loop_advances_time_ends_and_sees_the_latency():
    hsl = HslLibrary.simulated(1)
    hsl.HSL_initial(0)
    hsl.HSL_M_start_tr_move(0, 10000, 0, 10000, 0.1, 0.1)
    ctl = hsl.controller(0)
    end = ctl.axes[0].motion.t_start + ctl.axes[0].motion.profile.duration
    polls = 0
    while hsl.HSL_M_motion_done(0):
        polls += 1
    poll = hsl.network.command_time(N.GET_U16)
    assert hsl.network.time >= end
    assert hsl.network.time - end <= poll + ctl.period + 1e-9   # one call late at most
    assert polls == pytest.approx((end - 2.588e-3) / poll, abs=3)
    # with eight modules the same loop is slower per call
    eight = HslLibrary.simulated(8)
    eight.HSL_initial(0)
    eight.HSL_M_start_tr_move(0, 10000, 0, 10000, 0.1, 0.1)
    n8 = 0
    while eight.HSL_M_motion_done(0):
        n8 += 1
    assert n8 == pytest.approx((end - 6e-3) / 1e-3, abs=3)


def test_waiting_for_an_event_with_motion_done_equal_zero():
    # `while (HSL_M_motion_done(axis) == 0)`: waiting for a motion another module starts
    hsl = HslLibrary.simulated(2)
    hsl.HSL_initial(0)
    hsl.HSL_M_set_general_comparator(0, 0, 1, 0, 0.0)
    hsl.controller(0).add_cycle_hook(
        lambda c, t: t > 0.05 and not c.axes[0].is_moving and c.axes[0].counters.command == 0
        and c.axes[0].move_velocity(1000.0, tacc=0.01))
    t0 = hsl.network.time
    while hsl.HSL_M_motion_done(0) == 0:
        pass
    assert 0.05 <= hsl.network.time - t0 <= 0.05 + 2e-3


def test_sim_switches_alarm_and_per_module_estop():
    hsl = HslLibrary.simulated(2)
    hsl.HSL_initial(0)
    sim = HslSim(hsl)
    sim.place_switch(0, "pel", 5000)
    hsl.HSL_M_start_tv_move(0, 0, 20000, 0.05)
    hsl.HSL_M_start_tv_move(4, 0, 20000, 0.05)
    hsl.HSL_M_start_tv_move(5, 0, 20000, 0.05)
    while hsl.HSL_M_motion_done(0):
        pass
    assert hsl.HSL_M_get_io_status(0) & (1 << 2)          # +EL
    assert 5000 <= hsl.HSL_M_get_command(0) <= 5000 + 20000 * 2e-3
    sim.trip_alarm(5)
    hsl.network.advance(0.01)
    assert hsl.HSL_M_get_current_speed(5) == 0 and hsl.HSL_M_get_io_status(5) & (1 << 1)
    assert hsl.HSL_M_get_current_speed(4) == 20000        # the other axis runs on
    sim.press_estop(1)
    hsl.network.advance(0.01)
    assert hsl.HSL_M_get_current_speed(4) == 0
    assert hsl.HSL_M_get_io_status(4) & (1 << 6)          # EMG of module 1
    assert hsl.HSL_M_start_tv_move(1, 0, 1000, 0.1) == 0  # module 0 is not stopped
    assert hsl.HSL_M_start_tv_move(6, 0, 1000, 0.1) == E.ERR_AxisState
    sim.release_estop(1)
    hsl.network.advance(0.01)
    sim.reset_axis(6)
    assert hsl.HSL_M_start_tv_move(6, 0, 1000, 0.1) == 0


def test_the_ported_example_runs(capsys):
    runpy.run_path(str(EXAMPLES / "pick_and_scan.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "scan done, next compare value 69000" in out
    assert "arc end (1800, 600)" in out
    assert "feeder restart: " in out and "(refused)" in out


def test_config_from_file_and_version():
    hsl = HslLibrary.simulated(1)
    hsl.HSL_initial(0)
    assert hsl.HSL_M_version_info(0)[0] % 10 > 0      # 4th digit > 0: arcs with Tacc (4.6)
    assert hsl.HSL_M_config_from_file(str(EXAMPLES / "two_modules.toml")) == 0
    assert hsl.HSL_get_module_count(0) == 2
    assert hsl.HSL_M_get_axis_location(5) == (1, 1)
    assert hsl.HSL_M_start_tv_move(4, 0, 1000, 0.1) == 0
    assert hsl.HSL_M_config_from_file(str(EXAMPLES / "two_modules.toml")) == E.ERR_AxisBusy


def test_latch_through_the_library():
    hsl = HslLibrary.simulated(1)
    hsl.HSL_initial(0)
    sim = HslSim(hsl)
    assert hsl.HSL_M_set_ltc_logic(0, 0) == 0
    assert math.isnan(hsl.HSL_M_get_latch_data(0, 0))   # nothing latched
    sim.place_switch(0, "ltc", 1500, 100)
    hsl.HSL_M_start_tr_move(0, 3000, 0, 10000, 0.01, 0.01)
    while hsl.HSL_M_motion_done(0):
        pass
    assert hsl.HSL_M_get_latch_data(0, 0) == 1500        # command counter at the edge
    assert hsl.HSL_M_get_latch_data(0, 1) == 1500        # feedback
    assert hsl.HSL_M_get_latch_data(0, 7) == E.ERR_InvalidParameter


def test_soft_limits_comparator_speed_change_and_backlash():
    hsl = HslLibrary.simulated(1)
    hsl.HSL_initial(0)
    assert hsl.HSL_M_set_softlimit(0, 8000, -8000) == 0
    assert hsl.HSL_M_enable_softlimit(0, 0) == 0
    assert hsl.HSL_M_start_tr_move(0, 10000, 0, 10000, 0.01, 0.01) == E.ERR_Limit
    assert hsl.HSL_M_check_compare_data(0, 1) == 8000
    assert hsl.HSL_M_diable_softlimit(0) == 0
    # comparator 4: past command 5000, change speed to 20000 pps (cmp_v_change)
    assert hsl.HSL_M_cmp_v_change(0, 20000, 0.05) == 0
    assert hsl.HSL_M_fix_speed_range(0, 20000) == 0
    assert hsl.HSL_M_set_general_comparator(0, 0, 4, 3, 5000.0) == 0
    assert hsl.HSL_M_check_compare_data(0, 4) == 5000
    assert hsl.HSL_M_start_tr_move(0, 30000, 0, 10000, 0.01, 0.01) == 0
    top = 0.0
    while hsl.HSL_M_motion_done(0):
        top = max(top, hsl.HSL_M_get_current_speed(0))
    assert top == pytest.approx(20000, abs=1.0)
    assert hsl.HSL_M_get_command(0) == 30000
    # backlash: 50 corrective pulses on each direction change, counters unaffected
    assert hsl.HSL_M_backlash_comp(1, 50, 1) == 0
    hsl.HSL_M_start_tr_move(1, 1000, 0, 10000, 0.01, 0.01)
    while hsl.HSL_M_motion_done(1):
        pass
    hsl.HSL_M_start_tr_move(1, -500, 0, 10000, 0.01, 0.01)
    while hsl.HSL_M_motion_done(1):
        pass
    assert hsl.HSL_M_get_command(1) == 500
    assert hsl.controller(0).hardware.command_position(1) == pytest.approx(500 - 50, abs=1)


def test_4_3_slave_id_occupancy():
    # full duplex: start 1 -> IDs 1, 3, 5, 7; the second module at 2 -> 2, 4, 6, 8
    two = (ModuleConfig(0, 1, default_module()), ModuleConfig(1, 2, default_module()))
    assert [m.ids("full") for m in NetworkConfig(two).modules] == [(1, 3, 5, 7), (2, 4, 6, 8)]
    # half duplex: start 1 -> 1..4; the second module at 5 -> 5..8; at 3 they overlap
    half = (ModuleConfig(0, 1, default_module()), ModuleConfig(1, 5, default_module()))
    assert NetworkConfig(half, duplex="half").modules[1].ids("half") == (5, 6, 7, 8)
    with pytest.raises(MotionError, match="ID 3, already used by module 0"):
        NetworkConfig((half[0], ModuleConfig(1, 3, default_module())), duplex="half")


@pytest.mark.parametrize("method,fires", [(1, True), (2, False), (3, True)])
def test_general_comparator_counting_down(method, fires):
    hsl = HslLibrary.simulated(1)
    hsl.HSL_initial(0)
    hsl.HSL_M_set_command(0, 3000)
    assert hsl.HSL_M_set_general_comparator(0, 0, method, 1, 1000.0) == 0  # stop at once
    hsl.HSL_M_start_tr_move(0, -3000, 0, 10000, 0.01, 0.01)
    while hsl.HSL_M_motion_done(0):
        pass
    stopped = hsl.HSL_M_get_command(0)
    assert (stopped > 0) == fires
    assert (abs(stopped - 1000) <= 20) == fires
