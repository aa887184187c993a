"""superpose(): the rest of a running move plus a next move is their exact sum."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.control.core.planning import position_move
from openmotion.errors import MotionError
from openmotion.profile.pcl import MoveSpec
from openmotion.profile.superpose import deceleration_start, superpose


def move(shape, p0, p1, v=5000.0, ta=0.05, td=0.08):
    return position_move(MoveSpec(shape, 0.0, v, ta, td), p0, p1)


@settings(max_examples=40, deadline=None)
@given(st.sampled_from("TS"), st.sampled_from("TS"), st.integers(-3000, 3000).filter(bool),
       st.integers(-3000, 3000).filter(bool), st.floats(0.0, 1.0), st.floats(0.0, 0.3))
def test_sum_matches_the_two_moves_sampled(sa, sb, da, db, frac, delay):
    a = move(sa, 100.0, 100.0 + da)
    b = move(sb, 100.0 + da, 100.0 + da + db, v=3000.0, ta=0.03, td=0.03)
    since = frac * a.duration
    s = superpose(a, since, b, delay)
    t = np.linspace(-0.01, s.duration + 0.05, 3001)
    got = s.sample(t)
    ra, nb = a.sample(t + since), b.sample(t - delay)
    want_p = np.where(t < 0, got.p, ra.p + nb.p - b.start.p)
    assert np.allclose(got.p[t >= 0], want_p[t >= 0], atol=1e-6)
    assert np.allclose(got.v[t >= 0], (ra.v + nb.v)[t >= 0], atol=1e-6)
    assert s.end.p == 100.0 + da + db
    assert s.state_at(0.0).p == pytest.approx(a.state_at(since).p, abs=1e-9)


def test_deceleration_start_of_t_and_s_moves():
    a = move("T", 0.0, 2000.0)   # cruise reached: the deceleration lasts td
    assert a.duration - deceleration_start(a) == pytest.approx(0.08, abs=1e-9)
    s = move("S", 0.0, 2000.0)
    assert s.duration - deceleration_start(s) == pytest.approx(0.08, abs=1e-9)
    tri = move("T", 0.0, 50.0)   # no cruise: from the peak on
    k = np.argmax(tri.sample(np.linspace(0, tri.duration, 10001)).v)
    assert deceleration_start(tri) == pytest.approx(k * tri.duration / 10000, abs=1e-3)


def test_refusals():
    a = move("T", 0.0, 2000.0)
    with pytest.raises(MotionError, match="since"):
        superpose(a, -1.0, a, 0.0)
    with pytest.raises(MotionError, match="delay"):
        superpose(a, 0.0, a, float("nan"))
