"""Bad input to every HSL function: a negative code with a message, never an exception,
and nothing changes on the controller (counters, states, motions, groups, network time
for the errors the host library finds itself)."""

from __future__ import annotations

import gc
import inspect
import math

import pytest

from openmotion.compat.hsl import HslError, HslLibrary, functions
from openmotion.compat.hsl import errors as E

GOOD = {
    "axis": 0, "M_No": 0, "card_ID": 0, "slave_ID": 1, "connect_index": 0, "cm": 0,
    "Dist": 1000.0, "Pos": 1000.0, "StrVel": 0.0, "MaxVel": 1000.0, "Tacc": 0.1,
    "Tdec": 0.1, "SVacc": 0.0, "SVdec": 0.0, "NewVel": 500.0, "NewPos": 500.0, "X": 100.0,
    "Y": 100.0, "Z": 100.0, "U": 100.0, "Cx": 100.0, "Cy": 0.0, "Ex": 200.0, "Ey": 0.0,
    "OffsetCx": 100.0, "OffsetCy": 0.0, "OffsetEx": 200.0, "OffsetEy": 0.0, "DIR": 0,
    "ratio": 1.0, "MaxSpeed": 0.0, "el_mode": 0, "el_logic": 0, "alm_logic": 0,
    "alm_mode": 0, "inp_enable": 0, "inp_logic": 0, "erc_logic": 0, "erc_on_time": 0,
    "enable": 0, "sd_logic": 0, "sd_latch": 0, "sd_mode": 0, "ltc_logic": 0,
    "pls_outmode": 1, "pls_iptmode": 2, "pls_logic": 0, "Src": 1, "on_off": 1, "Cmd": 0,
    "CntSrc": 2, "Value": 0.0, "LatchNo": 0, "PLimit": 1e6, "NLimit": -1e6, "Action": 0,
    "Tolerance": 100, "On_Off": 0, "CmpSrc": 1, "CmpMethod": 1, "CmpAction": 0,
    "Data": 0.0, "Method": 1, "Type": 0, "Start": 10.0, "End": 20.0, "Interval": 1.0,
    "tableArray": [10.0, 20.0, 1e6], "Size": 3, "SelectSource": 0, "CompType": 5,
    "BCompPulse": 0, "Mode": 0, "T1": 0, "T2": 0, "home_mode": 0, "org_logic": 0,
    "ez_logic": 0, "ez_count": 0, "erc_out": 0, "ORG_ESC_Offset": 0.0, "ORGOffset": 0.0,
    "code": -4, "filename": "/nonexistent/network.toml",
}
BAD = [math.nan, None, -1, 10**12, [1, 2]]  # ("7" converts, as a number)
SKIP = {"HSL_initial", "HSL_close", "HSL_M_get_error_message"}


def call_args(name: str, sig: inspect.Signature) -> list[object]:
    args: list[object] = []
    for p in sig.parameters.values():
        if p.name == "self":
            continue
        if p.kind is p.VAR_POSITIONAL:
            args.append(1000.0)             # MaxVel after the arc's end point
        elif p.name == "AxisArray":
            n = 3 if "line3" in name else 2
            args.append(list(range(n)))
        else:
            args.append(GOOD[p.name])
    return args


def state(hsl: HslLibrary) -> tuple:
    out = [hsl.network.time]
    for k in hsl.network.modules:
        mod = hsl._modules[k]
        out.append(tuple(a.snapshot() for a in mod.ctl.axes))
        out.append(tuple((axes, g.state, g.queue_length) for axes, g in mod.groups.items()))
        out.append(tuple(sorted(mod.home.items(), key=str)))
        s = mod.ctl.safety
        out.append(tuple(repr(s.settings(i)) for i in range(len(mod.ctl.axes))))
        out.append(tuple(repr(s.soft.get(i)) for i in range(len(mod.ctl.axes))))
        out.append(tuple(s.cmp.general_comparator(i) for i in range(len(mod.ctl.axes))))
    return tuple(out)


_FRESH = [0]


def fresh() -> HslLibrary:
    # controllers are cycles holding large plans: free the last ones now and then (a full
    # collection in a loaded test worker costs up to a second; every 8th keeps memory low)
    _FRESH[0] += 1
    if _FRESH[0] % 8 == 0:
        gc.collect()
    hsl = HslLibrary.simulated(2)
    hsl.HSL_initial(0)
    return hsl


NAMES = [e.name for e in functions.TABLE if e.name not in SKIP]


