"""A move whose deceleration has its own shape (MoveSpec.dec_shape, MCCL MCC_SetPtPDecType):
S up and T down or the reverse, each ramp with its own time, exact end; on the fly too."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.errors import MotionError
from openmotion.profile.pcl import MoveSpec

V, TA, TD = 10_000.0, 0.05, 0.1


def ramps(spec: MoveSpec, dist: float = 5_000.0):
    prof = spec.plan(dist).profile
    t = np.linspace(0.0, prof.duration, 200_001)
    s = prof.sample(t)
    at = np.nonzero(s.v >= V * (1 - 1e-9))[0]
    up, down = t <= t[at[0]], t >= t[at[-1]]
    return prof, t, s, up, down


@pytest.mark.parametrize("acc,dec", [("S", "T"), ("T", "S")])
def test_each_ramp_has_its_shape_and_time(acc, dec):
    prof, t, s, up, down = ramps(MoveSpec(acc, 0.0, V, TA, TD, dec_shape=dec))
    assert prof.end.p == 5_000.0
    assert t[up][-1] == pytest.approx(TA, abs=1e-5)
    assert prof.duration - t[down][0] == pytest.approx(TD, abs=1e-5)
    jerky = {"S": True, "T": False}
    assert bool(np.abs(s.j[up]).max() > 0) is jerky[acc]
    assert bool(np.abs(s.j[down]).max() > 0) is jerky[dec]
    # the S side peaks at twice the T side's mean (pure S: VS = 0)
    peak_up, peak_down = s.a[up].max(), -s.a[down].min()
    assert peak_up == pytest.approx((2.0 if acc == "S" else 1.0) * V / TA, rel=1e-3)
    assert peak_down == pytest.approx((2.0 if dec == "S" else 1.0) * V / TD, rel=1e-3)


def test_short_move_and_same_shape_default():
    spec = MoveSpec("S", 0.0, V, TA, TD, dec_shape="T")
    prof = spec.plan(37.0).profile       # MaxVel not reached: automatic decrease
    assert prof.end.p == 37.0
    assert MoveSpec("S", 0.0, V, TA, TD).decel_shape == "S"
    assert spec.derived(max_vel=5000.0).dec_shape == "T"
    with pytest.raises(MotionError, match="dec_shape"):
        MoveSpec("S", 0.0, V, TA, TD, dec_shape="X")
