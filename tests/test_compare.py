"""Compare engine: exact trigger times/positions vs analytic solutions, no lost or doubled
triggers (reversal, stop on a point, a point at a cycle end), MPOS, vector distance, log."""

import csv
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import free_axes, start_line
from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.trigger.compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    LevelSeq,
    Pulse,
    SetLevel,
    Toggle,
    VectorSource,
    WindowJob,
)
from openmotion.control.trigger.compare_io import plot_firings
from openmotion.errors import MotionError
from openmotion.profile.jerk import jerk_limited
from openmotion.profile.segments import ProfileBuilder

machine = free_axes  # n axes x, y, z, u without switches, enabled


def trapezoid_profile(dist, v, a):
    """Rest-to-rest T-curve with phases accel a / cruise v / decel a (analytic times)."""
    t1 = v / a
    x1 = 0.5 * a * t1 * t1
    if 2 * x1 > dist:
        t1 = math.sqrt(dist / a)
        v = a * t1
        x1 = dist / 2
    tc = (dist - 2 * x1) / v
    b = ProfileBuilder(0.0)
    b.segment(t1, accel=a).segment(tc, accel=0.0).segment(t1, accel=-a)
    return b.build(end_p=dist), (t1, tc, v, x1)


def analytic_time(x, a, t1, tc, v, x1, dist):
    if x <= x1:
        return math.sqrt(2 * x / a)
    if x <= dist - x1:
        return t1 + (x - x1) / v
    r = dist - x  # distance still to go: r = a*tau'^2/2 before the end
    return 2 * t1 + tc - math.sqrt(2 * r / a)


def run(c, timeout=60.0):
    assert c.wait_motion_done(timeout=timeout)


@given(v=st.floats(5_000, 500_000), a=st.floats(1e6, 5e7), n=st.integers(1, 40),
       seed=st.integers(0, 2**31), phase=st.floats(0, 0.00099))
@settings(max_examples=20, deadline=None)
def test_firing_times_and_positions_are_exact(v, a, n, seed, phase):
    c = machine(1)
    c.advance(phase)  # any cycle phase (whole cycles; the profile starts at a cycle end)
    dist = 2_000.0
    prof, (t1, tc, vv, x1) = trapezoid_profile(dist, v, a)
    rng = np.random.default_rng(seed)
    levels = np.sort(rng.choice(np.arange(1, 2_000), size=n, replace=False)).astype(float)
    eng = CompareEngine(c)
    jid = eng.add(LevelJob(AxisSource(0), levels, Pulse(0, 1e-6), direction=1))
    t_start = c.time
    c.axes[0].run_profile(prof, stop_accel=a, stop_jerk=1e9)
    run(c)
    log = eng.log.for_job(jid)
    assert log["time"].size == n  # none lost, none doubled
    assert np.array_equal(log["index"], np.arange(n))
    expect = [t_start + analytic_time(x, a, t1, tc, vv, x1, dist) for x in levels]
    np.testing.assert_allclose(log["time"], expect, rtol=0, atol=1e-9)
    np.testing.assert_allclose(log["positions"][:, 0], levels, rtol=0, atol=1e-6)


def test_reversal_fires_each_table_point_once():
    c = machine(1)
    eng = CompareEngine(c)
    jid = eng.add(LevelJob(AxisSource(0), np.arange(100.0, 1000.0, 100.0), Toggle(0)))
    single = eng.add(LevelJob(AxisSource(0), [450.0], SetLevel(1), repeat=True))
    up = eng.add(LevelJob(AxisSource(0), [450.0], SetLevel(2), repeat=True, direction=1))
    ax = c.axes[0]
    for d in (1000, -1000, 1000, -300):
        ax.move_relative(d, max_vel=20_000, tacc=0.01, tdec=0.01)
        run(c)
    tab = eng.log.for_job(jid)
    assert tab["time"].size == 9 and np.array_equal(tab["value"], np.arange(100.0, 1000, 100))
    assert np.all(np.diff(tab["time"]) > 0)
    assert eng.log.for_job(single)["time"].size == 3  # every pass of the single value
    assert eng.log.for_job(up)["time"].size == 2      # upward passes only
    # toggling output: ON at 100, OFF at 200, ... ON at 900
    assert tab["state"].tolist() == [1, 0, 1, 0, 1, 0, 1, 0, 1]


