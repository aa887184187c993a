"""A position loop closed in the control layer, for axes whose motor takes an effort (duty)
rather than pulses: the "dc_servo" drive of the simulator, or a real PWM / torque output.

Each loop sample (a controller sample hook, `LoopConfig.samples_per_cycle` per cycle):

    command  = planned position at the sample time (the axis's Profile) x move_ratio + bias
    feedback = encoder count read from the hardware at that time
    output   = compensator.step(command, feedback)      (lead filter or PID+FF)
    duty     = output / full_scale -> hardware.command_effort(axis, t, duty), held a sample

Counts everywhere: the filter gains are per encoder count, as on the HCTL-1100. The lead
filter works like the chip's: an 8-bit MC (+-127, integer arithmetic) and duty
min(|MC|, 100)/100 (100-part PWM); PID+FF outputs duty directly (clamped to +-1).

The command and pulse counters keep their meaning (planned position) and the feedback
counter is the encoder. When the loop closes (servo on, or after a fault reset) `bias` is
set so that the error is zero at that instant: the motor holds where it is instead of
jumping (a drive's deviation counter cleared at servo-on). The loop is off (duty 0) while
the axis is unpowered. A following error beyond the limit turns the loop off (amplifier
duty 0), and sends the axis to ErrorStop "following error"; motion is refused until
`reset()`, after which the loop closes again on the current position.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...config import LoopConfig
from ...errors import MotionError, check_finite
from ...hw.interface import EffortHardware
from ..core.states import AxisState
from .servo import PIDFF, Compensator, FollowingErrorMonitor, LeadFilter

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller

#: Fault reason given to Axis.fault_stop on a following-error trip.
FOLLOWING_ERROR = "following error"
#: The chip's motor command saturates at 8 bits; the PWM has 100 parts.
LEAD_MC_LIMIT = 127.0
LEAD_FULL_SCALE = 100.0
#: Largest step `inject_step` accepts (counts).
MAX_STEP = 1e6


def make_compensator(loop: LoopConfig, sample_period: float) -> tuple[Compensator, float]:
    """(compensator, full-scale output) for a LoopConfig sampled every `sample_period` s."""
    if not isinstance(loop, LoopConfig):
        raise MotionError(f"loop must be a LoopConfig, got {type(loop).__name__}")
    if loop.compensator == "lead":
        return LeadFilter(loop.a, loop.b, loop.k, limit=LEAD_MC_LIMIT, quantize=True), \
            LEAD_FULL_SCALE
    return PIDFF(loop.kp, loop.ki, loop.kd, dt=sample_period, kvff=loop.kvff,
                 kaff=loop.kaff, output_limit=1.0, integral_limit=1.0), 1.0


class ServoLoop:
    """The closed loop of one axis; attaches itself to the controller as a sample hook.

    `loop` defaults to the axis's AxisConfig.loop. The hardware must implement
    hw.interface.EffortHardware for that axis (checked here with a zero effort).
    """

    def __init__(self, controller: Controller, axis: int | str,
                 loop: LoopConfig | None = None) -> None:
        ax = controller.axis(axis)
        cfg = ax.config.loop if loop is None else loop
        if cfg is None:
            raise MotionError(f"axis {ax.name}: no loop configured (AxisConfig.loop)")
        hw = controller.hardware
        if not isinstance(hw, EffortHardware):
            raise MotionError(f"axis {ax.name}: the hardware has no effort outputs "
                              "(hw.interface.EffortHardware) for a servo loop")
        hw.command_effort(ax.index, hw.time, 0.0)  # MotionError if the axis has none
        self.config = cfg
        self.axis: Axis = ax
        self.sample_period = controller.period / cfg.samples_per_cycle
        self.compensator, self.full_scale = make_compensator(cfg, self.sample_period)
        fe = cfg.following_error
        self.monitor = FollowingErrorMonitor(fe) if math.isfinite(fe) else None
        self.ratio = ax.config.move_ratio  # encoder counts per command pulse (mechanism)
        self.bias = 0.0
        self.closed = False       # loop running (axis powered, no following-error trip)
        self.tripped = False
        self.error = 0.0          # last command - feedback (counts)
        self.peak_error = 0.0     # largest |error| since the loop last closed
        self.duty = 0.0
        self._trace: list[tuple[float, float, float, float]] | None = None
        self._hw = hw
        self._ctl = controller
        controller.add_sample_hook(self._sample, cfg.samples_per_cycle)

    def detach(self) -> None:
        """Stop sampling (the effort output is set to 0)."""
        self._ctl.remove_sample_hook(self._sample)
        self._hw.command_effort(self.axis.index, self._hw.time, 0.0)
        self.closed = False

    def inject_step(self, counts: float) -> None:
        """Tuning aid: add a step of `counts` to the loop's set-point (its bias), as a servo
        tuning tool's step test does. The axis's command counter does not change; inject
        the opposite step to undo it. The loop must be closed (axis enabled, no trip)."""
        c = check_finite("counts", counts)
        if abs(c) > MAX_STEP:
            raise MotionError(f"counts must be within +-{MAX_STEP:g}, got {counts!r}")
        if not self.closed:
            raise MotionError(f"axis {self.axis.name}: the loop is open (axis disabled, not "
                              "yet sampled or tripped); a step needs a closed loop")
        self.bias += c

    def retune(self, loop: LoopConfig) -> None:
        """Tuning: run the loop with `loop`'s gains and following-error limit from the next
        sample (the compensator starts from rest; the set-point and its bias are kept).
        The sample rate is fixed while the loop runs: samples_per_cycle must not change."""
        if not isinstance(loop, LoopConfig):
            raise MotionError(f"loop must be a LoopConfig, got {type(loop).__name__}")
        if loop.samples_per_cycle != self.config.samples_per_cycle:
            raise MotionError(f"samples_per_cycle must stay {self.config.samples_per_cycle} "
                              f"on a running loop, got {loop.samples_per_cycle}")
        comp, full = make_compensator(loop, self.sample_period)
        fe = loop.following_error
        self.compensator, self.full_scale = comp, full
        self.monitor = FollowingErrorMonitor(fe) if math.isfinite(fe) else None
        self.config = loop

    # ------------------------------------------------------------------ tracing
    def start_trace(self) -> None:
        """Record every sample from now: time, command, feedback (counts), duty."""
        self._trace = []

    def stop_trace(self) -> None:
        """Stop recording (what was recorded is dropped: read `trace()` first)."""
        self._trace = None

    def trace(self) -> dict[str, np.ndarray]:
        """The recorded samples as arrays t, command, feedback, duty (empty if none)."""
        rows = np.array(self._trace or [], dtype=float).reshape(-1, 4)
        return {"t": rows[:, 0], "command": rows[:, 1], "feedback": rows[:, 2],
                "duty": rows[:, 3]}

    # ------------------------------------------------------------------ the sample
    def _command_counts(self, t: float) -> float:
        ax = self.axis
        m = ax.motion
        p = ax.raw_position if m is None else m.state(t)[0]  # raw pulse frame, like the encoder
        return p * self.ratio

    def _open(self, t: float) -> None:
        if self.closed:
            self.closed = False
            self.duty = 0.0
            self._hw.command_effort(self.axis.index, t, 0.0)

    def _sample(self, ctl: Controller, t: float) -> None:
        ax = self.axis
        if self.tripped and ax.state is not AxisState.ERROR_STOP:
            self.tripped = False  # the fault was reset: close again on the current position
        if not ax.powered or self.tripped:  # SVON off, or after a following-error trip
            self._open(t)
            return
        fb = float(self._hw.read_axis(ax.index).encoder)
        cmd = self._command_counts(t)
        if not self.closed:
            self.bias = fb - cmd
            self.compensator.reset()
            if self.monitor is not None:
                self.monitor.reset()
            self.peak_error = 0.0
            self.closed = True
        c = cmd + self.bias
        e = c - fb
        self.error = e
        if abs(e) > self.peak_error:
            self.peak_error = abs(e)
        if self.monitor is not None and self.monitor.check(c, fb).tripped:
            self.tripped = True
            self._open(t)
            if self._trace is not None:
                self._trace.append((t, c, fb, 0.0))
            ax.fault_stop(FOLLOWING_ERROR)
            return
        out = self.compensator.step(c, fb)
        duty = max(-1.0, min(1.0, out / self.full_scale))
        self.duty = duty
        self._hw.command_effort(ax.index, t, duty)
        if self._trace is not None:
            self._trace.append((t, c, fb, duty))


def attach_servo_loops(controller: Controller) -> dict[str, ServoLoop]:
    """A ServoLoop for every axis that has a loop configured (dc_servo axes always do)."""
    return {ax.name: ServoLoop(controller, ax.index) for ax in controller.axes
            if ax.config.loop is not None}
