"""The compare engine's fast level-event solver (compiled, compare_math) gives the same events
as MotionHistory's crossing solver (to a few ulps), on random piecewise-cubic motion."""

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from helpers import segment_profile
from openmotion.control.trigger.compare_math import Track, crossings_after, first_crossing
from openmotion.history import MotionHistory

seg = st.tuples(st.floats(1e-4, 0.01), st.floats(-1e7, 1e7), st.floats(-1e4, 1e4),
                st.booleans())


@given(segs=st.lists(seg, min_size=1, max_size=6), v0=st.floats(-5e3, 5e3),
       pick=st.floats(0, 1), mode=st.sampled_from(["value", "knot", "random"]),
       w0=st.floats(0, 1), w1=st.floats(0, 1), direction=st.sampled_from([-1, 0, 1]))
@settings(max_examples=300, deadline=None)
def test_same_events_as_history(segs, v0, pick, mode, w0, w1, direction):
    prof = segment_profile(segs, v0)
    h = MotionHistory(1)
    h.append(0, 0.0, prof)
    r = h.records(0)
    T = prof.duration
    if mode == "value":
        level = float(prof.state_at(pick * T).p)
    elif mode == "knot":
        level = float(r["p0"][min(int(pick * r["p0"].size), r["p0"].size - 1)])
    else:
        level = float(pick * 20 - 10)
    t, t1 = sorted((w0 * T, w1 * T))
    # Motion spanning less than a micro-pulse around the level is below any counter's
    # resolution; there the two solvers' "on the level" ulp rules may legitimately differ.
    span = prof.sample(np.linspace(0.0, T, 257)).p
    assume(np.ptp(span) > 1e-6)
    ref_t, ref_d = h.crossing_events(0, level, t, t1)
    keep = ref_t > t
    if direction:
        keep &= ref_d == direction
    ref = ref_t[keep]
    tr = Track(r["ts"], r["p0"], r["v0"], r["a0"], r["j"])
    got = crossings_after(tr, level, t, t1, direction)
    assert got.size == ref.size, (got, ref)
    np.testing.assert_allclose(got, ref, rtol=0, atol=8 * np.finfo(float).eps * (1 + T))
    first = first_crossing(tr, level, t, t1, direction)
    assert ([] if first is None else [first]) == got[:1].tolist()
