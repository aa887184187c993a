"""Sampled compensators (HCTL lead filter, PID+FF) and the following-error monitor."""

import cmath
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.control.loops.servo import PIDFF, FollowingErrorMonitor, LeadFilter
from openmotion.errors import MotionError

byte = st.integers(0, 255)


# ---------------------------------------------------------------- lead filter
def test_lead_filter_difference_equation_by_hand():
    f = LeadFilter(0x80, 0x40, 0x40)  # A/256 = 0.5, B/256 = 0.25, K/4 = 16
    assert f.step(10, 0) == 160.0                      # 16*10
    # 16*10 - (0.5*16*10 + 0.25*160) = 160 - 80 - 40
    assert f.step(10, 0) == 40.0
    assert f.step_error(0.0) == pytest.approx(-(0.5 * 16 * 10 + 0.25 * 40))


@settings(max_examples=40, deadline=None)
@given(a=byte, b=st.integers(0, 250), k=st.integers(1, 255),
       w=st.floats(0.05, 3.0))
def test_lead_filter_matches_z_domain_transfer_function(a, b, k, w):
    """A sinusoid in steady state comes out scaled by |D(e^jw)| = |K(z-A/256)/(4(z+B/256))|."""
    f = LeadFilter(a, b, k)
    n = np.arange(3000)
    x = np.cos(w * n)
    y = np.array([f.step_error(float(v)) for v in x])
    z = cmath.exp(1j * w)
    d = k * (z - a / 256) / (4 * (z + b / 256))
    expect = np.real(d * np.exp(1j * w * n))
    tail = slice(2000, None)  # the pole |B/256| <= 0.977 has decayed by then
    assert np.max(np.abs(y[tail] - expect[tail])) <= 1e-6 * max(1.0, abs(d))


@settings(max_examples=40, deadline=None)
@given(a=byte, b=byte, k=byte, x=st.floats(-100, 100))
def test_lead_filter_dc_gain(a, b, k, x):
    f = LeadFilter(a, b, k)
    for _ in range(4000):
        y = f.step_error(x)
    if b < 250:
        assert y == pytest.approx(f.gain_at_dc() * x, abs=1e-6)


def test_lead_filter_limit_and_quantize_store_the_output():
    f = LeadFilter(0xE5, 0x40, 0xFF, limit=127, quantize=True)
    assert f.step_error(100) == 127.0
    # history is the saturated value: 63.75*3 - (0.89453125*63.75*100 + 0.25*127)
    raw = 63.75 * 3 - (229 / 256 * 63.75 * 100 + 0.25 * 127)
    assert f.step_error(3) == max(-127.0, float(math.trunc(raw)))
    g = LeadFilter(0, 0, 5, quantize=True)
    assert g.step_error(1.0) == 1.0  # 1.25 truncated
    assert g.step_error(-1.0) == -1.0


def test_lead_filter_reset_and_on_the_fly_change():
    f = LeadFilter()
    f.step_error(5)
    f.set_parameters(0, 0, 4)
    assert f.step_error(2) == 2.0  # A = B = 0: pure gain, the old history no longer counts
    f.reset()
    f.set_parameters(0x80, 0x80, 0x40)
    assert f.step_error(1) == 16.0


@pytest.mark.parametrize("bad", [-1, 256, 1.5, True, None, "1"])
def test_lead_filter_rejects_bad_parameters_unchanged(bad):
    f = LeadFilter(1, 2, 3)
    with pytest.raises(MotionError, match="0..255"):
        f.set_parameters(bad, 2, 3)
    with pytest.raises(MotionError, match="k"):
        f.set_parameters(1, 2, bad)
    assert (f.a, f.b, f.k) == (1, 2, 3)
    with pytest.raises(MotionError):
        LeadFilter(limit=-1)


# ---------------------------------------------------------------- PID + FF
def test_pid_proportional_and_derivative_on_feedback():
    c = PIDFF(2.0, kd=0.5, dt=0.01)
    assert c.step(1.0, 0.0) == 2.0          # first sample: no derivative kick
    assert c.step(3.0, 0.0) == 6.0          # command step: still no kick (derivative on fb)
    assert c.step(3.0, 0.1) == pytest.approx(2.0 * 2.9 - 0.5 * 0.1 / 0.01)


