"""ZMotion HW_PSWITCH2 modes and HW_TIMER: the seed's scenarios, windows, timer pulses."""

import math

import numpy as np
import pytest

from helpers import free_axes, start_line
from openmotion.control.trigger.compare import CompareEngine
from openmotion.control.trigger.pso import ZPso
from openmotion.errors import MotionError

UNITS = 100.0  # seed: UNITS=100


def setup(n=3, buffer_size=100_000):
    c = free_axes(n)
    eng = CompareEngine(c, buffer_size=buffer_size)
    z = ZPso(eng)
    z.base(*range(n))
    for a in range(n):
        z.set_units(a, UNITS)
    return c, eng, z


def line_to(c, end_units, **kw):
    """Synchronised straight line to `end_units` (units -> pulses) on axes 0..k-1."""
    start = [c.axes[i].position for i in range(len(end_units))]
    if start_line(c, start, np.asarray(end_units, float) * UNITS, **kw):
        assert c.wait_motion_done(timeout=30)


def quick(v: float = 20_000.0, k: float = 4.0) -> dict[str, float]:
    """start_line's limits for a line at speed v (pulses/s; default the helper's), time-scaled
    by k: v, a and j times k, k^2, k^3 trace the same path in 1/k of the time (and cycles).
    Where a timer train must end before the next point, the legs still last long enough
    (the tests check the widths and overruns)."""
    return {"v": v * k, "a": 2e5 * k**2, "j": 2e7 * k**3}


SEED_2D = (0, 0, 50, 50, 100, 100, 50, 150, 0, 200, -50, 150, -100, 100, -50, 50)
SEED_3D = (20, 20, 20, 40, 40, 40, 70, 70, 70, 100, 100, 100, 140, 140, 140, 180, 180, 180)


def test_mode1_table_with_direction_toggles():
    c, eng, z = setup(1)
    z.table(0, 100, 150, 250, 300, 400, 450)
    jid = z.hw_pswitch2(1, 0, 1, 0, 5, 1)  # seed Test_Mode1
    assert z.pending() == 6
    c.axes[0].move_relative(500 * UNITS, max_vel=50_000, tacc=0.05, tdec=0.05)
    assert c.wait_motion_done(timeout=30)
    log = eng.log.for_job(jid)
    np.testing.assert_allclose(log["positions"][:, 0] / UNITS, [100, 150, 250, 300, 400, 450],
                               atol=1e-9)
    assert log["state"].tolist() == [1, 0, 1, 0, 1, 0]
    assert z.pending() == 0 and z.remaining() == 100_000
    # negative direction with a descending table, moving back
    z.table(10, 400, 300, 200)
    jid2 = z.hw_pswitch2(1, 1, 0, 10, 12, 0)
    c.axes[0].move_relative(-500 * UNITS, max_vel=50_000, tacc=0.05, tdec=0.05)
    assert c.wait_motion_done(timeout=30)
    log2 = eng.log.for_job(jid2)
    assert log2["value"].tolist() == [40000.0, 30000.0, 20000.0]
    assert log2["state"].tolist() == [0, 1, 0]


def test_mode3_vector_table_and_mode2_clears():
    c, eng, z = setup(2)
    z.table(0, 100, 150, 250, 300, 400, 450)
    z.set_vector_moved(0)
    jid = z.hw_pswitch2(3, 0, 1, 0, 5)  # seed Test_Mode3: MOVEABS(300,200) MOVEABS(400,0)
    line_to(c, (300, 200), **quick())
    line_to(c, (400, 0), **quick())
    l1, l2 = math.hypot(300, 200), math.hypot(100, 200)
    assert z.vector_moved() == pytest.approx(l1 + l2, abs=1e-9)
    log = eng.log.for_job(jid)
    assert log["value"].tolist() == [100, 150, 250, 300, 400, 450]
    for (x, y), s in zip(log["positions"] / UNITS, log["value"], strict=True):
        along = math.hypot(x, y) if s <= l1 else l1 + math.hypot(x - 300, y - 200)
        assert along == pytest.approx(s, abs=1e-7)
    # mode 2 stops and deletes unfinished points
    z.table(0, 1000, 2000)
    z.hw_pswitch2(3, 0, 1, 0, 1)
    assert z.pending() == 2
    z.hw_pswitch2(2)
    assert z.pending() == 0 and not eng.jobs


