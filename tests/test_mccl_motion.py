"""MCCL facade: the manual's group example (2.5.1), default speeds and acceleration steps
(2.6.2, 2.6.4), separate acc/dec steps, the delay (2.6.3 V), hold/continue/abort, status
and command queries."""

from __future__ import annotations

import numpy as np
import pytest

from mccl_common import open_lib
from openmotion.compat import mccl_defs as D
from openmotion.compat.mccl import COMMAND_INFO


def first_motion(lib, axis, t0=0.0):
    """Time the axis first moves after t0 (from the history, 1 us resolution)."""
    ctl = lib.controller
    t = np.arange(t0, ctl.time, 1e-5)
    v = ctl.history.sample(axis, t).v
    return float(t[np.nonzero(np.abs(v) > 1e-9)[0][0]])


def test_four_command_group_example():
    # Figure 6: group 0 = channels 0, 1 and group 1 = channels 2, 3 of card 0
    lib = open_lib(groups={0: [0, 1], 1: [2, 3]})
    idx = [lib.MCC_Line(10, 10, 0, 0, 0, 0, 0),   # command 0
           lib.MCC_Line(15, 34, 0, 0, 0, 0, 0),   # command 1
           lib.MCC_Line(20, 20, 0, 0, 0, 0, 1),   # command 2
           lib.MCC_Line(73, 54, 0, 0, 0, 0, 1)]   # command 3
    assert idx == [0, 1, 0, 1]                    # separate queues, separate indices
    assert lib.MCC_GetCommandCount(0) == 2 and lib.MCC_GetCommandCount(1) == 2
    lib.advance(0.02)
    info0, info1 = COMMAND_INFO(), COMMAND_INFO()
    lib.MCC_GetCurCommand(info0, 0)
    lib.MCC_GetCurCommand(info1, 1)
    assert (info0.nCommandIndex, info1.nCommandIndex) == (0, 0)
    assert info0.nType == D.CMD_LINE and info0.dfPos[:2] == [10.0, 10.0]
    assert info1.dfPos[:2] == [20.0, 20.0]
    assert lib.MCC_GetMotionStatus(0) == D.GMS_RUNNING
    # command 0 and command 2 are first in their queues: they start at the same time,
    # on channels 0/1 and 2/3 of card 0
    starts = [first_motion(lib, a) for a in range(4)]
    assert max(starts) - min(starts) < 1e-4
    assert lib.wait_motion(0) and lib.wait_motion(1)
    assert lib.MCC_GetCurPos(0)[1:3] == (15.0, 34.0)
    assert lib.MCC_GetCurPos(1)[1:3] == (73.0, 54.0)
    # pulses on card 0's channels 2, 3 (500 pulses/mm)
    assert lib.MCC_GetPulsePos(1)[1:3] == (36500, 27000)
    assert lib.MCC_GetMotionStatus(0) == D.GMS_STOP


def test_default_group_is_channels_0_to_3_of_card_0():
    lib = open_lib()
    assert lib.MCC_Line(1, 2, 3, 4, 0, 0, 0) == 0
    assert lib.wait_motion(0)
    assert lib.MCC_GetPulsePos(0)[1:5] == (500, 1000, 1500, 2000)
    assert lib.MCC_Line(1, 1, 0, 0, 0, 0, 1) == D.GROUP_PARAMETER_ERR


