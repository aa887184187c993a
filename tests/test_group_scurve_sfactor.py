"""S paths sized from the ramp times (`set_path_shape("S", s_factor=...)`, MCCL's S-curve):
a ramp from rest to the feed lasts the acceleration time, one to rest the deceleration
time; s-factor 1 gives a triangular acceleration peaking at twice feed / Tacc."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import finish_group, table_without_mel
from openmotion.control.groups.group import Group
from openmotion.errors import MotionError

FEED, ACC_T = 20_000.0, 0.05  # pps, s


def run_line(acc_t: float, dec_t: float | None, s: float, length: float = 30_000.0):
    ctl = table_without_mel(safety=False)
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=acc_t)
    if dec_t is not None:
        g.set_dec_time(dec_t)
    g.set_path_shape("S", s_factor=s)
    t0 = ctl.time
    g.line([length, 0.0])
    t1 = finish_group(ctl, g)
    assert [a.position for a in g.axes] == [length, 0.0]
    t = np.linspace(t0, t1, 200_001)
    st = ctl.history.sample(g.axes[0].index, t)
    return t - t0, st


def ramps(t: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """(time from the start until the feed is reached, time from leaving it to rest)."""
    at = np.nonzero(v >= FEED * (1 - 1e-9))[0]
    moving = np.nonzero(v > 1e-6)[0]
    return t[at[0]] - t[moving[0]], t[moving[-1]] - t[at[-1]]


@pytest.mark.parametrize("acc_t,dec_t", [(ACC_T, None), (0.04, 0.1), (0.1, 0.04)])
def test_ramps_last_the_acc_and_dec_times(acc_t, dec_t):
    t, st = run_line(acc_t, dec_t, 1.0)
    up, down = ramps(t, st.v)
    dt = t[1] - t[0]
    assert up == pytest.approx(acc_t, abs=3 * dt)
    assert down == pytest.approx(dec_t or acc_t, abs=3 * dt)
    short = min(acc_t, dec_t or acc_t)
    # the shorter ramp's acceleration is a triangle: peak 2 F / T, jerk 4 F / T^2
    peak = np.abs(st.a).max()
    assert peak == pytest.approx(2 * FEED / short, rel=1e-3)
    assert np.abs(st.j).max() == pytest.approx(4 * FEED / short ** 2, rel=1e-3)


def test_smaller_s_factor_keeps_the_ramp_time_with_a_flat_acceleration():
    t, st = run_line(ACC_T, None, 0.5)
    up, down = ramps(t, st.v)
    assert up == pytest.approx(ACC_T, abs=1e-5) and down == pytest.approx(ACC_T, abs=1e-5)
    # jerk phases ACC_T/4 each, flat part ACC_T/2 at F / (0.75 ACC_T)
    assert np.abs(st.a).max() == pytest.approx(FEED / (0.75 * ACC_T), rel=1e-3)
    flat = np.abs(st.a) >= FEED / (0.75 * ACC_T) * (1 - 1e-6)
    assert (t[1] - t[0]) * flat.sum() == pytest.approx(ACC_T, rel=0.01)  # 2 ramps x T/2


def test_s_factor_is_validated_and_leaves_the_group_unchanged():
    ctl = table_without_mel(safety=False)
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=ACC_T)
    for bad in (0.0, -0.1, 1.5, float("nan"), "1"):
        with pytest.raises(MotionError, match="s_factor"):
            g.set_path_shape("S", s_factor=bad)
    with pytest.raises(MotionError, match="not both"):
        g.set_path_shape("S", jerk=1e7, s_factor=1.0)
    with pytest.raises(MotionError, match="only for shape 'S'"):
        g.set_path_shape("T", s_factor=1.0)
    assert g._path_jerk == 0.0 and g._path_sfactor == 0.0
