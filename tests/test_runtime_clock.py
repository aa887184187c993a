"""The no-op pacer baseline (control/core/clock.py): OS wake-up lateness measured the way the
real-time cycle is measured."""

from __future__ import annotations

import pytest

from openmotion.control.core.clock import pacer_baseline
from openmotion.errors import MotionError


def test_baseline_runs_a_no_op_cycle_and_reports_statistics():
    s = pacer_baseline(0.001, 0.05)
    assert s.cycles > 0 and s.period == 0.001
    assert 0.0 <= s.mean_busy <= s.max_busy and s.mean_jitter <= s.max_jitter


@pytest.mark.parametrize("period,seconds,match", [
    (0.0001, 1.0, "period"), (0.001, 0.0, "seconds"), (0.001, float("nan"), "seconds"),
])
def test_baseline_validates(period, seconds, match):
    with pytest.raises(MotionError, match=match):
        pacer_baseline(period, seconds)