@pytest.mark.parametrize("name", NAMES)
def test_every_function_answers_bad_input_with_a_code(name):
    hsl = fresh()
    sig = inspect.signature(getattr(HslLibrary, name))
    good = call_args(name, sig)
    for k in range(len(good)):
        for bad in BAD:
            args = list(good)
            args[k] = bad
            before = state(hsl)
            r = getattr(hsl, name)(*args)      # must not raise
            if not isinstance(r, HslError):     # accepted (e.g. True as 1): start afresh
                hsl.HSL_close(0)
                hsl = fresh()
            else:
                assert int(r) < 0
                assert r.message and hsl.HSL_M_get_error_message(r) == r.message
                assert hsl.last_error is r
                after = state(hsl)
                if int(r) in E.HOST_SIDE:
                    assert after == before, (name, k, bad, r)
                else:
                    assert after[1:] == before[1:], (name, k, bad, r)
    hsl.HSL_close(0)


def test_not_initialised_and_closed():
    hsl = HslLibrary.simulated(1)
    assert hsl.HSL_M_start_tr_move(0, 100, 0, 1000, 0.1, 0.1) == E.ERR_NotInitial
    assert hsl.HSL_initial(1) == E.ERR_InvalidCard
    assert hsl.HSL_initial(0) == 0
    assert hsl.HSL_M_start_tv_move(0, 0, 1000, 0.1) == 0
    assert hsl.HSL_close(0) == 0
    assert hsl.controller(0).axes[0].speed == 0.0
    assert hsl.HSL_M_motion_done(0) == E.ERR_NotInitial


def test_refusals_while_moving_leave_the_motion_as_planned():
    hsl = fresh()
    assert hsl.HSL_M_start_tr_move(0, 20000, 0, 10000, 0.1, 0.1) == 0
    hsl.network.advance(0.5)
    ax = hsl.controller(0).axes[0]
    plan = (ax.motion.t_start, ax.motion.profile.duration, ax.motion.target)
    for call in (lambda: hsl.HSL_M_start_tr_move(0, 100, 0, 1000, 0.1, 0.1),   # busy
                 lambda: hsl.HSL_M_p_change(0, 5000),                          # relative
                 lambda: hsl.HSL_M_v_change(0, 20000, 0.1),                    # range
                 lambda: hsl.HSL_M_start_tr_move_xy(0, 100, 100, 0, 1000, 0.1, 0.1)):
        r = call()
        assert isinstance(r, HslError) and r < 0
        assert (ax.motion.t_start, ax.motion.profile.duration, ax.motion.target) == plan
    assert hsl.HSL_M_start_tr_move(0, 100, 0, 1000, 0.1, 0.1) == E.ERR_AxisBusy
    while hsl.HSL_M_motion_done(0):
        pass
    assert hsl.HSL_M_get_command(0) == 20000


def test_codes_name_the_rule():
    hsl = fresh()
    assert hsl.HSL_M_start_tr_move(63, 1, 0, 1, 1, 1) == E.ERR_InvalidAxis
    assert hsl.HSL_M_start_tr_move(8, 1, 0, 1, 1, 1) == E.ERR_InvalidAxis   # no module 2
    assert "module 2" in hsl.last_error.message
    assert hsl.HSL_M_start_tr_move_xy(5, 1, 1, 0, 1, 1, 1) == E.ERR_InvalidModule
    assert hsl.HSL_M_start_tr_line2([0, 4], 1, 1, 0, 1, 1, 1) == E.ERR_InvalidAxis
    assert "one module" in hsl.last_error.message
    assert hsl.HSL_M_v_change(0, 100, 0.1) == E.ERR_NoMotion
    assert hsl.HSL_M_set_trigger_comparator(2, 1, 1, 0.0) == E.ERR_NotSupported
    assert hsl.HSL_M_set_el_logic(0, 1) == E.ERR_ConfigMismatch
    assert "axes.cm1.logic.pel" in hsl.last_error.message
    assert hsl.HSL_M_start_tr_move(0, 1000, 0, 1000, 0.1, 1e6) == E.ERR_SpeedRange  # > maxAccT
    assert hsl.HSL_M_start_tr_move(0, 1e9, 0, 1000, 0.1, 0.1) == E.ERR_InvalidParameter
    assert hsl.HSL_M_start_a_arc_xy(0, 100, 0, 150, 0, 1000.0) == E.ERR_ArcGeometry
    assert hsl.HSL_M_get_error_message(E.ERR_SpeedRange).startswith("the speed")
    hsl.controller(0).hardware.scenario.press_estop()
    hsl.network.advance(0.01)
    assert hsl.HSL_M_start_tr_move(0, 1000, 0, 1000, 0.1, 0.1) == E.ERR_AxisState
    assert hsl.HSL_M_start_tr_move(4, 1000, 0, 1000, 0.1, 0.1) == 0   # module 1 has its own


@pytest.mark.parametrize("arg", [[1], None, "x", 3.5, -99, 0])
def test_error_message_and_initial_take_anything(arg):
    hsl = HslLibrary.simulated(1)
    assert isinstance(hsl.HSL_M_get_error_message(arg), str)
    r = hsl.HSL_initial(arg)
    assert r == 0 if arg == 0 else r == E.ERR_InvalidCard
