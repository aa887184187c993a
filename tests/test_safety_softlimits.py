"""Soft limits: refused moves, per-cycle prediction, never passed (hypothesis)."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import with_own_safety
from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.control import AxisState, Controller
from openmotion.control.guard.safety import Safety
from openmotion.control.guard.softlimits import profile_extent
from openmotion.errors import MotionError
from openmotion.profile.jerk import jerk_limited
from openmotion.profile.segments import ProfileBuilder

S = AxisState


def setup(period: float = 0.001) -> tuple[Controller, Safety]:
    ax = AxisConfig(name="a", lead=10.0, max_speed=1000.0)  # 1e6 pps
    return with_own_safety(MachineConfig("t", (ax,), 0, 0, period))


class Watch:
    """Largest / smallest command position seen by the pulse generator, every cycle, and
    the planned extent over the whole run (history, exact between cycles)."""

    def __init__(self, ctl: Controller) -> None:
        self.hi = -math.inf
        self.lo = math.inf
        ctl.add_cycle_hook(self)

    def __call__(self, ctl: Controller, t: float) -> None:
        p = ctl.hardware.command_position(0)
        self.hi = max(self.hi, p)
        self.lo = min(self.lo, p)


def test_profile_extent_matches_dense_sampling() -> None:
    b = ProfileBuilder(0.0, 100.0, -300.0)
    b.segment(0.5, jerk=200.0).segment(0.3, jerk=-900.0).segment(0.2)
    pr = b.build(end_v=b.state.v)
    for u0, u1 in ((0.1, 0.9), (0.0, 1.0), (0.5, 1.7), (1.2, 1.5)):
        ts = np.linspace(u0, u1, 200_001)
        p = pr.sample(ts).p
        lo, hi = profile_extent(pr, u0, u1)
        assert lo == pytest.approx(p.min(), abs=1e-6)
        assert hi == pytest.approx(p.max(), abs=1e-6)
        assert lo <= p.min() + 1e-9 and hi >= p.max() - 1e-9
    end = pr.end
    assert profile_extent(pr, 0.0, math.inf)[1 if end.v > 0 else 0] == \
        math.copysign(math.inf, end.v)


@pytest.mark.parametrize("kind", ["relative", "absolute", "jerk", "profile"])
def test_moves_beyond_a_soft_limit_are_refused(kind: str) -> None:
    ctl, safety = setup()
    safety.soft.set("a", 10_000.0, -10_000.0)
    safety.soft.enable("a", "decel")
    ax = ctl.axis("a")
    snap = ax.snapshot()
    with pytest.raises(MotionError, match=r"\+ soft limit"):
        if kind == "relative":
            ax.move_relative(10_001.0, max_vel=1e5)
        elif kind == "absolute":
            ax.move_absolute(12_000.0, max_vel=1e5)
        elif kind == "jerk":
            ax.move_jerk_limited(10_001.0, v_max=1e5, a_max=1e6, j_max=1e8)
        else:
            ax.run_profile(jerk_limited(10_500.0, 1e5, 1e6, 1e8), stop_accel=1e6,
                           stop_jerk=1e8)
    assert ax.snapshot() == snap
    ax.move_relative(10_000.0, max_vel=1e5, tacc=0.02)  # onto the limit is fine
    assert ctl.wait_motion_done(timeout=2.0)
    assert ax.state is S.STANDSTILL and ax.position == 10_000.0


def test_change_position_past_the_limit_is_refused() -> None:
    ctl, safety = setup()
    safety.soft.set(0, 50_000.0, -50_000.0)
    safety.soft.enable(0)
    ax = ctl.axis(0)
    ax.move_absolute(40_000.0, max_vel=1e5, tacc=0.05)
    ctl.advance(0.1)
    with pytest.raises(MotionError, match="soft limit"):
        ax.change_position(60_000.0)
    assert ctl.wait_motion_done(timeout=2.0) and ax.position == 40_000.0


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(speed=st.floats(2e3, 8e5), tacc=st.floats(0.005, 0.3), shape=st.sampled_from("TS"),
       strv=st.floats(0.0, 0.5), sign=st.sampled_from([1, -1]),
       reach=st.floats(0.02, 0.4), decel=st.booleans(), period=st.sampled_from([1e-3, 2e-3]))
def test_velocity_moves_never_pass_a_soft_limit(speed, tacc, shape, strv, sign, reach, decel,
                                                period) -> None:
    ctl, safety = setup(period)
    dist = max(speed * reach, 5.0)
    lim = round(dist)
    safety.soft.set(0, lim, -lim)
    safety.soft.enable(0, "decel" if decel else "immediate")
    ax = ctl.axis(0)
    w = Watch(ctl)
    try:
        ax.move_velocity(sign * speed, str_vel=strv * speed, tacc=tacc, shape=shape)
    except MotionError as e:  # too close to start at that speed: a refusal is fine
        assert "too close" in str(e)
        return
    ctl.run_until(lambda: ax.state is S.ERROR_STOP and ax.motion is None, 30.0)
    assert ax.fault == ("+SL" if sign > 0 else "-SL")
    ctl.advance(0.01)
    tol = 1e-6  # float rounding of the planned position; the integer count never passes
    assert w.hi <= lim + tol and w.lo >= -lim - tol
    assert abs(ax.position) <= lim + tol
    # the plan (exact between cycles) never reaches past the limit either
    assert len(ctl.history.crossings(0, sign * (lim + 1e-6), 0.0, ctl.time)) == 0
    # and the stop was not needlessly early: within one cycle of travel + a stop
    if not decel:
        assert abs(ax.position) >= lim - speed * period * 1.000001 - 1e-6


@settings(max_examples=15, deadline=None)
@given(v2=st.floats(1e4, 4e5), at=st.floats(0.01, 0.2))
def test_change_speed_towards_a_soft_limit_never_passes(v2, at) -> None:
    ctl, safety = setup()
    safety.soft.set(0, 60_000.0, -60_000.0)
    safety.soft.enable(0, "decel")
    ax = ctl.axis(0)
    w = Watch(ctl)
    ax.move_velocity(1e5, tacc=0.05)
    ax.fix_speed_range(5e5)
    ctl.advance(at)
    if ax.state is S.CONTINUOUS_MOTION:
        with contextlib.suppress(MotionError):
            ax.change_speed(v2, 0.05)
    ctl.run_until(lambda: ax.motion is None, 10.0)
    assert w.hi <= 60_000.0 + 1e-9


def test_soft_limit_stop_then_reset_move_away_and_towards() -> None:
    ctl, safety = setup()
    safety.soft.set(0, 30_000.0, -30_000.0)
    safety.soft.enable(0, 1)
    ax = ctl.axis(0)
    ax.move_velocity(2e5, tacc=0.1)
    ctl.run_until(lambda: ax.motion is None and ax.fault == "+SL", 5.0)
    assert safety.last_stop(0).reason == "+SL"
    ax.reset()
    with pytest.raises(MotionError, match="soft limit"):
        ax.move_velocity(1e4, tacc=0.1)
    ax.move_velocity(-1e4, tacc=0.1)
    ctl.advance(0.2)
    ax.stop()
    assert ctl.wait_motion_done(timeout=1.0) and ax.state is S.STANDSTILL


def test_limits_follow_the_command_counter_frame() -> None:
    ctl, safety = setup()
    ax = ctl.axis(0)
    ax.counters.set_command(1_000_000)
    safety.soft.set(0, 1_020_000.0, 990_000.0)
    safety.soft.enable(0)
    w = Watch(ctl)
    ax.move_velocity(1e5, tacc=0.02)
    ctl.run_until(lambda: ax.motion is None, 2.0)
    assert ax.fault == "+SL" and ax.position <= 1_020_000.0
    assert w.hi <= 20_000.0 + 1e-9  # raw pulse frame


def test_disable_and_suspend_let_the_axis_pass() -> None:
    ctl, safety = setup()
    safety.soft.set(0, 5000.0, -5000.0)
    safety.soft.enable(0)
    ax = ctl.axis(0)
    with safety.suspended(0, "soft"):
        ax.move_relative(8000.0, max_vel=1e5, tacc=0.01)
        assert ctl.wait_motion_done(timeout=1.0) and ax.position == 8000.0
    # outside the limits: moving further out is refused, moving back in is allowed
    with pytest.raises(MotionError, match="soft limit"):
        ax.move_relative(10.0, max_vel=1e5)
    ax.move_relative(-1000.0, max_vel=1e5, tacc=0.01)
    assert ctl.wait_motion_done(timeout=1.0) and ax.position == 7000.0
    safety.soft.disable(0)
    assert not safety.soft.get(0).enabled
    ax.move_relative(3000.0, max_vel=1e5, tacc=0.01)
    assert ctl.wait_motion_done(timeout=1.0) and ax.position == 10_000.0


@pytest.mark.parametrize("call, match", [
    (lambda sl: sl.set(0, 5.0, 5.0), "nlimit"),
    (lambda sl: sl.set(0, float("inf"), 0.0), "plimit"),
    (lambda sl: sl.set(0, 1.0, float("nan")), "nlimit"),
    (lambda sl: sl.enable(0, "soon"), "action"),
    (lambda sl: sl.enable(0, True), "action"),
    (lambda sl: sl.enable(3), "axis"),
])
def test_bad_soft_limit_settings(call, match) -> None:
    ctl, safety = setup()
    safety.soft.set(0, 100.0, -100.0)
    before = safety.soft.get(0)
    with pytest.raises(MotionError, match=match):
        call(safety.soft)
    assert safety.soft.get(0) == before


def test_enable_before_set_is_refused() -> None:
    ctl, safety = setup()
    with pytest.raises(MotionError, match="not set"):
        safety.soft.enable(0)


def test_a_fault_stop_decelerating_towards_a_soft_limit_never_passes_it() -> None:
    ax_cfg = AxisConfig(name="s", lead=10.0, max_speed=1000.0, drive=DriveConfig(type="servo"))
    ctl, safety = with_own_safety(MachineConfig("t", (ax_cfg,), 0, 0, 0.001))
    safety.set_alm(0, "decel")
    safety.soft.set(0, 20_000.0, -20_000.0)
    safety.soft.enable(0, "immediate")
    ax = ctl.axis(0)
    w = Watch(ctl)
    ax.move_velocity(2e5, tacc=0.05)  # stopping takes 5000 pulses
    ctl.run_until(lambda: ax.position > 17_000.0, 1.0)
    ctl.hardware.scenario.trip_alarm(0)
    ctl.step()
    assert ax.fault == "servo alarm" and ax.motion is not None  # decelerating
    ctl.run_until(lambda: ax.motion is None, 2.0)
    assert ax.fault == "+SL"  # the soft limit cut the alarm's deceleration short
    assert w.hi <= 20_000.0 + 1e-9 and ax.position <= 20_000.0
