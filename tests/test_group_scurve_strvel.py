"""StrVel on S-curve group paths (issue 4): the vector speed jumps from rest to StrVel, an S
acceleration starts from a = 0, an S deceleration reaches StrVel with a = 0 on the target
and the speed jumps to rest there (the PCL6045 S-curve with StrVel, on the path)."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import finish_group, table_without_mel
from openmotion.control.groups.group import Group, GroupState
from openmotion.errors import MotionError
from openmotion.path.smoothing import fir_smooth
from openmotion.profile.pcl import scurve
from openmotion.profile.segments import ProfileBuilder

FEED, ACC_T, JERK, SV = 20_000.0, 0.05, 2.0e7, 5000.0
ACC = FEED / ACC_T
REL = 1e-9


def make(sv: float = SV) -> tuple:
    ctl = table_without_mel(safety=False)
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=ACC_T)
    g.set_path_shape("S", jerk=JERK)
    g.set_str_vel(sv)
    return ctl, g


def recorded(ctl, g, t0: float, t1: float, n: int = 20001):
    t = np.linspace(t0, t1, n)
    return t, [ctl.history.sample(a.index, t) for a in g.axes]


def end_speed(sp) -> float:
    dt = float(sp.dt[-1])
    return float(sp.v0[-1] + dt * (sp.a0[-1] + dt * sp.j[-1] / 2.0))


def end_accel(sp) -> float:
    return float(sp.a0[-1] + float(sp.dt[-1]) * sp.j[-1])


def check_limits(t, sx, sy, feed: float = FEED) -> np.ndarray:
    """Path speed, acceleration and jerk within the limits; the acceleration continuous
    (no step beyond jerk*dt between samples). Returns the path speed."""
    v = np.hypot(sx.v, sy.v)
    assert v.max() <= feed * (1 + REL)
    assert np.hypot(sx.a, sy.a).max() <= ACC * (1 + REL)
    assert np.hypot(sx.j, sy.j).max() <= JERK * (1 + REL)
    dt = t[1] - t[0]
    for s in (sx, sy):
        assert np.max(np.abs(np.diff(s.a))) <= JERK * dt * (1 + 1e-6) + 1e-6
    return v


def test_line_starts_with_the_jump_and_ends_on_the_target_at_str_vel():
    ctl, g = make()
    t0 = ctl.time
    g.line([30_000, 12_000])
    ctl.step()
    sp = g._run.plan.sprof
    # the exact plan: rest before, first segment at StrVel with a = 0, a jerk-limited rise
    assert sp.start.v == 0.0 and sp.v0[0] == pytest.approx(SV, rel=1e-12)
    assert sp.a0[0] == 0.0 and sp.j[0] > 0.0
    assert np.abs(sp.j).max() <= JERK * (1 + REL)
    assert end_speed(sp) == pytest.approx(SV, rel=1e-9)
    assert abs(end_accel(sp)) <= 1e-6 * ACC
    assert sp.end.p == g._run.plan.chain.length and sp.end.v == 0.0
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [30_000.0, 12_000.0]
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    v = check_limits(t, sx, sy)
    mv = np.nonzero(v > 0.0)[0]
    first, last = mv[0], mv[-1]
    assert v[first] == pytest.approx(SV, rel=1e-3)   # the jump, not a ramp from 0
    assert sx.v[first] / sy.v[first] == pytest.approx(30 / 12, rel=1e-9)  # axes in ratio
    assert abs(np.hypot(sx.a[first], sy.a[first])) <= 0.01 * ACC   # a = 0 after the jump
    assert v[last] == pytest.approx(SV, rel=1e-3)  # into the end jump at StrVel
    assert np.hypot(sx.a[last], sy.a[last]) <= 0.01 * ACC
    assert v.max() == pytest.approx(FEED, rel=1e-6)


def test_single_line_is_shaped_like_the_pcl_scurve_with_str_vel():
    """Both jump to StrVel, leave and reach it with a = 0, and take about as long (the two
    S shapes differ: the PCL's jerk phases vs a moving average)."""
    ctl, g = make()
    g.line([40_000, 0])
    ctl.step()
    sp = g._run.plan.sprof
    pcl = scurve(40_000.0, SV, FEED, ACC_T, ACC_T, 0.0, 0.0)
    for p in (sp, pcl):
        assert p.start.v == 0.0 and p.v0[0] == pytest.approx(SV)
        assert abs(p.a0[0]) <= 1e-9 * ACC
        assert end_speed(p) == pytest.approx(SV, rel=1e-6)
        assert abs(end_accel(p)) <= 1e-6 * ACC
    assert sp.end.p == pytest.approx(pcl.end.p - pcl.start.p)
    assert sp.duration == pytest.approx(pcl.duration, rel=0.25)


def test_hold_stops_at_rest_and_continue_jumps_to_str_vel_again():
    ctl, g = make()
    t0 = ctl.time
    g.line([60_000, 20_000])
    ctl.advance(0.8)
    g.hold()
    assert ctl.run_until(lambda: g.state is GroupState.HELD, 5.0)
    sp = g._held.plan.sprof
    assert sp.end.p < g._held.plan.chain.length and end_speed(sp) == pytest.approx(0, abs=1e-6)
    t_held = ctl.time
    ctl.advance(0.05)
    g.cont()
    ctl.step()
    sp2 = g._run.plan.sprof
    assert sp2.v0[0] == pytest.approx(SV) and sp2.a0[0] == 0.0  # the jump again
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [60_000.0, 20_000.0]
    for a, b in ((t0, t_held), (t_held + 0.05, t1)):
        t, (sx, sy) = recorded(ctl, g, a, b)
        check_limits(t, sx, sy)


@pytest.mark.parametrize("sv", [0.0, SV])
def test_hold_in_the_last_window_finishes_with_the_end_jump(sv):
    """Too late to stop before the end: the path ends on the target (with StrVel: its end
    jump), the group is held, and continue has nothing left to do (S paths raised)."""
    ctl, g = make(sv)
    g.line([20_000, 0])
    ctl.step()
    plan = g._run.plan
    ctl.advance(plan.t_end - ctl.time - 0.4 * plan.tj)
    g.hold()
    assert ctl.run_until(lambda: g.state is GroupState.HELD, 2.0)
    assert [a.position for a in g.axes] == [20_000.0, 0.0]
    g.cont()
    finish_group(ctl, g)
    assert [a.position for a in g.axes] == [20_000.0, 0.0]


def test_streamed_commands_join_with_one_start_and_one_end_jump():
    ctl, g = make()
    g.set_corner_velocity(2000.0)
    t0 = ctl.time
    pts = [[15_000, 0], [30_000, 5_000], [45_000, 5_000], [60_000, 0]]
    g.line(pts[0])
    for p in pts[1:]:
        ctl.advance(0.1)
        g.line(p)
    owners: set[int] = set()

    def joined() -> bool:
        if g._run is not None and g._run.plan is not None:
            owners.update(g._run.plan.chain.owners)
            return len(set(g._run.plan.chain.owners)) >= 2
        return False

    assert ctl.run_until(joined, 5.0)  # a later command joined the running chain
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [60_000.0, 0.0]
    t, (sx, sy) = recorded(ctl, g, t0, t1, 40001)
    v = check_limits(t, sx, sy)
    moving = v > 0.0
    k = np.nonzero(moving)[0]
    assert v[k[0]] == pytest.approx(SV, rel=1e-3) and v[k[-1]] == pytest.approx(SV, rel=1e-3)
    # jumps only at the chain's start and end: elsewhere speed changes by <= a*dt
    dv = np.abs(np.diff(v[k[0]:k[-1] + 1]))
    assert dv.max() <= ACC * (t[1] - t[0]) * 1.01


def test_override_keeps_the_limits_and_the_str_vel_end():
    ctl, g = make()
    t0 = ctl.time
    g.line([80_000, 0])
    ctl.advance(0.3)
    g.set_override(50)
    ctl.advance(0.5)
    g.set_override(120)
    ctl.step()
    sp = g._run.plan.sprof
    assert end_speed(sp) <= SV * (1 + REL) and abs(end_accel(sp)) <= 1e-6 * ACC
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [80_000.0, 0.0]
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    v = check_limits(t, sx, sy, 1.2 * FEED)
    assert v[(t > t0 + 0.7) & (t < t0 + 0.8)].max() < 0.51 * FEED  # the override took


def test_override_in_the_last_window_leaves_the_end_unchanged():
    ctl, g = make()
    g.line([20_000, 0])
    ctl.step()
    plan = g._run.plan
    ctl.advance(plan.t_end - ctl.time - 0.3 * plan.tj)
    g.set_override(30)
    assert g._run.plan.t_end == pytest.approx(plan.t_end, abs=1e-12)
    finish_group(ctl, g)
    assert [a.position for a in g.axes] == [20_000.0, 0.0]


@pytest.mark.parametrize("length", [300.0, 1500.0, 4000.0])
def test_short_lines_end_exactly_within_limits(length):
    """Shorter than the StrVel stretches (StrVel*tj): the jump speed is lowered to fit."""
    ctl, g = make()
    t0 = ctl.time
    g.line([length, 0])
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [length, 0.0]
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    check_limits(t, sx, sy)


def test_fir_smooth_with_a_str_vel_history_and_end():
    """Raw: history at 3, accelerate, decelerate to 2, hold 2 for tj/2: the average starts
    on raw start - 3*tj/2 at v = 3, a = 0 and ends on the raw end at v = 2, a = 0."""
    tj = 0.2
    b = ProfileBuilder(0.0, 3.0)
    b.segment(0.5, 0.0, accel=4.0).segment(0.75, 0.0, accel=-4.0)
    b.segment(tj / 2, 0.0, accel=0.0)
    raw = b.build()
    sp = fir_smooth(raw, tj, v_after=2.0)
    assert sp.p0[0] == pytest.approx(-1.5 * tj) and sp.v0[0] == pytest.approx(3.0)
    assert sp.a0[0] == 0.0
    assert sp.end.p == raw.end.p and sp.duration == pytest.approx(raw.duration + tj / 2)
    assert end_speed(sp) == pytest.approx(2.0) and abs(end_accel(sp)) <= 1e-12
    last = sp.p0[-1] + sum(float(sp.dt[-1]) ** (k + 1) * c / f for k, (c, f) in
                           enumerate(((sp.v0[-1], 1), (sp.a0[-1], 2), (sp.j[-1], 6))))
    assert last == pytest.approx(raw.end.p, abs=1e-12)
    assert np.abs(sp.j).max() <= 4.0 * 2 / tj * (1 + 1e-12)
    with pytest.raises(MotionError, match="v_after"):
        fir_smooth(raw, tj, v_after=3.0)    # the raw does not end at that speed
    with pytest.raises(MotionError, match="v_after"):
        fir_smooth(raw, tj, v_after=-1.0)


def test_dry_run_plans_the_jump_with_a_zero_acceleration():
    ctl, g = make()
    g.enable_dry_run()
    g.line([10_000, 0])
    seen = []
    ctl.add_cycle_hook(lambda c, t: seen.append(g.position[0]))
    finish_group(ctl, g)
    assert g.position.tolist() == [10_000.0, 0.0]
    assert [a.position for a in g.axes] == [0.0, 0.0]
    first = next(p for p in seen if p > 0.0)  # one period after the start: SV*h + J'h**3/6
    h = ctl.period
    assert SV * h < first < SV * h * (1 + 1e-3)


def _speed_near(sp, s: float, ds: float = 1e-6) -> float:
    smp = sp.sample(np.linspace(0.0, sp.duration, 200_001))
    return float(smp.v[np.abs(smp.p - s) <= ds].max())


def test_exact_stop_near_the_start_lowers_the_jump_and_is_passed_at_rest():
    """The raw motion starts StrVel*tj/2 ahead and must stop at the corner: the jump speed
    v solves v*tj/2 + v**2/(2A) = 150 (5565 pps), not StrVel (the corner would be skipped)."""
    ctl, g = make(8000.0)
    g.line([150, 0])
    g.line([150, 20_000])
    ctl.step()
    plan = g._run.plan
    sp = plan.sprof
    h = plan.tj / 2
    assert sp.v0[0] == pytest.approx(ACC * (np.sqrt(h * h + 2 * 150 / ACC) - h), rel=1e-9)
    assert _speed_near(sp, 150.0) <= 0.1  # at rest at the exact-stop corner
    finish_group(ctl, g)
    assert [a.position for a in g.axes] == [150.0, 20_000.0]


def test_exact_stop_near_the_end_lowers_the_end_speed():
    """100 pulses after an exact stop: the end stretch (ve*tj/2) and the rise from rest
    need v*tj/2 + v**2/(2A) <= 100, so the path ends at 4000 pps with a = 0 (the second
    command joins the running chain)."""
    ctl, g = make(8000.0)
    plans = []
    ctl.add_cycle_hook(lambda c, t: plans.append(g._run.plan) if g._run is not None and
                       g._run.plan is not None and (not plans or plans[-1] is not g._run.plan)
                       else None)
    g.line([20_000, 0])
    g.line([20_000, 100])
    t0 = ctl.time
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [20_000.0, 100.0]
    sp = plans[-1].sprof
    assert end_speed(sp) == pytest.approx(4000.0, rel=1e-9)
    assert abs(end_accel(sp)) <= 1e-6 * ACC
    t, (sx, sy) = recorded(ctl, g, t0, t1, 200_001)
    check_limits(t, sx, sy)
    at = (np.abs(sx.p - 20_000.0) <= 1e-6) & (sy.p <= 1e-6)
    assert at.any() and np.hypot(sx.v, sy.v)[at].max() <= 0.1  # the corner at rest
