"""MCCL facade: compensation (2.10.1: the 15,000 -> 15,011 example, the compensation
range) and in-position control (2.10.2: the example of figure 18)."""

from __future__ import annotations

import pytest

from mccl_common import manual_param, open_lib, state_of
from openmotion.compat import mccl_defs as D
from openmotion.compat.mccl import SYS_COMP_PARAM

# 1000 pulses/mm; working interval -40 mm .. +30 mm = -40 000 .. +30 000 pulses
STROKE = dict(dwPPR=1000, dfHighLimit=31.0, dfHighLimitOffset=1.0, dfLowLimit=-41.0,
              dfLowLimitOffset=1.0)


def manual_table() -> SYS_COMP_PARAM:
    p = SYS_COMP_PARAM()
    p.dwInterval = 10000
    p.wHome_No = 4
    for k, v in enumerate((22, 20, 15, 11, 0, 10, 12, 15)):
        p.nForwardTable[k] = v
    return p


def test_compensation_example_15000_to_15011():
    lib = open_lib(param=manual_param(**STROKE))
    assert lib.MCC_SetCompParam(manual_table(), 0, 0) == 0
    assert lib.MCC_UpdateCompParam() == 0
    # the table's ranges: +10000 x (7 - 4) = 30 000, -10000 x (4 - 0) = 40 000 pulses
    assert lib._comp[0]._table.span == (-40000, 30000)
    lib.MCC_SetFeedSpeed(20.0, 0)
    assert lib.MCC_Line(15, 0, 0, 0, 0, 0, 0) == 0       # 15 000 pulses from home
    assert lib.wait_motion(0)
    lib.advance(0.05)
    assert lib.MCC_GetPulsePos(0)[1] == 15000
    # 15000 + 10 + round((15000 - 10000) / 10000 x (12 - 10)) = 15011 pulses sent
    assert lib.controller.hardware.command_position(0) == 15011


def test_compensation_range_must_cover_the_stroke():
    lib = open_lib(param=manual_param(**{**STROKE, "dfLowLimit": -42.0}))  # -41 000
    assert lib.MCC_SetCompParam(manual_table(), 0, 0) == 0
    before = state_of(lib)
    # the negative range is 10000 x 4 = 40 000 pulses < 41 000: refused, nothing applied
    assert lib.MCC_UpdateCompParam() == D.PARAMETER_ERR
    assert "cover" in lib.last_error
    assert state_of(lib) == before and not lib._comp
    bad = manual_table()
    bad.nForwardTable[4] = 3                     # the home value must be 0
    assert lib.MCC_SetCompParam(bad, 0, 0) == 0
    assert lib.MCC_UpdateCompParam() == D.PARAMETER_ERR
    short = manual_table()
    short.nForwardTable = [0] * 10
    assert lib.MCC_SetCompParam(short, 0, 0) == D.PARAMETER_ERR


def test_compensation_disabled_by_a_zero_interval():
    lib = open_lib(param=manual_param(**STROKE))
    lib.MCC_SetCompParam(manual_table(), 0, 0)
    assert lib.MCC_UpdateCompParam() == 0
    off = manual_table()
    off.dwInterval = 0
    lib.MCC_SetCompParam(off, 0, 0)
    assert lib.MCC_UpdateCompParam() == 0
    lib.MCC_SetFeedSpeed(20.0, 0)
    lib.MCC_Line(15, 0, 0, 0, 0, 0, 0)
    assert lib.wait_motion(0)
    lib.advance(0.05)
    assert lib.controller.hardware.command_position(0) == 15000


def test_in_position_example_of_figure_18():
    # Tolerance[0] = 0.5 mm, Tolerance[1] = 0.3 mm; target (100, 100); the axes stand at
    # (99.7, 99): X is in position, Y is not, so the group is not in position
    lib = open_lib(param=manual_param(dwPPR=1000))
    ctl = lib.controller
    assert lib.MCC_SetInPosTolerance([0.5, 0.3, 0, 0, 0, 0], 0) == 0
    assert lib.MCC_GetInPosToleranceEx(0) == (0, 0.5, 0.3, 0.0, 0.0, 0.0, 0.0)
    assert lib.MCC_SetInPosCheckTime(500, 0) == 0
    assert lib.MCC_EnableInPos(0) == 0
    lib.MCC_SetFeedSpeed(40.0, 0)
    assert lib.MCC_Line(100, 100, 0, 0, 0, 0, 0) == 0
    assert lib.MCC_Line(0, 0, 0, 0, 0, 0, 0) == 1
    lib.advance(1.0)
    # the motors slip: X ends 300 pulses (0.3 mm) short, Y 1000 pulses (1 mm)
    ctl.hardware.scenario.inject_step_loss(0, 300)
    ctl.hardware.scenario.inject_step_loss(1, 1000)
    ctl.run_until(lambda: ctl.axes[0].position == 100000.0 and
                  ctl.axes[1].position == 100000.0, 10)
    lib.advance(0.1)
    assert lib.MCC_GetCurPos(0)[1:3] == (100.0, 100.0)          # the command position
    assert [a.counters.error for a in ctl.axes[:2]] == [300, 1000]
    assert lib._inpos.in_position(0) and not lib._inpos.in_position(1)
    assert lib.MCC_GetInPosStatus(0) == 0
    assert lib.MCC_GetMotionStatus(0) == D.GMS_RUNNING          # waiting for in-position
    info_before = lib.MCC_GetCommandCount(0)
    assert info_before == 1                                     # the second line waits
    # the check time passes: the system error, the following commands stop
    lib.advance(0.6)
    assert lib.MCC_GetErrorCode(0) == D.ERROR_INPOS_TIMEOUT
    assert lib.MCC_Line(5, 5, 0, 0, 0, 0, 0) < 0                # a command while in error
    assert lib.MCC_GetCommandCount(0) == 0
    assert lib.MCC_ClearError(0) == 0
    assert lib.MCC_GetErrorCode(0) == D.ERROR_NONE


def test_in_position_passes_with_a_wider_tolerance():
    lib = open_lib(param=manual_param(dwPPR=1000))
    ctl = lib.controller
    lib.MCC_SetInPosTolerance([0.5, 1.0, 0, 0], 0)
    lib.MCC_SetInPosCheckTime(500, 0)
    lib.MCC_EnableInPos(0)
    lib.MCC_SetFeedSpeed(40.0, 0)
    lib.MCC_Line(100, 100, 0, 0, 0, 0, 0)
    lib.MCC_Line(0, 0, 0, 0, 0, 0, 0)
    lib.advance(1.0)
    ctl.hardware.scenario.inject_step_loss(0, 300)
    ctl.hardware.scenario.inject_step_loss(1, 1000)
    assert lib.wait_motion(0, 20)
    assert lib.MCC_GetErrorCode(0) == D.ERROR_NONE
    assert lib.MCC_GetCurPos(0)[1:3] == (0.0, 0.0)
    assert lib.MCC_DisableInPos(0) == 0


@pytest.mark.parametrize("bad", [[0.5], [-0.1, 0, 0, 0], [float("nan"), 0, 0, 0]])
def test_bad_tolerances_are_refused(bad):
    lib = open_lib()
    before = state_of(lib)
    assert lib.MCC_SetInPosTolerance(bad, 0) == D.PARAMETER_ERR
    assert lib.MCC_GetInPosToleranceEx(0) == (0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert state_of(lib) == before
