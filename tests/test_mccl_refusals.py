"""MCCL facade bad input: the library's negative return code for every refusal (a bad
group index, a value out of range, a command while in error, before MCC_InitSystem),
nothing changed, and never an exception (fuzzed over every MCC_* function)."""

from __future__ import annotations

import inspect
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mccl_common import manual_param, open_lib, state_of
from openmotion.compat import mccl
from openmotion.compat import mccl_defs as D
from openmotion.compat.mccl import MCCL, SYS_CARD_CONFIG, SYS_GROUP_CONFIG, SYS_GROUP_INFO

FUNCTIONS = sorted(n for n in dir(MCCL) if n.startswith("MCC_"))

GROUP_CALLS = [
    ("MCC_Line", (1, 1, 0, 0, 0, 0)), ("MCC_PtP", (1, 1, 0, 0, 0, 0)),
    ("MCC_ArcXY", (1, 1, 2, 0)), ("MCC_CircleXY", (1, 0, 0)),
    ("MCC_SetFeedSpeed", (5.0,)), ("MCC_SetPtPSpeed", (20.0,)), ("MCC_SetAccStep", (5,)),
    ("MCC_SetDecStep", (5,)), ("MCC_SetOverSpeed", (50.0,)), ("MCC_HoldMotion", ()),
    ("MCC_ContiMotion", ()), ("MCC_AbortMotion", ()), ("MCC_DelayMotion", (5,)),
    ("MCC_SetAbsolute", ()), ("MCC_SetIncrease", ()), ("MCC_SetUnit", (1,)),
    ("MCC_EnableBlend", ()), ("MCC_JogPulse", (5, 0)), ("MCC_JogSpace", (1.0, 10.0, 0)),
    ("MCC_JogConti", (0, 10.0, 0)), ("MCC_SetOverTravelCheck", (1, 1, 1, 1, 0, 0)),
    ("MCC_EnableInPos", ()), ("MCC_SetAccType", ("S",)), ("MCC_GetErrorCode", ()),
    ("MCC_ClearError", ()), ("MCC_GetMotionStatus", ()), ("MCC_GetCurPos", ()),
]


@pytest.mark.parametrize("name,args", GROUP_CALLS)
@pytest.mark.parametrize("group", [1, -1, 72, 1.0, None, "0", True])
def test_bad_group_index_is_refused_and_changes_nothing(name, args, group):
    lib = open_lib()          # only group 0 exists
    before = state_of(lib)
    rc = getattr(lib, name)(*args, group)
    assert rc == D.GROUP_PARAMETER_ERR or (isinstance(rc, tuple) and
                                           rc[0] == D.GROUP_PARAMETER_ERR)
    assert state_of(lib) == before


@pytest.mark.parametrize("name,args", [
    ("MCC_SetFeedSpeed", (0.0,)), ("MCC_SetFeedSpeed", (-5.0,)),
    ("MCC_SetFeedSpeed", (1e9,)), ("MCC_SetFeedSpeed", (math.nan,)),
    ("MCC_SetPtPSpeed", (0.0,)), ("MCC_SetPtPSpeed", (101.0,)),
    ("MCC_SetAccStep", (0,)), ("MCC_SetAccStep", (2.5,)), ("MCC_SetDecStep", (-1,)),
    ("MCC_SetPtPAccStep", (0,)), ("MCC_SetOverSpeed", (0.0,)), ("MCC_SetOverSpeed", (201.0,)),
    ("MCC_SetPtPOverSpeed", (-1.0,)), ("MCC_SetUnit", (2,)), ("MCC_DelayMotion", (-1,)),
    ("MCC_SetAccType", ("X",)), ("MCC_SetDecType", ("Q",)),
    ("MCC_SetSysMaxSpeed", (0.0,)), ("MCC_Line", (math.inf, 0, 0, 0, 0, 0)),
    ("MCC_Line", (0, 0, 0, 0, 0, 0)), ("MCC_PtP", ("a", 0, 0, 0, 0, 0)),
    ("MCC_CircleXY", (1, 0, 5)), ("MCC_SetOverTravelCheck", (2, 0, 0, 0)),
    ("MCC_SetInPosCheckTime", (0,)), ("MCC_SetPtPAccType", ("T", "Q", "T", "T")),
    ("MCC_JogSpace", (0.0, 10.0, 0)), ("MCC_JogSpace", (1.0, 0.0, 0)),
    ("MCC_JogConti", (2, 10.0, 0)), ("MCC_JogPulse", (1.5, 0)),
])
def test_values_out_of_range_are_refused_and_change_nothing(name, args):
    lib = open_lib()
    before = state_of(lib)
    rc = getattr(lib, name)(*args, 0)
    assert isinstance(rc, int) and rc < 0, (rc, lib.last_error)
    assert state_of(lib) == before


