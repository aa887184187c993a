"""MCCL facade: homing (2.7) - phases 0-3, their speeds (phases 1, 2, 3 at about 1/10 of
phase 0), the modes, the per-axis order, status and abort."""

from __future__ import annotations

import numpy as np
import pytest

from mccl_common import manual_param, open_lib, state_of
from openmotion.compat import mccl_defs as D
from openmotion.compat.mccl import HOME_CONFIG
from openmotion.config import SwitchConfig

PPU = 500.0  # pulses per mm of the manual's example axis (dwPPR 500, pitch 1)
# home sensor from -20 mm to -15.8 mm; the encoder index every 1 mm (500 counts)
ORG = SwitchConfig(position=-10000.0, width=2100.0)


def setup(home=None, **kw):
    param = manual_param(stHome=home or HOME_CONFIG(wType=D.NORMAL_MODE, wPhase0Dir=1,
                                                    wPhase1Dir=0, dfOffset=2.0), **kw)
    return open_lib(param=param, axis_setup=lambda card, ch: {"org": ORG})


def speeds(lib, axis, t0, t1):
    t = np.arange(t0, t1, 1e-5)
    return t, lib.controller.history.sample(axis, t).v / PPU


def test_phases_and_their_speeds():
    lib = setup()
    t0 = lib.controller.time
    assert lib.MCC_GetGoHomeStatus() == D.HOME_COMMAND_NOTCALLED_ERR
    assert lib.MCC_GoHome(20, 0, 0, 0, 0, 0, 0, -1, -1, -1) == 0
    assert lib.MCC_GetGoHomeStatus() == -1          # in process
    assert lib.controller.run_until(lambda: lib.MCC_GetGoHomeStatus() != -1, 60, event_driven=True)
    assert lib.MCC_GetGoHomeStatus() == 1           # finished
    t, v = speeds(lib, 0, t0, lib.controller.time)
    # phase 0 at 20 mm/s in wPhase0Dir (negative); phases 1-3 at 2 mm/s (1/10)
    assert v.min() == pytest.approx(-20.0, rel=1e-9)
    moving = v != 0.0
    stop0 = np.nonzero(moving[:-1] & ~moving[1:])[0][0]   # phase 0 ends at rest
    slow = v[stop0 + 1:]
    assert np.abs(slow).max() == pytest.approx(2.0, rel=1e-9)
    assert slow.max() == pytest.approx(2.0, rel=1e-9)  # phase 1/2 upwards (wPhase1Dir 0)
    # phase 1 leaves the sensor upwards (it releases at -7900 pulses), phase 2 stops on
    # the nearest index above (-7500), phase 3 moves dfOffset = 2 mm: the logical home
    h = lib.controller.axes[0]
    assert lib.controller.hardware.motor_position(0) == -7500 + 2 * PPU
    assert h.position == 0.0 and lib.MCC_GetCurPos(0)[1] == 0.0
    moves = [k for k in range(1, len(v)) if (v[k - 1] == 0.0) != (v[k] == 0.0)]
    assert len(moves) >= 4  # phase 0, phases 1+2 (one motion), phase 3


def test_home_only_mode_skips_the_index():
    lib = setup(HOME_CONFIG(wType=D.HOME_ONLY_MODE, wPhase0Dir=1, wPhase1Dir=0))
    assert lib.MCC_GoHome(20, 0, 0, 0, 0, 0, 0, -1, -1, -1) == 0
    assert lib.controller.run_until(lambda: lib.MCC_GetGoHomeStatus() != -1, 60, event_driven=True)
    assert lib.MCC_GetGoHomeStatus() == 1
    assert lib.controller.hardware.motor_position(0) == -7900   # the sensor's release edge


def test_index_only_mode():
    lib = setup(HOME_CONFIG(wType=D.INDEX_ONLY_MODE, wPhase0Dir=1, wPhase1Dir=0))
    assert lib.MCC_GoHome(20, 0, 0, 0, 0, 0, 0, -1, -1, -1) == 0
    assert lib.controller.run_until(lambda: lib.MCC_GetGoHomeStatus() != -1, 60, event_driven=True)
    assert lib.MCC_GetGoHomeStatus() == 1
    assert lib.controller.hardware.motor_position(0) == 500    # first index, upwards


