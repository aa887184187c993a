"""A path command whose deceleration shape differs from its acceleration shape (MCCL
MCC_SetAccType / MCC_SetDecType, 2.6.3 I) runs alone as one move along its length
(control/groups/pathmove.py): each ramp lasts its own time with its own shape; hold,
override and continue keep the shapes' rates; it ends exactly on its end point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers import finish_group, free_axes
from openmotion.control.groups.group import Group, GroupError, GroupState
from openmotion.errors import MotionError

F, TA, TD = 20_000.0, 0.1, 0.2   # pps, s


def group(period=0.005, acc="T", dec="S"):
    ctl = free_axes(2, period=period)
    g = Group(ctl, ["x", "y"], feed=F, acc_time=TA)
    g.set_dec_time(TD)
    if acc == "S":
        g.set_path_shape("S", s_factor=1.0)
    g.set_path_dec_shape(dec)
    return ctl, g


def path_speed(ctl, t0, t1, dt=1e-5):
    t = np.arange(t0, t1, dt)
    sx, sy = ctl.history.sample(0, t), ctl.history.sample(1, t)
    v = np.hypot(sx.v, sy.v)
    a = np.hypot(sx.a, sy.a)
    return t, v, a


def ramps(t, v):
    moving = np.nonzero(v > 1e-6)[0]
    cruise = np.nonzero(v >= F * (1 - 1e-9))[0]
    return t[cruise[0]] - t[moving[0]], t[moving[-1]] - t[cruise[-1]]


@pytest.mark.parametrize("acc,dec", [("S", "T"), ("T", "S")])
def test_each_ramp_lasts_its_time_with_its_shape(acc, dec):
    ctl, g = group(acc=acc, dec=dec)
    assert g.path_shapes == (acc, dec)
    t0 = ctl.time
    g.line([30_000, 40_000])
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [30_000.0, 40_000.0]
    t, v, a = path_speed(ctl, t0, t1)
    up, down = ramps(t, v)
    assert up == pytest.approx(TA, abs=3e-5) and down == pytest.approx(TD, abs=3e-5)
    acc_part = a[(v > 1e-6) & (t < t[np.argmax(v >= F * (1 - 1e-9))])]
    dec_part = a[(t > t[np.nonzero(v >= F * (1 - 1e-9))[0][-1]]) & (v > 1e-6)]
    # T: a constant rate F/T; S (s-factor 1): a triangle peaking at 2F/T
    for part, shape, ramp in ((acc_part, acc, TA), (dec_part, dec, TD)):
        peak = 2 * F / ramp if shape == "S" else F / ramp
        assert part.max() == pytest.approx(peak, rel=2e-3)
        flat = np.mean(np.abs(part - F / ramp) < 1e-6 * F / ramp)
        assert (flat > 0.9) == (shape == "T")


def test_same_shapes_chain_as_before():
    ctl, g = group(acc="T", dec=None)
    assert g.path_shapes == ("T", "T")
    g.set_path_dec_shape("T")
    g.line([10_000, 0])
    g.line([20_000, 0])                  # collinear: one chain, no stop in between
    t0 = ctl.time
    t1 = finish_group(ctl, g)
    t, v, _ = path_speed(ctl, t0, t1)
    mid = (t > t0 + 0.2) & (t < t1 - 0.3)
    assert v[mid].min() > 0.9 * F


def test_commands_apart_stop_at_their_end_exactly():
    ctl, g = group(acc="S", dec="T")
    g.line([10_000, 0])
    g.line([20_000, 0])                  # runs alone: stops at 10000 first
    t0 = ctl.time
    t1 = finish_group(ctl, g)
    t, v, _ = path_speed(ctl, t0, t1)
    x = ctl.history.sample(0, t).p
    stops = t[(v < 1e-6) & (t > t0 + 0.05) & (t < t1 - 0.05)]
    assert len(stops) and np.allclose(ctl.history.sample(0, stops).p, 10_000.0, atol=1e-6)
    assert x[-1] == pytest.approx(20_000.0) and g.axes[0].position == 20_000.0


def test_arc_ends_on_its_end_point_within_the_arc_speed():
    ctl, g = group(acc="S", dec="T")
    g.arc([10_000, 0], [20_000, 0], direction="CW")   # a half circle of radius 10000
    t0 = ctl.time
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [20_000.0, 0.0]
    t = np.arange(t0, t1, 1e-4)
    p = np.stack([ctl.history.sample(k, t).p for k in (0, 1)], axis=1)
    r = np.hypot(p[:, 0] - 10_000, p[:, 1])
    assert np.abs(r - 10_000).max() < 1.0            # on the arc (pulses)
    _, v, _ = path_speed(ctl, t0, t1)
    assert v.max() <= F * (1 + 1e-9)


def test_hold_decelerates_with_the_deceleration_shape_and_continue_ends_exactly():
    ctl, g = group(acc="S", dec="T")
    g.line([60_000, 0])
    ctl.advance(1.0)                       # cruising
    t_hold = ctl.time
    g.hold()
    ctl.run_until(lambda: g.state is GroupState.HELD, 5.0)
    t, v, a = path_speed(ctl, t_hold, ctl.time)
    stop = t[np.nonzero(v < 1e-6)[0][0]]
    assert stop - t_hold == pytest.approx(TD, abs=2e-5)    # T: F / (F/TD)
    dec = a[(t > t_hold + 1e-4) & (t < stop - 1e-4)]
    assert np.allclose(dec, F / TD, rtol=1e-6)
    x_held = g.axes[0].position
    assert 20_000 < x_held < 60_000
    g.cont()
    finish_group(ctl, g)
    assert g.axes[0].position == 60_000.0


@pytest.mark.parametrize("acc,dec", [("T", "S"), ("S", "T")])
def test_override_changes_the_speed_at_the_commands_rate_and_keeps_the_shapes(acc, dec):
    ctl, g = group(acc=acc, dec=dec)
    g.line([80_000, 0])
    ctl.advance(0.5)
    t_ov = ctl.time
    g.set_override(50.0)
    ctl.advance(0.3)
    # slowing down: the deceleration's rate and shape, F/2 reached within TD/2
    t, v, a = path_speed(ctl, t_ov, ctl.time)
    assert np.allclose(v[t > t_ov + TD / 2 + 0.01], F / 2, rtol=1e-9)
    ramp = a[(t > t_ov + 1e-4) & (t < t_ov + TD / 2 - 1e-4)]
    assert ramp.max() == pytest.approx(2 * F / TD if dec == "S" else F / TD, rel=2e-3)
    t_end = finish_group(ctl, g)
    assert g.axes[0].position == 80_000.0
    # the final deceleration keeps the deceleration shape: T at F/TD, S peaking at 2F/TD
    t, v, a = path_speed(ctl, t_end - TD / 2 - 0.02, t_end)
    final = a[v > 1e-6]
    assert final.max() == pytest.approx(2 * F / TD if dec == "S" else F / TD, rel=2e-3)


def test_refusals_change_nothing():
    ctl, g = group()
    for bad in ("Q", 1, ""):
        with pytest.raises(MotionError, match="shape"):
            g.set_path_dec_shape(bad)
    assert g.path_shapes == ("T", "S")
    g.set_str_vel(1000.0)
    n = g.queue_length
    with pytest.raises(GroupError, match="StrVel"):
        g.line([1000, 0])
    assert g.queue_length == n and g.state is GroupState.IDLE
    assert not math.isnan(g.axes[0].position)