def test_modes_4_5_fixed_pulses_every_distance():
    c, eng, z = setup(2)
    jid4 = z.hw_pswitch2(4, 0, 1, 10, 500)        # every 10 units, 500 us
    jid5 = z.hw_pswitch2(5, 1, 1, 25, 200, 3)     # every 25 units, 3 pulses only
    line_to(c, (60, 80))  # length 100 units
    assert eng.log.for_job(jid4)["time"].size == 10
    assert eng.log.for_job(jid5)["time"].size == 3
    np.testing.assert_allclose(eng.output(0).pulse_widths(), [500e-6] * 10, atol=1e-12)
    np.testing.assert_allclose(eng.output(1).pulse_widths(), [200e-6] * 3, atol=1e-12)
    assert jid4 in eng.jobs and jid5 not in eng.jobs  # 4 runs on, 5 finished


def test_modes_6_7_use_the_timer():
    c, eng, z = setup(2)
    z.hw_timer(2, 2000, 1000, 2, 0, 0)
    jid6 = z.hw_pswitch2(6, 0, 1, 10, 20, 4)  # at 10, 30, 50, 70 units
    line_to(c, (60, 80))
    log = eng.log.for_job(jid6)
    r = np.hypot(*(log["positions"] / UNITS).T)
    np.testing.assert_allclose(r, [10, 30, 50, 70], atol=1e-7)
    np.testing.assert_allclose(eng.output(0).pulse_widths(), [1e-3] * 8, atol=1e-12)
    z.set_vector_moved(0)
    z.table(0, 5, 15)
    jid7 = z.hw_pswitch2(7, 0, 1, 0, 1)
    line_to(c, (0, 0))
    assert eng.log.for_job(jid7)["time"].size == 2
    assert eng.output(0).pulse_widths().size == 12


def test_mode25_seed_2d_table_fires_inside_window_in_order():
    c, eng, z = setup(2)
    z.table(0, *SEED_2D)
    jid = z.hw_pswitch2(25, 0, 1, 10, 8, 0)  # seed: OUT0, first ON, maxerr 10, 8 points
    pts = np.array(SEED_2D, float).reshape(8, 2)
    for p in [*pts[1:], pts[0]]:
        line_to(c, p, **quick())
    log = eng.log.for_job(jid)
    assert log["index"].tolist() == list(range(8))
    assert log["state"].tolist() == [1, 0, 1, 0, 1, 0, 1, 0]
    dev = np.abs(log["positions"][:, :2] - pts * UNITS)
    assert np.all(dev <= 10 + 1e-9)          # inside the window ...
    assert np.max(dev[0]) == 0.0  # the axes start on point 0: it fires at once
    assert np.all(np.max(dev[1:], axis=1) >= 10 - 1e-6)  # the others on entering the window
    assert np.all(np.diff(log["time"]) >= 0)


def test_window_fires_only_inside_and_waits_for_its_point():
    c, eng, z = setup(2)
    z.table(0, 100, 0, 0, 0)  # point 0 at (100, 0), point 1 back at the origin
    jid = z.hw_pswitch2(25, 0, 1, 10, 2, 0)
    line_to(c, (0, 50))       # passes near the origin but point 0 comes first: nothing
    line_to(c, (50, 0))       # never within 10 pulses of (100, 0) units
    assert eng.log.for_job(jid)["time"].size == 0
    line_to(c, (100, 0.05))   # y off by 5 pulses: inside the window
    line_to(c, (0, 0))
    log = eng.log.for_job(jid)
    assert log["index"].tolist() == [0, 1]
    assert abs(log["positions"][0, 1]) <= 10 + 1e-9


def test_mode26_timer_pulses_per_point():
    c, eng, z = setup(2)
    z.table(0, *SEED_2D)
    z.hw_timer(2, 100000, 50000, 2, 0, 0)  # seed: 100 ms period, 50 ms on, 2 pulses
    jid = z.hw_pswitch2(26, 0, 1, 10, 8, 0)
    pts = np.array(SEED_2D, float).reshape(8, 2)
    for p in [*pts[1:], pts[0]]:
        line_to(c, p, **quick(10_000, 3))  # legs > 0.2 s: no train overlaps the next point
    c.advance(0.3)
    assert eng.log.for_job(jid)["time"].size == 8
    w = eng.output(0).pulse_widths()
    np.testing.assert_allclose(w, [0.05] * 16, atol=1e-9)
    assert z.timer.overruns == 0