def test_default_ptp_speed_ratio_and_acc_time():
    lib = open_lib(period_ms=5)
    assert lib.MCC_GetPtPSpeed(0) == 10.0                # default ratio 10 %
    assert lib.MCC_GetAccStep(0) == 20                   # 20 x interpolation time
    assert lib.MCC_GetDecStep(0) == 20
    t0 = lib.controller.time
    assert lib.MCC_PtP(20, 0, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    v = lib.controller.history.sample(0, t).v / 500.0   # mm/s
    # maximum safe speed = wRPM x pitch / (gear x 60) = 3000 x 1 / 60 = 50 mm/s; 10 %
    assert v.max() == pytest.approx(5.0, rel=1e-9)
    up = t[np.nonzero(v >= 5.0 * (1 - 1e-9))[0][0]] - t[np.nonzero(v > 1e-9)[0][0]]
    assert up == pytest.approx(20 * 0.005, abs=2e-5)    # 20 x interpolation time


def test_ptp_speed_ratio_30_and_the_linear_motor_formula():
    # linear motor: wRPM 32767 (the manual's example), dwPPR 3000, pitch 1
    from mccl_common import manual_param
    lib = open_lib(param=manual_param(wRPM=32767, dwPPR=3000))
    assert lib.MCC_SetPtPSpeed(30, 0) == 0
    assert lib.MCC_PtP(100, 0, 0, 0, 0, 0, 0) == 0
    t0 = lib.controller.time
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    v = lib.controller.history.sample(0, t).v
    # (wRPM x pitch x PPR) / (gear x 60) x 30 / 100 pulses/s
    assert v.max() == pytest.approx(32767 * 1.0 * 3000 / 60 * 0.30, rel=1e-9)


def test_feed_acc_and_dec_steps_and_acceleration():
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetFeedSpeed(20.0, 0) == 0
    assert lib.MCC_SetAccStep(10, 0) == 0          # 50 ms
    assert lib.MCC_SetDecStep(40, 0) == 0          # 200 ms
    assert (lib.MCC_GetAccStep(0), lib.MCC_GetDecStep(0)) == (10, 40)
    t0 = lib.controller.time
    assert lib.MCC_Line(30, 0, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    v = lib.controller.history.sample(0, t).v / 500.0
    a = np.gradient(v, t)
    # a = feeding speed / acc time (2.6.4 IV, figure 13)
    assert a.max() == pytest.approx(20.0 / 0.05, rel=1e-2)
    assert a.min() == pytest.approx(-20.0 / 0.2, rel=1e-2)
    moving = np.nonzero(v > 1e-9)[0]
    cruise = np.nonzero(v >= 20.0 * (1 - 1e-9))[0]
    assert t[cruise[0]] - t[moving[0]] == pytest.approx(0.05, abs=2e-5)
    assert t[moving[-1]] - t[cruise[-1]] == pytest.approx(0.2, abs=2e-5)
    assert lib.MCC_GetCurPos(0)[1] == 30.0


@pytest.mark.parametrize("acc,dec", [(20, 20), (10, 40)])
def test_s_curve_ramps_last_the_acc_and_dec_times(acc, dec):
    # 2.6.3 I: s-factor 1, the acceleration a triangle over the acceleration time
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetFeedSpeed(20.0, 0) == 0
    assert lib.MCC_SetAccStep(acc, 0) == 0 and lib.MCC_SetDecStep(dec, 0) == 0
    assert lib.MCC_SetAccType("S", 0) == 0 and lib.MCC_GetAccType(0) == "S"
    assert lib.MCC_GetDecType(0) == "T"       # a type of its own (default T)
    assert lib.MCC_SetDecType("S", 0) == 0 and lib.MCC_GetDecType(0) == "S"
    t0 = lib.controller.time
    assert lib.MCC_Line(30, 0, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    st = lib.controller.history.sample(0, t)
    v = st.v / 500.0
    moving = np.nonzero(v > 1e-9)[0]
    cruise = np.nonzero(v >= 20.0 * (1 - 1e-9))[0]
    assert t[cruise[0]] - t[moving[0]] == pytest.approx(acc * 0.005, abs=3e-5)
    assert t[moving[-1]] - t[cruise[-1]] == pytest.approx(dec * 0.005, abs=3e-5)
    short = min(acc, dec) * 0.005
    assert np.abs(st.a).max() / 500.0 == pytest.approx(2 * 20.0 / short, rel=1e-3)
    assert lib.MCC_GetCurPos(0)[1] == 30.0


def test_ptp_acc_and_dec_steps():
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetPtPAccStep(10, 0) == 0
    assert lib.MCC_SetPtPDecStep(30, 0) == 0
    t0 = lib.controller.time
    assert lib.MCC_PtP(20, 0, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    v = lib.controller.history.sample(0, t).v
    moving = np.nonzero(v > 1e-9)[0]
    cruise = np.nonzero(v >= v.max() * (1 - 1e-9))[0]
    assert t[cruise[0]] - t[moving[0]] == pytest.approx(0.05, abs=2e-5)
    assert t[moving[-1]] - t[cruise[-1]] == pytest.approx(0.15, abs=2e-5)


@pytest.mark.parametrize("period", [1, 5, 10])
@pytest.mark.parametrize("kinds", ["line-line", "line-ptp", "ptp-ptp"])
def test_delay_200_interpolation_times_is_exact(period, kinds):
    # 2.6.3 V: after command A ends, delay 200 x interpolation time, then command B
    # (a path or a point-to-point command: both start at the delay's exact end)
    if True:
        lib = open_lib(period_ms=period)
        T = period / 1000.0
        a_kind, b_kind = kinds.split("-")
        cmd = {"line": lib.MCC_Line, "ptp": lib.MCC_PtP}
        assert cmd[a_kind](10.003, 10, 10, 0, 0, 0, 0) == 0  # A (X ends last, inside a cycle)
        assert lib.MCC_DelayMotion(200, 0) == 1
        assert cmd[b_kind](15, 15, 15, 0, 0, 0, 0) == 2     # B
        lib.controller.run_until(lambda: lib.MCC_GetMotionStatus(0) == D.GMS_DELAYING,
                                 10)
        assert lib.MCC_CheckDelay(0) == 1
        info = COMMAND_INFO()
        lib.MCC_GetCurCommand(info, 0)
        assert (info.nType, info.nCommandIndex) == (D.CMD_DELAY, 1)
        assert lib.wait_motion(0)
        ctl = lib.controller
        t = np.arange(0.0, ctl.time, 1e-5)
        moving = np.abs(ctl.history.sample(0, t).v) > 1e-9
        edges = np.nonzero(np.diff(moving.astype(int)))[0] + 1
        a_end, b_start = t[edges[1]], t[edges[2]]   # A stops, B starts
        # A ends anywhere in a cycle; B starts exactly 200 T later (within the sampling)
        assert b_start - a_end == pytest.approx(200 * T, abs=3e-5)
        assert lib.MCC_CheckDelay(0) == 0


def test_delay_on_an_idle_group_starts_now():
    lib = open_lib(period_ms=10)
    ctl = lib.controller
    lib.advance(0.05)
    t_q = ctl.time
    assert lib.MCC_DelayMotion(20, 0) == 0
    assert lib.MCC_GetMotionStatus(0) == D.GMS_DELAYING
    assert lib.MCC_Line(1, 0, 0, 0, 0, 0, 0) == 1
    assert lib.wait_motion(0)
    # the line starts 20 periods after the call, not one period later
    assert first_motion(lib, 0, t_q) - t_q == pytest.approx(0.2, abs=3e-5)


def test_hold_continue_abort_and_status():
    lib = open_lib()
    assert lib.MCC_HoldMotion(0) == D.HOLD_ILLEGAL_ERR
    assert lib.MCC_ContiMotion(0) == D.CONTI_ILLEGAL_ERR
    lib.MCC_SetFeedSpeed(10.0, 0)
    lib.MCC_Line(20, 0, 0, 0, 0, 0, 0)
    lib.MCC_Line(20, 20, 0, 0, 0, 0, 0)
    lib.advance(0.5)
    assert lib.MCC_HoldMotion(0) == 0
    lib.advance(1.0)
    assert lib.MCC_GetMotionStatus(0) == D.GMS_HOLD
    held = lib.MCC_GetCurPos(0)
    lib.advance(0.5)
    assert lib.MCC_GetCurPos(0) == held
    assert lib.MCC_ContiMotion(0) == 0
    lib.advance(0.2)
    assert lib.MCC_GetMotionStatus(0) == D.GMS_RUNNING
    assert lib.MCC_GetCurFeedSpeed(0) > 0.0
    assert lib.MCC_AbortMotion(0) == 0
    assert lib.wait_motion(0)
    assert lib.MCC_GetCommandCount(0) == 0
    x, y = lib.MCC_GetCurPos(0)[1:3]
    assert y < 20.0


def test_override_changes_the_running_feed():
    lib = open_lib()
    lib.MCC_SetFeedSpeed(10.0, 0)
    lib.MCC_Line(40, 0, 0, 0, 0, 0, 0)
    lib.advance(1.0)
    assert lib.MCC_GetCurFeedSpeed(0) == pytest.approx(10.0)
    assert lib.MCC_SetOverSpeed(50, 0) == 0
    assert lib.MCC_GetOverSpeed(0) == 50.0
    lib.advance(1.0)
    assert lib.MCC_GetCurFeedSpeed(0) == pytest.approx(5.0)
    assert lib.MCC_SetOverSpeed(0, 0) == D.PARAMETER_ERR
    assert lib.MCC_GetOverSpeed(0) == 50.0


def test_absolute_increase_inch_arcs_and_circles():
    lib = open_lib()
    assert lib.MCC_GetCoordType(0) == D.COORD_ABSOLUTE
    lib.MCC_SetFeedSpeed(20.0, 0)
    lib.MCC_SetIncrease(0)
    assert lib.MCC_GetCoordType(0) == D.COORD_INCREASE
    lib.MCC_Line(10, 0, 0, 0, 0, 0, 0)
    lib.MCC_Line(10, 0, 0, 0, 0, 0, 0)
    assert lib.wait_motion(0)
    assert lib.MCC_GetCurPos(0)[1] == 20.0
    lib.MCC_SetAbsolute(0)
    # arc through (30, 10) to (40, 0): a half circle around (30, 0), clockwise
    assert lib.MCC_ArcXY(30, 10, 40, 0, 0) >= 0
    lib.advance(0.3)
    info = COMMAND_INFO()
    lib.MCC_GetCurCommand(info, 0)
    assert info.nType == D.CMD_CW                      # over the top from (20, 0): clockwise
    assert lib.wait_motion(0)
    assert lib.MCC_GetCurPos(0)[1:3] == pytest.approx((40.0, 0.0), abs=1e-9)
    assert lib.MCC_CircleXY(35, 0, D.CIR_CCW, 0) >= 0
    assert lib.MCC_ArcXYZ(45, 5, 5, 50, 0, 10, 0) >= 0
    assert lib.MCC_HelicalXY_Z(45, 0, 40, 0, 0, D.CIR_CW, 0) >= 0
    assert lib.wait_motion(0, 30)
    assert lib.MCC_GetCurPos(0)[1:4] == pytest.approx((40.0, 0.0, 0.0), abs=1e-6)
    lib.MCC_SetUnit(D.UNIT_INCH, 0)
    assert lib.MCC_GetCurPos(0)[1] == pytest.approx(40.0 / 25.4)
    assert lib.MCC_Line(2, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0)
    assert lib.MCC_GetPulsePos(0)[1] == round(2 * 25.4 * 500)
    assert lib.MCC_ArcXY(40, 0, 40, 0, 0) == D.PARAMETER_ERR   # collinear: arc error


def test_blend_and_dry_run():
    lib = open_lib()
    assert lib.MCC_CheckBlend(0) == 0
    assert lib.MCC_EnableBlend(0) == 0 and lib.MCC_CheckBlend(0) == 1
    assert lib.MCC_EnableDryRun() == 0 and lib.MCC_CheckDryRun() == 1
    lib.MCC_Line(10, 0, 0, 0, 0, 0, 0)
    lib.MCC_Line(10, 10, 0, 0, 0, 0, 0)
    lib.advance(0.5)
    assert lib.MCC_GetCurPos(0)[1] > 0.0                 # the planned position
    assert lib.controller.axes[0].position == 0.0        # no pulses
    assert lib.MCC_DisableDryRun() == D.COMMAND_NOTACCEPTED_ERR   # only while idle
    assert lib.wait_motion(0, 20)
    assert lib.MCC_GetCurPos(0)[1:3] == (10.0, 10.0)
    assert lib.MCC_DisableDryRun() == 0
    assert lib.MCC_DisableBlend(0) == 0 and lib.MCC_CheckBlend(0) == 0


def test_blended_ptp_keeps_each_axis_moving():
    # 2.6.3 II: continuous trajectory of point-to-point motion, each axis's speed and
    # trajectory continuous: the next PtP starts while the last axis decelerates
    def run(blend):
        lib = open_lib(period_ms=5)
        assert lib.MCC_SetPtPSpeed(30, 0) == 0
        if blend:
            assert lib.MCC_EnableBlend(0) == 0
        t0 = lib.controller.time
        for x, y in ((20, 5), (40, 30), (10, 30)):
            assert lib.MCC_PtP(x, y, 0, 0, 0, 0, 0) >= 0
        assert lib.wait_motion(0)
        assert lib.MCC_GetPulsePos(0)[1:3] == (5000, 15000)
        t = np.arange(t0, lib.controller.time, 1e-4)
        return t - t0, lib.controller.history.sample(0, t).v
    t_apart, v_apart = run(False)
    t_blend, v_blend = run(True)
    assert t_blend[-1] < t_apart[-1] - 0.05
    # x goes 0 -> 20 -> 40 mm: blended it never stops between the two commands
    first_stop = lambda t, v: t[np.nonzero((t > 0.05) & (np.abs(v) < 1e-6))[0][0]]  # noqa: E731
    assert first_stop(t_blend, v_blend) > first_stop(t_apart, v_apart) + 0.1


def test_ptp_acc_and_dec_types_apart():
    # 2.6.3 I: for point-to-point motion each axis has its own types; S up, T down on X
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetPtPAccType("S", "T", "T", "T", "T", "T", 0) == 0
    assert lib.MCC_SetPtPDecType("T", "S", "T", "T", "T", "T", 0) == 0
    assert lib.MCC_GetPtPAccType(0)[:2] == ("S", "T")
    assert lib.MCC_GetPtPDecType(0)[:2] == ("T", "S")
    assert lib.MCC_SetPtPSpeed(20, 0) == 0             # keeps the types
    assert lib.MCC_GetPtPAccType(0)[:2] == ("S", "T")
    t0 = lib.controller.time
    assert lib.MCC_PtP(30, 30, 0, 0, 0, 0, 0) == 0
    assert lib.wait_motion(0)
    t = np.arange(t0, lib.controller.time, 1e-5)
    ctl = lib.controller
    for axis, (up_s, down_s) in ((0, (True, False)), (1, (False, True))):
        st = ctl.history.sample(axis, t)
        cruise = np.nonzero(st.v >= st.v.max() * (1 - 1e-9))[0]
        up, down = slice(0, cruise[0]), slice(cruise[-1], None)
        assert bool(np.abs(st.j[up]).max() > 1.0) is up_s
        assert bool(np.abs(st.j[down]).max() > 1.0) is down_s
    assert lib.MCC_GetCurPos(0)[1:3] == (30.0, 30.0)