def test_stop_on_a_point_fires_once_then_continues():
    c = machine(1)
    eng = CompareEngine(c)
    jid = eng.add(LevelJob(AxisSource(0), [250.0, 500.0, 750.0], Toggle(0), direction=1))
    ax = c.axes[0]
    ax.move_relative(500, max_vel=10_000, tacc=0.02, tdec=0.02)
    run(c)
    c.advance(0.2)  # dwell on the point
    log = eng.log.for_job(jid)
    assert log["value"].tolist() == [250.0, 500.0]
    assert log["positions"][1, 0] == pytest.approx(500.0, abs=1e-9)
    assert eng.job(jid).value == 750.0
    ax.move_relative(500, max_vel=10_000, tacc=0.02, tdec=0.02)
    run(c)
    assert eng.log.for_job(jid)["value"].tolist() == [250.0, 500.0, 750.0]


def test_point_at_the_last_count_of_a_cycle():
    # x = 1000 t^2: the points 10, 40, 90 are reached exactly at cycle ends 0.1, 0.2, 0.3 s
    c = machine(1)
    eng = CompareEngine(c)
    jid = eng.add(LevelJob(AxisSource(0), [10.0, 40.0, 90.0, 160.0], Toggle(0)))
    prof = ProfileBuilder(0.0).segment(0.5, accel=2000.0).build()
    c.axes[0].run_profile(prof, stop_accel=1e5, stop_jerk=1e9)
    ends = []
    eng_hook = lambda ctl, t: ends.append(t)  # noqa: E731
    c.add_cycle_hook(eng_hook)
    c.advance(0.45)
    log = eng.log.for_job(jid)
    np.testing.assert_allclose(log["time"], [0.1, 0.2, 0.3, 0.4], atol=1e-9)
    assert log["time"].size == 4
    assert min(abs(np.array(ends) - 0.3)) < 1e-12  # 0.3 really is a cycle end


def test_mpos_stepper_fires_within_one_count():
    c = machine(1)
    eng = CompareEngine(c)
    levels = np.arange(1000.0, 30_000.0, 997.0)
    jid = eng.add(LevelJob(AxisSource(0, "mpos"), levels, Pulse(0, 1e-6), direction=1))
    c.axes[0].move_relative(40_000, max_vel=400_000, tacc=0.02, tdec=0.02)
    run(c)
    log = eng.log.for_job(jid)
    assert log["time"].size == levels.size
    assert np.max(np.abs(log["positions"][:, 0] - levels)) <= 1.0


def test_mpos_servo_fires_later_than_dpos_in_the_right_cycle():
    cfg = MachineConfig("t", (AxisConfig(name="x", drive=DriveConfig(type="servo")),))
    c = Controller(cfg)
    c.enable_all()
    eng = CompareEngine(c)
    levels = np.arange(500.0, 9500.0, 250.0)
    jm = eng.add(LevelJob(AxisSource(0, "mpos"), levels, Pulse(0, 1e-6), direction=1))
    jd = eng.add(LevelJob(AxisSource(0, "dpos"), levels, Pulse(1, 1e-6), direction=1))
    fb = []
    c.add_cycle_hook(lambda ctl, t: fb.append((t, ctl.axes[0].counters.feedback_unwrapped())))
    c.axes[0].move_relative(10_000, max_vel=50_000, tacc=0.05, tdec=0.05)
    run(c)
    m, d = eng.log.for_job(jm), eng.log.for_job(jd)
    assert m["time"].size == d["time"].size == levels.size
    assert np.all(m["time"] > d["time"])  # the servo lags the command
    fb = np.array(fb)
    k = np.searchsorted(fb[:, 0], m["time"])  # the cycle each firing was found in
    assert np.all(fb[k - 1, 1] < levels + 1) and np.all(fb[k, 1] >= levels - 1)


def straight_line(c, start, end, **kw):
    """Synchronised straight line (helpers.start_line), run to the end."""
    assert start_line(c, start, end, **kw)
    run(c)


def test_vector_distance_every_n_along_a_line():
    c = machine(2)
    eng = CompareEngine(c)
    src = VectorSource((0, 1))
    jid = eng.add(LevelJob(src, LevelSeq(100.0, 100.0), Pulse(0, 1e-6)))
    straight_line(c, (0, 0), (3000, 4000))
    log = eng.log.for_job(jid)
    assert log["time"].size == 50
    r = np.hypot(log["positions"][:, 0], log["positions"][:, 1])
    np.testing.assert_allclose(r, 100.0 * np.arange(1, 51), atol=1e-7)
    assert eng.vector_moved(src) == pytest.approx(5000.0, abs=1e-7)


