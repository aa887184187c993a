"""Time-overlap blending (MCCL 2.6.3 II in the core, control/groups/overlap.py): the next
command starts when the running one begins its final deceleration and every axis follows
the sum of both motions. Times, corner positions, speeds and caps on recorded runs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers import finish_group, free_axes
from openmotion.control.groups.group import Group, GroupState

F, TA = 20_000.0, 0.1


def run(cmds, *, blend=True, period=0.005, amax=None, dec=None, setup=None):
    ctl = free_axes(2, period=period)
    g = Group(ctl, ["x", "y"], feed=F, acc_time=TA)
    if dec is not None:
        g.set_dec_time(dec)
    if amax is not None:
        g.set_max_pulse_acc([amax, amax])
    if blend:
        g.enable_overlap_blend()
        assert g.blend_mode == "overlap"
    if setup:
        setup(g)
    t0 = ctl.time
    for kind, *args in cmds:
        kw = args.pop() if args and isinstance(args[-1], dict) else {}
        getattr(g, kind)(*args, **kw)
    t1 = finish_group(ctl, g)
    return ctl, g, t0, t1


def samples(ctl, t0, t1, dt=1e-5):
    t = np.arange(t0, t1, dt)
    return t, ctl.history.sample(0, t), ctl.history.sample(1, t)


CORNER = [("line", [10_000, 0]), ("line", [10_000, 10_000])]


def test_a_corner_overlaps_the_deceleration_and_the_acceleration():
    ctl, g, t0, t1 = run(CORNER)
    _, _, a0, a1 = run(CORNER, blend=False)
    assert [a.position for a in g.axes] == [10_000.0, 10_000.0]
    # apart: 2 x (L/F + TA); blended: one deceleration time less
    assert (a1 - a0) - (t1 - t0) == pytest.approx(TA, abs=1e-9)
    t, sx, sy = samples(ctl, t0, t1)
    # the second line starts as the first begins to decelerate: L/F after its start
    start_y = t[np.nonzero(np.abs(sy.v) > 1e-6)[0][0]]
    start_x = t[np.nonzero(np.abs(sx.v) > 1e-6)[0][0]]
    assert start_y - start_x == pytest.approx(10_000 / F, abs=2e-5)
    # in the middle of the overlap both axes run at F/2: the tangent speed F/sqrt(2)
    mid = start_y + TA / 2
    vx, vy = ctl.history.sample(0, [mid]).v[0], ctl.history.sample(1, [mid]).v[0]
    tol = F / TA * 2e-5                   # the sampled start is up to 1e-5 s late
    assert (vx, vy) == (pytest.approx(F / 2, abs=tol), pytest.approx(F / 2, abs=tol))
    # and the path passes sqrt(2) F TA / 8 from the corner (T ramps: F tau^2 / (2 TA))
    px, py = ctl.history.sample(0, [mid]).p[0], ctl.history.sample(1, [mid]).p[0]
    assert (px, py) == (pytest.approx(10_000 - F * TA / 8, abs=0.5),
                        pytest.approx(F * TA / 8, abs=0.5))
    # speed and position continuous, no axis above the feed or the command acceleration
    assert np.abs(sx.v).max() <= F * (1 + 1e-9) and np.abs(sy.v).max() <= F * (1 + 1e-9)
    assert np.abs(sx.a).max() <= F / TA * (1 + 1e-6)


def test_collinear_commands_keep_the_feed_through_the_join():
    cmds = [("line", [10_000, 0]), ("line", [25_000, 0])]
    ctl, g, t0, t1 = run(cmds)
    t, sx, _ = samples(ctl, t0, t1)
    cruise = (t > t0 + TA + 0.01) & (t < t1 - TA - 0.01)
    assert np.allclose(sx.v[cruise], F, rtol=1e-9)
    assert g.axes[0].position == 25_000.0


def test_line_arc_and_arc_arc_stay_within_the_caps_and_end_exactly():
    cmds = [("line", [10_000, 0]), ("arc", [10_000, 5_000], [10_000, 10_000]),
            ("arc", [10_000, 15_000], [10_000, 20_000], {"direction": "CW"}),
            ("line", [20_000, 20_000])]
    amax = 3.0 * F / TA
    ctl, g, t0, t1 = run(cmds, amax=amax)
    _, _, a0, a1 = run(cmds, blend=False, amax=amax)
    assert [a.position for a in g.axes] == [20_000.0, 20_000.0]
    # symmetric ramps: each command starts L/F after the one before (when that one begins
    # to decelerate), so the whole would take sum(L)/F + TA, as the look-ahead chain of
    # these tangent elements; an arc ramps at half the path acceleration (the look-ahead's
    # arc rule, 2 TA), so the last line (TA) starts TA after the arc began to decelerate:
    # one TA more. It never stops: the speed dips to F/2 at the end of a line's overlay
    assert (t1 - t0) - (a1 - a0) == pytest.approx(TA, abs=1e-9)
    t, sx, sy = samples(ctl, t0, t1)
    inner = (t > t0 + TA + 0.01) & (t < t1 - TA - 0.01)
    assert np.hypot(sx.v, sy.v)[inner].min() == pytest.approx(F / 2, rel=1e-6)
    # an arc decelerates over 2 TA, the line after it accelerates in TA: it starts TA
    # before the arc ends, so the speeds never add up beyond the feed
    assert np.hypot(sx.v, sy.v).max() <= F * (1 + 1e-9)
    for s in (sx, sy):
        assert np.abs(s.a).max() <= amax * (1 + 1e-6)
    # position continuous (no jump between samples beyond the speed)
    assert np.abs(np.diff(sx.p)).max() <= F * 1e-5 * 1.01


def test_a_reversal_that_would_pass_the_acceleration_cap_runs_apart():
    cmds = [("line", [10_000, 0]), ("line", [0, 0])]
    # reversing, the axis decelerates and accelerates backwards at once: 2 F/TA
    ctl, g, t0, t1 = run(cmds, amax=1.5 * F / TA)
    _, _, a0, a1 = run(cmds, blend=False, amax=1.5 * F / TA)
    assert t1 - t0 == pytest.approx(a1 - a0, abs=1e-9)
    t, sx, _ = samples(ctl, t0, t1)
    assert np.abs(sx.a).max() <= 1.5 * F / TA * (1 + 1e-6)
    # with room for it the reversal blends, at twice the acceleration
    ctl, g, t0, t1 = run(cmds, amax=2.0 * F / TA)
    assert t1 - t0 == pytest.approx(a1 - a0 - TA, abs=1e-9)
    t, sx, _ = samples(ctl, t0, t1)
    assert np.abs(sx.a).max() == pytest.approx(2.0 * F / TA, rel=1e-6)
    assert g.axes[0].position == 0.0


def test_ptp_and_paths_blend_into_each_other():
    cmds = [("ptp", [10_000, 5_000]), ("line", [20_000, 5_000]), ("ptp", [0, 0])]
    ctl, g, t0, t1 = run(cmds)
    _, _, a0, a1 = run(cmds, blend=False)
    assert t1 - t0 < a1 - a0 - 0.05
    assert [a.position for a in g.axes] == [0.0, 0.0]


def test_many_short_segments_end_exactly_and_overlap_two_at_a_time():
    pts = [[1_000 * (k + 1), 700 * ((k + 1) % 2)] for k in range(12)]
    cmds = [("line", p) for p in pts]
    ctl, g, t0, t1 = run(cmds)
    _, _, a0, a1 = run(cmds, blend=False)
    assert [a.position for a in g.axes] == [12_000.0, 0.0]
    assert t1 - t0 < a1 - a0
    t, sx, sy = samples(ctl, t0, t1)
    assert np.hypot(sx.v, sy.v).max() <= F * (1 + 1e-9)


def test_hold_and_override_during_the_overlap_wait_for_its_end():
    ctl = free_axes(2, period=0.005)
    g = Group(ctl, ["x", "y"], feed=F, acc_time=TA)
    g.enable_overlap_blend()
    for c in CORNER:
        getattr(g, c[0])(c[1])
    ctl.run_until(lambda: abs(g.axes[1].velocity) > 0.0, 5.0)   # the overlap began
    t_hold = ctl.time
    g.hold()
    assert g.state is GroupState.HOLDING
    ctl.run_until(lambda: g.state is GroupState.HELD, 5.0)
    t = np.arange(t_hold, ctl.time, 1e-5)
    vx = ctl.history.sample(0, t).v
    # x finishes its own deceleration (TA); then the second line's stop from there
    assert t[np.nonzero(np.abs(vx) < 1e-6)[0][0]] - t_hold <= TA + 0.005 + 1e-6
    g.cont()
    finish_group(ctl, g)
    assert [a.position for a in g.axes] == [10_000.0, 10_000.0]
    # an override asked in the overlap applies when it ends
    ctl2 = free_axes(2, period=0.005)
    g2 = Group(ctl2, ["x", "y"], feed=F, acc_time=TA)
    g2.enable_overlap_blend()
    g2.line([10_000, 0])
    g2.line([10_000, 30_000])
    ctl2.run_until(lambda: abs(g2.axes[1].velocity) > 0.0, 5.0)
    g2.set_override(50.0)
    ctl2.advance(TA + 0.3)
    assert abs(g2.axes[1].velocity) == pytest.approx(F / 2)
    finish_group(ctl2, g2)
    assert [a.position for a in g2.axes] == [10_000.0, 30_000.0]


def test_no_blend_in_dry_run_or_after_disable():
    ctl, g, t0, t1 = run(CORNER, setup=lambda g: g.enable_dry_run())
    _, _, a0, a1 = run(CORNER, blend=False, setup=lambda g: g.enable_dry_run())
    assert t1 - t0 == pytest.approx(a1 - a0, abs=1e-9)
    ctl, g, t0, t1 = run(CORNER, setup=lambda g: g.disable_blend())
    assert g.blend_mode == "off"
    assert t1 - t0 == pytest.approx(a1 - a0, abs=1e-9)
    assert math.isfinite(t1)


@pytest.mark.parametrize("dec_shape", [None, "T"])
def test_s_ramps_overlap_exactly_and_a_deceleration_shape_apart_blends_too(dec_shape):
    def setup(g):
        g.set_path_shape("S", s_factor=1.0)
        g.set_path_dec_shape(dec_shape)
    cmds = [("line", [10_000, 0]), ("line", [25_000, 0]), ("line", [25_000, 10_000])]
    ctl, g, t0, t1 = run(cmds, setup=setup)
    assert [a.position for a in g.axes] == [25_000.0, 10_000.0]
    t, sx, sy = samples(ctl, t0, t1)
    speed = np.hypot(sx.v, sy.v)
    assert speed.max() <= F * (1 + 1e-9)
    # the collinear join: an S deceleration and an S acceleration of equal times add up
    # to the feed; a T deceleration under an S acceleration does not (a dip)
    join = (t > t0 + 0.5 - 0.04) & (t < t0 + 0.5 + 0.14)
    flat = bool(np.allclose(speed[join], F, rtol=1e-9))
    assert flat == (dec_shape is None)
    assert speed[join].min() > 0.7 * F


@pytest.mark.parametrize("kind", ["path", "mixed"])
def test_virtual_jumps_give_the_same_blends_as_every_cycle(kind):
    cmds = CORNER + [("line", [0, 10_000])] if kind == "path" else \
        [("ptp", [10_000, 5_000]), ("line", [20_000, 5_000]), ("ptp", [0, 0])]

    def once(jumps):
        ctl = free_axes(2, period=0.005)
        ctl.virtual_jumps = jumps
        g = Group(ctl, ["x", "y"], feed=F, acc_time=TA)
        g.enable_overlap_blend()
        t0 = ctl.time
        for c, p in cmds:
            getattr(g, c)(p)
        t1 = finish_group(ctl, g)
        t = np.arange(t0, t1, 1e-3)
        return t1 - t0, [ctl.history.sample(k, t).p for k in (0, 1)]
    (d1, p1), (d2, p2) = once(True), once(False)
    assert d1 == d2
    for a, b in zip(p1, p2, strict=True):
        assert np.array_equal(a, b)
