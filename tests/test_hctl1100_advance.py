"""HCTL-1100 commutator phase advance: the AIM104 manual's formula and worked example."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from openmotion.compat import hctl1100_regs as R
from openmotion.compat.hctl1100 import HCTL1100
from openmotion.compat.hctl1100_commutator import (
    advance_counts,
    commutator_mask,
    phase_advance,
    switching_angle_deg,
    velocity_timer_interval,
    velocity_timer_register,
)
from openmotion.errors import MotionError


class SpinningRotor:
    """A plant turning at a fixed rate (quadrature counts/s), whatever the drive."""

    def __init__(self, rate: float) -> None:
        self.rate = rate
        self.position = 0.0

    @property
    def counts(self) -> int:
        return math.floor(self.position + 1e-9)

    def advance(self, dt: float, duty: float) -> None:
        self.position += self.rate * dt


def test_manual_worked_example():
    """200-step motor, L = 20.4 mH, R = 7.4 ohm, 500-line encoder, driven at 20 Hz."""
    angle = switching_angle_deg(20.0, 20.4e-3, 7.4, 50)          # p = 90 / 1.8 deg
    assert math.degrees(math.atan(2 * math.pi * 20 * 20.4e-3 / 7.4)) == pytest.approx(19.1,
                                                                                     abs=0.05)
    assert round(angle, 2) == 0.38
    assert angle / 360 * 2000 == pytest.approx(2.1, abs=0.05)
    assert advance_counts(angle, 2000) == 2                        # "2.1 => 2"
    assert velocity_timer_register(2, 500, 20.0) == 24             # "R19H ... as 24"
    dt = velocity_timer_interval(24)
    assert dt == pytest.approx(200e-6)
    assert 500 * 20 * dt == pytest.approx(2.0)                     # equation 13 holds


def test_advance_follows_speed_up_to_the_maximum():
    nf = 500  # full counts per revolution
    assert phase_advance(nf * 20.0, 24, 2) == 2
    assert phase_advance(nf * 10.0, 24, 2) == 1
    assert phase_advance(nf * 9.0, 24, 2) == 0
    assert phase_advance(nf * 40.0, 24, 2) == 2                    # capped at R1FH
    assert phase_advance(-nf * 20.0, 24, 2) == -2                  # in the rotation direction
    assert phase_advance(nf * 20.0, 0, 0) == 0                     # registers 0: none


@given(st.integers(0, 200), st.integers(-3, 3), st.sampled_from([1, -1]))
def test_advance_acts_as_a_rotor_further_on(pos, adv, sign):
    assert commutator_mask(pos, 40, 10, 0, 0, sign, adv) == \
        commutator_mask(pos + adv, 40, 10, 0, 0, sign)


def _chip(rate: float, vel_timer: int, max_adv: int) -> HCTL1100:
    c = HCTL1100(SpinningRotor(rate))
    c.write(R.R_SAMPLE_TIMER, 24)  # 200 us samples: 8 counts per sample at 40,000 counts/s
    for reg, v in ((R.R_COMM_RING, 40), (R.R_COMM_X, 10), (R.R_COMM_Y, 0),
                   (R.R_COMM_VEL_TIMER, vel_timer), (R.R_COMM_ADVANCE, max_adv)):
        c.write(reg, v)
    c.run_samples(5)
    return c


def test_chip_commutates_earlier_at_the_manual_speed():
    c = _chip(2000 * 20.0, 24, 2)  # 2000 quadrature counts/rev at 20 rev/s
    assert c.commutator_advance == 2
    base = c._ring_origin
    switched = [r for r in range(1, 80) if c.commutator_output(base + r, 1)
                != c.commutator_output(base + r - 1, 1)]
    plain = [r for r in range(1, 80) if commutator_mask(r, 40, 10, 0, 0, 1)
             != commutator_mask(r - 1, 40, 10, 0, 0, 1)]
    assert switched == [r - 2 for r in plain]                      # 2 counts earlier
    assert _chip(2000 * 20.0, 0, 0).commutator_advance == 0        # not programmed: none
    assert _chip(2000 * 5.0, 24, 2).commutator_advance == 0        # slow: below one count
    assert _chip(-2000 * 20.0, 24, 2).commutator_advance == -2


def test_bad_design_values_are_refused():
    for f in (lambda: switching_angle_deg(0, 1e-3, 1, 50),
              lambda: switching_angle_deg(20, 1e-3, math.nan, 50),
              lambda: advance_counts(-1, 2000),
              lambda: advance_counts(30, 2000),               # 166 counts > 7 bits
              lambda: velocity_timer_register(0, 500, 20),
              lambda: velocity_timer_register(2, 500, 0.001),  # R19H out of range
              lambda: velocity_timer_interval(256),
              lambda: phase_advance(1e3, 24, 128),
              lambda: phase_advance(math.inf, 24, 2)):
        with pytest.raises(MotionError):
            f()
