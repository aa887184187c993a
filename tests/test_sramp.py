"""profile.sramp: an acceleration with an S-ramp time as PCL6045 S-curve parameters."""

import numpy as np
import pytest

from helpers import free_axes
from openmotion.errors import MotionError
from openmotion.profile.sramp import ramp_spec


@pytest.mark.parametrize("v,a,ts", [(10_000, 100_000, 0.05), (10_000, 100_000, 0.2),
                                    (10_000, 100_000, 0.0), (3_000, 50_000, 0.01)])
def test_ramp_reaches_accel_at_jerk_accel_over_ramp_time(v, a, ts):
    shape, t, vs = ramp_spec(v, a, ts)
    c = free_axes(1)
    c.axes[0].move_relative(50_000, max_vel=v, tacc=t, tdec=t, shape=shape, vs_acc=vs,
                            vs_dec=vs)
    p = c.axes[0].motion.profile
    tt = np.linspace(0.0, p.duration, 40_001)
    acc = np.array([p.state_at(x).a for x in tt])
    if ts == 0.0:
        assert shape == "T" and t == pytest.approx(v / a)
        assert acc.max() == pytest.approx(a)
        return
    jerk = np.abs(np.diff(acc) / np.diff(tt)).max()
    assert jerk == pytest.approx(a / ts, rel=1e-6)          # jerk ACCEL / SRAMP
    if v >= a * ts:
        assert acc.max() == pytest.approx(a) and t == pytest.approx(v / a + ts)
    else:                                                   # never reaches ACCEL
        assert acc.max() < a and vs == 0.0


def test_bad_values():
    for args in ((0, 1, 0), (1, -1, 0), (1, 1, -0.1), (float("nan"), 1, 0)):
        with pytest.raises(MotionError):
            ramp_spec(*args)
