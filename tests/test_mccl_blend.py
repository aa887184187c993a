"""MCCL velocity blending (2.6.3 II, figures 9 and 10) and the deceleration type of general
motion (2.6.3 I) through the facade: line-line, line-arc, arc-arc overlap in time, the
deceleration and acceleration of consecutive commands "no more there"."""

from __future__ import annotations

import numpy as np
import pytest

from mccl_common import manual_param, open_lib
from openmotion.compat import mccl_defs as D

PPMM = 500.0   # the manual's example mechanism: 1000 pulses / 2 mm


def run(blend, cmds, acc_type="T", dec_type="T", steps=(20, 20)):
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetFeedSpeed(20.0, 0) == 0
    assert lib.MCC_SetAccStep(steps[0], 0) == 0 and lib.MCC_SetDecStep(steps[1], 0) == 0
    assert lib.MCC_SetAccType(acc_type, 0) == 0 and lib.MCC_SetDecType(dec_type, 0) == 0
    if blend:
        assert lib.MCC_EnableBlend(0) == 0 and lib.MCC_CheckBlend(0) == 1
    t0 = lib.controller.time
    for name, *args in cmds:
        assert getattr(lib, name)(*args, 0) >= 0
    assert lib.wait_motion(0, 60)
    t1 = lib.controller.time
    t = np.arange(t0, t1, 1e-4)
    h = lib.controller.history
    sx, sy = h.sample(0, t), h.sample(1, t)
    return lib, t - t0, np.hypot(sx.v, sy.v) / PPMM, t1 - t0


SQUARE = [("MCC_Line", 10, 0, 0, 0, 0, 0), ("MCC_Line", 10, 10, 0, 0, 0, 0),
          ("MCC_Line", 0, 10, 0, 0, 0, 0), ("MCC_Line", 0, 0, 0, 0, 0, 0)]


def test_blended_lines_start_as_the_previous_one_decelerates():
    lib, t, v, total = run(True, SQUARE)
    _, ta, va, apart = run(False, SQUARE)
    assert lib.MCC_GetCurPos(0)[1:3] == (0.0, 0.0)
    # four lines of 10 mm at 20 mm/s, 100 ms ramps: apart 4 x 0.6 s; blended three
    # decelerations (3 x 100 ms) less
    assert apart - total == pytest.approx(0.3, abs=1e-9)
    # apart the speed falls to 0 at every corner; blended it never does (F/sqrt(2) least)
    inner = (t > 0.15) & (t < total - 0.15)
    assert va[(ta > 0.15) & (ta < apart - 0.15)].min() < 1e-6
    assert v[inner].min() == pytest.approx(20.0 / np.sqrt(2.0), rel=1e-3)
    assert v.max() <= 20.0 * (1 + 1e-9)


def test_blended_line_arc_arc_keeps_moving_and_ends_exactly():
    cmds = [("MCC_Line", 10, 0, 0, 0, 0, 0), ("MCC_ArcXY", 15, 5, 10, 10),
            ("MCC_ArcXY", 5, 15, 10, 20)]
    lib, t, v, total = run(True, cmds)
    assert lib.MCC_GetCurPos(0)[1:3] == (10.0, 20.0)
    assert lib.MCC_GetPulsePos(0)[1:3] == (5000, 10000)
    inner = (t > 0.15) & (t < total - 0.25)
    assert v[inner].min() > 5.0 and v.max() <= 20.0 * (1 + 1e-9)
    assert lib.MCC_DisableBlend(0) == 0 and lib.MCC_CheckBlend(0) == 0


