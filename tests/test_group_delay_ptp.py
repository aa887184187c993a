"""An exact delay before a point-to-point command (MCCL 2.6.3 V in the core): counted from
the exact end of the previous command (a PtP: its last axis), the PtP axes start at the
delay's exact end inside a cycle (`Axis.move_absolute(start_in=)`)."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import finish_group, free_axes
from openmotion.control.groups.group import Group
from openmotion.errors import MotionError


def edges(ctl, axis: int) -> np.ndarray:
    t = np.arange(0.0, ctl.time, 1e-5)
    moving = np.abs(ctl.history.sample(axis, t).v) > 1e-9
    return t[np.nonzero(np.diff(moving.astype(int)))[0] + 1]


@pytest.mark.parametrize("period", [0.001, 0.004, 0.01])
def test_ptp_delay_ptp_gap_is_exact(period):
    ctl = free_axes(2, period=period)
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    g.ptp([12_345, 3_000])          # x ends last, inside a cycle
    g.delay(0.3)
    g.ptp([0, 0])
    finish_group(ctl, g)
    e = edges(ctl, 0)
    assert e[2] - e[1] == pytest.approx(0.3, abs=3e-5)
    assert [a.position for a in g.axes] == [0.0, 0.0]


def test_start_in_starts_inside_the_cycle_and_is_validated():
    ctl = free_axes(1, period=0.01)
    ax = ctl.axes[0]
    t0 = ctl.time
    before = ax.snapshot()
    for bad in (-1e-3, 0.01, float("nan")):
        with pytest.raises(MotionError, match="start_in"):
            ax.move_absolute(1000, max_vel=10_000, tacc=0.02, start_in=bad)
        assert ax.snapshot() == before
    ax.move_absolute(1000, max_vel=10_000, tacc=0.02, start_in=0.0037)
    ctl.run_until(lambda: not ax.is_moving, 5.0)
    assert ax.position == 1000.0
    assert edges(ctl, 0)[0] - t0 == pytest.approx(0.0037, abs=2e-5)
    assert ax.motion_ended_at == pytest.approx(t0 + 0.0037 + 0.1 + 0.02, abs=1e-9)


def ptp_chain(blend: bool, period: float = 0.005, targets=((20_000, 5_000), (40_000, 30_000),
                                                             (10_000, 30_000))):
    ctl = free_axes(2, period=period)
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    g.set_ptp_speed(40.0)
    if blend:
        g.enable_blend(0.0)
    t0 = ctl.time
    for p in targets:
        g.ptp(list(p))
    t1 = finish_group(ctl, g)
    t = np.linspace(t0, t1, 40_001)
    return ctl, g, t1 - t0, t, [ctl.history.sample(a.index, t) for a in g.axes]


def test_blended_ptp_overlaps_the_ramps_and_ends_exactly():
    _, g, t_apart, _, _ = ptp_chain(False)
    ctl, g, t_blend, t, st = ptp_chain(True)
    assert [a.position for a in g.axes] == [10_000.0, 30_000.0]
    # the deceleration of one command and the acceleration of the next overlap: the x
    # axis never stops between command 1 and 2 (same direction), and the chain is shorter
    x = st[0]
    mid = (t > t[0] + 0.05) & (t < t[-1] - 0.3)
    moving_x = np.abs(x.v[mid]) > 1e-6
    assert moving_x[: int(0.5 * moving_x.size)].all()
    assert t_blend < t_apart - 0.08
    # speed and position continuous, within the axis caps (speed from the PtP ratio)
    for s, a in zip(st, g.axes, strict=True):
        assert np.abs(np.diff(s.v)).max() <= np.abs(s.a).max() * (t[1] - t[0]) * 1.01 + 1e-6
        assert np.abs(s.v).max() <= a.max_speed * (1 + 1e-9)


def test_blend_refused_over_the_speed_cap_runs_apart():
    # 100 % PtP speed: two same-direction moves overlapping would exceed the axis speed
    ctl = free_axes(1, period=0.005)
    g = Group(ctl, ["x"], feed=20_000.0, acc_time=0.05)
    g.set_ptp_speed(100.0)
    g.set_ptp_dec_time(0.2)          # long decel + short accel: the sum passes max speed
    g.set_ptp_acc_time(0.02)
    g.enable_blend(0.0)
    g.ptp([100_000])
    g.ptp([200_000])
    t0 = ctl.time
    t1 = finish_group(ctl, g)
    t = np.linspace(t0, t1, 20_001)
    v = ctl.history.sample(g.axes[0].index, t).v
    assert np.abs(v).max() <= g.axes[0].max_speed * (1 + 1e-9)
    assert g.axes[0].position == 200_000.0
