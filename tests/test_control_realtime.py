"""Real-time mode: the same cycle paced by a thread; statistics exist and are sane.

No wall-clock numbers are asserted (CI machines vary); only structure and consistency.
"""

import math
import time

import pytest

from openmotion.control import Controller
from openmotion.errors import MotionError


def test_realtime_four_axis_job_reports_stats():
    c = Controller()
    c.enable_all()
    for k, name in enumerate("xyzu"):
        c.axis(name).move_relative(200 * (k + 1), max_vel=20_000, tacc=0.01)
    with c.start_realtime():
        assert c.realtime
        with pytest.raises(MotionError, match="real-time"):
            c.advance(0.01)
        with pytest.raises(MotionError, match="already"):
            c.start_realtime()
        deadline = time.monotonic() + 10.0
        while any(ax.motion_done for ax in c.axes) and time.monotonic() < deadline:
            time.sleep(0.01)
    assert not c.realtime
    for k, ax in enumerate(c.axes):
        assert ax.counters.command == 200 * (k + 1)
    s = c.cycle_stats()
    assert s.cycles == c.cycles > 0
    assert s.period == 0.001
    for v in (s.mean_busy, s.p99_busy, s.max_busy, s.max_jitter, s.p99_jitter):
        assert math.isfinite(v) and v >= 0.0
    assert s.mean_busy <= s.max_busy and s.p99_busy <= s.max_busy
    assert s.p99_jitter <= s.max_jitter
    assert 0 <= s.overruns <= s.cycles


def test_stats_before_any_realtime_run():
    s = Controller().cycle_stats()
    assert s.cycles == 0 and s.overruns == 0


def test_commands_from_another_thread_while_running():
    c = Controller()
    c.enable_all()
    ax = c.axis("x")
    c.start_realtime()
    try:
        ax.move_velocity(10_000, tacc=0.01)
        time.sleep(0.05)
        ax.stop()
        deadline = time.monotonic() + 5.0
        while ax.motion_done and time.monotonic() < deadline:
            time.sleep(0.005)
    finally:
        c.stop_realtime()
    assert ax.motion_done == 0
    assert ax.counters.command == ax.counters.feedback
