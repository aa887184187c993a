"""Sampled position compensators and a following-error monitor.

Two compensators share one small protocol, `step(command, feedback) -> output` once per
sample and `reset()`, so the same class closes a loop on the HCTL-1100 emulation, on a sim
servo axis or on a real drive:

- `LeadFilter`: the HCTL-1100 first-order lead filter D(z) = K(z - A/256) / (4(z + B/256)),
  run as the chip's difference equation (AIM104 manual, appendix 2, eq. [5]):

      MC_n = (K/4) X_n - [(A/256)(K/4) X_{n-1} + (B/256) MC_{n-1}],   X = command - feedback

  Dividing the z-domain form by z gives MC(1 + (B/256) z^-1) = (K/4) X (1 - (A/256) z^-1),
  which is exactly that recursion. The chip keeps MC in an 8-bit register, so with
  `limit`/`quantize` set the stored MC_{n-1} is the saturated, truncated value it output.
- `PIDFF`: a textbook parallel PID with velocity and acceleration feed-forward taken from
  backward differences of the command, a clamped integrator (no wind-up at saturation) and
  a derivative on the feedback (no kick on command steps).

`FollowingErrorMonitor` latches a trip once |command - feedback| exceeds its limit; the
controller turns a trip into ErrorStop. The per-sample paths use plain floats only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from openmotion.errors import (
    MotionError,
    check_finite,
    check_flag,
    check_nonnegative,
    check_positive,
    is_real,
    show,
)


def _sample(name: str, x: float) -> float:
    """A sample value: floats pass as they are (NaN is a fault the caller handles)."""
    if type(x) is float:
        return x
    if is_real(x):
        try:
            return float(x)
        except OverflowError:
            raise MotionError(f"{name} must be finite, got {show(x)}") from None
    raise MotionError(f"{name} must be a real number, got {show(x)}")


class Compensator(Protocol):
    """A sampled compensator: one `step` per sample, `reset` clears its history."""

    def step(self, command: float, feedback: float) -> float: ...

    def reset(self) -> None: ...


def _check_byte(name: str, value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise MotionError(f"{name} must be an int in 0..255, got {value!r}")
    if not 0 <= value <= 255:
        raise MotionError(f"{name} must be in 0..255, got {value!r}")
    return value


class LeadFilter:
    """HCTL-1100 lead filter with zero A, pole B and gain K (each an 8-bit scalar, 0..255).

    `limit` (e.g. 127) saturates the output symmetrically, as the chip's 8-bit motor command
    does; `quantize` truncates the output toward zero to an integer, as the chip's integer
    arithmetic does (our model of it: see docs/hctl1100.md). Both default off, which gives
    the ideal linear filter.
    """

    __slots__ = ("_a", "_b", "_k", "_limit", "_quantize", "_x1", "_mc1")

    def __init__(self, a: int = 0xE5, b: int = 0x40, k: int = 0x40, *,
                 limit: float | None = None, quantize: bool = False) -> None:
        self._a = self._b = self._k = 0
        self.set_parameters(a, b, k)
        if limit is not None:
            limit = check_positive("limit", limit)
        self._limit = limit
        self._quantize = check_flag("quantize", quantize)
        self._x1 = 0.0
        self._mc1 = 0.0

    @property
    def a(self) -> int:
        return self._a

    @property
    def b(self) -> int:
        return self._b

    @property
    def k(self) -> int:
        return self._k

    def set_parameters(self, a: int, b: int, k: int) -> None:
        """Change A, B, K on the fly (the chip allows it); the history is kept."""
        a = _check_byte("a", a)
        b = _check_byte("b", b)
        k = _check_byte("k", k)
        self._a, self._b, self._k = a, b, k

    def reset(self) -> None:
        """Clear the sampled history (Init/Idle does this on the chip)."""
        self._x1 = 0.0
        self._mc1 = 0.0

    def step(self, command: float, feedback: float) -> float:
        """One sample with error X_n = command - feedback; returns MC_n."""
        return self.step_error(_sample("command", command) - _sample("feedback", feedback))

    def step_error(self, x: float) -> float:
        """One sample from the position error X_n directly."""
        g = self._k * 0.25
        mc = g * x - (self._a * (1.0 / 256.0) * g * self._x1 + self._b * (1.0 / 256.0)
                      * self._mc1)
        lim = self._limit
        if lim is not None:
            if mc > lim:
                mc = lim
            elif mc < -lim:
                mc = -lim
        if self._quantize:
            mc = float(math.trunc(mc))
        self._x1 = x
        self._mc1 = mc
        return mc

    def gain_at_dc(self) -> float:
        """Static gain D(1) = K(1 - A/256) / (4(1 + B/256)) (output per count of error)."""
        return self._k * (1.0 - self._a / 256.0) / (4.0 * (1.0 + self._b / 256.0))


class PIDFF:
    """Parallel PID with velocity/acceleration feed-forward, sampled at period `dt` (s).

    output = kp*e + ki*sum(e*dt) - kd*d(feedback)/dt + kvff*d(command)/dt
             + kaff*d2(command)/dt2, clamped to +-`output_limit`. The integral term is frozen
    while the output saturates in the direction that would grow it (conditional
    integration) and is itself kept within +-`integral_limit` (output units).
    """

    __slots__ = ("kp", "ki", "kd", "kvff", "kaff", "dt", "output_limit", "integral_limit",
                 "_i", "_c1", "_v1", "_f1", "_primed")

    def __init__(self, kp: float, ki: float = 0.0, kd: float = 0.0, *, dt: float,
                 kvff: float = 0.0, kaff: float = 0.0, output_limit: float = math.inf,
                 integral_limit: float = math.inf) -> None:
        self.kp = check_nonnegative("kp", kp)
        self.ki = check_nonnegative("ki", ki)
        self.kd = check_nonnegative("kd", kd)
        self.kvff = check_finite("kvff", kvff)
        self.kaff = check_finite("kaff", kaff)
        self.dt = check_positive("dt", dt)
        for name, val in (("output_limit", output_limit), ("integral_limit", integral_limit)):
            try:
                if not is_real(val):
                    raise TypeError
                v = float(val)
            except OverflowError:
                v = math.nan  # an int beyond the float range: refused below
            except (TypeError, ValueError):
                raise MotionError(f"{name} must be a real number > 0, got {show(val)}") from None
            if math.isnan(v) or v <= 0.0:
                raise MotionError(f"{name} must be > 0 (inf allowed), got {show(val)}")
            setattr(self, name, v)
        self._i = 0.0
        self._c1 = self._v1 = self._f1 = 0.0
        self._primed = False

    def reset(self) -> None:
        """Clear integrator and difference history."""
        self._i = 0.0
        self._c1 = self._v1 = self._f1 = 0.0
        self._primed = False

    def step(self, command: float, feedback: float) -> float:
        """One sample: returns the clamped output."""
        command, feedback = _sample("command", command), _sample("feedback", feedback)
        dt = self.dt
        if not self._primed:  # no history yet: zero derivatives instead of a kick
            self._c1, self._f1, self._v1 = command, feedback, 0.0
            self._primed = True
        e = command - feedback
        vcmd = (command - self._c1) / dt
        acmd = (vcmd - self._v1) / dt
        dfb = (feedback - self._f1) / dt
        self._c1, self._v1, self._f1 = command, vcmd, feedback
        base = self.kp * e - self.kd * dfb + self.kvff * vcmd + self.kaff * acmd
        lim = self.output_limit
        inc = self.ki * e * dt
        trial = self._i + inc
        il = self.integral_limit
        trial = min(il, max(-il, trial))
        out = base + trial
        # conditional integration: keep the old integral if the new one deepens saturation
        if (out > lim and inc > 0.0) or (out < -lim and inc < 0.0):
            trial = self._i
            out = base + trial
        self._i = trial
        return min(lim, max(-lim, out))


@dataclass(frozen=True)
class FollowingErrorResult:
    """Result of one check: `tripped` stays True (latched) until `reset()`."""

    tripped: bool
    error: float
    peak: float


class FollowingErrorMonitor:
    """Trips when |command - feedback| > `limit`; the trip latches until `reset()`."""

    __slots__ = ("limit", "_tripped", "_peak", "trip_error")

    def __init__(self, limit: float) -> None:
        self.limit = check_positive("limit", limit)
        self._tripped = False
        self._peak = 0.0
        self.trip_error: float | None = None

    @property
    def tripped(self) -> bool:
        return self._tripped

    def check(self, command: float, feedback: float) -> FollowingErrorResult:
        """Compare one sample; returns the (latched) trip state, the error and its peak."""
        e = _sample("command", command) - _sample("feedback", feedback)
        if e != e:  # NaN feedback or command is itself a fault
            self._tripped = True
            self.trip_error = e
            return FollowingErrorResult(True, e, self._peak)
        ae = abs(e)
        if ae > self._peak:
            self._peak = ae
        if ae > self.limit and not self._tripped:
            self._tripped = True
            self.trip_error = e
        return FollowingErrorResult(self._tripped, e, self._peak)

    def reset(self) -> None:
        """Clear the trip and the peak (the controller's fault reset)."""
        self._tripped = False
        self._peak = 0.0
        self.trip_error = None
