"""DC motor + amplifier plant: exact piecewise solution against fine RK4, limits, encoder."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.hw.sim.dcmotor import DCMotor, DCMotorParams


def rk4(p: DCMotorParams, th, w, duty, t, n=20000):
    """Reference: the same ODE with the current clamp, RK4 on a fine grid."""
    ke = p.back_emf
    duty = max(-1.0, min(1.0, duty))

    def f(w):
        i = (duty * p.supply_v - ke * w) / p.resistance
        i = max(-p.current_limit, min(p.current_limit, i))
        return (p.kt * i - p.viscous * w - p.load_torque) / p.inertia

    h = t / n
    for _ in range(n):
        k1 = f(w)
        k2 = f(w + 0.5 * h * k1)
        k3 = f(w + 0.5 * h * k2)
        k4 = f(w + h * k3)
        th += h * (w + h / 6 * (k1 + k2 + k3))  # RK4 for th'' = f(w)
        w += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return th, w


@settings(max_examples=25, deadline=None)
@given(duty=st.floats(-1.2, 1.2), w0=st.floats(-900, 900), t=st.floats(1e-4, 0.05),
       load=st.floats(-0.02, 0.02), viscous=st.sampled_from([0.0, 1e-5, 1e-4]))
def test_exact_solution_matches_rk4_through_current_limit(duty, w0, t, load, viscous):
    p = DCMotorParams(load_torque=load, viscous=viscous)
    m = DCMotor(p, omega=w0)
    m.advance(t, duty)
    th, w = rk4(p, 0.0, w0, duty, t)
    assert m.omega == pytest.approx(w, rel=1e-6, abs=1e-4)
    assert m.theta == pytest.approx(th, rel=1e-6, abs=1e-6)


@settings(max_examples=30, deadline=None)
@given(duty=st.floats(-1, 1), w0=st.floats(-800, 800), t1=st.floats(0, 0.02),
       t2=st.floats(0, 0.02))
def test_split_advance_equals_one_advance(duty, w0, t1, t2):
    a, b = DCMotor(omega=w0), DCMotor(omega=w0)
    a.advance(t1 + t2, duty)
    b.advance(t1, duty)
    b.advance(t2, duty)
    assert a.omega == pytest.approx(b.omega, rel=1e-9, abs=1e-7)
    assert a.theta == pytest.approx(b.theta, rel=1e-9, abs=1e-9)


def test_steady_state_speed_and_current_by_hand():
    p = DCMotorParams()
    m = DCMotor(p)
    m.advance(5.0, 0.5)
    # i = (12 - 0.03 w)/4, 0.03 i = 1e-5 w  ->  w = 0.36/(9e-4/4*4 + 4e-5) ...
    w = 0.03 * 12 / 4 / (0.03 * 0.03 / 4 + 1e-5)
    assert m.omega == pytest.approx(w, rel=1e-9)
    assert abs(m.current) < p.current_limit
    assert m.velocity_counts == pytest.approx(w * 4000 / (2 * math.pi))


def test_current_limit_sets_the_start_acceleration():
    p = DCMotorParams()
    m = DCMotor(p)
    dt = 1e-5
    m.advance(dt, 1.0)  # 24 V / 4 ohm = 6 A, clamped to 1 A
    assert m.omega == pytest.approx(p.kt * 1.0 / p.inertia * dt, rel=1e-3)
    assert m.current == pytest.approx(1.0)


def test_duty_is_clamped_and_encoder_counts_floor():
    a, b = DCMotor(), DCMotor()
    a.advance(0.01, 3.0)
    b.advance(0.01, 1.0)
    assert a.theta == b.theta
    m = DCMotor(theta=2 * math.pi)
    assert m.counts == 4000
    m = DCMotor(theta=-1e-9)
    assert m.counts == -1


def test_validation():
    with pytest.raises(MotionError, match="inertia"):
        DCMotorParams(inertia=0)
    with pytest.raises(MotionError, match="encoder_lines"):
        DCMotorParams(encoder_lines=2.5)
    with pytest.raises(MotionError, match="params"):
        DCMotor(params="x")
    m = DCMotor()
    for bad in ((-1, 0.1), (math.nan, 0.1), (0.1, math.inf)):
        with pytest.raises(MotionError):
            m.advance(*bad)
    assert m.theta == 0.0 and m.omega == 0.0
