"""ActiveMotion.piece: the per-cycle cubic handed to the hardware matches the profile."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from longrun import size
from openmotion.control.core.motion import ActiveMotion
from openmotion.profile.pcl import MoveSpec
from openmotion.profile.velocity import velocity_move


def cubic(piece, s):
    p0, v0, a0, j, _, _ = piece
    return p0 + v0 * s + a0 * s * s / 2 + j * s**3 / 6, v0 + a0 * s + j * s * s / 2


@given(
    distance=st.floats(-1e5, 1e5).filter(lambda d: abs(d) > 1),
    str_vel=st.floats(0, 500),
    max_vel=st.floats(1000, 1e5),
    tacc=st.floats(0.001, 0.2),
    tdec=st.floats(0.001, 0.2),
    shape=st.sampled_from("TS"),
    period=st.sampled_from([0.001, 0.002, 0.01]),
    t_start=st.floats(0, 100),
)
@settings(max_examples=size(15, 60), deadline=None)
def test_pieces_hit_the_profile_at_every_cycle_end(distance, str_vel, max_vel, tacc, tdec,
                                                   shape, period, t_start):
    spec = MoveSpec(shape, str_vel, max_vel, tacc, tdec)
    prof = spec.plan(distance, 10.0).profile
    m = ActiveMotion(prof, t_start, "relative", spec, prof.end.p)
    n = int(np.ceil(prof.duration / period)) + 1
    ends = []
    for k in range(n):
        t0, t1 = t_start + k * period, t_start + (k + 1) * period
        pc = m.piece(t0, t1)
        h = t1 - t0
        p1, v1 = cubic(pc, h)
        assert p1 == pytest.approx(pc[4], abs=1e-6 * max(1.0, abs(distance)))
        assert v1 == pytest.approx(pc[5], abs=1e-6 * max(1.0, max_vel))
        ends.append(pc[4])
        # inside one segment the piece is the segment itself: compare mid-cycle too
        mid = prof.state_at(t0 - t_start + h / 2)
        seg_k = np.searchsorted(prof.t0, t0 - t_start, side="right")
        nxt = prof.t0[seg_k] if seg_k < prof.n_segments else prof.duration
        if t1 - t_start <= nxt and t1 - t_start < prof.duration:
            assert cubic(pc, h / 2)[0] == pytest.approx(mid.p, abs=1e-6 * max(1, max_vel))
    times = period * np.arange(1, n + 1)
    want = prof.sample(times).p
    np.testing.assert_allclose(ends, want, atol=1e-6 * max(1.0, abs(distance)))
    assert ends[-1] == prof.end.p  # the last cycle lands exactly on the target
    assert m.finished(t_start + n * period)


def test_velocity_profile_is_held_after_its_ramp():
    spec = MoveSpec("T", 100, 5000, 0.1, 0.1)
    prof = velocity_move(spec, -1.0, start=0.0)
    m = ActiveMotion(prof, 2.0, "velocity", spec)
    pc = m.piece(3.0, 3.001)
    assert pc[1] == pytest.approx(-5000) and pc[2] == 0.0 and pc[3] == 0.0
    assert not m.finished(1e6)
    assert m.done_code(3.0) == 12
    assert m.done_code(2.0) == 11  # accelerating (speeding up in the negative direction)
