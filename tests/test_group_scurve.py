"""S-curve (jerk-limited) path speed in groups: the jerk of the path position stays within
the limit on lines, arcs and holds; paths still end exactly on their targets."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import finish_group, table_without_mel
from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.errors import MotionError
from openmotion.path.smoothing import fir_smooth, jerk_window
from openmotion.profile.segments import ProfileBuilder

FEED, ACC_T, JERK = 20_000.0, 0.05, 2.0e7  # pps, s (accel 400 000 pps^2), pps^3


def make() -> tuple[Controller, Group]:
    ctl = table_without_mel(safety=False)  # the table's -EL sits just below 0
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=ACC_T)
    g.set_path_shape("S", jerk=JERK)
    return ctl, g


finish = finish_group  # run until idle, queue empty, axes still; the end time


def test_line_jerk_within_limit_and_exact_end():
    ctl, g = make()
    t0 = ctl.time
    g.line([30_000, 12_000])
    t1 = finish(ctl, g)
    assert [a.position for a in g.axes] == [30_000.0, 12_000.0]
    t = np.linspace(t0, t1, 40001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    jerk = np.hypot(sx.j, sy.j)
    acc = np.hypot(sx.a, sy.a)
    assert jerk.max() <= JERK * (1 + 1e-9)
    assert jerk.max() > 0.2 * JERK  # the jerk is really used (not a T-curve)
    assert acc.max() <= FEED / ACC_T * (1 + 1e-9)
    assert np.hypot(sx.v, sy.v).max() <= FEED * (1 + 1e-9)
    # acceleration is continuous: no jump between samples beyond jerk * dt
    assert np.max(np.abs(np.diff(sx.a))) <= JERK * (t[1] - t[0]) * (1 + 1e-6) + 1e-6


def test_arc_path_jerk_within_limit_and_on_circle():
    ctl, g = make()
    t0 = ctl.time
    g.arc([0, 10_000], [0, 20_000], direction="CW")
    sp = []
    ctl.add_cycle_hook(lambda c, t: sp.append(g._run.plan.sprof) if g._run is not None
                       and g._run.kind == "path" and (not sp or sp[-1] is not g._run.plan.sprof)
                       else None)
    t1 = finish(ctl, g)
    assert [a.position for a in g.axes] == [0.0, 20_000.0]
    s = sp[0].sample(np.linspace(0.0, sp[0].duration, 20001))
    assert np.abs(s.j).max() <= JERK * (1 + 1e-9)
    t = np.linspace(t0, t1, 20001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    assert np.max(np.abs(np.hypot(sx.p, sy.p - 10_000) - 10_000)) < 1e-3


def test_hold_keeps_jerk_and_continue_ends_exactly():
    ctl, g = make()
    t0 = ctl.time
    g.line([60_000, 0])
    ctl.run_until(lambda: ctl.time >= t0 + 0.08, 5)  # mid acceleration ramp
    g.hold()
    ctl.run_until(lambda: g.state is GroupState.HELD, 5)
    t1 = ctl.time
    x = ctl.history.sample(g.axes[0].index, np.linspace(t0, t1, 40001))
    assert np.abs(x.j).max() <= JERK * (1 + 1e-9)
    assert np.max(np.abs(np.diff(x.a))) <= JERK * (t1 - t0) / 40000 * (1 + 1e-6) + 1e-6
    assert 0 < g.axes[0].position < 60_000
    g.cont()
    finish(ctl, g)
    assert g.axes[0].position == 60_000.0


def test_bad_shape_refused():
    _, g = make()
    with pytest.raises(MotionError, match="shape"):
        g.set_path_shape("Q")
    with pytest.raises(MotionError, match="jerk"):
        g.set_path_shape("S", jerk=0.0)
    with pytest.raises(MotionError, match="jerk"):
        g.set_path_shape("S", jerk=float("nan"))


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(0.001, 0.2), st.floats(-300.0, 300.0)), min_size=1,
                max_size=6), st.floats(1e3, 1e5))
def test_fir_smooth_bounds(pieces, jerk):
    # any constant-acceleration motion from rest to rest (a braking tail appended)
    b = ProfileBuilder(1.0, 0.0)
    for dt, a in pieces:
        v = b.state.v
        if v + a * dt < 0.0:  # do not reverse
            dt = v / -a if a < 0 else dt
        b.segment(dt, 0.0, accel=a)
    v = b.state.v
    if v > 0.0:
        b.segment(v / 300.0, 0.0, accel=-300.0)
    raw = b.build()
    raw_end = raw.segment_end(raw.n_segments - 1).p if raw.n_segments else raw.end.p
    raw = b.build(end_p=raw_end)
    tj = jerk_window(300.0, jerk)
    f = fir_smooth(raw, tj)
    assert f.duration == pytest.approx(raw.duration + tj)
    s = f.sample(np.linspace(0.0, f.duration, 4001))
    rv = raw.sample(np.linspace(0.0, raw.duration, 4001)).v
    assert np.abs(s.j).max() <= jerk * (1 + 1e-9)
    assert np.abs(s.a).max() <= 300.0 * (1 + 1e-9)
    assert s.v.max() <= rv.max() * (1 + 1e-9) + 1e-12
    assert f.end.p == raw.end.p
    e = f.segment_end(f.n_segments - 1)
    assert abs(e.p - raw.end.p) < 1e-9 and abs(e.v) < 1e-9
