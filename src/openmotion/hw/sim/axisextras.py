"""SimMachine's per-axis extras (a mixin of SimMachine): the effort output of a dc_servo
axis (hw.interface.EffortHardware), armed edge stops (EdgeStopHardware), the readouts tests
and tools use (lost steps, motor/load/command position), the pulse rule, the pulse record
and the board's encoder decoding.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from openmotion.config import AxisConfig
from openmotion.errors import MotionError
from openmotion.hw.interface import AXIS_INPUTS

from .encoder import Decoder, EncoderWiring
from .plant import StepperPlant
from .pulserecord import PulseRecord, check_capacity

if TYPE_CHECKING:
    from . import kernel
    from .simaxis import SimAxis


class SimAxisExtras:
    """Mixin of SimMachine: per-axis extras (the state is SimMachine's)."""

    _t: float
    _ax: list[SimAxis]
    _ks: kernel.KernelState | None
    _stale: bool
    _emg_armed: bool | None

    if TYPE_CHECKING:
        @property
        def _axes(self) -> list[SimAxis]: ...
        def _axis(self, axis: int) -> SimAxis: ...
        def _view(self, axis: int) -> SimAxis: ...
        def _index(self, axis: int) -> int: ...

    def command_effort(self, axis: int, t0: float, value: float) -> None:
        """Motor effort (PWM duty in [-1, 1], clamped) of a dc_servo axis, held from t0 (>=
        the current time) until the next call (hw.interface.EffortHardware)."""
        ax = self._axis(axis)
        if not ax.is_dc:
            raise MotionError(f"axis {axis} has no effort output (drive type "
                              f"{ax.cfg.drive.type!r}, needs 'dc_servo')")
        ax.plant.set_effort(self._t, t0, value)

    def arm_stop(self, axis: int | None, signal: str, level: bool | None,
                 direction: int = 0) -> None:
        """Cut the pulse output at the exact time `signal` goes to electrical `level`
        (hw.interface.EdgeStopHardware); `level` None disarms."""
        if level is not None and not isinstance(level, bool):
            raise MotionError(f"level must be a bool or None, got {level!r}")
        if direction not in (-1, 0, 1) or isinstance(direction, bool):
            raise MotionError(f"direction must be -1, 0 or 1, got {direction!r}")
        if axis is None:
            if signal != "emg":
                raise MotionError(f"signal must be 'emg' for axis None, got {signal!r}")
            self._emg_armed = level
            return
        ax = self._axis(axis)
        if signal not in AXIS_INPUTS:
            raise MotionError(f"signal must be one of {AXIS_INPUTS}, got {signal!r}")
        if level is None:
            ax.armed.pop(signal, None)
        else:
            ax.armed[signal] = (level, direction)

    def stop_time(self, axis: int) -> float | None:
        """When an armed stop cut the pulses of `axis` in the last advance, else None."""
        if self._stale:  # the kernel ran last: its arrays hold the stop times
            assert self._ks is not None
            return self._ks.stop_time(self._index(axis))
        return self._view(axis).stop_time

    def steps_lost(self, axis: int) -> int:
        """Pulses the stepper of `axis` has lost (stalls + injected losses); 0 for a servo."""
        p = self._view(axis).plant
        return p.lost if isinstance(p, StepperPlant) else 0

    def motor_position(self, axis: int) -> float:
        """Motor position (command pulses) at the current time."""
        ax = self._view(axis)
        return ax.plant.motor(ax.gen)

    def load_position(self, axis: int) -> float:
        """Position seen by encoder and switches (after backlash and pitch error)."""
        return self._view(axis).y

    def command_position(self, axis: int) -> float:
        """Commanded (float) position at the current time."""
        return self._view(axis).gen.pos(self._t)

    @property
    def half_pulse(self) -> bool:
        """True (the default) when the generators count by the half-pulse rule (see
        `set_half_pulse`); the control layer reads it (control.home.pulserule) to rebuild counts
        at edge times the same way."""
        return self._ax[0].gen.half == 0.5 if self._ax else True

    def set_half_pulse(self, on: bool = True) -> None:
        """Pulse rule of every axis's generator from now on.

        On (the default): pulse k leaves when the command reaches k - 1/2 going up (k + 1/2
        going down, Klipper's step_dist/2), so the count is the command rounded to nearest,
        within half a pulse of the ideal path (issue 4's quantization bound); a switch
        crossed by pulse k trips when the command is at k -/+ 1/2.
        Off: pulse k leaves when the command reaches k itself (floor going up, ceil going
        down), so a count lags the command by up to one pulse. Use it to model a generator
        that truncates (a DDA that only carries whole pulses, or a card compared against
        one), or to reproduce results recorded with the earlier default.
        Set it at standstill; counts already emitted are not changed.
        """
        if not isinstance(on, bool):
            raise MotionError(f"on must be a bool, got {on!r}")
        for ax in self._axes:
            ax.gen.half = 0.5 if on else 0.0

    def record_pulses(self, on: bool = True, capacity: int = 1_000_000) -> None:
        """Start recording every pulse and command of every axis from now on (a fresh
        record), or stop (on=False, the record is dropped). `capacity` bounds each axis's
        record (monotone stretches and commands, a few per cycle); a full record stops."""
        if not isinstance(on, bool):
            raise MotionError(f"on must be a bool, got {on!r}")
        cap = check_capacity(capacity)
        for ax in self._axes:
            g = ax.gen
            g.record = PulseRecord(g.count, cap, self._t, g.cubic, g.tc, g.te) if on else None

    def pulse_record(self, axis: int) -> PulseRecord:
        """What `axis` emitted since `record_pulses()`: `pulses()` gives every pulse's exact
        time and the count after it, `command_at(times)` the commanded position.
        MotionError if not recording or if the record filled its capacity."""
        rec = self._view(axis).gen.record
        if rec is None:
            raise MotionError("pulse_record needs record_pulses() first")
        if not rec.complete:
            raise MotionError(f"axis {axis}: the pulse record filled its capacity "
                              f"{rec.capacity}; record a shorter run or raise capacity")
        return rec

    def configure_decoder(self, axis: int, cfg: AxisConfig) -> None:
        """The board's decoding of an axis's encoder input from now on, as `cfg` sets it
        (encoder_mode x1/x2/x4 or another signal mode, swap_ab, invert_a/b/z: HSL
        pls_iptmode, MCCL MCC_SetENCInputRate / stEncoder): the encoder itself (its
        wiring and resolution) stays, the count keeps its value and goes on as the new
        settings decode it (a setting that differs from the wiring misreads it)."""
        ax = self._axis(axis)
        if not isinstance(cfg, AxisConfig):
            raise MotionError(f"cfg must be an AxisConfig, got {type(cfg).__name__}")
        old = ax.decoder
        wiring = EncoderWiring(old.kind, old.upp, old.swap != ax.cfg.swap_ab,
                               old.flip_a != ax.cfg.invert_a, old.flip_b != ax.cfg.invert_b,
                               ax.z_flip != ax.cfg.invert_z)
        new = Decoder(wiring, cfg, ax.y)
        new.q, new.last_dir, new.count = old.q, old.last_dir, old.count
        ax.decoder, ax.z_flip = new, wiring.invert_z != cfg.invert_z
        ax.cfg = dataclasses.replace(ax.cfg, encoder_mode=cfg.encoder_mode,
                                     swap_ab=cfg.swap_ab, invert_a=cfg.invert_a,
                                     invert_b=cfg.invert_b, invert_z=cfg.invert_z)
        ax.run_start = (ax.run_start[0], ax._dec_state())
