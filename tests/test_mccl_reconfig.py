"""MCCL parameters changed on an initialised machine (2.4, 2.6.4 I, 2.9): the interpolation
time "later any time", MCC_UpdateMachParam after MCC_SetMachParam, the encoder rate."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import free_axes
from mccl_common import manual_param, open_lib, per_period_pulses
from openmotion.compat import mccl_defs as D
from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.errors import MotionError

FAST = {"dwPPR": 10000, "wRPM": 32767}   # 10 000 pulses/mm, 546 mm/s


def test_interpolation_time_set_later_scales_steps_caps_and_delays():
    lib = open_lib(period_ms=5, param=manual_param(**FAST))
    lib.MCC_SetSysMaxSpeed(500.0, 0)
    assert lib.MCC_SetFeedSpeed(360.448, 0) == 0
    # at 5 ms, 360.448 mm/s is 18 022.4 pulses per period: accepted
    assert lib.MCC_Line(1, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 30)
    assert lib.MCC_SetInterpolationTime(10) == D.NO_ERR
    assert lib.MCC_GetInterpolationTime() == 10 and lib.controller.period == 0.01
    # 36 044.8 pulses per 10 ms period: now over the 30 000 default cap (2.6.4)
    assert lib.MCC_Line(100, 0, 0, 0, 0, 0, 0) == D.FEED_RATE_ERR
    # the acceleration step count stays 20: 20 x 10 ms = 200 ms
    assert lib.MCC_GetAccStep(0) == 20
    assert lib.MCC_SetFeedSpeed(100.0, 0) == 0
    t0 = lib.controller.time
    assert lib.MCC_Line(101, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 30)
    t = np.arange(t0, lib.controller.time, 1e-4)
    v = lib.controller.history.sample(0, t).v / 10_000.0
    moving, cruise = np.nonzero(v > 1e-9)[0], np.nonzero(v >= 100.0 * (1 - 1e-9))[0]
    assert t[cruise[0]] - t[moving[0]] == pytest.approx(0.2, abs=2e-4)
    assert per_period_pulses(lib, 0, t0, lib.controller.time).max() <= 10_000 + 1e-6
    # the delay counts interpolation times of 10 ms: 200 x 10 ms = 2 s
    assert lib.MCC_Line(102, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.MCC_DelayMotion(200, 0) >= 0
    assert lib.MCC_Line(103, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 30)
    # cycles now come every 10 ms
    n0, t1 = lib.controller.cycles, lib.controller.time
    lib.advance(0.1)
    assert lib.controller.cycles - n0 == 10
    assert lib.controller.time == pytest.approx(t1 + 0.1, abs=1e-12)


def test_interpolation_time_refused_while_a_group_moves():
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetFeedSpeed(20.0, 0) == 0
    assert lib.MCC_Line(30, 0, 0, 0, 0, 0, 0) >= 0
    lib.advance(0.3)
    for bad in (0, 1001, 2.5, "5"):
        assert lib.MCC_SetInterpolationTime(bad) == D.PARAMETER_ERR
    assert lib.MCC_SetInterpolationTime(10) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_GetInterpolationTime() == 5 and lib.controller.period == 0.005
    assert lib.wait_motion(0, 30)
    assert lib.MCC_GetCurPos(0)[1] == 30.0
    assert lib.MCC_SetInterpolationTime(1) == D.NO_ERR
    assert lib.controller.period == 0.001


def test_controller_set_period_keeps_the_grid_and_asks_the_groups():
    ctl = free_axes(2, period=0.005)
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    g.set_period_pulse_caps([30_000, 30_000], [30_000, 30_000])
    ctl.advance(0.02)
    for bad in (0.0, 2.0, float("nan")):
        with pytest.raises(MotionError, match="period"):
            ctl.set_period(bad)
    g.line([10_000, 0])
    with pytest.raises(MotionError, match="period"):
        ctl.set_period(0.01)     # queued
    ctl.step()
    with pytest.raises(MotionError, match="period"):
        ctl.set_period(0.01)     # moving
    assert ctl.period == 0.005
    ctl.run_until(lambda: not g.axes[0].is_moving and g.queue_length == 0, 10.0)
    t = ctl.time
    assert g._amax[0] == pytest.approx(30_000 / 0.005 ** 2)
    ctl.set_period(0.01)
    assert g._amax[0] == pytest.approx(30_000 / 0.01 ** 2)   # the caps follow (2.6.4)
    ctl.step()
    assert ctl.time == pytest.approx(t + 0.01, abs=1e-12)
    g.line([0, 0])
    ctl.run_until(lambda: g.queue_length == 0 and not g.axes[0].is_moving, 10.0)
    assert g.axes[0].position == 0.0
    assert isinstance(ctl, Controller)


def test_encoder_rate_on_a_running_machine_changes_the_count_rate():
    lib = open_lib(period_ms=5)
    ppmm = lib.controller.axes[0].config.pulses_per_unit

    def moved(mm):
        before = lib.MCC_GetENCValue(0)[1]
        pos = lib.MCC_GetCurPos(0)[1]
        assert lib.MCC_Line(pos + mm, 0, 0, 0, 0, 0, 0) >= 0
        assert lib.wait_motion(0, 30)
        return lib.MCC_GetENCValue(0)[1] - before
    assert moved(4) == round(4 * ppmm)                    # x4, the default
    assert lib.MCC_SetENCInputRate(1, 0) == D.NO_ERR      # x1 of the same encoder
    assert moved(4) == round(4 * ppmm) // 4
    assert lib.MCC_SetENCInputRate(2, 0) == D.NO_ERR
    assert moved(-4) == -(round(4 * ppmm) // 2)
    assert lib.MCC_SetENCInputRate(4, 0) == D.NO_ERR
    assert moved(4) == round(4 * ppmm)
    assert lib.controller.axes[1].config.encoder_mode == "ab_x4"   # other channels keep
    # refused while the channel moves, and bad values; nothing changed
    assert lib.MCC_Line(30, 0, 0, 0, 0, 0, 0) >= 0
    lib.advance(0.2)
    assert lib.MCC_SetENCInputRate(1, 0) == D.COMMAND_NOTACCEPTED_ERR
    for bad in (3, 0, 8, 1.5):
        assert lib.MCC_SetENCInputRate(bad, 0) == D.PARAMETER_ERR
    assert lib.controller.axes[0].config.encoder_mode == "ab_x4"
    assert lib.wait_motion(0, 30)


def test_controller_set_encoder_mode_refusals():
    ctl = free_axes(1, period=0.005)
    before = ctl.axes[0].config
    for bad in ("x4", "cw_ccw", 4):
        with pytest.raises(MotionError, match="mode"):
            ctl.set_encoder_mode(0, bad)
    assert ctl.axes[0].config == before
    ctl.set_encoder_mode(0, "ab_x2")
    assert ctl.axes[0].config.encoder_mode == "ab_x2"
    assert ctl.config.axes[0].encoder_mode == "ab_x2"


def test_update_mach_param_applies_the_mechanism_on_a_machine_at_rest():
    lib = open_lib(period_ms=5)
    p = manual_param()
    ppmm = lib.controller.axes[0].config.pulses_per_unit
    assert lib.MCC_SetFeedSpeed(10.0, 0) == 0
    assert lib.MCC_Line(10, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 30)
    pulses = lib.MCC_GetPulsePos(0)[1]
    assert pulses == round(10 * ppmm)
    # 2.4: change the mechanism after MCC_InitSystem, then MCC_UpdateMachParam
    p.dwPPR *= 2                                   # twice the pulses per mm
    p.stEncoder.wABSwap = 1                        # encoder read with A/B swapped
    assert lib.MCC_SetMachParam(p, 0, 0) == 0
    assert lib.controller.axes[0].config.pulses_per_unit == ppmm   # not yet
    assert lib.MCC_UpdateMachParam() == D.NO_ERR
    assert lib.controller.axes[0].config.pulses_per_unit == 2 * ppmm
    assert lib.MCC_GetPulsePos(0)[1] == pulses     # the counters keep their pulses
    assert lib.MCC_GetCurPos(0)[1] == pytest.approx(5.0)   # 10 mm of the old ratio
    enc0 = lib.MCC_GetENCValue(0)[1]
    assert lib.MCC_Line(15, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 30)
    assert lib.MCC_GetPulsePos(0)[1] == pulses + round(10 * 2 * ppmm)
    assert lib.MCC_GetCurPos(0)[1] == pytest.approx(15.0)
    # the swapped A/B reading counts backwards (the encoder is wired as before)
    assert lib.MCC_GetENCValue(0)[1] - enc0 < 0
    # the speed limit follows wRPM (max speed = wRPM x pitch / (gear x 60))
    assert lib.MCC_SetFeedSpeed(40.0, 0) == 0
    p.wRPM = 600                                    # 600 x 2 / 60 = 20 mm/s
    assert lib.MCC_SetMachParam(p, 0, 0) == 0
    assert lib.MCC_UpdateMachParam() == D.NO_ERR
    assert lib.MCC_Line(0, 0, 0, 0, 0, 0, 0) == D.FEED_RATE_ERR


def test_update_mach_param_refusals_change_nothing():
    lib = open_lib(period_ms=5)
    cfg = lib.controller.axes[0].config
    p = manual_param()
    p.dwPPR = 4000
    assert lib.MCC_SetMachParam(p, 0, 0) == 0
    assert lib.MCC_SetFeedSpeed(20.0, 0) == 0
    assert lib.MCC_Line(30, 0, 0, 0, 0, 0, 0) >= 0
    lib.advance(0.2)
    assert lib.MCC_UpdateMachParam() == D.COMMAND_NOTACCEPTED_ERR    # moving
    assert lib.controller.axes[0].config == cfg
    assert lib.wait_motion(0, 30)
    assert lib.MCC_GetCurPos(0)[1] == 30.0
    bad = manual_param()
    bad.dfPitch = 0.0
    assert lib.MCC_SetMachParam(bad, 1, 0) == D.PARAMETER_ERR
    assert lib.controller.axes[0].config == cfg
    assert lib.MCC_UpdateMachParam() == D.NO_ERR
    assert lib.controller.axes[0].config.pulses_per_rev == 4000


def test_controller_reconfigure_axis_is_validated_and_told_to_groups():
    ctl = free_axes(2, period=0.005)
    g = Group(ctl, ["x", "y"], units=True, feed=10.0)
    before = ctl.axes[0].config
    for kw in ({"name": "q"}, {"lead": 0.0}, {"logic": {"pel": "x"}}):
        with pytest.raises(MotionError):
            ctl.reconfigure_axis(0, **kw)
        assert ctl.axes[0].config == before
    g.line([1.0, 0.0])
    with pytest.raises(MotionError, match="queued|running"):
        ctl.reconfigure_axis(0, pulses_per_rev=before.pulses_per_rev * 2)
    ctl.run_until(lambda: g.queue_length == 0 and not g.axes[0].is_moving, 10.0)
    x_pulses = ctl.axes[0].position
    ctl.reconfigure_axis(0, pulses_per_rev=before.pulses_per_rev * 2,
                         logic={"pel": "nc"})
    assert g.position[0] == pytest.approx(x_pulses / (2 * before.pulses_per_unit))
    assert ctl.config.axes[0].signal_logic("pel") == "nc"
