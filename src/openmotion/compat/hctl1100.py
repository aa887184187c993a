"""HCTL-1100 motion control chip emulation, run in virtual time sample by sample.

Register reads/writes follow the AIM104-MOTION-1 manual appendices 1-2 (and seed-facts
section 3 where the manual is silent); docs/hctl1100.md lists what is modelled and what is
simplified. The chip drives a plant with `counts` (quadrature counts) and
`advance(dt, duty)` (duty in [-1, 1]), e.g. `openmotion.hw.sim.dcmotor.DCMotor`.

Per sample (at the sample boundary): latch LIMIT/STOP, read the encoder, run the mode's
generator and filter, write the motor command to R09H; the PWM duty min(|MC|, 100)/100 is
then held over the whole sample while the plant moves.

Python-API errors (MotionError, nothing changed): unknown register addresses, values
outside 0..255, a 7-bit register written above 7FH, a sample timer below the current
mode's minimum, entering a mode whose minimum the sample timer does not meet, two control
flags at once, an integral velocity step above 127. Writes the chip itself ignores (preset
outside Init/Idle, command data during a profile, PC 02H/03H outside Init/Idle, F1) are
ignored and counted in `ignored_writes`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from openmotion.control.loops.servo import LeadFilter
from openmotion.errors import MotionError, check_nonnegative, check_positive

from . import hctl1100_regs as R
from .hctl1100_commutator import PHASE_A, PHASE_D, commutator_mask, phase_advance
from .hctl1100_io import _CONTROL_FLAGS, RegisterAccess, _duty
from .hctl1100_profile import IntegralVelocity, trapezoid_commands
from .hctl1100_regs import Mode


class Plant(Protocol):
    """What the chip drives: an encoder count and a duty-driven motion."""

    @property
    def counts(self) -> int: ...

    def advance(self, dt: float, duty: float) -> None: ...


@dataclass(frozen=True)
class ChipEvent:
    """A chip status change: 'limit', 'stop', 'profile_start', 'profile_done'."""

    time: float
    kind: str


@dataclass(frozen=True)
class Trace:
    """Per-sample record: boundary time (s), command/actual position (counts), MC."""

    t: np.ndarray
    command: np.ndarray
    actual: np.ndarray
    mc: np.ndarray


class HCTL1100(RegisterAccess):
    """One chip with its plant. `advance(dt)` / `run_samples(n)` move virtual time."""

    def __init__(self, plant: Plant, *, clock_hz: float = R.CLOCK_HZ) -> None:
        if not (hasattr(plant, "counts") and callable(getattr(plant, "advance", None))):
            raise MotionError("plant must have `counts` and `advance(dt, duty)`")
        self.plant = plant
        self.clock_hz = check_positive("clock_hz", clock_hz)
        self.time = 0.0
        self.listeners: list[Callable[[ChipEvent], None]] = []
        self.limit_pin = False   # True = LIMIT input active (pin low)
        self.stop_pin = False
        self.ignored_writes = 0
        self._filter = LeadFilter(limit=127.0, quantize=True)
        self._into = 0.0
        self._soft_reset(hard=True)

    # ------------------------------------------------------------------ reset / modes
    def _soft_reset(self, hard: bool = False) -> None:
        if hard:
            self._flags = 0
        self._pos_offset = -self.plant.counts  # actual position counters set to 0
        self._filter.set_parameters(R.DEFAULT_A, R.DEFAULT_B, R.DEFAULT_K)
        self._t_reg = R.DEFAULT_SAMPLE_TIMER
        self._t_buffer = R.DEFAULT_SAMPLE_TIMER
        self._period = R.sample_time(self._t_reg, self.clock_hz)
        self._status_low = 0
        self._limit_latched = False
        self._stop_latched = False
        self._cmd = 0
        self._cmd_buf = [0, 0]
        self._preset_buf = [0, 0]
        self._final = 0
        self._accel = 0
        self._vmax = 0
        self._prop_vel = 0
        self._int_vel = 0
        self._act_vel = 0
        self._act_latch = (0, 0)
        self._last_actual = 0
        self._prev_actual = 0
        self._rotor_rate = 0.0  # quadrature counts/s over the last sample (phase advance)
        self._ring_origin = self.plant.counts  # commutator logic cleared
        self._ring_hold = 0
        self._comm = {R.R_COMM_RING: 0, R.R_COMM_VEL_TIMER: 0, R.R_COMM_X: 0, R.R_COMM_Y: 0,
                      R.R_COMM_OFFSET: 0, R.R_COMM_ADVANCE: 0}
        self._enter_idle()

    def _enter_idle(self) -> None:
        self.mode = Mode.INIT_IDLE
        self._mc = 0
        self._duty = 0.0
        self._filter.reset()
        self._traj: np.ndarray | None = None
        self._traj_k = 0
        self._iv: IntegralVelocity | None = None
        self._align_k = 0
        self._flags &= ~(1 << R.F0)

    def _enter_control(self) -> None:
        mode = Mode.POSITION
        for f, m in _CONTROL_FLAGS.items():
            if self._flags & (1 << f):
                mode = m
        self._require_timer(mode, self._t_buffer)
        self._filter.reset()
        if mode is Mode.TRAPEZOID:
            self._start_profile()
        elif mode is Mode.INTEGRAL_VELOCITY:
            self._iv = IntegralVelocity(self._cmd)
        self._prev_actual = self.actual_position
        self.mode = mode

    def _require_timer(self, mode: Mode, t_reg: int) -> None:
        lo = R.MIN_SAMPLE_TIMER[mode]
        if t_reg < lo:
            raise MotionError(f"sample timer {t_reg:#04x} is below the {mode.value} minimum "
                              f"{lo:#04x}")

    def _start_profile(self) -> None:
        dist = R.wrap24(self._final - self._cmd)
        acc = self._accel / 256.0
        if dist != 0 and (acc <= 0.0 or self._vmax <= 0):
            raise MotionError("a trapezoidal move needs acceleration (R26H/R27H) > 0 and "
                              "maximum velocity (R28H) > 0")
        self._traj = trapezoid_commands(self._cmd, dist, acc, float(self._vmax))
        self._traj_k = 0
        self.mode = Mode.TRAPEZOID
        self._emit("profile_start")

    # ------------------------------------------------------------------ positions
    @property
    def actual_position(self) -> int:
        """24-bit two's-complement actual position (quadrature counts)."""
        return R.wrap24(self.plant.counts + self._pos_offset)

    @property
    def command_position(self) -> int:
        return R.wrap24(self._cmd)

    @property
    def sample_period(self) -> float:
        """The sample time now in use, in seconds."""
        return self._period

    @property
    def flags(self) -> int:
        f = self._flags & ~(1 << R.F1)
        return f | ((1 << R.F1) if self.mode is Mode.INIT_IDLE else 0)

    @property
    def motor_command(self) -> int:
        """The signed 8-bit motor command now output (R09H as a signed value)."""
        return self._mc

    @property
    def limit_latched(self) -> bool:
        return self._limit_latched

    @property
    def stop_latched(self) -> bool:
        return self._stop_latched

    # ------------------------------------------------------------------ inputs
    def set_limit(self, active: bool) -> None:
        """Drive the LIMIT input; going active enters Init/Idle at once (and latches)."""
        active = bool(active)
        if active and not self.limit_pin:
            self._limit_latched = True
            self._enter_idle()
            self._emit("limit")
        self.limit_pin = active

    def set_stop(self, active: bool) -> None:
        """Drive the STOP input (acts in integral velocity mode only; always latches)."""
        active = bool(active)
        if active and not self.stop_pin:
            self._stop_latched = True
            self._emit("stop")
        self.stop_pin = active

    def sync(self) -> None:
        """SYNC pulse: restart the sample timer now (a new sample begins at this instant)."""
        self._into = 0.0
        self._sample()

    def _emit(self, kind: str) -> None:
        ev = ChipEvent(self.time, kind)
        for cb in self.listeners:
            cb(ev)

    # ------------------------------------------------------------------ virtual time
    def advance(self, dt: float) -> None:
        """Move virtual time by `dt` seconds, running every sample that falls due."""
        left = check_nonnegative("dt", dt)
        plant = self.plant
        while left > 0.0:
            to_next = self._period - self._into
            if left + 1e-15 >= to_next:
                plant.advance(to_next, self._duty)
                self.time += to_next
                left -= to_next
                self._into = 0.0
                self._sample()
            else:
                plant.advance(left, self._duty)
                self.time += left
                self._into += left
                left = 0.0

    def run_samples(self, n: int, *, record: bool = False) -> Trace | None:
        """Run `n` whole samples from the next boundary; optionally record each one."""
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise MotionError(f"n must be an int >= 0, got {n!r}")
        if not record:
            for _ in range(n):
                self.advance(self._period - self._into)
            return None
        t = np.empty(n)
        cmd = np.empty(n, dtype=np.int64)
        act = np.empty(n, dtype=np.int64)
        mc = np.empty(n, dtype=np.int64)
        for i in range(n):
            self.advance(self._period - self._into)
            t[i] = self.time
            cmd[i] = self._cmd
            act[i] = self._last_actual
            mc[i] = self._mc
        return Trace(t, cmd, act, mc)

    def _sample(self) -> None:
        """The chip's work at one sample boundary."""
        elapsed = self._period
        self._t_reg = self._t_buffer
        self._period = R.sample_time(self._t_reg, self.clock_hz)
        actual = self.actual_position
        self._rotor_rate = R.wrap24(actual - self._last_actual) / elapsed
        self._last_actual = actual
        mode = self.mode
        if mode is Mode.INIT_IDLE:
            return  # R09H (written by the user) drives the motor open loop
        if mode is Mode.ALIGN:
            self._align_step()
            return
        if mode is Mode.PROP_VELOCITY:
            vact = R.wrap24(actual - self._prev_actual)
            self._prev_actual = actual
            self._act_vel = vact
            k4 = self._filter.k * 0.25
            mc = int(k4 * (self._prop_vel / 16.0 - vact))
            self._set_mc(mc)
            return
        if mode is Mode.TRAPEZOID:
            traj = self._traj
            self._cmd = R.wrap24(int(traj[self._traj_k]))
            self._traj_k += 1
            if self._traj_k >= traj.size:
                self._flags &= ~(1 << R.F0)
                self._traj = None
                self.mode = Mode.POSITION
                self._emit("profile_done")
        elif mode is Mode.INTEGRAL_VELOCITY:
            target = 0.0 if self._stop_latched else float(self._int_vel)
            self._cmd = R.wrap24(self._iv.step(target, self._accel / 256.0))
        err = R.wrap24(self._cmd - actual)
        self._set_mc(int(self._filter.step_error(float(err))))

    def _set_mc(self, mc: int) -> None:
        mc = 127 if mc > 127 else (-128 if mc < -128 else mc)
        self._mc = mc
        self._duty = _duty(mc)

    def _align_step(self) -> None:
        # PHA for 2048 samples, then PHD for 2048, then position control at 0 [seed, app. 1]
        self._align_k += 1
        self._mc = 100
        self._duty = 1.0
        if self._align_k >= 2 * R.ALIGN_SAMPLES:
            self._flags &= ~(1 << R.F4)
            self._ring_origin = self.plant.counts  # rotor on the PHD detent: ring position 0
            self._pos_offset = -self.plant.counts  # [low] actual position cleared too
            self._cmd = 0
            self._filter.reset()
            self._set_mc(0)
            self.mode = Mode.POSITION

    def commutator_output(self, rotor_counts: int, sign: int) -> int:
        """Phases on (bit mask A=1, B=2, C=4, D=8) for the rotor at `rotor_counts` (plant
        counts) and motor command sign `sign`; the board turns them into winding currents."""
        if self.mode is Mode.ALIGN:
            return PHASE_A if self._align_k < R.ALIGN_SAMPLES else PHASE_D
        frozen = self._flags & (1 << R.F4)
        pos = self._ring_hold if frozen else rotor_counts - self._ring_origin
        if self._status_low & R.ST_FULL_COUNTS:
            pos //= 4
        c = self._comm
        return commutator_mask(pos, c[R.R_COMM_RING], c[R.R_COMM_X], c[R.R_COMM_Y],
                               R.signed8(c[R.R_COMM_OFFSET]), sign,
                               0 if frozen else self.commutator_advance)

    @property
    def commutator_advance(self) -> int:
        """Phase advance now in effect (commutator counts, signed like the rotor speed):
        the rotor speed measured over the last sample, in full counts/s, through
        `phase_advance` with R19H and R1FH."""
        c = self._comm
        return phase_advance(self._rotor_rate / 4.0, c[R.R_COMM_VEL_TIMER],
                             c[R.R_COMM_ADVANCE], self.clock_hz)

    @property
    def align_phase(self) -> str | None:
        """'A' or 'D' while align energises that phase, else None."""
        if self.mode is not Mode.ALIGN:
            return None
        return "A" if self._align_k < R.ALIGN_SAMPLES else "D"
