"""HCTL-1100 4-phase commutator, the AIM104 stepper drive logic and a quasi-static stepper.

Commutator (AIM104 appendix 2, seed-facts section 3): the ring counter follows the encoder
modulo Ring (quadrature or full counts, status bit 2); each of the 4 phases owns a sector
of X + Y = Ring/4 counts, X with that phase alone and Y with it and the next phase on. Align
leaves the rotor on the PHD detent at ring position 0, so the detent of phase j (A=0..D=3)
alone is at (j+1)*Ring/4 and that of the pair (j, j+1) half a sector further. For torque in
the direction of the motor command the commutator energises the state ahead of the rotor
(ahead by more than 0 and at most one sector plus the overlap); the negative direction is
the mirror image. Phase advance / velocity timer are stored but not modelled.

Board drive logic (configuration bits 0-1): one-phase-on maps A/B/C/D to winding currents
(1,0)/(0,1)/(-1,0)/(0,-1); two-phases-on maps them to the diagonals (the board's logic
shifts the sequence by half a step); half-step passes the chip's overlapped sequence
A, AB, B, BC, ... through (X = Y). The electrical angle atan2(ib, ia) fixes the detent.

`IdealStepper` is a quasi-static rotor: it moves in half-step increments toward the
detent of the energised state, re-reading the commutator after each; its step rate follows
duty * `max_step_rate` through a first-order lag `tau` (a stand-in for inertia), and it
holds when the drive is off. No resonance, no torque curve, no missed steps: a documented
simplification.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from openmotion.errors import MotionError

PHASE_A, PHASE_B, PHASE_C, PHASE_D = 1, 2, 4, 8
_PHASE_BITS = (PHASE_A, PHASE_B, PHASE_C, PHASE_D)

DRIVE_DC, DRIVE_FULL_ONE, DRIVE_FULL_TWO, DRIVE_HALF = 0, 1, 2, 3
_MAX_SAMPLE = 16 * 256 / 2.0e6


def _positive_detent(r: int, x: int, q: int) -> int:
    """Half-sector detent index (mod 8) the commutator energises for + torque at ring pos r."""
    s, u = divmod(r, q)
    s %= 4
    return (2 * s + 2) % 8 if u < x else (2 * s + 3) % 8


def detent_mask(d: int) -> int:
    """Phase bit mask of half-sector detent index d: even = one phase, odd = two phases."""
    d %= 8
    if d % 2 == 0:
        return _PHASE_BITS[(d // 2 - 1) % 4]
    j = (d - 3) // 2 % 4
    return _PHASE_BITS[j] | _PHASE_BITS[(j + 1) % 4]


def commutator_mask(position: int, ring: int, x: int, y: int, offset: int, sign: int) -> int:
    """Phases (bit mask A=1 .. D=8) on at ring `position` for motor command sign `sign`.

    `position` is the ring-counter input in commutator counts (already divided for full
    counts); 0 outputs nothing (no drive) and an unusable ring (X + Y = 0) does the same.
    """
    q = x + y
    if sign == 0 or ring <= 0 or q <= 0:
        return 0
    r = (position + offset) % ring
    c = (x - y) // 2  # centre the lead on one step: full step (q/2, 3q/2], half (q/2, q]
    if sign > 0:
        return detent_mask(_positive_detent((r + c) % (4 * q), x, q))
    # mirror: run the + rule on -r within the 4q cycle and mirror the detent back
    d = _positive_detent((c - r) % (4 * q), x, q)
    return detent_mask(-d)


_ANGLE_ONE = {PHASE_A: 0.0, PHASE_B: 90.0, PHASE_C: 180.0, PHASE_D: 270.0}


def winding_angle(mask: int, drive: int) -> float | None:
    """Electrical angle (degrees) of the winding currents the board makes of `mask`."""
    if mask == 0 or drive == DRIVE_DC:
        return None
    angles = [_ANGLE_ONE[b] for b in _PHASE_BITS if mask & b]
    if drive == DRIVE_FULL_ONE:
        return angles[0]
    if drive == DRIVE_FULL_TWO:
        return (angles[0] + 45.0) % 360.0
    if len(angles) == 1:
        return angles[0]
    a0, a1 = angles
    if abs(a1 - a0) > 180.0:  # D and A: midpoint across 0
        return 315.0
    return (a0 + a1) / 2.0


def winding_currents(mask: int, drive: int, *, shaping: bool = False) -> tuple[float, float]:
    """(ia, ib): relative currents in windings A1-A2 and B1-B2 (each -1, 0 or 1; current
    shaping, AIM104 link 7 removed, boosts one-phase half steps by sqrt 2)."""
    ang = winding_angle(mask, drive)
    if ang is None:
        return (0.0, 0.0)
    rad = math.radians(ang)
    ia = float((round(math.cos(rad), 9) > 0) - (round(math.cos(rad), 9) < 0))
    ib = float((round(math.sin(rad), 9) > 0) - (round(math.sin(rad), 9) < 0))
    if drive == DRIVE_HALF and shaping and (ia == 0.0 or ib == 0.0):
        return (ia * math.sqrt(2.0), ib * math.sqrt(2.0))
    return (ia, ib)


class IdealStepper:
    """Quasi-static stepper with an encoder: counts move between detents, no dynamics.

    `drive(counts, sign) -> angle | None` is wired by the board: given the rotor position
    (quadrature counts) and the sign of the motor command it returns the electrical angle
    of the energised windings (degrees) or None when no phase is on.
    """

    def __init__(self, steps_per_rev: int = 200, counts_per_rev: int = 2000, *,
                 max_step_rate: float = 4000.0, tau: float = 0.01) -> None:
        if not isinstance(steps_per_rev, int) or steps_per_rev <= 0 or steps_per_rev % 4:
            raise MotionError(f"steps_per_rev must be a positive multiple of 4, "
                              f"got {steps_per_rev!r}")
        if not isinstance(counts_per_rev, int) or counts_per_rev % steps_per_rev:
            raise MotionError("counts_per_rev must be an integer multiple of steps_per_rev, "
                              f"got {counts_per_rev!r}")
        if not (max_step_rate > 0.0 and math.isfinite(max_step_rate)):
            raise MotionError(f"max_step_rate must be > 0, got {max_step_rate!r}")
        self.counts_per_step = counts_per_rev // steps_per_rev
        self.cycle = 4 * self.counts_per_step  # one electrical cycle in counts
        if not (tau > 0.0 and math.isfinite(tau)):
            raise MotionError(f"tau must be > 0, got {tau!r}")
        self.max_step_rate = float(max_step_rate)
        self.tau = float(tau)
        self._rate = 0.0
        self.position = 0.0  # quadrature counts
        self.drive: Callable[[int, int], float | None] = lambda counts, sign: None
        self._budget = 0.0

    @property
    def counts(self) -> int:
        return math.floor(self.position + 1e-9)

    def _target(self, angle: float, sign: int = 1) -> float:
        """Nearest detent of electrical angle `angle` to the rotor (counts, unwrapped); a
        detent half a cycle away (zero static torque) is taken in the direction `sign`."""
        q = self.counts_per_step
        phase = q + angle / 360.0 * self.cycle  # ring position of the detent
        d = (phase - self.position) % self.cycle
        half = self.cycle / 2
        if d > half + 1e-9 or (abs(d - half) <= 1e-9 and sign < 0):
            d -= self.cycle
        return self.position + d

    def advance(self, dt: float, duty: float) -> None:
        # step rate r (full steps/s) lags duty*max_step_rate with time constant tau; its
        # mean over dt sets the step budget and its sign the commutation direction:
        #   r(t) = r_inf + (r0 - r_inf) exp(-t/tau),  mean = r_inf + (r0 - r_inf) tau/dt (1 - e)
        r_inf = duty * self.max_step_rate
        r0 = self._rate
        if dt > 0.0:
            em1 = -math.expm1(-dt / self.tau)
            mean = r_inf + (r0 - r_inf) * self.tau / dt * em1
            self._rate = r_inf + (r0 - r_inf) * (1.0 - em1)
        else:
            mean = r0
        sign = (mean > 0.0) - (mean < 0.0)
        if duty == 0.0:
            sign = 0
        self._budget = min(self._budget + abs(mean) * dt,
                           1.0 + self.max_step_rate * _MAX_SAMPLE)
        for _ in range(256):
            angle = self.drive(self.counts, sign)
            if angle is None:
                break
            target = self._target(angle, sign)
            dist = target - self.position
            if abs(dist) < 1e-9:
                self._rate = 0.0  # held on the detent of the energised phases
                break
            # move by at most half a step per go, re-reading the commutator on the way
            move = min(abs(dist), 0.5 * self.counts_per_step)
            need = move / self.counts_per_step
            if need > self._budget + 1e-12:
                break
            self._budget -= need
            self.position += math.copysign(move, dist)
        if sign == 0:
            self._budget = 0.0
