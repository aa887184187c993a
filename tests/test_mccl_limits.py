"""MCCL facade: the maximum pulse speed and acceleration (2.6.4 I-III), the working
interval from the limit offsets (2.4) with the over-travel check, jog limits (2.6.2 III)."""

from __future__ import annotations

import numpy as np
import pytest

from mccl_common import manual_param, open_lib, per_period_pulses, state_of
from openmotion.compat import mccl_defs as D
from openmotion.control.groups.group import PERIOD_PULSES_MAX

# 10 000 pulses/mm, 546 mm/s (5.46 M pps): fast enough to pass 32768 pulses per 10 ms
FAST = dict(dwPPR=10000, wRPM=32767)


def test_max_pulse_speed_rule_and_defaults():
    # Max pulse speed = 32768 / interpolation time (pulse/ms): 32768 pulses per period
    assert PERIOD_PULSES_MAX == 32768
    lib = open_lib(period_ms=10, param=manual_param(**FAST))
    assert lib.MCC_GetMaxPulseSpeed(0) == (0, 30000, 30000, 30000, 30000, 0, 0)
    assert lib.MCC_GetMaxPulseAcc(0) == (0, 30000, 30000, 30000, 30000, 0, 0)
    g = lib._groups[0].group
    # the cap in pps is pulses per period / period: 30000 / 10 ms = 3 M pps
    assert g._vmax[0] == pytest.approx(3e6)


def test_a_line_over_the_per_period_cap_is_refused_and_one_at_it_keeps_it():
    lib = open_lib(period_ms=10, param=manual_param(**FAST))
    lib.MCC_SetSysMaxSpeed(500.0, 0)
    # 360.448 mm/s x 10 000 pulses/mm x 10 ms = 36 044.8 pulses in one period
    assert lib.MCC_SetFeedSpeed(360.448, 0) == 0
    before = state_of(lib)
    assert lib.MCC_Line(500, 0, 0, 0, 0, 0, 0) == D.FEED_RATE_ERR
    assert state_of(lib) == before
    # at 300 mm/s: 30 000 pulses per period, the default cap
    assert lib.MCC_SetFeedSpeed(300.0, 0) == 0
    t0 = lib.controller.time
    assert lib.MCC_Line(500, 0, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0, 30)
    n = per_period_pulses(lib, 0, t0, lib.controller.time)
    assert n.max() <= 30000 + 1e-6
    assert n.max() >= 30000 - 1e-6
    assert lib.MCC_GetPulsePos(0)[1] == 5_000_000


def test_set_max_pulse_speed_range_and_effect():
    lib = open_lib(period_ms=10, param=manual_param(**FAST))
    lib.MCC_SetSysMaxSpeed(500.0, 0)
    before = state_of(lib)
    for bad in (0, -1, 32769, 1.5, True):
        assert lib.MCC_SetMaxPulseSpeed(bad, 30000, 30000, 30000) == D.PARAMETER_ERR
    assert lib.MCC_SetMaxPulseSpeed(100, 100, 100, 100, wCardIndex=1) == D.PARAMETER_ERR
    assert state_of(lib) == before
    assert lib.MCC_SetMaxPulseSpeed(32768, 32768, 32768, 32768) == 0
    assert lib.MCC_SetFeedSpeed(327.68, 0) == 0   # 32 768 pulses per period: accepted
    assert lib.MCC_Line(100, 0, 0, 0, 0, 0, 0) == 0
    assert lib.MCC_SetFeedSpeed(360.448, 0) == 0
    assert lib.MCC_Line(200, 0, 0, 0, 0, 0, 0) == D.FEED_RATE_ERR  # beyond 32768 always
    assert lib.wait_motion(0, 30)
    # a low cap: 100 pulses per period = 10 000 pps = 1 mm/s for PtP at 100 %
    assert lib.MCC_SetMaxPulseSpeed(100, 100, 100, 100) == 0
    assert lib.MCC_SetPtPSpeed(100, 0) == 0
    t0 = lib.controller.time
    assert lib.MCC_PtP(101.1, 0.5, 0, 0, 0, 0, 0) == 1   # (refused ones take no index)
    assert lib.wait_motion(0, 30)
    for axis in (0, 1):
        assert per_period_pulses(lib, axis, t0, lib.controller.time).max() <= 100 + 1e-6


def test_max_pulse_acc_caps_the_change_between_periods():
    lib = open_lib(period_ms=10, param=manual_param(**FAST))
    lib.MCC_SetSysMaxSpeed(500.0, 0)
    lib.MCC_SetFeedSpeed(100.0, 0)           # 10 000 pulses per period
    lib.MCC_SetAccStep(10, 0)                # reach it in 10 periods: +1000 per period
    assert lib.MCC_SetMaxPulseAcc(500, 500, 500, 500) == 0
    assert lib.MCC_Line(200, 0, 0, 0, 0, 0, 0) == D.FEED_RATE_ERR
    assert lib.MCC_SetMaxPulseAcc(1000, 1000, 1000, 1000) == 0
    t0 = lib.controller.time
    assert lib.MCC_Line(200, 0, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0, 30)
    n = per_period_pulses(lib, 0, t0, lib.controller.time)
    assert np.abs(np.diff(n)).max() <= 1000 * (1 + 1e-9)