@pytest.mark.parametrize("acc,dec", [("S", "T"), ("T", "S")])
def test_dec_type_apart_for_lines(acc, dec):
    lib, t, v, total = run(False, [("MCC_Line", 30, 0, 0, 0, 0, 0)], acc, dec, (20, 40))
    assert lib.MCC_GetAccType(0) == acc and lib.MCC_GetDecType(0) == dec
    assert lib.MCC_GetCurPos(0)[1] == 30.0
    moving, cruise = np.nonzero(v > 1e-9)[0], np.nonzero(v >= 20.0 * (1 - 1e-9))[0]
    assert t[cruise[0]] - t[moving[0]] == pytest.approx(0.1, abs=2e-4)    # 20 x 5 ms
    assert t[moving[-1]] - t[cruise[-1]] == pytest.approx(0.2, abs=2e-4)  # 40 x 5 ms
    a = np.gradient(v, t)
    up = a[(t > t[moving[0]] + 0.01) & (t < t[cruise[0]] - 0.01)]
    down = -a[(t > t[cruise[-1]] + 0.01) & (t < t[moving[-1]] - 0.01)]
    # T: constant F/T; S (s-factor 1): a triangle reaching 2F/T
    for part, shape, ramp in ((up, acc, 0.1), (down, dec, 0.2)):
        flat = np.allclose(part, 20.0 / ramp, rtol=1e-2)
        assert flat == (shape == "T")
        if shape == "S":
            assert part.max() == pytest.approx(2 * 20.0 / ramp, rel=2e-2)


def test_a_ptp_beyond_the_working_interval_is_refused_at_the_call():
    # 2.4: working interval up to dfHighLimit - dfHighLimitOffset = 30 - 5 = 25 mm
    lib = open_lib(period_ms=5, param=manual_param(dfHighLimit=30.0, dfHighLimitOffset=5.0))
    assert lib.MCC_SetOverTravelCheck(1, 1, 1, 1, 0, 0, 0) == 0
    hi = 25.0
    n = lib.MCC_GetCommandCount(0)
    assert lib.MCC_PtP(hi + 1.0, 0, 0, 0, 0, 0, 0) == D.COMMAND_NOTACCEPTED_ERR
    assert lib.MCC_GetCommandCount(0) == n and lib.MCC_GetErrorCode(0) == 0
    assert lib.MCC_PtP(hi - 1.0, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 60)
    assert lib.MCC_GetCurPos(0)[1] == pytest.approx(hi - 1.0)


@pytest.mark.parametrize("shape", ["T", "S"])
def test_figure_9_one_constant_speed_region_runs_into_the_next(shape):
    # "after the first constant speed region directly ... accelerate continuously to the
    # second constant speed region": 20 mm/s, then 10 mm/s on the same line
    lib = open_lib(period_ms=5)
    assert lib.MCC_SetAccType(shape, 0) == 0 and lib.MCC_SetDecType(shape, 0) == 0
    assert lib.MCC_EnableBlend(0) == 0
    t0 = lib.controller.time
    assert lib.MCC_SetFeedSpeed(20.0, 0) == 0
    assert lib.MCC_Line(10, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.MCC_SetFeedSpeed(10.0, 0) == 0
    assert lib.MCC_Line(20, 0, 0, 0, 0, 0, 0) >= 0
    assert lib.wait_motion(0, 60)
    assert lib.MCC_GetCurPos(0)[1] == 20.0
    t = np.arange(t0, lib.controller.time, 1e-4)
    v = lib.controller.history.sample(0, t).v / PPMM
    first = np.nonzero(v >= 20.0 * (1 - 1e-9))[0][-1]      # end of the 20 mm/s region
    second = first + np.nonzero(v[first:] <= 10.0 * (1 + 1e-9))[0][0]
    # the 20 -> 10 mm/s change takes one ramp time (20 x 5 ms), never below 10 mm/s
    assert t[second] - t[first] == pytest.approx(0.1, abs=3e-4)
    assert np.all(np.diff(v[first:second + 1]) <= 1e-9)
    cruise2 = (t > t[second] + 1e-3) & (t < t[second] + 0.3)
    assert np.allclose(v[cruise2], 10.0, rtol=1e-9)
