"""Profile container and builder: sampling, holding states, splicing, ramps."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.profile import ProfileBuilder, State, empty_profile
from openmotion.profile.quantize import check_quantized, quantize
from openmotion.profile.ramps import ramp_accel, ramp_jerk, ramp_jerk_duration


def _move(direction=1.0):
    b = ProfileBuilder(5.0, direction=direction)
    ramp_jerk(b, 100.0, 400.0, 4000.0)
    b.segment(0.5, label="cruise")
    ramp_jerk(b, 0.0, 400.0, 4000.0)
    return b.build(end_p=b.state.p if direction > 0 else None)


def test_sample_matches_state_at_and_holds_outside():
    pr = _move()
    t = np.linspace(-1.0, pr.duration + 1.0, 2001)
    s = pr.sample(t)
    for k in range(0, t.size, 97):
        st_ = pr.state_at(float(t[k]))
        assert s.p[k] == pytest.approx(st_.p, abs=1e-9)
        assert s.v[k] == pytest.approx(st_.v, abs=1e-9)
    assert np.all(s.p[t < 0] == 5.0)
    assert np.all(s.p[t >= pr.duration] == pr.end.p)
    assert np.all(s.v[t >= pr.duration] == 0.0)


def test_scalar_sample_shape():
    pr = _move()
    s = pr.sample(0.1)
    assert s.p.shape == ()


def test_negative_direction_mirrors():
    pos, neg = _move(1.0), _move(-1.0)
    t = np.linspace(0, pos.duration, 301)
    assert np.allclose(pos.sample(t).p - 5.0, -(neg.sample(t).p - 5.0))
    assert neg.sample(0.3).v < 0


def test_empty_profile():
    pr = empty_profile(7.0)
    assert pr.duration == 0.0
    assert pr.sample([0.0, 1.0]).p.tolist() == [7.0, 7.0]


def test_splice_continues_from_cut():
    pr = _move()
    t_cut = 0.4
    st_ = pr.state_at(t_cut)
    b = ProfileBuilder(st_.p, st_.v, st_.a)
    ramp_jerk(b, 0.0, 400.0, 4000.0)
    tail = b.build()
    sp = pr.splice(t_cut, tail)
    assert sp.duration == pytest.approx(t_cut + tail.duration)
    assert sp.state_at(0.2) == pr.state_at(0.2)
    eps = 1e-9
    assert sp.state_at(t_cut + eps).p == pytest.approx(st_.p, abs=1e-6)
    assert sp.end.p == tail.end.p


@settings(max_examples=200, deadline=None)
@given(
    v0=st.floats(-1e3, 1e3), a_frac=st.floats(-1, 1), v1=st.floats(-1e3, 1e3),
    a_max=st.floats(1.0, 1e5), j_max=st.floats(1.0, 1e7),
)
def test_ramp_jerk_reaches_target_within_limits(v0, a_frac, v1, a_max, j_max):
    a0 = a_frac * a_max
    b = ProfileBuilder(0.0, v0, a0)
    ramp_jerk(b, v1, a_max, j_max)
    pr = b.build(end_v=v1)
    end = pr.segment_end(pr.n_segments - 1) if pr.n_segments else State(0, v0, a0)
    scale = max(1.0, abs(v0), abs(v1))
    assert end.v == pytest.approx(v1, abs=1e-9 * scale + 1e-9 * a_max * a_max / j_max)
    assert abs(end.a) <= 1e-7 * a_max
    assert np.all(np.abs(pr.j) <= j_max * (1 + 1e-12))
    for k in range(pr.n_segments):
        e = pr.segment_end(k)
        assert abs(e.a) <= a_max * (1 + 1e-9) + 1e-9
    assert pr.duration == pytest.approx(ramp_jerk_duration(v0, a0, v1, a_max, j_max))


def test_ramp_jerk_is_minimum_time_symmetric_case():
    # From rest to v with a reached: t = v/a + a/j (the classic closed form).
    b = ProfileBuilder()
    ramp_jerk(b, 1000.0, 2000.0, 1e4)
    assert b.time == pytest.approx(1000 / 2000 + 2000 / 1e4)
    # Not reached: t = 2*sqrt(v/j).
    b = ProfileBuilder()
    ramp_jerk(b, 100.0, 2000.0, 1e4)
    assert b.time == pytest.approx(2 * np.sqrt(100 / 1e4))


def test_ramp_accel():
    b = ProfileBuilder(0.0, 100.0)
    ramp_accel(b, -300.0, 1000.0)
    pr = b.build(end_v=-300.0)
    assert pr.duration == pytest.approx(0.4)
    assert pr.sample(pr.duration + 1).v == -300.0


def test_quantize_ends_exactly_and_checks():
    b = ProfileBuilder(0.0)
    ramp_jerk(b, 3333.3, 1e4, 1e6)
    b.segment(0.0123)
    ramp_jerk(b, 0.0, 1e4, 1e6)
    pr = b.build(end_p=round(b.state.p))
    counts = quantize(pr, 0.001)
    assert counts[0] == 0
    assert counts[-1] == round(pr.end.p)
    assert check_quantized(counts, pr, 0.001) <= 0.5
    bad = counts.copy()
    bad[len(bad) // 2] += 2
    with pytest.raises(ValueError, match="count"):
        check_quantized(bad, pr, 0.001)


def test_quantize_rejects_bad_period():
    with pytest.raises(ValueError, match="period"):
        quantize(empty_profile(), 0.0)
    with pytest.raises(ValueError, match="period"):
        quantize(empty_profile(), float("nan"))