def test_working_interval_from_the_limit_offsets():
    # dfHighLimit 30, offset 5: positive working interval 25; dfLowLimit -20, offset 2: -18
    lib = open_lib(param=manual_param(dfHighLimit=30.0, dfHighLimitOffset=5.0,
                                      dfLowLimit=-20.0, dfLowLimitOffset=2.0))
    lib.MCC_SetFeedSpeed(20.0, 0)
    assert lib.MCC_SetOverTravelCheck(1, 1, 0, 0, 0, 0, 0) == 0
    assert lib.MCC_GetOverTravelCheck(0) == (0, 1, 1, 0, 0, 0, 0)
    before = state_of(lib)
    assert lib.MCC_Line(25.5, 0, 0, 0, 0, 0, 0) < 0     # past 30 - 5
    assert lib.MCC_Line(0, -18.5, 0, 0, 0, 0, 0) < 0    # past -20 + 2
    assert state_of(lib) == before
    assert lib.MCC_Line(25, -18, 0, 0, 0, 0, 0) == 0    # on the borders
    assert lib.MCC_Line(0, 0, 40, 0, 0, 0, 0) == 1      # z not checked
    assert lib.wait_motion(0, 30)
    assert lib.MCC_GetCurPos(0)[1:4] == (0.0, 0.0, 40.0)


@pytest.mark.parametrize("field,value", [
    ("dfHighLimitOffset", -1.0), ("dfHighLimitOffset", 50001.0), ("dfLowLimitOffset", -1.0),
    ("dfLowLimitOffset", 50001.0), ("dfLowLimit", 10.0), ("dfHighLimit", -1.0)])
def test_limit_offsets_out_of_range_are_refused(field, value):
    from openmotion.compat.mccl import MCCL
    lib = MCCL()
    p = manual_param(**{field: value})
    assert lib.MCC_SetMachParam(p, 0, 0) == D.PARAMETER_ERR
    got = manual_param()
    lib.MCC_GetMachParam(got, 0, 0)
    assert got == manual_param()  # unchanged (the defaults)


def test_jog_pulse_limit_and_only_without_motion():
    lib = open_lib()
    before = state_of(lib)
    assert lib.MCC_JogPulse(2049, 0, 0) == D.PARAMETER_ERR    # maximum 2048 pulses
    assert lib.MCC_JogPulse(0, 0, 0) == D.PARAMETER_ERR
    assert lib.MCC_JogPulse(10, 6, 0) == D.PARAMETER_ERR
    assert state_of(lib) == before
    assert lib.MCC_JogPulse(2048, 0, 0) == 0
    assert lib.MCC_JogPulse(10, 1, 0) == D.COMMAND_NOTACCEPTED_ERR  # there is motion
    assert lib.wait_motion(0)
    assert lib.MCC_JogPulse(-10, 0, 0) == 1
    assert lib.wait_motion(0)
    assert lib.MCC_GetPulsePos(0)[1] == 2038


def test_jog_space_and_jog_conti_to_the_working_interval_border():
    lib = open_lib(param=manual_param(dfHighLimit=30.0, dfHighLimitOffset=5.0))
    t0 = lib.controller.time
    assert lib.MCC_JogSpace(1, 20, 0, 0) == 0       # 1 mm at 20 % of 50 mm/s
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    v = lib.controller.history.sample(0, t).v / 500.0
    assert v.max() == pytest.approx(10.0, rel=1e-9)
    assert lib.MCC_GetCurPos(0)[1] == 1.0
    assert lib.MCC_JogConti(0, 50, 0, 0) == 1       # positive, 50 %
    lib.advance(0.2)
    assert lib.MCC_GetMotionStatus(0) == D.GMS_RUNNING
    assert lib.wait_motion(0, 10)
    assert lib.MCC_GetCurPos(0)[1] == 25.0          # stops at 30 - 5
    assert lib.MCC_JogConti(0, 50, 0, 0) == D.COMMAND_NOTACCEPTED_ERR  # at the border
    assert lib.MCC_JogConti(1, 50, 0, 0) == 2       # negative: stopped by an abort
    lib.advance(0.3)
    assert lib.MCC_AbortMotion(0) == 0
    assert lib.wait_motion(0)
    x = lib.MCC_GetCurPos(0)[1]
    assert -49995.0 < x < 25.0


@pytest.mark.parametrize("mode", [0, 1])
def test_limit_switch_check_modes(mode):
    from openmotion.config import SwitchConfig
    # y starts on its engaged -OT switch (active up to 0.5 mm); the line moves y up, away
    lib = open_lib(axis_setup=lambda card, ch: {"mel": SwitchConfig(250.0, -100000.0)}
                   if ch == 1 else {})
    assert lib.MCC_GetLimitSwitchStatus(1, 1, 0) == (0, 1)
    assert lib.MCC_EnableLimitSwitchCheck(mode) == 0
    lib.MCC_SetFeedSpeed(10.0, 0)
    assert lib.MCC_Line(0, 2, 0, 0, 0, 0, 0) == 0
    lib.wait_motion(0)
    if mode == 0:   # direction sensitive: moving away from the switch is allowed
        assert lib.MCC_GetErrorCode(0) == D.ERROR_NONE
        assert lib.MCC_GetCurPos(0)[2] == 2.0
    else:           # any engaged switch stops the moving group
        assert lib.MCC_GetErrorCode(0) == D.ERROR_LIMIT_SWITCH
        assert lib.MCC_GetCurPos(0)[2] < 0.5
    assert lib.MCC_EnableLimitSwitchCheck(2) == D.PARAMETER_ERR
    assert lib.MCC_DisableLimitSwitchCheck() == 0