def test_mode35_36_seed_3d_table():
    c, eng, z = setup(3)
    z.table(0, *SEED_3D)
    jid = z.hw_pswitch2(35, 0, 1, 10, 6, 0)
    pts = np.array(SEED_3D, float).reshape(6, 3)
    for p in pts:
        line_to(c, p, **quick())
    log = eng.log.for_job(jid)
    assert log["index"].tolist() == list(range(6))
    assert np.all(np.abs(log["positions"] - pts * UNITS) <= 10 + 1e-9)
    # mode 36 with the pulse parameters given inline (ophwtimeus, ophwtimes, hwcyctimeus)
    jid36 = z.hw_pswitch2(36, 1, 1, 10, 6, 0, 50000, 1, 100000)
    line_to(c, (0, 0, 0), **quick())
    for p in pts:
        line_to(c, p, **quick())
    c.advance(0.2)
    assert eng.log.for_job(jid36)["time"].size == 6
    np.testing.assert_allclose(eng.output(1).pulse_widths(), [0.05] * 6, atol=1e-9)


def test_timer_repeat_stop_soft_close_and_replace():
    c, eng, z = setup(1)
    line = eng.output(2)
    z.hw_timer(2, 1000, 300, 3, 0, 2)
    t0 = c.time + 0.0005
    z.timer.apply(eng, t0, 0)
    c.advance(0.01)
    e = line.edges
    np.testing.assert_allclose([t for t, _ in e], [t0, t0 + 3e-4, t0 + 1e-3, t0 + 1.3e-3,
                                                   t0 + 2e-3, t0 + 2.3e-3], atol=1e-12)
    # soft close: the train already started finishes, new triggers are ignored
    t1 = c.time + 0.0001
    z.timer.apply(eng, t1, 0)
    z.hw_timer(2, 1000, 300, 0, 0, 2)
    z.timer.apply(eng, c.time + 0.005, 0)
    c.advance(0.01)
    assert line.pulse_widths().size == 6 and z.timer.ignored == 1
    # a new call replaces the timer; stop (mode 0) drops scheduled pulses at once
    z.hw_timer(2, 10000, 6000, 5, 0, 2)
    z.timer.apply(eng, c.time, 0)
    c.advance(0.015)  # inside the second pulse
    z.hw_timer(0, 10000, 6000, 1, 0, 2)  # seed reset idiom
    c.advance(0.1)
    assert not line.level_at(c.time)
    assert line.pulse_widths().size == 8  # 6 + 2 started, the rest dropped
    assert not c.hardware.read_output(None, "do2")


def test_bad_calls_are_refused_and_job_unchanged():
    c, eng, z = setup(2, buffer_size=20)
    z.table(0, 1, 2, 3)
    jid = z.hw_pswitch2(1, 0, 1, 0, 2, 1)
    z.table(10, 3, 2, 1)
    bad = [
        lambda: z.hw_pswitch2(1, 0, 1, 10, 12, 1),       # not increasing for dir 1
        lambda: z.hw_pswitch2(1, 0, 1, 5, 4, 1),         # empty range
        lambda: z.hw_pswitch2(25, 0, 1, 0, 2, 0),        # maxerr 0
        lambda: z.hw_pswitch2(25, 0, 1, 10, 0, 0),       # no points
        lambda: z.hw_pswitch2(3, 9, 1, 0, 2),            # output not PSO-capable
        lambda: z.hw_pswitch2(3, 0, 1, 0, 30),           # too long for the buffer
        lambda: z.hw_pswitch2(8, 0, 1, 0, 2),            # no such mode
        lambda: z.hw_pswitch2(1, 0, 1, 0, 2),            # missing dir
        lambda: z.hw_pswitch2(26, 0, 1, 10, 1, 0, 600, 1, 500),  # on > cycle
        lambda: z.hw_timer(2, 1000, 2000, 1, 0, 0),      # on-time longer than cycle
        lambda: z.hw_timer(2, 1000, 200, 1, 0, 7),       # output not capable
        lambda: z.hw_timer(1, 1000, 200, 1, 0, 0),
        lambda: z.table(0, math.nan),
    ]
    for f in bad:
        with pytest.raises(MotionError):
            f()
    assert list(eng.jobs) == [jid] and z.pending() == 3 and not z.timer.running
    c.axes[0].move_relative(300, max_vel=10_000, tacc=0.01, tdec=0.01)
    assert c.wait_motion_done(timeout=5)
    assert eng.log.for_job(jid)["time"].size == 3


