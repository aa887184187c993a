"""Blended group paths on recorded runs: tolerance, speed gain, per-axis limits, ends; and
the path-execution math (speed curves, axis profiles) as properties."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import finish_group, table_without_mel
from longrun import size
from openmotion.control import Controller, pulse_accuracy
from openmotion.control.groups import pathexec as px
from openmotion.control.groups.group import Group, GroupState
from openmotion.path import Arc, Line, plan_speeds

VMAX = 50_000.0
AMAX = 500_000.0


def make(tol: float | None) -> tuple[Controller, Group]:
    ctl = table_without_mel()
    g = Group(ctl, ["x", "y"], feed=40_000.0, acc_time=0.1)
    g.set_max_pulse_speed([VMAX, VMAX])
    g.set_max_pulse_acc([AMAX, AMAX])
    if tol is not None:
        g.enable_blend(tol)
    return ctl, g


def run(points: np.ndarray, tol: float | None):
    ctl, g = make(tol)
    t0 = ctl.time
    g.line(points[0])  # from the origin to the first vertex
    for p in points[1:]:
        g.line(p)
    finish_group(ctl, g, 60)
    t = np.linspace(t0, ctl.time, 40001)
    s = [ctl.history.sample(a.index, t) for a in g.axes]
    return ctl.time - t0, g.position, s


def dist_to_polyline(xy: np.ndarray, verts: np.ndarray) -> np.ndarray:
    """Distance of every row of xy to the polyline through verts."""
    best = np.full(len(xy), np.inf)
    for a, b in zip(verts[:-1], verts[1:], strict=True):
        ab = b - a
        u = np.clip(((xy - a) @ ab) / (ab @ ab), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(xy - (a + u[:, None] * ab), axis=1))
    return best


def polygon(n: int, r: float) -> np.ndarray:
    ang = np.linspace(0.0, 2 * np.pi, n + 1)
    return np.stack([r + r * np.cos(ang) + 1000, r * np.sin(ang) + r + 1000], axis=1)


def zigzag(n: int, dx: float, dy: float) -> np.ndarray:
    x = 1000 + dx * np.arange(n)
    y = 1000 + dy * (np.arange(n) % 2)
    return np.stack([x, y], axis=1)


def _check(points: np.ndarray, tol: float) -> tuple[float, float, np.ndarray]:
    t_exact, end_e, _ = run(points, None)
    t_blend, end_b, (sx, sy) = run(points, tol)
    assert end_b.tolist() == points[-1].tolist() == end_e.tolist()  # ends exact
    verts = np.vstack([[0.0, 0.0], points])
    dev = dist_to_polyline(np.stack([sx.p, sy.p], axis=1), verts)
    assert dev.max() <= tol * (1 + 1e-6)
    for s in (sx, sy):
        assert np.abs(s.v).max() <= VMAX * (1 + 1e-9)
        assert np.abs(s.a).max() <= AMAX * (1 + 1e-9)
    assert t_blend < t_exact
    return t_exact, t_blend, np.hypot(sx.v, sy.v)


def test_polygon_blends_within_tolerance_and_beats_exact_stop():
    pts = polygon(100, 50_000.0)  # chord deviation of the 100-gon: r(1-cos(pi/100)) = 24.7
    t_exact, t_blend, speed = _check(pts, 25.0)
    assert t_blend < 0.6 * t_exact
    # after the lead-in corner the whole polygon runs at the full feed (look-ahead)
    n = speed.size
    assert np.all(speed[int(0.35 * n):int(0.95 * n)] >= 40_000.0 * (1 - 1e-6))


def test_zigzag_blends_within_tolerance():
    _check(zigzag(40, 2000.0, 3000.0), 50.0)


# ------------------------------------------------------------------ pathexec properties
v2s = st.lists(st.floats(0.0, 1e4), min_size=2, max_size=8)


@settings(max_examples=60, deadline=None)
@given(v2s, v2s)
def test_curve_min_max_are_pointwise(a, b):
    ca = px.SpeedCurve(np.linspace(0.0, 10.0, len(a)), np.array(a))
    cb = px.SpeedCurve(np.linspace(0.0, 10.0, len(b)), np.array(b))
    grid = np.linspace(0.0, 10.0, 501)
    lo, hi = px.curve_min(ca, cb), px.curve_max(ca, cb)
    ya, yb = np.interp(grid, ca.s, ca.v2), np.interp(grid, cb.s, cb.v2)
    assert np.allclose(np.interp(grid, lo.s, lo.v2), np.minimum(ya, yb), atol=1e-6)
    assert np.allclose(np.interp(grid, hi.s, hi.v2), np.maximum(ya, yb), atol=1e-6)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.floats(-5e3, 5e3), st.floats(-5e3, 5e3)), min_size=1,
                max_size=6), st.floats(0.2, 0.8), st.sampled_from([0.0, 2000.0]))
def test_axis_profiles_follow_the_path_and_end_exactly(pts, hold_frac, scv):
    verts = [np.zeros(2)]
    for p in pts:
        q = verts[-1] + np.array(p)
        if np.linalg.norm(q - verts[-1]) > 1.0:
            verts.append(q)
    if len(verts) < 2:
        return
    els = [Line(a, b) for a, b in zip(verts[:-1], verts[1:], strict=True)]
    c = verts[-1] + np.array([500.0, 0.0])
    els.append(Arc(verts[-1], c, verts[-1] + np.array([1000.0, 0.0])))
    chain = px.Chain(els, range(len(els)))
    lim = px.Limits(20_000.0, 200_000.0, np.array([15_000.0, 15_000.0]),
                    np.array([150_000.0, 150_000.0]), scv)
    curve = px.plan_curve(chain, 0.0, 0.0, lim)
    sp = px.s_profile(curve, chain.length, chain.cum[1:-1].tolist())
    profs = px.axis_profiles(chain, sp, 0.001, [0.0, 0.0])
    for i, p in enumerate(profs):
        assert p.end.p == els[-1].end[i]
    t = np.linspace(0.0, sp.duration, 4001)
    xy = np.stack([p.sample(t).p for p in profs], axis=1)
    s = sp.sample(t).p
    k = np.clip(np.searchsorted(chain.cum, s, side="right") - 1, 0, len(els) - 1)
    ref = np.empty_like(xy)
    for i in np.unique(k):
        ref[k == i] = els[i].point(np.clip(s[k == i] - chain.cum[i], 0.0, els[i].length))
    assert np.max(np.abs(xy - ref)) < 1e-3
    for p in profs:
        smp = p.sample(t)
        assert np.abs(smp.v).max() <= 15_000.0 * (1 + 1e-6)
        assert np.abs(smp.a).max() <= 150_000.0 * (1 + 1e-4)
    # hold part-way: decelerates on the path, never faster than the plan, stops at rest
    st_ = sp.state_at(hold_frac * sp.duration)
    a_min = min(x.accel for x in plan_speeds(els, lim.feed, lim.accel,
                                             axis_vmax=lim.axis_vmax,
                                             axis_amax=lim.axis_amax) if x.length > 0)
    held = px.hold_curve(curve, st_.p, st_.v, a_min)
    s_stop = px.stop_point(held)
    assert st_.p <= s_stop <= chain.length
    grid = np.linspace(st_.p, s_stop, 200)
    assert np.all(np.interp(grid, held.s, held.v2) <= np.interp(grid, curve.s, curve.v2) + 1e-6)
    # continue from there: the rest of the path ends on the same point
    rest = px.plan_curve(chain, s_stop, 0.0, lim)
    sp2 = px.s_profile(rest, chain.length, chain.cum[1:-1].tolist())
    start = chain.point(s_stop)
    profs2 = px.axis_profiles(chain, sp2, 0.001, start)
    assert [p.end.p for p in profs2] == [p.end.p for p in profs]


def test_sharp_zigzag_is_never_slower_than_exact_stop():
    # 143 degree turns with a small tolerance: tiny blend arcs would crawl; they are skipped
    pts = zigzag(30, 1000.0, 3000.0)
    t_exact, _, _ = run(pts, None)
    t_blend, end, (sx, sy) = run(pts, 20.0)
    assert end.tolist() == pts[-1].tolist()
    assert t_blend <= t_exact + 1e-9
    for s in (sx, sy):
        assert np.abs(s.a).max() <= AMAX * (1 + 1e-9)


def test_contour_error_of_a_recorded_arc_run():
    ctl, g = make(None)
    g.line([20_000, 10_000])
    g.arc([20_000, 15_000], [20_000, 20_000], direction="CCW")
    t0 = ctl.time
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and not any(
        a.is_moving for a in g.axes), 10, event_driven=True)
    t = np.linspace(t0, ctl.time, 5001)
    xy = np.stack([ctl.history.sample(a.index, t).p for a in g.axes], axis=1)
    els = [Line([0, 0], [20_000, 10_000]),
           Arc([20_000, 10_000], [20_000, 15_000], [20_000, 20_000])]
    err = px.contour_error(xy, els)
    assert err.max() < 1e-3  # the planned motion: far inside the half-pulse bound
    off = px.contour_error(xy + np.array([0.0, 3.0]), els[:1])
    assert off.max() >= 2.0  # it does measure something


def test_integer_pulse_counts_follow_the_arc():
    ctl, g = make(None)
    g.arc([5000, 0], [10_000, 0], direction="CCW")
    rows = []
    ctl.add_cycle_hook(lambda c, t: rows.append(
        [c.hardware.read_axis(k).pulses_out for k in (0, 1)]
        + [c.axes[0].position, c.axes[1].position]))
    finish_group(ctl, g, 10)
    r = np.array(rows, dtype=float)
    # the simulated pulse generator rounds to nearest (half-pulse rule): at every cycle end
    # the counts are the planned positions rounded, and those are on the circle
    assert np.abs(r[:, :2] - r[:, 2:]).max() <= 0.5 + 1e-9
    arc = Arc([0, 0], [5000, 0], [10_000, 0])
    assert px.contour_error(r[:, 2:], [arc]).max() < 1e-6
    assert px.contour_error(r[:, :2], [arc]).max() <= 0.5 * np.sqrt(2.0) + 1e-6


def run_recorded(names, feed, build, half=True):
    """Run a group program with the pulse record on; (controller, group, t0)."""
    ctl = table_without_mel()
    ctl.hardware.set_half_pulse(half)
    g = Group(ctl, names, feed=feed, acc_time=0.1)
    ctl.hardware.record_pulses()
    t0 = ctl.time
    build(g)
    finish_group(ctl, g)
    return ctl, g, t0


def test_half_pulse_counts_stay_within_half_a_pulse_on_lines_and_arcs():
    # issue 4 item 6: at every pulse of every axis (the instants where a count changes, so
    # the supremum over the run), each integer count is within half a pulse of the position
    # its generator follows, both directions, lines and arcs at unequal axis speeds
    els = [Line([0, 0], [7_001, 3_333]), Arc([7_001, 3_333], [7_001, 8_333], [7_001, 13_333]),
           Line([7_001, 13_333], [10.4, 20.6])]

    def build(g):
        g.line([7_001, 3_333])
        g.arc([7_001, 8_333], [7_001, 13_333], direction="CCW")  # x goes up then down
        g.line([10.4, 20.6])  # both axes: down / up at non-integer rates

    ctl, g, t0 = run_recorded(["x", "y"], 40_000.0, build)
    acc = pulse_accuracy(ctl, ["x", "y"], els, t0, ctl.time)
    assert acc.samples > 2 * 13_333  # every pulse of both axes was checked
    assert max(acc.axis_error) <= 0.5 + 1e-9
    assert min(acc.axis_error) > 0.5 - 1e-6  # the bound is reached: the check means something
    # the commanded cubic (one per cycle) follows the plan closely; the count point then
    # stays within the half-pulse box around the path
    assert max(acc.command_error) < 0.02
    assert acc.contour_error <= 0.5 * np.sqrt(2.0) + np.hypot(*acc.command_error) + 1e-3
    assert [ctl.hardware.read_axis(k).pulses_out for k in (0, 1)] == [10, 21]


def test_half_pulse_bound_on_a_full_circle_and_a_3_axis_helix():
    r = 1_500.0
    els = [Line([0, 0, 0], [r, 0, 1_234]),
           Arc([r, 0, 1_234], [0, 0], [r, 0, 1_234]),              # full circle, z still
           Arc([r, 0, 1_234], [0, 0], [-r, 0, 0], direction="CW"),  # helix: z goes down
           Line([-r, 0, 0], [-1, 17, 5])]

    def build(g):
        g.line([r, 0, 1_234])
        g.circle([0, 0])
        g.arc([0, 0], [-r, 0, 0], direction="CW")
        g.line([-1, 17, 5])

    ctl, g, t0 = run_recorded(["x", "y", "z"], 30_000.0, build)
    acc = pulse_accuracy(ctl, ["x", "y", "z"], els, t0, ctl.time)
    assert max(acc.axis_error) <= 0.5 + 1e-9
    assert min(acc.axis_error) > 0.5 - 1e-6
    bound = 0.5 * np.sqrt(3.0) + np.linalg.norm(acc.command_error) + 1e-3
    assert acc.contour_error <= bound
    assert g.position.tolist() == [-1, 17, 5]
    assert [ctl.hardware.read_axis(k).pulses_out for k in (0, 1, 2)] == [-1, 17, 5]


def test_floor_rule_opt_out_measures_up_to_one_pulse():
    # the same helper on the opt-out rule: a count lags its command by up to a whole pulse
    els = [Line([0, 0], [4_001, 2_222])]
    ctl, g, t0 = run_recorded(["x", "y"], 40_000.0, lambda g: g.line([4_001, 2_222]),
                              half=False)
    acc = pulse_accuracy(ctl, ["x", "y"], els, t0, ctl.time)
    assert max(acc.axis_error) <= 1.0 + 1e-9
    assert min(acc.axis_error) > 1.0 - 1e-6
    assert acc.contour_error > 0.5 * np.sqrt(2.0)


def test_commands_queued_while_running_join_the_look_ahead():
    ctl, g = make(30.0)
    t0 = ctl.time
    pts = polygon(24, 20_000.0)
    g.line(pts[0])
    g.line(pts[1])
    ctl.advance(0.05)
    for p in pts[2:]:  # streamed while the first lines run: no stop at any junction
        g.line(p)
        ctl.advance(0.01)
    # commands wait in the queue until the running chain needs them (lazy look-ahead)
    assert g.queue_length > 0
    ctl.run_until(lambda: g.state is GroupState.IDLE and not any(
        a.is_moving for a in g.axes), 30, event_driven=True)
    assert g.position.tolist() == pts[-1].tolist()
    t = np.linspace(t0, ctl.time, 20001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    speed = np.hypot(sx.v, sy.v)
    inner = (t > t0 + 0.3) & (t < ctl.time - 0.3)
    assert speed[inner].min() > 1000.0  # never stopped on the polygon
    verts = np.vstack([[0.0, 0.0], pts])
    assert dist_to_polyline(np.stack([sx.p, sy.p], axis=1), verts).max() <= 30.0 * (1 + 1e-6)
    for s in (sx, sy):
        assert np.abs(s.a).max() <= AMAX * (1 + 1e-9)
        assert np.abs(s.v).max() <= VMAX * (1 + 1e-9)


def test_command_queued_while_braking_stops_exactly_at_the_corner():
    ctl, g = make(30.0)
    g.line([3000, 1000])
    ctl.step()
    ctl.run_until(lambda: g.axes[0].velocity < 2000 and g.axes[0].motion_done == 13, 5)
    assert g.state is GroupState.MOVING
    g.line([3000, 5000])  # too late to blend: the corner is an exact stop
    ctl.run_until(lambda: g.state is GroupState.IDLE and not any(
        a.is_moving for a in g.axes), 10, event_driven=True)
    assert g.position.tolist() == [3000.0, 5000.0]


@settings(max_examples=size(3, 10), deadline=None)
@given(st.lists(st.tuples(st.floats(0.02, 0.6), st.floats(5.0, 200.0)), min_size=1,
                max_size=3), st.booleans())
def test_overrides_and_holds_at_random_times_keep_path_limits_and_end(events, with_hold):
    ctl, g = make(40.0)
    t0 = ctl.time
    pts = np.array([[20_000.0, 0], [20_000, 20_000], [0, 20_000], [1000, 1000]])
    for p in pts:
        g.line(p)
    ctl.step()
    for k, (dt, pct) in enumerate(events):
        ctl.advance(dt)
        if g.state is GroupState.MOVING:
            g.set_override(pct)
        if with_hold and k == 0 and g.state is GroupState.MOVING:
            g.hold()
            ctl.run_until(lambda: g.state is GroupState.HELD, 5, event_driven=True)
            g.cont()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and not any(
        a.is_moving for a in g.axes), 60, event_driven=True)
    assert g.position.tolist() == pts[-1].tolist()
    t = np.linspace(t0, ctl.time, 8001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    verts = np.vstack([[0.0, 0.0], pts])
    assert dist_to_polyline(np.stack([sx.p, sy.p], axis=1), verts).max() <= 40.0 * (1 + 1e-6)
    for s in (sx, sy):
        assert np.abs(s.a).max() <= AMAX * (1 + 1e-9)
        assert np.abs(s.v).max() <= VMAX * (1 + 1e-9)
