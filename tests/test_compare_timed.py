"""Compare outputs at their exact time on the physical line: pre-advance hook, the
simulator's write_output_at / output_record, CMP and HW_TIMER pulses with their true widths,
MPOS and non-timed hardware falling back to the cycle end, sub-cycle speed PWM."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import free_axes
from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.control.trigger.compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    Pulse,
    Toggle,
    VectorSource,
)
from openmotion.control.trigger.hsl_trigger import HslTrigger
from openmotion.control.trigger.pso import ZPso
from openmotion.errors import MotionError
from openmotion.hw.interface import TimedOutputHardware
from openmotion.hw.sim import SimMachine

MM = 1000.0


machine = free_axes  # n axes x, y, z, u without switches, enabled


def phys(c, n):
    return c.hardware.output_record.edges(f"do{n}")


class UntimedSim:
    """The simulator seen through the plain Hardware protocol (no write_output_at)."""

    def __init__(self, cfg):
        self.sim = SimMachine(cfg)

    n_axes = property(lambda self: self.sim.n_axes)
    time = property(lambda self: self.sim.time)

    def command(self, axis, cmd):
        self.sim.command(axis, cmd)

    def advance(self, t):
        return self.sim.advance(t)

    def read_axis(self, axis):
        return self.sim.read_axis(axis)

    def write_output(self, axis, signal, level):
        self.sim.write_output(axis, signal, level)

    def read_input(self, signal):
        return self.sim.read_input(signal)


# ----------------------------------------------------------------------------- sim + hook
def test_sim_write_output_at_exact_times_and_refusals():
    c = machine(1)
    hw = c.hardware
    assert isinstance(hw, TimedOutputHardware)
    t = hw.time
    hw.write_output_at(t + 0.00031, None, "do1", True)
    hw.write_output_at(t + 0.00031 + 7e-6, None, "do1", False)
    hw.write_output_at(t + 0.0005, 0, "erc", True)
    for bad in (lambda: hw.write_output_at(t - 1e-3, None, "do1", True),
                lambda: hw.write_output_at(math.nan, None, "do1", True),
                lambda: hw.write_output_at(t + 1e-4, None, "do99", True),
                lambda: hw.write_output_at(t + 1e-4, 0, "do1", True),
                lambda: hw.write_output_at(t + 1e-4, None, "do1", 1)):
        with pytest.raises(MotionError):
            bad()
    c.step()
    assert phys(c, 1) == [(t + 0.00031, True), (t + 0.00031 + 7e-6, False)]
    np.testing.assert_allclose(hw.output_record.pulse_widths("do1"), [7e-6], atol=1e-15)
    assert hw.output_record.edges("erc", 0) == [(t + 0.0005, True)]
    assert hw.read_output(0, "erc") is True and hw.read_output(None, "do1") is False


def test_pre_advance_hook_sees_the_commanded_cycle_before_the_hardware_runs():
    c = machine(1)
    seen = []
    hook = lambda ctl, t0, t1: seen.append((t0, t1, ctl.hardware.time,  # noqa: E731
                                            ctl.history.position_at(0, t1)))
    c.add_pre_advance_hook(hook)
    c.axes[0].move_relative(100, max_vel=10_000, tacc=0.01, tdec=0.01)
    c.step()
    t0, t1, hw_t, p1 = seen[0]
    assert hw_t == t0 and t1 == pytest.approx(t0 + c.period)
    c.remove_pre_advance_hook(hook)
    c.step()
    assert len(seen) == 1
    assert p1 == pytest.approx(c.history.position_at(0, t1), abs=1e-12)
    with pytest.raises(MotionError):
        c.add_pre_advance_hook(42)


# ----------------------------------------------------------------------------- DPOS exact
def test_hsl_cmp_10us_pulses_land_on_the_line_at_their_exact_time():
    c = machine(2)
    eng = CompareEngine(c)
    h = HslTrigger(eng)
    h.set_trigger_comparator(0, 0, 1, 0.0)
    h.build_compare_function(0, 1001, 1400, 7)   # a point every 7/6000 s: all cycle phases
    h.set_auto_compare(0, 1)
    levels = []
    c.add_cycle_hook(lambda ctl, t: levels.append((t, ctl.hardware.read_output(None, "do0"))))
    c.axes[0].move_relative(1500, max_vel=6000, tacc=0.05, tdec=0.05)
    assert c.wait_motion_done(timeout=5)
    fire = eng.log.arrays()["time"]
    assert fire.size == 58
    rec = phys(c, 0)
    assert rec[0][1] is True  # idles high (normal high CMP)
    falls = np.array([t for t, lv in rec[1:] if not lv])
    rises = np.array([t for t, lv in rec[1:] if lv])
    np.testing.assert_array_equal(falls, fire)             # every edge at the firing time
    np.testing.assert_allclose(rises - falls, 10e-6, atol=1e-12)  # true 10 us width
    phase = np.mod(fire, c.period) / c.period
    assert np.ptp(phase) > 0.5  # not on cycle boundaries
    # read back at every cycle end: the exact level (low only inside a 10 us pulse)
    assert [lv for _, lv in levels] == [eng.output(0).level_at(t) for t, _ in levels]
    assert sum(not lv for _, lv in levels) < fire.size // 4  # no stretching


def test_hw_timer_trains_have_the_commanded_widths_on_the_line():
    c = machine(1)
    eng = CompareEngine(c)
    z = ZPso(eng)
    z.base(0)
    z.table(0, 101.5, 577.25, 1303.75)
    z.hw_timer(2, 350, 120, 3, 0, 2)          # 3 pulses of 120 us every 350 us on do2
    jid = z.hw_pswitch2(7, 2, 0, 0, 2)        # VECTOR_MOVED table, each point a train
    c.axes[0].move_relative(2000, max_vel=50_000, tacc=0.01, tdec=0.01)
    assert c.wait_motion_done(timeout=5)
    c.advance(0.01)
    fire = eng.log.for_job(jid)["time"]
    assert fire.size == 3
    rec = phys(c, 2)
    rises = np.array([t for t, lv in rec if lv])
    falls = np.array([t for t, lv in rec if not lv])
    want = (fire[:, None] + 350e-6 * np.arange(3)).ravel()
    np.testing.assert_allclose(rises, want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(falls - rises, 120e-6, atol=1e-12)
    assert rec == eng.output(2).edges


@settings(max_examples=25, deadline=None)
@given(v=st.floats(2_000.0, 500_000.0), width=st.floats(1e-7, 3e-3),
       period=st.sampled_from([0.001, 0.002, 0.003]), first=st.floats(3.0, 50.0),
       step=st.floats(5.0, 400.0))
def test_physical_line_equals_the_exact_waveform(v, width, period, first, step):
    c = machine(1, period=period)
    eng = CompareEngine(c)
    eng.add(LevelJob(AxisSource(0), first + step * np.arange(6), Pulse(3, width)))
    eng.add(LevelJob(AxisSource(0), [first + 0.5 * step, first + 2.5 * step], Toggle(1)))
    c.axes[0].move_relative(first + 6 * step, max_vel=v, tacc=0.005, tdec=0.005)
    assert c.wait_motion_done(timeout=30)
    c.advance(width + 2 * period)
    for n in (1, 3):
        assert phys(c, n) == eng.output(n).edges
        assert c.hardware.read_output(None, f"do{n}") == eng.output(n).level_at(c.time)
    assert len(eng.log) == 8


# ----------------------------------------------------------------------------- fallbacks
def test_untimed_hardware_keeps_cycle_granular_line_with_stretched_pulses():
    c = machine(1, hardware=UntimedSim)
    eng = CompareEngine(c)
    assert not eng.timed
    eng.add(LevelJob(AxisSource(0), [100.3], Pulse(2, 5e-6)))  # shorter than a cycle
    eng.add(LevelJob(AxisSource(0), [200.0, 300.0], Toggle(3)))
    seen = []
    c.add_cycle_hook(lambda ctl, t: seen.append((ctl.hardware.sim.read_output(None, "do2"),
                                                 ctl.hardware.sim.read_output(None, "do3"))))
    c.axes[0].move_relative(400, max_vel=10_000, tacc=0.01, tdec=0.01)
    assert c.wait_motion_done(timeout=5)
    c.advance(0.005)
    do2 = [s[0] for s in seen]
    assert sum(do2) == 1 and not do2[-1]  # the 5 us pulse is shown for exactly one cycle
    np.testing.assert_allclose(eng.output(2).pulse_widths(), [5e-6], atol=1e-12)
    rec = c.hardware.sim.output_record.edges("do2")
    assert len(rec) == 2 and rec[1][0] - rec[0][0] == pytest.approx(c.period)
    do3 = [s[1] for s in seen]
    assert do3[0] is False and do3[-1] is False and any(do3)


def test_mpos_pulses_are_written_at_the_cycle_end_and_logged_exactly():
    c = machine(1)
    eng = CompareEngine(c)
    eng.add(LevelJob(AxisSource(0, "mpos"), [150.5], Pulse(2, 5e-6)))
    eng.add(LevelJob(AxisSource(0, "dpos"), [150.5], Pulse(1, 5e-6)))
    c.axes[0].move_relative(400, max_vel=10_000, tacc=0.01, tdec=0.01)
    assert c.wait_motion_done(timeout=5)
    c.advance(0.005)
    a = eng.log.arrays()
    assert a["time"].size == 2 and a["time"][0] == pytest.approx(a["time"][1], abs=1e-9)
    t_fire = a["time"][0]
    assert [t for t, _ in phys(c, 1)] == [t_fire, t_fire + 5e-6]  # DPOS: exact
    rec = phys(c, 2)                                               # MPOS: after the fact
    assert len(rec) == 2 and rec[0][0] > t_fire
    assert rec[1][0] - rec[0][0] == pytest.approx(c.period)      # stretched to one cycle
    assert math.isclose(rec[0][0] / c.period, round(rec[0][0] / c.period), abs_tol=1e-9)


# ----------------------------------------------------------------------------- speed PWM
def test_sub_cycle_speed_pwm_integrates_to_the_path_length():
    cfg = MachineConfig("t", (AxisConfig(name="x"), AxisConfig(name="y")))
    c = Controller(cfg)
    c.enable_all()
    eng = CompareEngine(c)
    src = VectorSource((0, 1), (MM, MM))
    full = 100.0  # mm/s; the feed is 50 mm/s
    pwm = eng.add_speed_pwm(src, 2, full_speed=full, per_cycle=10)
    g = Group(c, [0, 1], feed=50 * MM, acc_time=0.05)
    g.line([30 * MM, 40 * MM])
    assert c.run_until(lambda: g.queue_length == 0 and all(a.motion_done == 0
                                                            for a in c.axes), 30.0,
                       event_driven=True)
    c.advance(0.005)
    t = np.array([x for x, _ in pwm.duties])
    duty = np.array([d for _, d in pwm.duties])
    p = c.period / 10
    np.testing.assert_allclose(np.diff(t), p, rtol=1e-6)
    assert duty.max() == pytest.approx(0.5, abs=1e-9)
    # each duty is the mean speed of its PWM period: they add up to the path length
    assert float(np.sum(duty) * p * full) == pytest.approx(50.0, rel=1e-9)
    # the line carries exactly those pulses, with exact widths
    w = c.hardware.output_record.pulse_widths("do2")
    on = duty[(duty > 0) & (duty < 1)] * p
    np.testing.assert_allclose(np.sort(w), np.sort(on), atol=1e-12)
    with pytest.raises(MotionError):
        eng.add_speed_pwm(src, 2, full_speed=1.0, per_cycle=0)


# ----------------------------------------------------------------------------- edge stops
def edge_stop_machine():
    from openmotion.config import DriveConfig, SwitchConfig
    from openmotion.control.guard.safety import Safety

    ax = AxisConfig(name="x", lead=10.0, max_speed=500.0, drive=DriveConfig(type="ideal_stepper"),
                    pel=SwitchConfig(position=20_000.0, width=5000.0),
                    mel=SwitchConfig(position=-20_000.0, width=-5000.0))
    c = Controller(MachineConfig("t", (ax,), 4, 4, 0.001), safety=False)
    assert Safety(c).set_edge_stop("x", True)
    c.enable_all()
    return c


@pytest.mark.parametrize("speed", [60_000.0, 173_000.0])
def test_hardware_edge_stop_mid_cycle_undoes_the_firings_never_reached(speed):
    from openmotion.control import AxisState

    c = edge_stop_machine()
    eng = CompareEngine(c)
    pts = np.arange(19_000.0, 21_000.0, 13.7)
    jid = eng.add(LevelJob(AxisSource(0), pts, Pulse(1, 5e-6)))
    c.axes[0].move_velocity(speed, tacc=0.05)
    assert c.run_until(lambda: c.axes[0].state is AxisState.ERROR_STOP, 10.0)
    t_cut = c.hardware.stop_time(0)
    assert t_cut is not None
    c.advance(0.01)
    a = eng.log.arrays()
    n = int(np.sum(pts <= 20_000.0))
    assert a["time"].size == n and np.all(a["time"] <= t_cut)     # nothing past the cut
    assert np.all(a["positions"][:, 0] <= 20_000.0 + 1e-6)
    assert eng.job(jid).index == n and eng.job(jid).remaining == pts.size - n  # still armed
    assert all(t <= t_cut + 5e-6 for t, _ in eng.output(1).edges)
    assert c.hardware.read_output(None, "do1") == eng.output(1).level_at(c.time)