def test_vector_moved_accumulates_back_and_forth():
    # seed: +200 then -100 gives absolute 100 but vector 300
    c = machine(1)
    eng = CompareEngine(c)
    src = VectorSource((0,))
    eng.track_vector(src)
    for d in (200, -100):
        c.axes[0].move_relative(d, max_vel=5000, tacc=0.01, tdec=0.01)
        run(c)
    assert eng.vector_moved(src) == pytest.approx(300.0, abs=1e-9)
    eng.set_vector_moved(src, 0.0)
    assert eng.vector_moved(src) == 0.0


def circle_profiles(radius, speed, n_pieces):
    """Per-axis cubic Hermite pieces of a circle at constant speed (a curved test path)."""
    w = speed / radius
    period = 2 * math.pi / w
    h = period / n_pieces
    profs = []
    for ax in range(2):
        def pos(t, ax=ax):
            return radius * (math.cos(w * t) - 1.0) if ax == 0 else radius * math.sin(w * t)

        def vel(t, ax=ax):
            return -radius * w * math.sin(w * t) if ax == 0 else radius * w * math.cos(w * t)

        b = ProfileBuilder(0.0, vel(0.0), v_before=0.0)
        for k in range(n_pieces):
            t0 = k * h
            p0, p1, v0, v1 = pos(t0), pos(t0 + h), vel(t0), vel(t0 + h)
            a0 = 6 * (p1 - p0) / h**2 - (4 * v0 + 2 * v1) / h
            jj = 12 * (p0 - p1) / h**3 + 6 * (v0 + v1) / h**2
            b.set_velocity(v0)
            b.segment(h, jj, accel=a0)
        profs.append(b.build(end_p=pos(period), end_v=0.0))
    return profs


def test_vector_distance_on_a_curve_matches_dense_quadrature():
    c = machine(2)
    eng = CompareEngine(c)
    src = VectorSource((0, 1))
    eng.track_vector(src)
    profs = circle_profiles(2000.0, 10_000.0, 37)
    t0 = c.time
    # run the curve through the history directly (velocity jumps are not for run_profile)
    for ax, p in enumerate(profs):
        c.history.append(ax, t0, p)
    c.advance(profs[0].duration + 0.01)
    # reference: 40-point Gauss-Legendre on each cubic piece (speed is smooth inside one)
    x, w = np.polynomial.legendre.leggauss(40)
    h = profs[0].duration / 37
    tt = (np.arange(37)[:, None] + (x[None, :] + 1) / 2) * h
    sp = np.hypot(profs[0].sample(tt.ravel()).v, profs[1].sample(tt.ravel()).v)
    ref = float(np.sum(sp.reshape(37, 40) * w) * h / 2)
    assert eng.vector_moved(src) == pytest.approx(ref, rel=1e-12)
    assert abs(ref - 2 * math.pi * 2000.0) < 1.0  # the pieces do follow the circle


def test_event_log_export_and_plot(tmp_path):
    c = machine(2)
    eng = CompareEngine(c)
    eng.add(LevelJob(VectorSource((0, 1)), LevelSeq(250.0, 250.0, 10), Toggle(3)))
    straight_line(c, (0, 0), (3000, 4000))
    a = eng.log.arrays()
    assert a["time"].size == 10 and a["positions"].shape == (10, 2)
    p = eng.log.save_csv(tmp_path / "log.csv")
    rows = list(csv.reader(p.open()))
    assert rows[0][:6] == ["time", "job", "index", "value", "output", "state"]
    assert len(rows) == 11
    assert float(rows[5][0]) == a["time"][4]  # full precision round trip
    assert float(rows[5][6]) == a["positions"][4, 0]
    z = np.load(eng.log.save_npz(tmp_path / "log.npz"))
    np.testing.assert_array_equal(z["positions"], a["positions"])
    xy = np.column_stack([np.linspace(0, 3000, 50), np.linspace(0, 4000, 50)])
    png = plot_firings(eng.log, tmp_path / "firings.png", path_xy=xy)
    assert png.stat().st_size > 1000
    with pytest.raises(MotionError, match="path"):
        eng.log.save_csv(tmp_path / "log.txt")


