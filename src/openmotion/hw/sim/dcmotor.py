"""Brushed DC motor + PWM amplifier plant with a quadrature encoder, integrated exactly.

The amplifier applies duty*V (duty in [-1, 1], the 20 kHz PWM taken at its average: the
PWM period is far below the electrical and mechanical time constants) and limits the
winding current to +-i_max (the AIM104 on-board drivers: 1 A per winding). The winding
inductance is neglected (electrical time constant << mechanical), so with i = (duty*V -
ke*w)/R the motion obeys a first-order ODE in w in each regime:

    unsaturated:  J w' = kt (duty V - ke w)/R - b w - tau_load   ->  w' = alpha - beta w
    saturated:    J w' = kt s i_max - b w - tau_load                 (s = sign of i)

With the duty held over a sample both are linear with constant coefficients, so

    w(t) = w_inf + (w0 - w_inf) exp(-beta t),  theta(t) = theta0 + w_inf t
           + (w0 - w_inf)(1 - exp(-beta t))/beta,       w_inf = alpha/beta
    (beta = 0: w = w0 + alpha t, theta = theta0 + w0 t + alpha t^2/2).

The regime changes when w crosses (duty V -+ R i_max)/ke; w is monotone within a regime, so
the crossing time has the closed form -ln((w_b - w_inf)/(w0 - w_inf))/beta and `advance`
chains at most a few exact pieces per call. No sub-stepping, no drift.

The encoder gives quadrature counts: floor(theta * 4*lines / 2pi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from openmotion.errors import MotionError, check_finite, check_nonnegative, check_positive

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class DCMotorParams:
    """Motor, amplifier and encoder constants (SI units).

    Defaults: a small unloaded 24 V servo motor on the AIM104 on-board driver (1 A).
    """

    supply_v: float = 24.0
    resistance: float = 4.0
    kt: float = 0.03          # torque constant, N*m/A
    ke: float | None = None   # back-EMF constant, V*s/rad (None: equal to kt, SI motor)
    inertia: float = 2.0e-6   # kg*m^2, rotor (unloaded: a poorly damped loop)
    viscous: float = 1.0e-5   # N*m*s/rad
    current_limit: float = 1.0
    load_torque: float = 0.0  # constant external torque, N*m
    encoder_lines: int = 1000

    def __post_init__(self) -> None:
        check_positive("supply_v", self.supply_v)
        check_positive("resistance", self.resistance)
        check_positive("kt", self.kt)
        if self.ke is not None:
            check_positive("ke", self.ke)
        check_positive("inertia", self.inertia)
        check_nonnegative("viscous", self.viscous)
        check_positive("current_limit", self.current_limit)
        check_finite("load_torque", self.load_torque)
        lines = self.encoder_lines
        if isinstance(lines, bool) or not isinstance(lines, int) or lines <= 0:
            raise MotionError(f"encoder_lines must be a positive int, got {lines!r}")

    @property
    def back_emf(self) -> float:
        return self.kt if self.ke is None else self.ke

    @property
    def counts_per_rev(self) -> int:
        """Quadrature counts per revolution (4 x lines)."""
        return 4 * self.encoder_lines


class DCMotor:
    """State (theta rad, omega rad/s) of one motor; `advance(dt, duty)` moves it exactly."""

    __slots__ = ("params", "theta", "omega", "current", "_cpr_per_rad", "_ke", "_r", "_v",
                 "_imax", "_beta_lin", "_beta_sat", "_kt_j", "_load_j")

    def __init__(self, params: DCMotorParams | None = None, *, theta: float = 0.0,
                 omega: float = 0.0) -> None:
        p = params if params is not None else DCMotorParams()
        if not isinstance(p, DCMotorParams):
            raise MotionError(f"params must be a DCMotorParams, got {type(p).__name__}")
        self.params = p
        self.theta = check_finite("theta", theta)
        self.omega = check_finite("omega", omega)
        self.current = 0.0
        self._cpr_per_rad = p.counts_per_rev / TWO_PI
        self._ke = p.back_emf
        self._r = p.resistance
        self._v = p.supply_v
        self._imax = p.current_limit
        self._kt_j = p.kt / p.inertia
        self._beta_lin = (p.kt * self._ke / p.resistance + p.viscous) / p.inertia
        self._beta_sat = p.viscous / p.inertia
        self._load_j = p.load_torque / p.inertia

    @property
    def counts(self) -> int:
        """Encoder position in quadrature counts (unwrapped)."""
        return math.floor(self.theta * self._cpr_per_rad)

    @property
    def counts_float(self) -> float:
        """Position in (fractional) quadrature counts."""
        return self.theta * self._cpr_per_rad

    @property
    def velocity_counts(self) -> float:
        """Speed in quadrature counts per second."""
        return self.omega * self._cpr_per_rad

    def _regime(self, w: float, duty_v: float) -> tuple[float, float, float, float]:
        """(alpha, beta, lower, upper): the ODE w' = alpha - beta w valid for w in [lo, hi]."""
        lo = (duty_v - self._r * self._imax) / self._ke  # below lo the current is +i_max
        hi = (duty_v + self._r * self._imax) / self._ke  # above hi it is -i_max
        lin_a = self._kt_j * duty_v / self._r - self._load_j
        if w < lo or (w == lo and lin_a - self._beta_lin * w < 0.0):
            return self._kt_j * self._imax - self._load_j, self._beta_sat, -math.inf, lo
        if w > hi or (w == hi and lin_a - self._beta_lin * w > 0.0):
            return -self._kt_j * self._imax - self._load_j, self._beta_sat, hi, math.inf
        return lin_a, self._beta_lin, lo, hi

    def advance(self, dt: float, duty: float) -> None:
        """Hold `duty` (clamped to [-1, 1]) for `dt` seconds."""
        dt = check_nonnegative("dt", dt)
        duty = check_finite("duty", duty)
        duty = 1.0 if duty > 1.0 else (-1.0 if duty < -1.0 else duty)
        duty_v = duty * self._v
        th, w = self.theta, self.omega
        left = dt
        for _ in range(6):  # at most two regime changes happen; 6 is a safe bound
            if left <= 0.0:
                break
            alpha, beta, lo, hi = self._regime(w, duty_v)
            t, w_end, th_end = self._piece(alpha, beta, lo, hi, w, th, left)
            th, w = th_end, w_end
            left -= t
        if left > 0.0:  # only on repeated float ties at a boundary: finish unbounded
            alpha, beta, _, _ = self._regime(w, duty_v)
            _, w, th = self._piece(alpha, beta, -math.inf, math.inf, w, th, left)
        self.theta, self.omega = th, w
        i = (duty_v - self._ke * w) / self._r
        self.current = max(-self._imax, min(self._imax, i))

    @staticmethod
    def _piece(alpha: float, beta: float, lo: float, hi: float, w0: float, th0: float,
               left: float) -> tuple[float, float, float]:
        """Run one regime for up to `left` s; stop early (exactly) on its boundary."""
        if beta > 0.0:
            w_inf = alpha / beta
            t = left
            bound = hi if w_inf > hi else (lo if w_inf < lo else None)
            if bound is not None and w0 != w_inf:
                ratio = (bound - w_inf) / (w0 - w_inf)
                if 0.0 < ratio <= 1.0:
                    t = min(left, -math.log(ratio) / beta)
            em1 = -math.expm1(-beta * t)  # 1 - exp(-beta t)
            w = w_inf + (w0 - w_inf) * (1.0 - em1)
            th = th0 + w_inf * t + (w0 - w_inf) * em1 / beta
            if t < left and bound is not None:
                w = bound  # land exactly on the boundary so the next regime is chosen right
            return t, w, th
        t = left
        if alpha > 0.0 and hi < math.inf:
            t = min(left, max(0.0, (hi - w0) / alpha))
        elif alpha < 0.0 and lo > -math.inf:
            t = min(left, max(0.0, (lo - w0) / alpha))
        w = w0 + alpha * t
        th = th0 + w0 * t + 0.5 * alpha * t * t
        if t < left:
            w = hi if alpha > 0.0 else lo
        return t, w, th