def test_order_and_abort():
    lib = setup()
    assert lib.MCC_GoHome(20, 20, 0, 0, 0, 0, 1, 0, -1, -1) == 0   # y first, then x
    ctl = lib.controller
    lib.advance(0.1)
    assert ctl.axes[1].velocity != 0.0 and ctl.axes[0].velocity == 0.0
    assert lib.MCC_GoHome(20, 20, 0, 0, 0, 0, 0, 0, -1, -1) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_AbortGoHome() == 0
    assert lib.MCC_GetGoHomeStatus() == 0
    ctl.run_until(lambda: not any(a.is_moving for a in ctl.axes), 5)
    assert lib.MCC_GoHome(20, 20, 0, 0, 0, 0, 1, 0, -1, -1) == 0
    assert ctl.run_until(lambda: lib.MCC_GetGoHomeStatus() != -1, 120, event_driven=True)
    assert lib.MCC_GetGoHomeStatus() == 1
    assert ctl.axes[0].position == 0.0 and ctl.axes[1].position == 0.0


def test_home_sensor_status_and_bad_arguments():
    lib = setup()
    assert lib.MCC_GetHomeSensorStatus(0, 0) == (0, 0)
    before = state_of(lib)
    assert lib.MCC_GoHome(0, 0, 0, 0, 0, 0, 0, -1, -1, -1) == D.PARAMETER_ERR   # speed 0
    assert lib.MCC_GoHome(20, 0, 0, 0, 0, 0, 9, -1, -1, -1) == D.PARAMETER_ERR  # order
    assert lib.MCC_GoHome(20, 0, 0, 0, 0, 0, -1, -1, -1, -1) == D.PARAMETER_ERR  # none
    assert lib.MCC_GoHome(20, 0, 0, 0, 0, 0, 0, -1, -1, -1, wCardIndex=3) == D.PARAMETER_ERR
    assert lib.MCC_SetHomeConfig(HOME_CONFIG(wType=7), 0, 0) == D.PARAMETER_ERR
    assert lib.MCC_SetGoHomeAccStep(0) == D.PARAMETER_ERR
    assert state_of(lib) == before
    lib.controller.axes[0].move_absolute(-9000.0, max_vel=20000, tacc=0.05)
    lib.controller.run_until(lambda: not lib.controller.axes[0].is_moving, 5)
    assert lib.MCC_GetHomeSensorStatus(0, 0) == (0, 1)


def test_home_acc_and_dec_steps():
    lib = setup()
    assert lib.MCC_SetGoHomeAccStep(10) == 0     # 50 ms to reach the phase-0 speed
    assert lib.MCC_SetGoHomeDecStep(40) == 0     # 200 ms to stop from it
    t0 = lib.controller.time
    assert lib.MCC_GoHome(5, 0, 0, 0, 0, 0, 0, -1, -1, -1) == 0
    assert lib.controller.run_until(lambda: lib.MCC_GetGoHomeStatus() != -1, 60, event_driven=True)
    t, v = speeds(lib, 0, t0, lib.controller.time)
    moving = v != 0.0
    stop0 = np.nonzero(moving[:-1] & ~moving[1:])[0][0]   # phase 0 ends at rest
    a = np.gradient(v, t)[:stop0]
    assert a.min() == pytest.approx(-5.0 / 0.05, rel=1e-2)   # accelerating downwards
    assert a.max() == pytest.approx(5.0 / 0.2, rel=1e-2)     # braking the search


def test_go_home_refused_while_an_axis_moves():
    lib = setup()
    lib.MCC_SetFeedSpeed(10.0, 0)
    assert lib.MCC_Line(0, 5, 0, 0, 0, 0, 0) == 0      # y moves
    lib.advance(0.1)
    assert lib.MCC_GoHome(20, 20, 0, 0, 0, 0, 0, 0, -1, -1) == D.COMMAND_NOTACCEPTED_ERR
    assert all(a.state.value != "Homing" for a in lib.controller.axes)  # none started
    assert lib.MCC_GetGoHomeStatus() == D.HOME_COMMAND_NOTCALLED_ERR
