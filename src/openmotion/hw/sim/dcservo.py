"""dc_servo drive: a DC motor on a PWM amplifier, driven by a motor effort (duty) that the
control layer's servo loop sets each sample (`SimMachine.command_effort`).

The pulse generator still follows the commanded cubic (the command counter = the planned
position), but the motor ignores it: it moves only under the duty held since the last
effort command. The DCMotor plant (dcmotor.py) is exact for a held duty, so motion between
effort changes is closed form. With the duty held, w' = g(w) is an autonomous scalar ODE,
so w is monotone over the interval: the motor reverses at most once, at the zero of w,
found by bisection on the exact solution; the position pieces either side are monotone.

Motor position in command pulses = theta * pulses_per_rev / 2pi; the board's decoder then
counts move_ratio counts per pulse (4 x lines per rev for a consistent config). The
amplifier is on while SVON is on and there is no alarm; off, the duty is 0 (the winding is
shorted through the bridge: dynamic braking; an assumption of this model).
"""

from __future__ import annotations

import copy

from openmotion.config import AxisConfig
from openmotion.errors import MotionError, check_finite

from .dcmotor import TWO_PI, DCMotor, DCMotorParams
from .pieces import Piece, SmoothPiece
from .pulses import PulseGenerator

#: Reversal time search stops below this width (s).
_T_TOL = 1e-12


def motor_params(cfg: AxisConfig) -> DCMotorParams:
    """DCMotorParams of a dc_servo axis from its DriveConfig.motor (ke 0 -> kt)."""
    m = cfg.drive.motor
    return DCMotorParams(supply_v=m.supply_v, resistance=m.resistance, kt=m.kt,
                         ke=m.ke if m.ke > 0.0 else None, inertia=m.inertia,
                         viscous=m.viscous, current_limit=m.current_limit,
                         load_torque=m.load_torque, encoder_lines=cfg.encoder_lines_per_rev)


class DCServoPlant:
    """Motor + amplifier of one dc_servo axis."""

    __slots__ = ("dc", "scale", "svon", "enabled", "duty", "_changes", "lost")

    def __init__(self, cfg: AxisConfig) -> None:
        self.dc = DCMotor(motor_params(cfg))
        self.scale = cfg.pulses_per_rev / TWO_PI  # command pulses per radian
        self.svon = False
        self.enabled = True   # False while an alarm is active
        self.duty = 0.0       # effort in force now (as commanded; gated by svon/enabled)
        self._changes: list[tuple[float, float]] = []  # future (time, duty), time-ordered
        self.lost = 0         # no steps to lose; kept for the scenario's step-loss action

    @property
    def powered(self) -> bool:
        return self.svon and self.enabled

    def motor(self, gen: PulseGenerator) -> float:
        """Motor position in command pulses."""
        return self.dc.theta * self.scale

    def set_effort(self, now: float, t0: float, duty: float) -> None:
        """Hold `duty` (clamped to [-1, 1]) from t0; later pending changes are dropped."""
        t0 = check_finite("t0", t0)
        duty = check_finite("value", duty)
        if t0 < now - 1e-12:
            raise MotionError(f"t0 must be >= the hardware time {now!r}, got {t0!r}")
        duty = max(-1.0, min(1.0, float(duty)))
        self._changes = [c for c in self._changes if c[0] < t0]
        if t0 <= now:
            self._changes = []
            self.duty = duty
        else:
            self._changes.append((t0, duty))

    def pieces(self, gen: PulseGenerator, ta: float, tb: float) -> list[Piece]:
        """Monotone motor pieces over [ta, tb]; advances the motor and the pulse count."""
        gen.stretches(ta, tb)  # the pulse output follows the command whatever the motor does
        out: list[Piece] = []
        t = ta
        while True:
            ch = self._changes
            while ch and ch[0][0] <= t:
                self.duty = ch.pop(0)[1]
            if t >= tb:
                break
            t_next = min(tb, ch[0][0]) if ch else tb
            self._run(t, t_next, out)
            t = t_next
        return out

    def _run(self, t0: float, t1: float, out: list[Piece]) -> None:
        duty = self.duty if self.powered else 0.0
        start = self.dc
        if start.omega == 0.0 and duty == 0.0 and start.params.load_torque == 0.0:
            return  # at rest with no torque: stays at rest
        scale = self.scale

        def state(t: float) -> DCMotor:
            m = copy.copy(start)
            m.advance(t - t0, duty)
            return m

        def f(t: float) -> float:
            return state(t).theta * scale

        def df(t: float) -> float:
            return state(t).omega * scale

        end = state(t1)
        cuts = [t0, t1]
        w0, w1 = start.omega, end.omega
        if (w0 > 0.0 and w1 < 0.0) or (w0 < 0.0 and w1 > 0.0):
            lo, hi = t0, t1
            for _ in range(100):  # w is monotone: one sign change, bisect it
                if hi - lo <= _T_TOL:
                    break
                mid = 0.5 * (lo + hi)
                if (state(mid).omega > 0.0) == (w0 > 0.0):
                    lo = mid
                else:
                    hi = mid
            cuts = [t0, hi, t1]
        m_prev = start.theta * scale
        for i in range(len(cuts) - 1):
            a, b = cuts[i], cuts[i + 1]
            m_b = end.theta * scale if i == len(cuts) - 2 else f(b)
            if b > a and m_b != m_prev:
                out.append(SmoothPiece(f, df, a, b, 1 if m_b > m_prev else -1, m_prev, m_b))
            m_prev = m_b
        self.dc = end