def test_bad_input_is_refused_and_running_job_unchanged():
    c = machine(2)
    eng = CompareEngine(c, buffer_size=10, outputs=[0, 1])
    jid = eng.add(LevelJob(AxisSource(0), np.arange(1.0, 6.0), Toggle(0)))
    before = eng.buffer_free()
    bad = [
        lambda: LevelJob(AxisSource(0), [], Toggle(0)),
        lambda: LevelJob(AxisSource(0), [1.0, math.nan], Toggle(0)),
        lambda: LevelJob(AxisSource(0), [1.0], Toggle(0), direction=2),
        lambda: LevelJob(AxisSource(0), [3.0, 2.0], Toggle(0), direction=1, monotonic=True),
        lambda: eng.add(LevelJob(AxisSource(0), np.arange(1.0, 8.0), Toggle(1))),  # too long
        lambda: eng.add(LevelJob(AxisSource(0), [1.0], Toggle(5))),  # output not capable
        lambda: eng.add(LevelJob(AxisSource(7), [1.0], Toggle(0))),
        lambda: eng.add(LevelJob(AxisSource(0, "xpos"), [1.0], Toggle(0))),
        lambda: WindowJob((0, 1), [[0.0, 0.0]], 0.0, Toggle(0)),
        lambda: WindowJob((0, 1), [[0.0, 0.0, 1.0]], 1.0, Toggle(0)),
        lambda: Pulse(0, -1.0),
        lambda: LevelSeq(0.0, 0.0),
    ]
    for f in bad:
        with pytest.raises(MotionError):
            f()
    assert eng.buffer_free() == before and list(eng.jobs) == [jid]
    c.axes[0].move_relative(10, max_vel=1000, tacc=0.01, tdec=0.01)
    run(c)
    assert eng.log.for_job(jid)["time"].size == 5


@given(moves=st.lists(st.integers(-3000, 3000).filter(lambda d: d != 0), min_size=1,
                      max_size=5),
       levels=st.lists(st.integers(-4000, 4000), min_size=1, max_size=30, unique=True),
       direction=st.sampled_from([-1, 0, 1]))
@settings(max_examples=25, deadline=None)
def test_back_and_forth_fires_like_the_value_block_model(moves, levels, direction):
    # model: one value loaded at a time; it fires when a leg reaches it (in the direction
    # asked), strictly after the position the leg was at; then the next value is loaded
    levels = np.array(levels, dtype=float)
    c = machine(1)
    eng = CompareEngine(c)
    jid = eng.add(LevelJob(AxisSource(0), levels, Toggle(0), direction=direction))
    expect, k, pos = [], 0, 0.0
    for d in moves:
        end = pos + d
        cur = pos
        up = d > 0
        while k < levels.size and (direction == 0 or direction == (1 if up else -1)):
            lv = levels[k]
            if (up and cur < lv <= end) or (not up and end <= lv < cur):
                expect.append(lv)
                cur = lv
                k += 1
            else:
                break
        c.axes[0].move_relative(d, max_vel=200_000, tacc=0.005, tdec=0.005)
        run(c)
        pos = end
    log = eng.log.for_job(jid)
    assert log["value"].tolist() == expect
    np.testing.assert_allclose(log["positions"][:, 0], expect, atol=1e-9)


def test_output_waveform_memory_is_bounded_by_the_history_window():
    cfg = MachineConfig("t", (AxisConfig(name="x"),))
    c = Controller(cfg, history_window_s=0.05)
    c.enable_all()
    eng = CompareEngine(c)
    eng.add(LevelJob(AxisSource(0), LevelSeq(10.0, 10.0), Pulse(0, 1e-4), direction=1))
    c.axes[0].move_velocity(20_000, tacc=0.01)
    c.advance(0.5)
    line = eng.output(0)
    assert len(eng.log) > 900
    assert len(line.edges) < 250 and line.edges[0][0] >= c.time - 0.05 - 1e-9
    np.testing.assert_allclose(line.pulse_widths(), 1e-4, atol=1e-12)


@given(dist=st.floats(100, 50_000), v=st.floats(10_000, 500_000), a=st.floats(1e5, 1e7),
       j=st.floats(1e6, 1e9), n=st.integers(1, 30), seed=st.integers(0, 2**31))
@settings(max_examples=15, deadline=None)
def test_jerk_limited_moves_fire_on_the_profile(dist, v, a, j, n, seed):
    # S-curve (constant-jerk) motion: on a monotone move the position fixes the time, so
    # firing exactly on the level, at a time inside the profile, is the analytic answer
    c = machine(1)
    prof = jerk_limited(dist, v, a, j)
    levels = np.sort(np.random.default_rng(seed).uniform(0.5, dist, n))
    eng = CompareEngine(c)
    jid = eng.add(LevelJob(AxisSource(0), levels, Pulse(0, 1e-7), direction=1))
    t_start = c.time
    c.axes[0].run_profile(prof, stop_accel=a, stop_jerk=j)
    run(c)
    log = eng.log.for_job(jid)
    assert log["time"].size == n
    at = prof.sample(log["time"] - t_start).p
    np.testing.assert_allclose(at, levels, rtol=0, atol=1e-7 * max(1.0, dist / 1e4))
    np.testing.assert_allclose(log["positions"][:, 0], levels, rtol=0, atol=1e-6)
