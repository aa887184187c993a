"""Distance-based firing along group paths: lines, arcs and blended corners (issue 6, 5)."""

import math

import numpy as np
import pytest

from helpers import free_axes
from openmotion.control.groups.group import Group
from openmotion.control.trigger.compare import CompareEngine, Pulse, VectorSource, every_distance
from openmotion.errors import MotionError

MM = 1000.0  # pulses per mm of the default axis (10000 ppr, 10 mm lead)


def setup():
    c = free_axes(2)
    return c, CompareEngine(c)


def rounded_rectangle(g, w=35.0, h=20.0, r=5.0):
    """Closed contour from (0, 0): four lines, four quarter arcs (mm -> pulses)."""
    P = lambda *xy: [v * MM for v in xy]  # noqa: E731
    g.line(P(w - r, 0))
    g.arc(P(w - r, r), P(w, r))
    g.line(P(w, h - r))
    g.arc(P(w - r, h - r), P(w - r, h))
    g.line(P(0, h))
    g.arc(P(0, h - r), P(-r, h - r))
    g.line(P(-r, r))
    g.arc(P(0, r), P(0, 0))
    return 2 * (w - r) + 2 * (h - 2 * r) + 2 * math.pi * r


def run(c, g):
    assert c.run_until(lambda: g.queue_length == 0 and all(a.motion_done == 0 for a in c.axes),
                       30.0)


def test_every_half_mm_along_a_contour_with_arcs():
    c, eng = setup()
    src = VectorSource((0, 1), (MM, MM))
    jid = eng.add(every_distance(src, 0.5, Pulse(0, 20e-6)))
    g = Group(c, [0, 1], feed=50 * MM, acc_time=0.05)
    length = rounded_rectangle(g)
    run(c, g)
    log = eng.log.for_job(jid)
    assert log["time"].size == math.floor(length / 0.5)
    assert eng.vector_moved(src) == pytest.approx(length, abs=1e-6)  # 1 nm on 111 mm
    p = log["positions"] / MM
    chord = np.hypot(*np.diff(p, axis=0).T)
    # 0.5 mm of path between firings: a chord of 0.5 on lines, 2 r sin(0.25 / r) on arcs
    assert chord.max() == pytest.approx(0.5, abs=1e-9)
    assert chord.min() >= 2 * 5.0 * math.sin(0.25 / 5.0) - 1e-9
    assert np.all(np.diff(log["time"]) > 0)
    np.testing.assert_allclose(eng.output(0).pulse_widths(), 20e-6, atol=1e-12)


def test_enable_window_and_blended_corners():
    c, eng = setup()
    src = VectorSource((0, 1), (MM, MM))
    jid = eng.add(every_distance(src, 1.0, Pulse(1, 1e-5), start=10.0, end=30.0))
    g = Group(c, [0, 1], feed=40 * MM, acc_time=0.05)
    g.enable_blend(0.2 * MM)
    for pt in ((20, 0), (20, 20), (0, 20), (0, 0)):
        g.line([v * MM for v in pt])
    run(c, g)
    log = eng.log.for_job(jid)
    assert log["value"].tolist() == [float(v) for v in range(10, 31)]  # only in the window
    assert jid not in eng.jobs  # the window is closed: the job is done
    # the blended path is shorter than the 80 mm square, but still > 78 mm
    assert 78.0 < eng.vector_moved(src) < 80.0


def test_every_distance_refuses_bad_windows():
    src = VectorSource((0, 1))
    for kw in ({"interval": 0.0}, {"interval": -1.0}, {"interval": math.nan},
               {"interval": 1.0, "start": 5.0, "end": 1.0}):
        with pytest.raises(MotionError):
            every_distance(src, action=Pulse(0, 1e-6), **kw)


def test_speed_following_pwm():
    c, eng = setup()
    src = VectorSource((0, 1), (MM, MM))
    pwm = eng.add_speed_pwm(src, 2, full_speed=100.0)  # mm/s; the feed is 50 mm/s
    g = Group(c, [0, 1], feed=50 * MM, acc_time=0.05)
    g.line([30 * MM, 40 * MM])
    run(c, g)
    c.advance(0.005)
    duty = np.array([d for _, d in pwm.duties])
    assert duty.max() == pytest.approx(0.5, abs=1e-9)          # cruise at half full speed
    assert duty[0] == 0.0 and duty[-1] == 0.0                     # at rest before and after
    assert np.all(np.diff(duty[: int(np.argmax(duty)) + 1]) >= -1e-12)  # ramps up
    w = eng.output(2).pulse_widths()
    on = duty[(duty > 0) & (duty < 1)] * c.period
    np.testing.assert_allclose(np.sort(w), np.sort(on), atol=1e-12)
    with pytest.raises(MotionError):
        eng.add_speed_pwm(src, 2, full_speed=0.0)