def test_timer_train_still_running_counts_an_overrun():
    c, eng, z = setup(2)
    z.table(0, 0, 0, 1, 0, 2, 0)  # three points 1 unit apart: passed within ~15 ms
    z.hw_timer(2, 100000, 50000, 2, 0, 0)
    jid = z.hw_pswitch2(26, 0, 1, 10, 3, 0)
    line_to(c, (3, 0))
    c.advance(0.3)
    assert eng.log.for_job(jid)["time"].size == 3  # every point still fires (logged) ...
    assert z.timer.overruns == 2                     # ... but only the first starts a train
    np.testing.assert_allclose(eng.output(0).pulse_widths(), [0.05, 0.05], atol=1e-9)


def test_mode26_36_accept_hw_pswitch2_before_hw_timer():
    """Seed order: HW_PSWITCH2(26, ...) then HW_TIMER(2, 100000, 50000, 2, OFF, 0)."""
    c, eng, z = setup(2)
    z.table(0, *SEED_2D)
    jid = z.hw_pswitch2(26, 0, 1, 10, 8, 0)  # no timer yet: accepted
    z.hw_timer(2, 100000, 50000, 2, 0, 0)
    pts = np.array(SEED_2D, float).reshape(8, 2)
    for p in [*pts[1:], pts[0]]:
        line_to(c, p, **quick(10_000, 3))
    c.advance(0.3)
    assert eng.log.for_job(jid)["time"].size == 8
    np.testing.assert_allclose(eng.output(0).pulse_widths(), [0.05] * 16, atol=1e-9)
    c3, eng3, z3 = setup(3)
    z3.table(0, *SEED_3D)
    jid3 = z3.hw_pswitch2(36, 0, 1, 10, 6, 0)
    z3.hw_timer(2, 100000, 50000, 1, 0, 0)
    for p in np.array(SEED_3D, float).reshape(6, 3):
        line_to(c3, p, **quick(10_000))
    c3.advance(0.2)
    assert eng3.log.for_job(jid3)["time"].size == 6
    np.testing.assert_allclose(eng3.output(0).pulse_widths(), [0.05] * 6, atol=1e-9)


def test_hw_timer_edited_while_a_timer_job_runs():
    c, eng, z = setup(1)
    z.table(0, 10, 20, 30)
    z.hw_pswitch2(7, 0, 1, 0, 2)              # vector table, a train per point
    z.hw_timer(2, 10000, 2000, 1, 0, 0)       # 2 ms pulses
    line_to(c, (15,), v=10_000)
    z.hw_timer(2, 10000, 5000, 2, 0, 0)       # edited: two 5 ms pulses per point
    line_to(c, (35,), v=10_000)
    c.advance(0.1)
    np.testing.assert_allclose(eng.output(0).pulse_widths(), [0.002] + [0.005] * 4, atol=1e-9)
    # a point reached while the timer is stopped fires nothing but its log entry
    z.hw_timer(0, 10000, 6000, 1, 0, 0)
    z.table(0, 40)
    jid = z.hw_pswitch2(7, 0, 1, 0, 0)
    line_to(c, (45,), v=10_000)
    assert eng.log.for_job(jid)["time"].size == 1 and z.timer.ignored == 1
    assert eng.output(0).pulse_widths().size == 5


def test_mode35_with_hw_timer_pulses_instead_of_inverting():
    """Seed 3-D example: HW_TIMER(2, 100000, 50000, 1, OFF, 0) -> one 50 ms pulse per point."""
    c, eng, z = setup(3)
    z.table(0, *SEED_3D)
    jid = z.hw_pswitch2(35, 0, 1, 10, 6, 0)
    z.hw_timer(2, 100000, 50000, 1, 0, 0)
    for p in np.array(SEED_3D, float).reshape(6, 3):
        line_to(c, p, **quick(10_000))
    c.advance(0.2)
    log = eng.log.for_job(jid)
    assert log["state"].tolist() == [1] * 6  # every point drives the pulse level
    w = eng.output(0).pulse_widths()
    np.testing.assert_allclose(w, [0.05] * 6, atol=1e-9)
    starts = [t for t, lv in eng.output(0).edges if lv]
    np.testing.assert_allclose(starts, log["time"], atol=1e-12)
    # without a timer on the output, mode 35 inverts at each point
    z.hw_timer(0, 10000, 6000, 1, 0, 0)
    line_to(c, (0, 0, 0), **quick())
    jid2 = z.hw_pswitch2(35, 0, 1, 10, 6, 0)
    for p in np.array(SEED_3D, float).reshape(6, 3):
        line_to(c, p, **quick(10_000))
    assert eng.log.for_job(jid2)["state"].tolist() == [1, 0, 1, 0, 1, 0]
