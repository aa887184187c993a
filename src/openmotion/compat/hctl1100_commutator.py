"""HCTL-1100 4-phase commutator, the AIM104 stepper drive logic and a quasi-static stepper.

Commutator (AIM104 appendix 2, seed-facts section 3): the ring counter follows the encoder
modulo Ring (quadrature or full counts, status bit 2); each of the 4 phases owns a sector
of X + Y = Ring/4 counts, X with that phase alone and Y with it and the next phase on. Align
leaves the rotor on the PHD detent at ring position 0, so the detent of phase j (A=0..D=3)
alone is at (j+1)*Ring/4 and that of the pair (j, j+1) half a sector further. For torque in
the direction of the motor command the commutator energises the state ahead of the rotor
(ahead by more than 0 and at most one sector plus the overlap); the negative direction is
the mirror image.

Phase advance (AIM104 "Commutator register descriptions", equations 11-14): at speed the
commutator switches earlier by `phase_advance(...)` counts in the direction of rotation.
The chip measures the rotor speed over the velocity-timer interval
dt = 16 (R19H + 1) / fclk [14]; the advance is the encoder counts in that interval,
Advance = N_f v dt [13] (N_f full counts per revolution, v in revolutions/s), capped at
Max. Phase Advance R1FH. The manual's design helpers: `switching_angle_deg` [11] (the
optimum angle tan^-1(wL/R)/p), `advance_counts` (angle/360 x counts per revolution) and
`velocity_timer_register` ([13] solved for R19H). Its example - 200 steps, L = 20.4 mH,
R = 7.4 ohm, 500-line encoder, 20 Hz - gives 0.38 deg, 2 quadrature counts and R19H = 24.

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


def _clock(clock_hz: float) -> float:
    if not (isinstance(clock_hz, int | float) and math.isfinite(clock_hz) and clock_hz > 0):
        raise MotionError(f"clock_hz must be a finite number > 0, got {clock_hz!r}")
    return float(clock_hz)


def velocity_timer_interval(vel_timer: int, clock_hz: float = 2.0e6) -> float:
    """dt = 16 (R19H + 1) / fclk, seconds (manual equation 14)."""
    if isinstance(vel_timer, bool) or not isinstance(vel_timer, int) or not 0 <= vel_timer <= 255:
        raise MotionError(f"vel_timer (R19H) must be an integer in [0, 255], got {vel_timer!r}")
    return 16.0 * (vel_timer + 1) / _clock(clock_hz)


def phase_advance(full_counts_per_s: float, vel_timer: int, max_advance: int,
                  clock_hz: float = 2.0e6) -> int:
    """Advance (counts, signed like the speed) at a rotor speed of `full_counts_per_s`
    (N_f v): the whole counts in one velocity-timer interval, N_f v dt (equation 13),
    capped at Max. Phase Advance `max_advance` (R1FH). Both registers 0: no advance."""
    if isinstance(max_advance, bool) or not isinstance(max_advance, int) \
            or not 0 <= max_advance <= 127:
        raise MotionError(f"max_advance (R1FH) must be an integer in [0, 127], "
                          f"got {max_advance!r}")
    v = float(full_counts_per_s)
    if not math.isfinite(v):
        raise MotionError(f"full_counts_per_s must be finite, got {full_counts_per_s!r}")
    counts = min(math.floor(abs(v) * velocity_timer_interval(vel_timer, clock_hz) + 1e-9),
                 max_advance)
    return int(math.copysign(counts, v)) if counts else 0


def switching_angle_deg(freq_hz: float, inductance_h: float, resistance_ohm: float,
                        rotor_teeth: float) -> float:
    """Optimum switching angle tan^-1(w L / R) / p in mechanical degrees (equation 11),
    w = 2 pi freq_hz, p = rotor teeth (90 / step angle)."""
    for name, val in (("freq_hz", freq_hz), ("inductance_h", inductance_h),
                      ("resistance_ohm", resistance_ohm), ("rotor_teeth", rotor_teeth)):
        if not (isinstance(val, int | float) and math.isfinite(val) and val > 0):
            raise MotionError(f"{name} must be a finite number > 0, got {val!r}")
    w = 2.0 * math.pi * freq_hz
    return math.degrees(math.atan(w * inductance_h / resistance_ohm)) / rotor_teeth


def advance_counts(angle_deg: float, counts_per_rev: int) -> int:
    """Max. Phase Advance for a switching angle: angle / 360 x counts per revolution, to
    whole counts (the manual: 0.38 deg of 2000 quadrature counts = 2.1 => 2)."""
    if not (isinstance(angle_deg, int | float) and math.isfinite(angle_deg) and angle_deg >= 0):
        raise MotionError(f"angle_deg must be a finite number >= 0, got {angle_deg!r}")
    if isinstance(counts_per_rev, bool) or not isinstance(counts_per_rev, int) \
            or counts_per_rev < 1:
        raise MotionError(f"counts_per_rev must be an integer >= 1, got {counts_per_rev!r}")
    n = math.floor(angle_deg / 360.0 * counts_per_rev + 1e-9)
    if n > 127:
        raise MotionError(f"advance {n} counts exceeds the 7-bit R1FH (127); use full counts")
    return n


def velocity_timer_register(max_advance: int, full_counts_per_rev: int, rev_per_s: float,
                            clock_hz: float = 2.0e6) -> int:
    """R19H for which the advance reaches `max_advance` at `rev_per_s`: equation 13,
    max_advance = N_f v 16 (R19H + 1) / fclk, solved for R19H (manual example: 24)."""
    if isinstance(max_advance, bool) or not isinstance(max_advance, int) \
            or not 1 <= max_advance <= 127:
        raise MotionError(f"max_advance must be an integer in [1, 127], got {max_advance!r}")
    if isinstance(full_counts_per_rev, bool) or not isinstance(full_counts_per_rev, int) \
            or full_counts_per_rev < 1:
        raise MotionError(f"full_counts_per_rev must be an integer >= 1, "
                          f"got {full_counts_per_rev!r}")
    if not (isinstance(rev_per_s, int | float) and math.isfinite(rev_per_s) and rev_per_s > 0):
        raise MotionError(f"rev_per_s must be a finite number > 0, got {rev_per_s!r}")
    reg = round(max_advance * _clock(clock_hz) / (16.0 * full_counts_per_rev * rev_per_s)) - 1
    if not 0 <= reg <= 255:
        raise MotionError(f"R19H would be {reg}, outside [0, 255]: the speed is out of the "
                          "velocity timer's range")
    return int(reg)


def commutator_mask(position: int, ring: int, x: int, y: int, offset: int, sign: int,
                    advance: int = 0) -> int:
    """Phases (bit mask A=1 .. D=8) on at ring `position` for motor command sign `sign`.

    `position` is the ring-counter input in commutator counts (already divided for full
    counts); 0 outputs nothing (no drive) and an unusable ring (X + Y = 0) does the same.
    `advance` (signed, commutator counts, from `phase_advance`) moves the switching points
    earlier in the direction of rotation: the commutator acts as if the rotor were
    `advance` counts further on.
    """
    q = x + y
    if sign == 0 or ring <= 0 or q <= 0:
        return 0
    r = (position + offset + advance) % ring
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
