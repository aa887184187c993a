"""Separate group deceleration (Group.set_dec_time, MCC_SetDecStep): the look-ahead
accelerates at feed/acc_time and brakes at feed/dec_time on T and S paths; hold, abort and
a lower override brake at the deceleration; point-to-point axes get it as their Tdec;
until set_dec_time is called everything is as before, bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import finish_group, table_without_mel
from openmotion.control.groups.group import Group, GroupState
from openmotion.errors import MotionError
from openmotion.path import Line, plan_speeds

FEED = 20_000.0
ACC_T = 0.05   # path acceleration 400 000 pps^2
DEC_T = 0.2    # path deceleration 100 000 pps^2


def make(**kw):
    ctl = table_without_mel()
    return ctl, Group(ctl, ["x", "y"], feed=FEED, acc_time=ACC_T, **kw)


def path_speed(ctl, g, t0, t1, n=40001):
    t = np.linspace(t0, t1, n)
    s = [ctl.history.sample(a.index, t) for a in g.axes]
    return t, np.hypot(s[0].v, s[1].v), np.hypot(s[0].p, s[1].p)


def ramp_times(t, v, feed, rel=1e-6):
    """Duration of the rise to the feed and of the fall from it (first/last cruise)."""
    moving = np.nonzero(v > rel * feed)[0]
    cruise = np.nonzero(v >= feed * (1 - rel))[0]
    return t[cruise[0]] - t[moving[0]], t[moving[-1]] - t[cruise[-1]]


def test_dec_time_follows_acc_time_until_set():
    _, g = make()
    assert g.acc_time == ACC_T and g.dec_time == ACC_T
    g.set_acc_time(0.1)
    assert g.dec_time == 0.1
    g.set_dec_time(0.3)
    g.set_acc_time(0.05)
    assert (g.acc_time, g.dec_time) == (0.05, 0.3)


@pytest.mark.parametrize("bad", [0.0, -0.1, math.nan, math.inf, "x"])
def test_bad_dec_time_is_refused_and_changes_nothing(bad):
    _, g = make()
    g.set_dec_time(0.2)
    with pytest.raises(MotionError):
        g.set_dec_time(bad)
    assert g.dec_time == 0.2


@pytest.mark.parametrize("shape", ["T", "S"])
def test_line_accelerates_at_acc_and_brakes_at_dec(shape):
    ctl, g = make()
    if shape == "S":
        g.set_path_shape("S", jerk=2e8)
    g.set_dec_time(DEC_T)
    t0 = ctl.time
    g.line([60_000, 0])
    t1 = finish_group(ctl, g)
    assert g.position.tolist() == [60_000.0, 0.0]
    t, v, _ = path_speed(ctl, g, t0, t1)
    up, down = ramp_times(t, v, FEED)
    tj = 2 * (FEED / ACC_T) / 2e8 if shape == "S" else 0.0  # window of the larger accel
    assert up == pytest.approx(ACC_T + tj, abs=2e-4)
    assert down == pytest.approx(DEC_T + tj, abs=2e-4)
    acc = np.gradient(v, t)
    assert acc.max() <= FEED / ACC_T * (1 + 1e-3)
    assert acc.min() >= -FEED / DEC_T * (1 + 1e-3)
    assert acc.min() <= -FEED / DEC_T * (1 - 1e-2)   # really brakes at the deceleration


def test_blended_chain_brakes_at_dec_before_a_corner():
    ctl, g = make()
    g.set_dec_time(DEC_T)
    t0 = ctl.time
    g.line([40_000, 0])
    g.line([40_000, 40_000])   # exact-stop corner (blending off)
    t1 = finish_group(ctl, g)
    t, v, _ = path_speed(ctl, g, t0, t1)
    acc = np.gradient(v, t)
    mid = np.nonzero((t > t0 + 0.5) & (t < t1 - 0.5))[0]
    k = mid[np.argmin(v[mid])]
    assert v[k] < 1e-3 * FEED  # it stops at the corner
    before, after = acc[:k], acc[k:]
    assert before.min() == pytest.approx(-FEED / DEC_T, rel=1e-2)
    assert after.max() == pytest.approx(FEED / ACC_T, rel=1e-2)
    assert acc.min() >= -FEED / DEC_T * (1 + 1e-3)


@pytest.mark.parametrize("action", ["hold", "abort"])
@pytest.mark.parametrize("shape", ["T", "S"])
def test_hold_and_abort_brake_at_dec(shape, action):
    ctl, g = make()
    if shape == "S":
        g.set_path_shape("S", jerk=2e8)
    g.set_dec_time(DEC_T)
    g.line([200_000, 0])
    ctl.advance(0.3)   # cruising
    t_hold = ctl.time
    getattr(g, action)()
    ctl.run_until(lambda: g.state in (GroupState.HELD, GroupState.IDLE), 5)
    assert g.state is (GroupState.HELD if action == "hold" else GroupState.IDLE)
    t, v, _ = path_speed(ctl, g, t_hold, ctl.time)
    stopped = t[np.nonzero(v <= 1e-6 * FEED)[0][0]]
    tj = 2 * (FEED / ACC_T) / 2e8 if shape == "S" else 0.0
    assert stopped - t_hold == pytest.approx(DEC_T + tj, abs=ctl.period + 2e-4)


def test_lower_override_brakes_at_dec_and_higher_accelerates_at_acc():
    ctl, g = make()
    g.set_dec_time(DEC_T)
    g.line([300_000, 0])
    ctl.advance(0.3)
    t_a = ctl.time
    g.set_override(50)
    ctl.advance(0.4)
    t_b = ctl.time
    g.set_override(100)
    ctl.advance(0.3)
    t, v, _ = path_speed(ctl, g, t_a, ctl.time)
    acc = np.gradient(v, t)
    down = acc[t < t_b]
    up = acc[t > t_b]
    assert down.min() == pytest.approx(-FEED / DEC_T, rel=1e-2)
    assert up.max() == pytest.approx(FEED / ACC_T, rel=1e-2)
    assert v[(t > t_a + DEC_T / 2 + 0.01) & (t < t_b)].min() <= FEED * 0.5 * (1 + 1e-9) + 1e-6
    g.abort()


def test_ptp_axes_get_dec_as_tdec():
    ctl, g = make()
    g.set_ptp_speed(50)
    g.set_dec_time(DEC_T)
    t0 = ctl.time
    g.ptp([100_000, 50_000])
    t1 = finish_group(ctl, g)
    assert g.position.tolist() == [100_000.0, 50_000.0]
    t = np.linspace(t0, t1, 40001)
    sx = ctl.history.sample(g.axes[0].index, t)
    vmax = sx.v.max()
    up, down = ramp_times(t, np.abs(sx.v), vmax)
    assert up == pytest.approx(ACC_T, abs=2e-4)
    assert down == pytest.approx(DEC_T, abs=2e-4)


def test_dec_time_equal_to_acc_time_is_bit_for_bit_the_old_motion():
    runs = []
    for set_dec in (False, True):
        ctl, g = make()
        g.enable_blend(40.0)
        g.set_path_shape("S", jerk=5e7)
        if set_dec:
            g.set_dec_time(ACC_T)
        for p in ([20_000, 0], [20_000, 15_000], [3000, 9000], [0, 0]):
            g.line(p)
        ctl.advance(0.4)
        g.set_override(70)
        t1 = finish_group(ctl, g)
        t = np.linspace(0.0, t1, 5001)
        runs.append([ctl.history.sample(a.index, t).p for a in g.axes])
    for a, b in zip(*runs, strict=True):
        assert np.array_equal(a, b)


def test_stream_mixes_commands_before_and_after_set_dec_time():
    ctl, g = make()
    g.enable_blend(40.0)
    for k in range(1, 6):
        g.line([k * 8000, (k % 2) * 4000])
    g.set_dec_time(DEC_T)
    g.line([0, 0])
    t0 = ctl.time
    t1 = finish_group(ctl, g)
    assert g.position.tolist() == [0.0, 0.0]
    t, v, _ = path_speed(ctl, g, t0, t1)
    acc = np.gradient(v, t)
    assert acc.min() >= -FEED / ACC_T * (1 + 1e-3)  # the first ones brake at most at acc
    late = acc[t > t1 - DEC_T * 0.9]
    assert late.min() == pytest.approx(-FEED / DEC_T, rel=1e-2)  # the last one at dec


# ---------------------------------------------------------------- the look-ahead itself
@settings(max_examples=60, deadline=None)
@given(acc=st.floats(1e3, 1e6), dec=st.floats(1e3, 1e6), n=st.integers(1, 6),
       v0=st.floats(0.0, 1.0), seed=st.integers(0, 10_000))
def test_plan_speeds_rises_at_accel_and_falls_at_decel(acc, dec, n, v0, seed):
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform(-1000, 1000, (n + 1, 2)), axis=0)
    els = [Line(pts[k], pts[k + 1]) for k in range(n) if np.any(pts[k] != pts[k + 1])]
    if not els:
        return
    feed = 3000.0
    sp = plan_speeds(els, feed, acc, decel=dec, square_corner_velocity=5.0)
    for x in sp:
        assert x.accel == pytest.approx(acc) and x.decel == pytest.approx(dec)
        assert x.cruise <= feed * (1 + 1e-12)
        # the trapezoid fits: rise at acc, fall at dec
        d_up = (x.cruise ** 2 - x.entry ** 2) / (2 * acc)
        d_down = (x.cruise ** 2 - x.exit ** 2) / (2 * dec)
        assert d_up + d_down <= x.length * (1 + 1e-9) + 1e-9
        assert x.exit ** 2 <= x.entry ** 2 + 2 * acc * x.length * (1 + 1e-9) + 1e-9
        assert x.entry ** 2 <= x.exit ** 2 + 2 * dec * x.length * (1 + 1e-9) + 1e-9
    assert sp[-1].exit == 0.0
    same = plan_speeds(els, feed, acc, decel=acc, square_corner_velocity=5.0)
    assert same == plan_speeds(els, feed, acc, square_corner_velocity=5.0)


def test_plan_speeds_single_line_peak_with_different_acc_and_dec():
    # 1000 long at a = 1000, d = 3000 from and to rest: v^2 = 2*a*d*L/(a+d) = 1.5e6
    (x,) = plan_speeds([Line([0.0, 0.0], [1000.0, 0.0])], 1e9, 1000.0, decel=3000.0)
    assert x.cruise == pytest.approx(math.sqrt(1.5e6))
    assert x.duration == pytest.approx(x.cruise / 1000.0 + x.cruise / 3000.0)