def test_pid_feed_forward():
    c = PIDFF(0.0, dt=0.5, kvff=2.0, kaff=1.0)
    c.step(0.0, 0.0)
    assert c.step(1.0, 1.0) == pytest.approx(2.0 * 2.0 + 1.0 * 4.0)  # v = 2, a = 4
    assert c.step(2.0, 2.0) == pytest.approx(4.0)                    # v = 2, a = 0


def test_pid_integral_removes_steady_state_error_on_a_plant_with_load():
    # first-order plant x' = u - 2 (a constant disturbance), sampled exactly enough at 1 ms
    dt = 1e-3
    c = PIDFF(20.0, ki=200.0, dt=dt, output_limit=50.0)
    x = 0.0
    for _ in range(20000):
        u = c.step(1.0, x)
        x += (u - 2.0) * dt
    assert x == pytest.approx(1.0, abs=1e-6)
    p = PIDFF(20.0, dt=dt)
    x = 0.0
    for _ in range(20000):
        x += (p.step(1.0, x) - 2.0) * dt
    assert x == pytest.approx(0.9, abs=1e-6)  # P only: error 2/kp stays


def test_pid_output_clamp_and_anti_windup():
    c = PIDFF(1.0, ki=10.0, dt=0.1, output_limit=5.0)
    for _ in range(100):
        assert c.step(100.0, 0.0) == 5.0
    # integral did not wind up: the output leaves saturation as soon as the error reverses
    assert c.step(0.0, 0.5) < 0.0
    d = PIDFF(0.0, ki=1.0, dt=1.0, integral_limit=3.0)
    for _ in range(10):
        out = d.step(1.0, 0.0)
    assert out == 3.0


@pytest.mark.parametrize("kwargs", [dict(kp=-1, dt=1), dict(kp=1, dt=0),
                                    dict(kp=1, dt=1, ki=math.nan),
                                    dict(kp=1, dt=1, output_limit=0),
                                    dict(kp=1, dt=1, integral_limit="x"),
                                    dict(kp=1, dt=1, kvff=math.inf)])
def test_pid_rejects_bad_arguments(kwargs):
    with pytest.raises(MotionError):
        PIDFF(**kwargs)


# ---------------------------------------------------------------- following error
def test_following_error_trips_and_latches():
    m = FollowingErrorMonitor(10.0)
    assert not m.check(100.0, 95.0).tripped
    r = m.check(100.0, 89.0)
    assert r.tripped and r.error == 11.0 and r.peak == 11.0
    r = m.check(100.0, 100.0)  # error gone: still tripped until reset
    assert r.tripped and m.tripped and m.trip_error == 11.0
    m.reset()
    assert not m.tripped and m.check(0.0, -10.0).tripped is False  # exactly the limit is ok


def test_following_error_nan_trips_and_bad_limit():
    m = FollowingErrorMonitor(1.0)
    assert m.check(0.0, math.nan).tripped
    for bad in (0, -1, math.nan, "a"):
        with pytest.raises(MotionError, match="limit"):
            FollowingErrorMonitor(bad)


def test_pid_ff_closes_a_loop_on_the_dc_motor_and_monitor_watches_it():
    """Ramp-and-hold under a load torque: the integral removes the final error, the velocity
    feed-forward keeps the ramp lag small; a tight monitor trips, a loose one does not."""
    from openmotion.hw.sim.dcmotor import DCMotor, DCMotorParams

    def run(kvff, limit):
        m = DCMotor(DCMotorParams(load_torque=0.005))
        dt = 2.5e-4
        c = PIDFF(0.02, ki=0.5, kd=0.0004, dt=dt, kvff=kvff, output_limit=1.0)
        mon = FollowingErrorMonitor(limit)
        worst = 0.0
        for n in range(8000):
            cmd = min(n * dt, 0.5) * 4000.0
            u = c.step(cmd, m.counts)
            if 0.1 < n * dt < 0.5:  # on the ramp
                worst = max(worst, abs(cmd - m.counts))
            mon.check(cmd, m.counts)
            m.advance(dt, u)
        return m.counts, worst, mon.tripped

    # back-EMF feed-forward: ke * (2 pi / 4000 counts) / 24 V duty per count/s
    final, lag_ff, tripped = run(0.03 * 2 * 3.141592653589793 / 4000 / 24, 100.0)
    assert final == 2000 and not tripped
    _, lag_noff, tripped = run(0.0, 20.0)
    assert lag_noff > lag_ff and tripped
