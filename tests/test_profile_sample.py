"""The compiled `Profile.sample` (openmotion._profile.sample, _profile_sample.c) gives the
floats of its numpy oracle (`Profile._sample_numpy`, the code segments.py ran before) bit
for bit: inside, before and after the profile, at segment boundaries, at duplicated
segment starts, for NaN and infinite instants, and for the profiles the planners build."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion import _profile as C
from openmotion.profile.segments import Profile, ProfileBuilder, State, delayed

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


def _same(x: np.ndarray, y: np.ndarray) -> bool:
    """Equal as bit patterns (the sign of a zero and NaN included)."""
    return x.shape == y.shape and np.array_equal(x.view(np.int64), y.view(np.int64))


def _check(pr: Profile, ts: np.ndarray) -> None:
    got = pr.sample(ts)
    ref = pr._sample_numpy(np.asarray(ts, dtype=float))
    for g, r in zip(got, ref, strict=True):
        assert _same(g, r)


@st.composite
def profiles(draw: st.DrawFn) -> Profile:
    b = ProfileBuilder(draw(finite), draw(finite), direction=draw(st.sampled_from([1, -1])))
    for _ in range(draw(st.integers(1, 8))):
        b.segment(draw(st.floats(1e-6, 10.0)), draw(finite),
                  accel=draw(st.none() | finite))
    end_v = draw(st.sampled_from([0.0, 0.0, 3.5, -2.0]))
    pr = b.build(end_p=draw(st.none() | finite), end_v=end_v)
    if draw(st.booleans()):
        pr = delayed(pr, draw(st.floats(1e-6, 2.0)))
    return pr


@settings(max_examples=300, deadline=None)
@given(profiles(), st.lists(st.floats(-5.0, 100.0), min_size=0, max_size=40),
       st.integers(0, 2**31))
def test_bit_for_bit_random(pr, extra, seed):
    rng = np.random.default_rng(seed)
    dur = pr.duration
    ts = np.concatenate([
        np.asarray(extra, dtype=float),
        pr.t0, np.nextafter(pr.t0, -np.inf), np.nextafter(pr.t0, np.inf),
        [0.0, -0.0, dur, np.nextafter(dur, 0.0), np.nextafter(dur, np.inf), -1e-300],
        rng.uniform(-0.1 * dur - 1.0, 1.1 * dur + 1.0, 50)])
    _check(pr, ts)
    _check(pr, np.sort(ts))
    _check(pr, ts.reshape(-1, 1)[: 2 * (len(ts) // 2)].reshape(2, -1))  # a 2-D shape


def test_nan_and_infinite_instants():
    pr = ProfileBuilder(1.0, 2.0).segment(0.5, 3.0).segment(0.25, -1.0).build(end_v=4.0)
    _check(pr, np.array([np.nan, np.inf, -np.inf, 0.1, np.nan]))
    _check(pr, np.array(0.3))  # a 0-d instant keeps its shape
    assert pr.sample(np.array(0.3)).p.shape == ()


def test_duplicated_starts_and_scalar_and_list_input():
    t0 = np.array([0.0, 0.5, 0.5, 1.0])
    pr = Profile(t0, np.array([0.0, 1.0, 2.0, 3.0]), np.ones(4), np.zeros(4),
                 np.array([1.0, -2.0, 3.0, 0.5]), 2.0, State(0.0, 1.0), State(9.0))
    _check(pr, np.array([0.5, 0.49999, 0.75, 1.0, 1.99, 2.0, -3.0]))
    assert _same(pr.sample([0.5, 1.5]).v, pr._sample_numpy(np.array([0.5, 1.5])).v)


def test_columns_that_are_not_contiguous_float64_use_numpy():
    base = np.arange(8, dtype=float)
    pr = Profile(base[::2], base[::2] * 2.0, np.ones(4), np.zeros(4), np.zeros(4), 8.0,
                 State(0.0), State(12.0))  # strided columns
    _check(pr, np.linspace(-1.0, 9.0, 23))
    ip = Profile(np.array([0, 1]), np.array([0, 1]), np.array([1, 1]), np.zeros(2),
                 np.zeros(2), 2.0, State(0.0), State(2.0))  # integer columns
    _check(ip, np.linspace(-1.0, 3.0, 9))


def test_no_segments_is_the_numpy_version():
    pr = ProfileBuilder(3.0).build(end_p=3.0)
    _check(pr, np.array([-1.0, 0.0, 2.0]))


def test_compiled_refuses_bad_arguments():
    a = np.zeros(3)
    out = [np.empty(2) for _ in range(4)]
    with pytest.raises(ValueError, match="matching lengths"):
        C.sample(a, a, a, a, np.zeros(2), np.zeros(2), *out, 0.0, 0.0, 0.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="matching lengths"):
        C.sample(*[np.zeros(0)] * 5, np.zeros(2), *out, 0.0, 0.0, 0.0, 0.0, 1.0)
    with pytest.raises(TypeError, match="float64"):
        C.sample(a, a, a, a, np.zeros(3, dtype=np.int64), np.zeros(2), *out,
                 0.0, 0.0, 0.0, 0.0, 1.0)
    with pytest.raises(TypeError, match="15 arguments"):
        C.sample(a)
    with pytest.raises(TypeError):
        C.sample(a, a, a, a, a, np.zeros(2), *out, "x", 0.0, 0.0, 0.0, 1.0)