def test_commands_while_in_error_are_refused_until_clear_error():
    lib = open_lib(param=manual_param(dfHighLimit=30.0, dfHighLimitOffset=5.0))
    ctl = lib.controller
    lib.MCC_SetFeedSpeed(20.0, 0)
    lib.MCC_Line(20, 0, 0, 0, 0, 0, 0)
    lib.advance(0.3)
    ctl.hardware.scenario.trip_alarm(0)           # the X drive alarms: the group stops
    lib.advance(0.05)
    assert lib.MCC_GetErrorCode(0) == D.ERROR_AXIS_FAULT
    assert lib.MCC_GetMotionStatus(0) == D.GMS_STOP
    before = state_of(lib)
    assert lib.MCC_Line(1, 1, 0, 0, 0, 0, 0) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_PtP(1, 1, 0, 0, 0, 0, 0) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_DelayMotion(5, 0) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_AbortMotion(0) == D.ABORT_ILLEGAL_ERR
    assert lib.MCC_ClearError(0) == D.PARAMETER_ERR   # the alarm is still on
    assert state_of(lib) == before
    ctl.hardware.scenario.clear_alarm(0)
    lib.advance(0.01)
    assert lib.MCC_ClearError(0) == 0
    assert lib.MCC_GetErrorCode(0) == D.ERROR_NONE
    assert lib.MCC_Line(1, 1, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0)


def test_calls_before_init_and_bad_init():
    lib = MCCL()
    assert lib.MCC_Line(1, 1, 0, 0, 0, 0, 0) == D.INITIAL_MOTION_ERR
    assert lib.MCC_GetMotionStatus(0) == D.INITIAL_MOTION_ERR
    assert lib.MCC_InitSystem(0, [SYS_CARD_CONFIG()], 1) == D.PARAMETER_ERR
    assert lib.MCC_InitSystem(1001, [SYS_CARD_CONFIG()], 1) == D.PARAMETER_ERR
    assert lib.MCC_InitSystem(5, [SYS_CARD_CONFIG(wCardType=1)], 1) == D.PARAMETER_ERR
    assert lib.MCC_InitSystem(5, [SYS_CARD_CONFIG()], 2) == D.PARAMETER_ERR
    cfg = SYS_GROUP_CONFIG()
    cfg.nGroupUsed[0] = cfg.nGroupUsed[1] = 0
    cfg.stGroupInfo[0] = SYS_GROUP_INFO(0, [0, 1, -1, -1, -1, -1])
    cfg.stGroupInfo[1] = SYS_GROUP_INFO(0, [1, 2, -1, -1, -1, -1])   # channel 1 twice
    assert lib.MCC_SetGroupConfig(cfg) == 0
    assert lib.MCC_InitSystem(5, [SYS_CARD_CONFIG()], 1) == D.GROUP_PARAMETER_ERR
    assert lib.controller is None
    cfg.stGroupInfo[1] = SYS_GROUP_INFO(0, [2, 3, -1, -1, -1, -1])
    assert lib.MCC_SetGroupConfig(cfg) == 0
    assert lib.MCC_InitSystem(5, [SYS_CARD_CONFIG()], 1) == 0
    assert lib.MCC_InitSystem(5, [SYS_CARD_CONFIG()], 1) == D.INITIAL_MOTION_ERR
    assert lib.MCC_SetGroupConfig(cfg) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_CloseSystem() == 0
    assert lib.MCC_Line(1, 1, 0, 0, 0, 0, 0) == D.INITIAL_MOTION_ERR


def test_module_level_functions_share_one_library():
    assert mccl.MCC_CloseSystem() == 0
    assert mccl.MCC_InitSystem(5, [SYS_CARD_CONFIG()], 1) == 0
    assert mccl.MCC_Line(1, 0, 0, 0, 0, 0, 0) == 0
    assert mccl.LIBRARY.wait_motion(0)
    assert mccl.MCC_GetCurPos(0)[1] == 1.0
    assert mccl.MCC_CloseSystem() == 0


_junk = st.one_of(st.integers(-3, 80), st.floats(allow_nan=True, allow_infinity=True),
                  st.none(), st.text(max_size=2), st.lists(st.integers(-1, 3), max_size=7),
                  st.booleans())


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_no_call_ever_raises(data):
    lib = open_lib()
    for _ in range(6):
        name = data.draw(st.sampled_from(FUNCTIONS))
        fn = getattr(lib, name)
        n = len(inspect.signature(fn).parameters)
        args = data.draw(st.lists(_junk, min_size=0, max_size=n))
        rc = fn(*args) if len(args) <= n else None
        assert rc is None or isinstance(rc, (int, float, str, tuple))
        lib.advance(0.01)
