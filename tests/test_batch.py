"""Vectorized jerk-limited planner: equals the scalar planner, validates like it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.profile.batch import jerk_limited_durations, jerk_limited_phases
from openmotion.profile.jerk import PHASE_LABELS, jerk_limited, jerk_limited_duration
from test_jerk import accs_, distances, jerks, vels


def _random_moves(n: int, seed: int = 3):
    rng = np.random.default_rng(seed)
    dist = rng.choice([-1.0, 1.0], n) * 10 ** rng.uniform(-3, np.log10(2**27 - 1), n)
    dist[::97] = 0.0
    return (dist, 10 ** rng.uniform(-1, 7, n), 10 ** rng.uniform(-1, 9, n),
            10 ** rng.uniform(-1, 12, n), 10 ** rng.uniform(-1, 9, n))


@pytest.mark.parametrize("with_d", [False, True])
def test_batch_equals_scalar_on_many_random_moves(with_d):
    dist, v, a, j, d = _random_moves(4000)
    dd = d if with_d else None
    got = jerk_limited_durations(dist, v, a, j, dd)
    ref = np.array([jerk_limited_duration(dist[i], v[i], a[i], j[i],
                                          d_max=None if dd is None else dd[i])
                    for i in range(dist.size)])
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=0.0)
    assert (got[::97] == 0.0).all()


@settings(max_examples=100, deadline=None)
@given(distances, vels, accs_, jerks, st.one_of(st.none(), accs_))
def test_phase_times_equal_the_built_profile(dist, v, a, j, d):
    ph = jerk_limited_phases(dist, v, a, j, d)
    assert ph.shape == (1, 7)
    prof = jerk_limited(dist, v, a, j, d_max=d)
    built = {p.label: p.duration for p in prof.phases()}
    for k, label in enumerate(PHASE_LABELS):
        assert ph[0, k] >= 0.0
        if label in built:  # zero-length phases are dropped by the builder
            assert built[label] == pytest.approx(ph[0, k], rel=1e-9, abs=1e-12 * prof.duration)
    assert ph.sum() == pytest.approx(prof.duration, rel=1e-12)


def test_broadcasting_and_shape():
    dist = np.array([[1.0, -2.0, 0.0], [10.0, 20.0, 30.0]])
    got = jerk_limited_durations(dist, 5.0, 10.0, 100.0)
    assert got.shape == (2, 3)
    assert got[0, 2] == 0.0
    assert got[0, 0] == pytest.approx(jerk_limited_duration(1.0, 5.0, 10.0, 100.0), rel=1e-15)
    per_axis_v = jerk_limited_durations(100.0, np.array([1.0, 10.0, 100.0]), 10.0, 100.0)
    assert per_axis_v.shape == (3,)
    assert np.all(np.diff(per_axis_v) < 0)  # faster cap, shorter move
    assert jerk_limited_phases(dist, 5.0, 10.0, 100.0).shape == (6, 7)
    assert jerk_limited_durations(3.0, 5.0, 10.0, 100.0).shape == ()


def test_ruckig_failure_case():
    t = jerk_limited_durations([9846.652521797609], 442.65611753961855, 98221.75531948937,
                               48860762.86873084)
    assert t[0] == pytest.approx(22.25099, abs=5e-6)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([np.nan], 1.0, 1.0, 1.0), "distance"),
        (([2.0**27], 1.0, 1.0, 1.0), "distance"),
        (([1.0], [1.0, 0.0], 1.0, 1.0), "v_max"),
        (([1.0], 1.0, np.inf, 1.0), "a_max"),
        (([1.0], 1.0, 1.0, -1.0), "j_max"),
        (([1.0], 1.0, 1.0, 1.0, 0.0), "d_max"),
        (([1.0, 2.0], [1.0, 2.0, 3.0], 1.0, 1.0), "broadcast"),
        ((["a"], 1.0, 1.0, 1.0), "distance"),
    ],
)
def test_invalid_arrays_are_refused(args, name):
    with pytest.raises(MotionError, match=name):
        jerk_limited_durations(*args)
