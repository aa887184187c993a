"""The planner's float fast paths give what the general code gave, bit for bit.

- `pathexec.s_profile` walks its speed curve on Python floats: compared with the same walk
  on numpy scalars (the code it replaced, kept here as the oracle) on random curves with
  exact stops, dwells and element breaks.
- `plan_speeds` checks per-element feeds/accelerations in one pass: a bad value is still
  refused by name and index.
- `jerk_limited_sync` (one compiled call for all axes, peak velocities reused) against
  profiles built axis by axis through `ProfileBuilder` from the oracle's phase times
  (tests/jerk_oracle.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import jerk_oracle as O
from openmotion.control.groups import pathexec as px
from openmotion.errors import InfeasibleError, MotionError
from openmotion.path import Line, plan_speeds
from openmotion.profile import jerk as J
from openmotion.profile.segments import Profile, ProfileBuilder


def _s_profile_oracle(curve: px.SpeedCurve, s_end: float, breaks, *, dwell: float = 0.0,
                      lead: float = 0.0) -> Profile:
    """s_profile as it was: the same loop on numpy scalars."""
    brk = np.asarray(breaks, dtype=float)
    knots = np.union1d(curve.s, brk[(brk > curve.s[0]) & (brk < s_end)])
    knots = knots[(knots >= curve.s[0]) & (knots <= s_end)]
    v2 = np.maximum(np.interp(knots, curve.s, curve.v2), 0.0)
    v = np.sqrt(v2)
    ds = np.diff(knots)
    dv2 = np.diff(v2)
    b = ProfileBuilder(float(knots[0]), float(v[0]), v_before=0.0 if curve.jump else None)
    if lead > 0.0:
        b.segment(lead, 0.0, accel=0.0, label="dwell")
    last = len(ds) - 1
    crawl = 2e-6 * float(v.max(initial=0.0))
    for k in range(len(ds)):
        if ds[k] <= 0.0:
            continue
        a = dv2[k] / (2.0 * ds[k])
        vm = v[k] + v[k + 1]
        if vm <= 0.0 or (2.0 * ds[k] / vm > 1e6 and vm < crawl):
            if ds[k] <= 1e-9 * max(1.0, s_end):
                continue
            raise InfeasibleError("path speed curve stalls at rest before its end")
        dt = 2.0 * ds[k] / vm
        b.set_velocity(float(v[k]))
        b.segment(dt, 0.0, accel=float(a))
        if dwell > 0.0 and v[k + 1] == 0.0 and k < last:
            b.set_velocity(0.0)
            b.segment(dwell, 0.0, accel=0.0, label="dwell")
    return b.build(end_p=float(s_end))


def _same(p: Profile, q: Profile) -> None:
    for f in ("t0", "p0", "v0", "a0", "j", "dt"):
        assert np.array_equal(getattr(p, f), getattr(q, f)), f
    assert (p.duration, p.start, p.end, p.labels) == (q.duration, q.start, q.end, q.labels)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.floats(1e-6, 50.0), st.floats(0.0, 1e4)), min_size=1,
                max_size=30),
       st.floats(0.0, 1e3), st.floats(0.0, 0.05), st.floats(0.0, 0.05), st.booleans(),
       st.lists(st.floats(0.0, 1.0), max_size=10))
def test_s_profile_is_the_numpy_scalar_walk(pieces, s0, dwell, lead, jump, brk):
    s = [s0]
    v2 = [pieces[0][1]]
    for ds, w in pieces:
        s.append(s[-1] + ds)
        v2.append(w)
    v2[-1] = 0.0  # a curve ends at rest
    curve = px.SpeedCurve(np.array(s), np.array(v2), jump=jump)
    breaks = [s0 + b * (s[-1] - s0) for b in brk]
    try:
        ref = _s_profile_oracle(curve, s[-1], breaks, dwell=dwell, lead=lead)
    except InfeasibleError:
        with pytest.raises(InfeasibleError):
            px.s_profile(curve, s[-1], breaks, dwell=dwell, lead=lead)
        return
    _same(px.s_profile(curve, s[-1], breaks, dwell=dwell, lead=lead), ref)


@pytest.mark.parametrize("bad, rule", [(math.nan, "finite"), (-2.0, "> 0"),
                                       (math.inf, "finite"), (0.0, "> 0")])
def test_per_element_values_still_refused_by_index(bad, rule):
    els = [Line(np.array([0.0, 0.0]), np.array([1.0, 0.0])),
           Line(np.array([1.0, 0.0]), np.array([2.0, 1.0]))]
    for name, kw in (("feed", {"feed": [1.0, bad], "accel": 100.0}),
                     ("accel", {"feed": 1.0, "accel": [100.0, bad]})):
        with pytest.raises(MotionError, match=rf"{name}\[1\] must be {rule}"):
            plan_speeds(els, **kw)


def _axis_by_axis(dists, v, a, j, d):
    """The synced profiles built one axis at a time through ProfileBuilder."""
    times = [O.phase_times(abs(x), v[i], a[i], d[i], j[i]) for i, x in enumerate(dists)]
    t_sync = max(math.fsum(t) for t in times)
    out = []
    for i, x in enumerate(dists):
        tm = times[i]
        if math.fsum(tm) < t_sync:
            cap = O._synced_cap(abs(x), t_sync, v[i], a[i], d[i], j[i])
            tm = O.phase_times(abs(x), v[i], a[i], d[i], j[i], v_cap=cap)
        out.append((O.build_with_builder(0.0, x, tm, a[i], d[i], j[i]), t_sync))
    return out


pos = st.floats(1.0, 1e6)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.floats(-1e6, 1e6).filter(lambda x: abs(x) > 1e-3), pos, pos,
                          st.floats(10.0, 1e9), pos), min_size=1, max_size=4))
def test_sync_is_axis_by_axis(axes):
    dists, v, a, j, d = (list(c) for c in zip(*axes, strict=True))
    got = J.jerk_limited_sync(dists, v, a, j, d_max=d)
    for p, (q, t_sync) in zip(got, _axis_by_axis(dists, v, a, j, d), strict=True):
        for f in ("t0", "p0", "v0", "a0", "j", "dt"):
            assert np.array_equal(getattr(p, f), getattr(q, f)), f
        assert p.duration == t_sync
        assert p.end == q.end and p.labels == q.labels


def test_peak_speed_bounds_every_sampled_speed():
    """groupexec._peak_speed bounds |v| everywhere (the join check skips evaluating s(t)
    while the length ahead minus peak x elapsed time still holds the reach)."""
    from openmotion.control.groups.groupexec import _peak_speed

    rng = np.random.default_rng(7)
    for _ in range(50):
        b = ProfileBuilder(0.0, float(rng.uniform(0, 5)))
        for _ in range(int(rng.integers(1, 8))):
            b.segment(float(rng.uniform(0.01, 0.5)), float(rng.uniform(-50, 50)),
                      accel=float(rng.uniform(-10, 10)))
        p = b.build()
        v = p.sample(np.linspace(0.0, p.duration, 2001)).v
        assert np.max(np.abs(v)) <= _peak_speed(p) * (1 + 1e-12)
