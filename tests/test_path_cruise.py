"""Minimum cruise ratio and corner velocity steps of the look-ahead (issue 4, item 5), and
the group settings that use them, on plans and on recorded runs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.errors import InfeasibleError, MotionError
from openmotion.path import Line, acceleration_reversals, blend_corner, corner_speed, plan_speeds
from openmotion.path.blend import TANGENT_ANGLE

REL = 1e-9
RATIOS = (0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99)


def wavy(turns_deg: list[float], lengths: list[float]) -> list[Line]:
    """Lines whose heading alternates +-turn/2 around x: turn k between line k and k+1."""
    pts = [np.zeros(2)]
    for k, length in enumerate(lengths):
        half = math.radians(turns_deg[k % len(turns_deg)]) / 2.0
        ang = half if k % 2 == 0 else -half
        pts.append(pts[-1] + length * np.array([math.cos(ang), math.sin(ang)]))
    return [Line(a, b) for a, b in zip(pts[:-1], pts[1:], strict=True)]


def check_plan(lines, plan, feed, accel, scv, *, start=0.0, end=0.0, vjump=None):
    """Limits every plan must obey: continuity, reachability, caps, corners, ends."""
    assert plan[0].entry == pytest.approx(start, rel=REL, abs=1e-12)
    assert plan[-1].exit <= end * (1 + REL) + 1e-12
    for k, (el, sp) in enumerate(zip(lines, plan, strict=True)):
        assert sp.entry <= sp.cruise * (1 + REL) + 1e-12
        assert sp.exit <= sp.cruise * (1 + REL) + 1e-12
        assert sp.cruise <= min(feed, sp.vmax) * (1 + REL)
        assert sp.accel <= accel * (1 + REL)
        d_acc = (sp.cruise**2 - sp.entry**2) / (2 * sp.accel)
        d_dec = (sp.cruise**2 - sp.exit**2) / (2 * sp.accel)
        assert d_acc + d_dec <= el.length * (1 + REL) + 1e-12
        if k:
            assert sp.entry == plan[k - 1].exit
            u1, u2 = lines[k - 1].end_tangent, el.start_tangent
            if 2 * math.asin(min(1.0, np.linalg.norm(u1 - u2) / 2)) >= TANGENT_ANGLE:
                vc = corner_speed(u1, u2, accel, scv, lengths=(lines[k - 1].length, el.length))
                assert sp.entry <= vc * (1 + REL) + 1e-12
                if vjump is not None:
                    assert np.all(sp.entry * np.abs(u2 - u1) <= np.asarray(vjump) * (1 + REL))


@st.composite
def shallow_zigzags(draw):
    """CAM-like zig-zags: 3..40 lines of 0.2..5 mm, turns in a band within 1..45 degrees."""
    n = draw(st.integers(3, 40))
    lo = draw(st.floats(1.0, 30.0))
    hi = draw(st.floats(lo, 45.0))
    turns = [draw(st.floats(lo, hi)) for _ in range(n)]
    lengths = [draw(st.floats(0.2, 5.0)) for _ in range(n)]
    return wavy(turns, lengths)


@st.composite
def polylines(draw):
    """Any polyline (sharp corners, reversals) in 2 or 3 axes, optionally blended."""
    dim = draw(st.integers(2, 3))
    count = draw(st.integers(1, 10))
    pts = [np.array(draw(st.lists(st.floats(-50, 50), min_size=dim, max_size=dim)))
           for _ in range(count + 1)]
    lines = [Line(a, b) for a, b in zip(pts, pts[1:], strict=False)]
    assume(all(line.length > 1e-3 for line in lines))
    if not draw(st.booleans()):
        return lines
    out, cur = [], lines[0]
    for nxt in lines[1:]:
        b = blend_corner(cur, nxt, draw(st.floats(1e-3, 2.0)), fraction=0.25)
        if b is None:
            out.append(cur)
            cur = nxt
        else:
            out += [b.first, b.arc]
            cur = b.second
    return [*out, cur]


# ---------------------------------------------------------------------------- the planner
@settings(max_examples=150, deadline=None)
@given(polylines(), st.floats(1.0, 300.0), st.floats(1.0, 5e3), st.floats(0.0, 50.0),
       st.floats(0.0, 0.99), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.data())
def test_limits_never_exceeded_and_ends_respected(elements, feed, accel, scv, ratio, f_start,
                                                  f_end, data):
    dim = elements[0].dim
    vmax = data.draw(st.lists(st.floats(1.0, 1e3), min_size=dim, max_size=dim))
    amax = data.draw(st.lists(st.floats(1.0, 1e4), min_size=dim, max_size=dim))
    vjump = data.draw(st.lists(st.floats(0.1, 100.0), min_size=dim, max_size=dim))
    kw = dict(square_corner_velocity=scv, axis_vmax=vmax, axis_amax=amax, axis_vjump=vjump)
    base = plan_speeds(elements, feed, accel, **kw)
    v_top = base[0].cruise  # any start speed the plain plan allows must stay allowed
    v_start, v_end = f_start * v_top, f_end * feed
    try:
        ref = plan_speeds(elements, feed, accel, start_speed=v_start, end_speed=v_end, **kw)
    except InfeasibleError:
        with pytest.raises(InfeasibleError):
            plan_speeds(elements, feed, accel, start_speed=v_start, end_speed=v_end,
                        min_cruise_ratio=ratio, **kw)
        return
    plan = plan_speeds(elements, feed, accel, start_speed=v_start, end_speed=v_end,
                       min_cruise_ratio=ratio, **kw)
    check_plan(elements, plan, feed, accel, scv, start=v_start, end=v_end, vjump=vjump)
    for sp, r in zip(plan, ref, strict=True):  # same caps, never above the optimal plan
        assert (sp.accel, sp.vmax, sp.length) == (r.accel, r.vmax, r.length)
        assert sp.entry <= r.entry * (1 + REL) + 1e-12
        assert sp.cruise <= r.cruise * (1 + REL) + 1e-12
    assert sum(sp.duration for sp in plan) >= sum(r.duration for r in ref) * (1 - REL)


@settings(max_examples=80, deadline=None)
@given(polylines(), st.floats(1.0, 300.0), st.floats(1.0, 5e3), st.floats(0.0, 50.0))
def test_ratio_zero_is_the_plain_plan_bit_for_bit(elements, feed, accel, scv):
    plain = plan_speeds(elements, feed, accel, square_corner_velocity=scv)
    assert plan_speeds(elements, feed, accel, square_corner_velocity=scv,
                       min_cruise_ratio=0.0) == plain
    # and the smoothing is continuous in the ratio: a tiny ratio changes next to nothing
    tiny = plan_speeds(elements, feed, accel, square_corner_velocity=scv, min_cruise_ratio=1e-12)
    for a, b in zip(tiny, plain, strict=True):
        for x, y in ((a.entry, b.entry), (a.cruise, b.cruise), (a.exit, b.exit)):
            assert x == pytest.approx(y, rel=1e-5, abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(shallow_zigzags(), st.floats(1.0, 200.0), st.floats(10.0, 5e3), st.floats(0.1, 50.0))
def test_reversals_never_increase_with_the_ratio_on_shallow_zigzags(lines, feed, accel, scv):
    counts = [acceleration_reversals(plan_speeds(lines, feed, accel, square_corner_velocity=scv,
                                                 min_cruise_ratio=r)) for r in RATIOS]
    assert counts == sorted(counts, reverse=True)


def test_reversals_drop_and_time_grows_on_a_cam_zigzag():
    turns = [10.0 + 20.0 * ((0.618034 * k) % 1.0) for k in range(60)]
    lines = wavy(turns, [1.0] * 60)
    plans = [plan_speeds(lines, 141.0, 1000.0, square_corner_velocity=10.0, min_cruise_ratio=r)
             for r in (0.0, 0.5, 0.9)]
    counts = [acceleration_reversals(p) for p in plans]
    times = [sum(sp.duration for sp in p) for p in plans]
    assert counts[0] > counts[1] > counts[2]
    assert times[0] < times[1] < times[2]


@pytest.mark.parametrize("ratio", [0.0, 0.3, 0.5, 0.8])
def test_short_moves_between_equal_corners_cruise_the_ratio(ratio):
    # equal turns and lengths: every inner corner runs at the same corner speed
    lines = wavy([20.0], [0.5] * 12)
    accel, scv = 1000.0, 2.0
    plan = plan_speeds(lines, 200.0, accel, square_corner_velocity=scv, min_cruise_ratio=ratio)
    vc = corner_speed(lines[0].direction, lines[1].direction, accel, scv, lengths=(0.5, 0.5))
    for sp in plan[3:-3]:
        assert sp.entry == pytest.approx(vc, rel=1e-9)
        assert sp.exit == pytest.approx(vc, rel=1e-9)
        assert sp.cruise**2 == pytest.approx(vc**2 + (1 - ratio) * accel * 0.5, rel=1e-9)
        d_ramp = (sp.cruise**2 - vc**2) / accel  # accelerate + brake at full accel
        assert (sp.length - d_ramp) / sp.length == pytest.approx(ratio, abs=1e-9)


def test_a_single_move_from_rest_cruises_the_ratio():
    (sp,) = plan_speeds([Line([0, 0], [2.0, 0])], 1000.0, 100.0, min_cruise_ratio=0.5)
    assert sp.cruise == pytest.approx(math.sqrt(0.5 * 100.0 * 2.0), rel=1e-12)
    assert (sp.cruise**2 / 100.0) / 2.0 == pytest.approx(0.5, rel=1e-12)  # ramps: half


def test_axis_vjump_caps_the_velocity_step_per_axis():
    lines = [Line([0, 0], [10, 0]), Line([10, 0], [20, 10])]  # 45 degree turn
    free = plan_speeds(lines, 100.0, 1000.0, square_corner_velocity=20.0)
    capped = plan_speeds(lines, 100.0, 1000.0, square_corner_velocity=20.0,
                         axis_vjump=[5.0, 1e9])
    du = np.abs(lines[1].direction - lines[0].direction)
    assert free[1].entry * du[0] > 5.0
    assert capped[1].entry * du[0] == pytest.approx(5.0, rel=1e-12)


@pytest.mark.parametrize("bad", [-0.1, 1.0, 1.5, math.nan, math.inf, "half", None])
def test_bad_ratio_is_refused(bad):
    with pytest.raises(MotionError, match="min_cruise_ratio"):
        plan_speeds([Line([0, 0], [1, 0])], 10.0, 10.0, min_cruise_ratio=bad)


@pytest.mark.parametrize("bad", [[1.0], [1.0, 0.0], [1.0, -2.0], [1.0, math.nan], "ab"])
def test_bad_axis_vjump_is_refused(bad):
    with pytest.raises(MotionError, match="axis_vjump"):
        plan_speeds([Line([0, 0], [1, 0])], 10.0, 10.0, axis_vjump=bad)


def test_acceleration_reversals_counts_sign_changes_only():
    lines = wavy([20.0], [1.0] * 4)
    plan = plan_speeds(lines, 1000.0, 100.0)  # exact stops: + - + - + - + -
    assert acceleration_reversals(plan) == 7
    assert acceleration_reversals(plan_speeds([Line([0, 0], [1e4, 0])], 10.0, 1.0)) == 1


# ---------------------------------------------------------------------------- the group
V, A = 50_000.0, 500_000.0  # pulses/s, pulses/s^2


def make() -> tuple[Controller, Group]:
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=V, acc_time=V / A)
    g.set_axis_limit_policy("slow")
    g.set_max_pulse_speed([V, V])
    g.set_max_pulse_acc([A, A])
    return ctl, g


def record(scv: float, ratio: float):
    """Run a 16-line CAM zig-zag (1000-pulse lines, 10..30 degree turns) from rest."""
    ctl, g = make()
    g.set_corner_velocity(scv)
    g.set_min_cruise_ratio(ratio)
    turns = [10.0 + 20.0 * ((0.618034 * k) % 1.0) for k in range(16)]
    pts = np.array([lines.start for lines in wavy(turns, [1000.0] * 16)]
                   + [wavy(turns, [1000.0] * 16)[-1].end]) + 5000.0
    g.ptp(pts[0])
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and not any(
        a.is_moving for a in g.axes), 30, event_driven=True)
    t0 = ctl.time
    for p in pts[1:]:
        g.line(p)
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0 and not any(
        a.is_moving for a in g.axes), 60, event_driven=True)
    t = t0 + np.arange(int(round((ctl.time - t0) / ctl.period)) + 1) * ctl.period
    smp = [ctl.history.sample(a.index, t) for a in g.axes]
    return ctl, g, pts, smp, ctl.time - t0


def _reversals(smp) -> int:
    """Sign changes of the recorded path acceleration (v.a), outside a small dead band."""
    v = np.stack([s.v for s in smp], axis=1)
    a = np.stack([s.a for s in smp], axis=1)
    speed = np.linalg.norm(v, axis=1)
    tang = (v * a).sum(axis=1) / np.maximum(speed, 1e-9)
    sign = np.sign(tang[np.abs(tang) > 1e-3 * A])
    return int(np.count_nonzero(sign[1:] != sign[:-1]))


def test_group_corner_velocity_and_cruise_ratio_on_a_recorded_run():
    scv = 10_000.0
    runs = {key: record(*key) for key in ((0.0, 0.0), (scv, 0.0), (scv, 0.5))}
    for _ctl, g, pts, smp, _ in runs.values():
        assert np.array_equal(np.array([a.position for a in g.axes]), pts[-1])  # exact end
        for s in smp:
            assert np.max(np.abs(s.a)) <= A * (1 + 1e-9)
            assert np.max(np.abs(s.v)) <= V * (1 + 1e-9)
    for key in ((scv, 0.0), (scv, 0.5)):  # steps at corners stay within the corner velocity
        ctl, _, _, smp, _ = runs[key]
        for s in smp:
            assert np.max(np.abs(np.diff(s.v))) <= scv * (1 + 1e-6) + A * ctl.period
    t_stop, t_fast, t_smooth = (runs[k][4] for k in ((0.0, 0.0), (scv, 0.0), (scv, 0.5)))
    assert t_fast < 0.7 * t_stop  # corners at speed pay on shallow turns
    assert t_fast < t_smooth < t_stop
    assert _reversals(runs[(scv, 0.5)][3]) < _reversals(runs[(scv, 0.0)][3])


def test_group_settings_validate_and_keep_the_old_value():
    _, g = make()
    assert (g.corner_velocity, g.min_cruise_ratio) == (0.0, 0.0)
    g.set_corner_velocity(1000.0)
    g.set_min_cruise_ratio(0.5)
    for bad in (-0.1, 1.0, math.nan, "x"):
        with pytest.raises(MotionError, match="ratio"):
            g.set_min_cruise_ratio(bad)
    for bad in (-1.0, math.inf, None):
        with pytest.raises(MotionError, match="velocity"):
            g.set_corner_velocity(bad)
    assert (g.corner_velocity, g.min_cruise_ratio) == (1000.0, 0.5)


def test_example_runs_and_ends_exactly():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "group_cam_zigzag.py"
    spec = importlib.util.spec_from_file_location("group_cam_zigzag", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    pts = mod.wavy(12)
    stop, smooth = mod.run(pts, 0.0, 0.0), mod.run(pts, 10_000.0, 0.5)
    for res in (stop, smooth):
        assert res["end"] == pts[-1].tolist()
    assert smooth["time"] < stop["time"]
    assert smooth["step"] <= 10_000.0 * (1 + 1e-6) + mod.A * 1e-3
