"""StrVel on group paths (HSL-4XMO 4.6: the vector speed jumps from rest to StrVel, ramps to
the feed, ramps down to StrVel and jumps to rest), and Axis.run_profile's start/end jump."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from openmotion.control import Controller
from openmotion.control.groups.group import ERR_SPEED, Group, GroupError, GroupState
from openmotion.errors import MotionError
from openmotion.profile.pcl import trapezoid

FEED = 20_000.0
ACC_T = 0.05
ACC = FEED / ACC_T  # 400 000 pps^2
SV = 5000.0


def make(axes=("x", "y"), str_vel: float = SV, **kw) -> tuple[Controller, Group]:
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):  # the default table's -EL sits at -5 mm: allow both signs
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, list(axes), feed=kw.pop("feed", FEED), acc_time=ACC_T, **kw)
    g.set_str_vel(str_vel)
    return ctl, g


def finish(ctl: Controller, g: Group, timeout: float = 30.0) -> float:
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                         and not any(a.is_moving for a in g.axes), timeout, event_driven=True)
    return ctl.time


def starts(ctl: Controller, ax: int) -> list[tuple[float, float]]:
    """(time, velocity) of every history record that starts moving from rest."""
    r = ctl.history.records(ax)
    moving = (r["v0"] != 0.0) | (r["a0"] != 0.0)
    k = np.nonzero(moving[1:] & ~moving[:-1])[0] + 1
    return [(float(r["ts"][i]), float(r["v0"][i])) for i in k]


def ends(ctl: Controller, ax: int) -> list[tuple[float, float]]:
    """(time, velocity just before) of every history record that stops at rest."""
    r = ctl.history.records(ax)
    moving = (r["v0"] != 0.0) | (r["a0"] != 0.0)
    k = np.nonzero(~moving[1:] & moving[:-1])[0] + 1
    out = []
    for i in k:
        dt = r["ts"][i] - r["ts"][i - 1]
        out.append((float(r["ts"][i]), float(r["v0"][i - 1] + r["a0"][i - 1] * dt
                                             + r["j"][i - 1] * dt * dt / 2)))
    return out


def speeds(ctl: Controller, g: Group, t0: float, t1: float, n: int = 40001):
    t = np.linspace(t0, t1, n)
    s = [ctl.history.sample(a.index, t) for a in g.axes]
    return t, s, np.sqrt(sum(x.v ** 2 for x in s))


def test_line_jumps_to_str_vel_and_back_like_the_pcl_trapezoid():
    ctl, g = make()
    g.line([30_000, 40_000])  # u = (0.6, 0.8), length 50 000
    t_end = finish(ctl, g)
    assert g.position.tolist() == [30_000.0, 40_000.0]  # exactly
    (tx, vx), = starts(ctl, 0)
    (ty, vy), = starts(ctl, 1)
    assert tx == ty and vx == pytest.approx(0.6 * SV, rel=1e-9) \
        and vy == pytest.approx(0.8 * SV, rel=1e-9)
    (ex, wx), = ends(ctl, 0)
    (ey, wy), = ends(ctl, 1)
    assert ex == ey and wx == pytest.approx(0.6 * SV, rel=1e-6) \
        and wy == pytest.approx(0.8 * SV, rel=1e-6)
    # the vector motion is the PCL6045 trapezoid StrVel -> feed -> StrVel at the path accel
    ref = trapezoid(50_000.0, SV, FEED, (FEED - SV) / ACC, (FEED - SV) / ACC)
    assert ex - tx == pytest.approx(ref.duration, abs=1e-9)
    t, (sx, sy), v = speeds(ctl, g, tx, ex)
    s_ref = ref.sample(t - tx)
    assert np.max(np.abs(sx.p - 0.6 * s_ref.p)) < 1e-6
    assert np.max(np.abs(sy.p - 0.8 * s_ref.p)) < 1e-6
    assert np.allclose(sy.v[v > 0], sx.v[v > 0] * 4 / 3, rtol=1e-9)  # the ratio is kept
    # acceleration within the path accel; the speed is continuous between the two jumps
    assert np.max(np.hypot(sx.a, sy.a)) <= ACC * (1 + 1e-9)
    dv = np.abs(np.diff(v[:-1]))  # v[-1]: at rest after the end jump
    assert np.max(dv) <= ACC * (t[1] - t[0]) * (1 + 1e-6)
    assert ctl.time >= t_end - 1e-12


def test_arc_starts_and_ends_at_str_vel_on_the_circle():
    ctl, g = make()
    g.set_max_pulse_acc([1e6, 1e6])
    g.arc([10_000, 0], [20_000, 0], direction="CW")  # half circle, radius 10 000
    finish(ctl, g)
    assert g.position.tolist() == [20_000.0, 0.0]
    (t0, vx0), = starts(ctl, 0)
    (e0, wx0), = ends(ctl, 0)
    assert vx0 == pytest.approx(0.0, abs=1e-6)  # the tangent at the start is (0, 1)
    assert starts(ctl, 1)[0][1] == pytest.approx(SV, rel=1e-9)
    assert ends(ctl, 1)[0][1] == pytest.approx(-SV, rel=1e-6)
    t, (sx, sy), v = speeds(ctl, g, t0, e0)
    assert np.max(np.abs(np.hypot(sx.p - 10_000, sy.p) - 10_000)) < 1e-3
    assert v[1] == pytest.approx(SV, rel=5e-3) and v[-2] == pytest.approx(SV, rel=5e-3)
    # no spike where the last interpolation interval meets the end jump
    assert np.max(np.abs(sx.a)) <= 1e6 * (1 + 1e-6) and np.max(np.abs(sy.a)) <= 1e6 * (1 + 1e-6)


def test_exact_stop_corner_is_at_rest_and_a_blended_chain_jumps_once():
    ctl, g = make()
    g.line([20_000, 0])
    g.line([20_000, 20_000])  # exact stop at the corner (no blending)
    finish(ctl, g)
    assert g.position.tolist() == [20_000.0, 20_000.0]
    assert [v for _, v in starts(ctl, 0)] == [pytest.approx(SV)]
    assert [v for _, v in ends(ctl, 0)] == [pytest.approx(0.0, abs=1e-6)]  # x stops at rest
    assert [v for _, v in starts(ctl, 1)] == [pytest.approx(0.0, abs=1e-9)]
    assert [v for _, v in ends(ctl, 1)] == [pytest.approx(SV, rel=1e-6)]
    ctl, g = make()
    g.enable_blend(50.0)
    t0 = ctl.time
    for p in ([20_000, 0], [20_000, 20_000], [0, 20_000]):
        g.line(p)
    t1 = finish(ctl, g)
    assert g.position.tolist() == [0.0, 20_000.0]
    _, _, v = speeds(ctl, g, t0, t1)
    moving = np.nonzero(v > 0)[0]
    assert starts(ctl, 0)[0][1] == pytest.approx(SV, rel=1e-9)  # the jump
    # the blend arcs (radius ~120 pulses) are taken above StrVel: no stop on the way
    assert np.all(v[moving[0]:moving[-1] + 1] >= SV * (1 - 1e-6))
    assert ends(ctl, 0)[-1][1] == pytest.approx(-SV, rel=1e-6) and v[-1] == 0.0


def test_start_is_lowered_when_the_path_must_stop_sooner():
    ctl, g = make()
    g.line([20, 0])  # 20 pulses then an exact stop: sqrt(2*A*20) = 4000 < StrVel
    g.line([20, 20_000])
    finish(ctl, g)
    v0 = starts(ctl, 0)[0][1]
    assert v0 == pytest.approx(math.sqrt(2 * ACC * 20), rel=1e-9)
    assert g.position.tolist() == [20.0, 20_000.0]


def test_hold_and_continue_restart_at_str_vel_and_end_exactly():
    ctl, g = make()
    ref_ctl, ref = make()
    for grp in (g, ref):
        grp.line([40_000, 0])
        grp.line([40_000, 30_000])
    finish(ref_ctl, ref)
    ctl.advance(0.5)
    g.hold()
    ctl.run_until(lambda: g.state is GroupState.HELD, 5, event_driven=True)
    held = g.position.copy()
    assert 0 < held[0] < 40_000
    ctl.advance(0.1)
    g.cont()
    finish(ctl, g)
    assert g.position.tolist() == ref.position.tolist() == [40_000.0, 30_000.0]
    st = starts(ctl, 0)
    assert len(st) == 2 and st[1][1] == pytest.approx(SV, rel=1e-9)  # after continue
    held_end = ends(ctl, 0)[0][1]
    assert held_end == pytest.approx(0.0, abs=1e-6)  # the hold decelerates to rest


def test_override_keeps_the_end_jump_and_the_limits():
    ctl, g = make()
    t0 = ctl.time
    g.line([60_000, 0])
    ctl.advance(0.2)
    g.set_override(50)
    ctl.advance(0.4)
    g.set_override(120)
    t1 = finish(ctl, g)
    assert g.position.tolist() == [60_000.0, 0.0]
    assert ends(ctl, 0)[0][1] == pytest.approx(SV, rel=1e-6)
    _, (sx, _), _ = speeds(ctl, g, t0, t1)
    assert np.max(np.abs(sx.a)) <= ACC * (1 + 1e-9)
    assert np.max(np.abs(sx.v)) == pytest.approx(1.2 * FEED, rel=1e-6)


def test_streamed_command_joins_and_the_chain_ends_at_str_vel():
    ctl, g = make()
    g.enable_blend(20.0)
    g.line([30_000, 0])
    ctl.advance(0.1)
    g.line([30_000, 30_000])  # joins the running chain when it runs short (lazy look-ahead)
    finish(ctl, g)
    assert g.position.tolist() == [30_000.0, 30_000.0]
    assert len(starts(ctl, 1)) == 1 and ends(ctl, 1)[0][1] == pytest.approx(SV, rel=1e-6)


def test_dry_run_plans_the_jump_without_pulses():
    ctl, g = make()
    g.enable_dry_run()
    g.line([10_000, 0])
    seen = []
    ctl.add_cycle_hook(lambda c, t: seen.append(g.position[0]))
    finish(ctl, g)
    assert g.position.tolist() == [10_000.0, 0.0]
    assert [a.position for a in g.axes] == [0.0, 0.0]
    first = next(p for p in seen if p > 0.0)  # one period after the start
    h = ctl.period
    assert first == pytest.approx(SV * h + ACC * h * h / 2, rel=1e-9)


def test_user_units_jump_in_each_axis_pulses():
    ctl = Controller(safety=False)
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=20.0, acc_time=0.05, units=True)  # x 1000, y 2000 p/mm
    g.set_str_vel(5.0)  # mm/s
    g.line([3.0, 4.0])
    finish(ctl, g)
    assert [a.position for a in g.axes] == [3000.0, 8000.0]
    assert starts(ctl, 0)[0][1] == pytest.approx(0.6 * 5.0 * 1000, rel=1e-9)
    assert starts(ctl, 1)[0][1] == pytest.approx(0.8 * 5.0 * 2000, rel=1e-9)


@pytest.mark.parametrize("value", [-1.0, float("nan"), float("inf")])
def test_bad_str_vel_is_refused(value):
    _, g = make(str_vel=100.0)
    with pytest.raises(MotionError) as e:
        g.set_str_vel(value)
    assert "speed" in str(e.value)
    assert g.str_vel == 100.0


@pytest.mark.parametrize("setup, code", [
    (lambda g: g.set_str_vel(FEED * 1.01), ERR_SPEED),                      # above the feed
    (lambda g: (g.set_axis_limit_policy("slow"),                            # above an axis
                g.set_max_pulse_speed([3000, 50_000])), ERR_SPEED),
])
def test_commands_with_a_bad_str_vel_are_refused_and_change_nothing(setup, code):
    ctl, g = make()
    g.line([1000, 0])
    before = (g.queue_length, g.state, g._tail.copy(), g._next_index)
    setup(g)
    with pytest.raises(GroupError) as e:
        g.line([5000, 1000])
    assert e.value.code == code and "StrVel" in str(e.value)
    assert (g.queue_length, g.state, g._next_index) == (before[0], before[1], before[3])
    assert np.array_equal(g._tail, before[2])


# ---------------------------------------------------------------- Axis.run_profile jumps
def test_run_profile_takes_a_pcl_str_vel_move_from_rest():
    ctl = Controller()
    ctl.enable_all()
    ax = ctl["x"]
    prof = trapezoid(8000.0, 2000.0, 20_000.0, 0.05, 0.05)
    before = ax.snapshot()
    for kw in ({}, {"str_vel": 1999.0}):
        with pytest.raises(MotionError, match="str_vel"):
            ax.run_profile(prof, stop_accel=1e6, stop_jerk=1e9, **kw)
        assert ax.snapshot() == before
    with pytest.raises(MotionError, match="str_vel"):
        ax.check_profile(prof, stop_accel=1e6, stop_jerk=1e9, str_vel=-1.0)
    t0 = ctl.time
    ax.run_profile(prof, stop_accel=1e6, stop_jerk=1e9, str_vel=2000.0)
    assert ctl.wait_motion_done(timeout=5)
    assert ax.position == 8000.0
    assert ctl.history.sample(0, [t0 + 1e-9]).v[0] == pytest.approx(2000.0, rel=1e-6)
    # moving: a replacement must start at the axis velocity, no jump allowed
    ax.run_profile(trapezoid(8000.0, 0.0, 20_000.0, 0.05, 0.05, start=8000.0),
                   stop_accel=1e6, stop_jerk=1e9)
    ctl.advance(0.02)
    moving = ax.snapshot()
    with pytest.raises(MotionError, match="velocity"):
        ax.run_profile(trapezoid(100.0, 500.0, 1000.0, 0.05, 0.05, start=ax.position),
                       stop_accel=1e6, stop_jerk=1e9, replace_running=True, str_vel=1e6)
    assert ax.snapshot() == moving


def test_run_profile_ends_with_a_jump_to_rest_on_the_target():
    ctl = Controller()
    ctl.enable_all()
    ax = ctl["x"]
    prof = trapezoid(8000.0, 2000.0, 20_000.0, 0.05, 0.05, start=0.0)
    t0 = ctl.time
    ax.run_profile(prof, stop_accel=1e6, stop_jerk=1e9, str_vel=2000.0)
    t_end = t0 + prof.duration
    assert ctl.wait_motion_done(timeout=5)
    assert ax.position == 8000.0 and ax.velocity == 0.0
    v = ctl.history.sample(0, [t_end - 1e-9, t_end]).v
    assert v[0] == pytest.approx(2000.0, rel=1e-5) and v[1] == 0.0


def test_example_runs_with_and_without_str_vel():
    path = Path(__file__).resolve().parents[1] / "examples" / "group_strvel.py"
    spec = importlib.util.spec_from_file_location("group_strvel_example", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    runs = mod.main()
    for mccl, pcl in (runs[:2], runs[2:]):  # T, then S paths
        # (an S path from rest shows its first record one cycle in, at j*dt**2/2)
        assert mccl["start_speed"] == pytest.approx(0.0, abs=0.0 if mccl["shape"] == "T" else 0.01)
        assert mccl["end_speed"] == pytest.approx(0.0, abs=1e-6)
        assert pcl["start_speed"] == pytest.approx(5.0, rel=1e-9)
        assert pcl["end_speed"] == pytest.approx(5.0, rel=1e-6)
        assert mccl["end"] == pcl["end"] == [10.0, 20.0]
        assert pcl["time"] < mccl["time"]  # the ramps start and end at StrVel
    # S with StrVel: no acceleration right after the jump (a line); before the end (an arc
    # of radius 10 mm) only the centripetal 5**2/10, no tangential one
    s_pcl = runs[3]
    assert s_pcl["start_accel"] <= 1e-6
    assert s_pcl["end_accel"] == pytest.approx(2.5, rel=1e-3)


def test_safety_stops_a_str_vel_path():
    ctl, g = make()
    ctl.safety.soft.set("y", 10_000, -100_000)
    ctl.safety.soft.enable("y", "decel")
    with pytest.raises(GroupError, match="soft limit"):  # refused when queued
        g.line([8000, 12_000])
    ctl.advance(0.1)
    assert g.queue_length == 0 and g.state is GroupState.IDLE
    assert [ctl.hardware.read_axis(i).pulses_out for i in (0, 1)] == [0, 0]
    ctl, g = make()
    g.line([20_000, 20_000])
    ctl.hardware.scenario.press_estop(at=0.3)
    ctl.run_until(lambda: g.state is GroupState.ERROR, 5.0, event_driven=True)
    ctl.advance(0.05)
    x, y = (ctl.hardware.read_axis(i).pulses_out for i in (0, 1))
    assert 0 < x < 20_000 and abs(x - y) <= 1 and not any(a.is_moving for a in g.axes)
