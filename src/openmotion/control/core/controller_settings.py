"""Changing a running controller's settings: the period, the encoder decoding, an axis.

A mixin of `controller.Controller`: `set_period` (MCC_SetInterpolationTime),
`set_encoder_mode` (MCC_SetENCInputRate) and `reconfigure_axis` (MCCL
MCC_UpdateMachParam), each refused with nothing changed while something moves or a
period/config hook (registered in controller_hooks.py) refuses, and committed between two cycles.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

from ...config import ENCODER_MULTIPLIER, MachineConfig
from ...errors import MotionError
from ...units import MAX_PULSE_RATE
from .clock import RealtimePacer, check_period

if TYPE_CHECKING:
    from ...hw.interface import Hardware
    from .axis import Axis
    from .realtime import HandoverLock, RealtimeExecutor

#: AxisConfig fields `Controller.reconfigure_axis` changes on a running machine.
DECODER_FIELDS = ("encoder_mode", "swap_ab", "invert_a", "invert_b", "invert_z")
RECONFIGURABLE = ("pulses_per_rev", "lead", "gear_ratio", "reverse", "max_speed", "logic",
                  "pulse_mode", "pulse_width_us", "encoder_lines_per_rev", "move_ratio",
                  *DECODER_FIELDS)

class ControllerSettings:
    """Mixin of `Controller`: set_period, set_encoder_mode, reconfigure_axis."""

    config: MachineConfig
    hardware: Hardware
    period: float
    axes: tuple[Axis, ...]
    _lock: HandoverLock
    _time: float
    _n: int
    _t_origin: float
    _pacer: RealtimePacer | RealtimeExecutor
    _period_hooks: list[Any]
    _config_hooks: list[Any]
    _nc: list[set[str]]
    _emg_nc: bool

    def set_period(self, seconds: float) -> None:
        """Change the interpolation period (MCC_SetInterpolationTime, 1 ms .. 1 s) between
        two cycles: the cycle grid goes on from now in steps of the new period. Refused
        (MotionError, nothing changed) in real-time mode, while an axis moves (its motion
        was checked against the old period's per-period limits) or when a period hook
        refuses (a group with commands queued or running)."""
        p = check_period(seconds)
        with self._lock:
            if self.realtime:
                raise MotionError("period: cannot change while the real-time pacer runs")
            for a in self.axes:
                if a.is_moving:
                    raise MotionError(f"period: cannot change while axis {a.name} moves")
            hooks = list(self._period_hooks)
            for hook in hooks:
                hook(p, False)
            self.period = p
            self._t_origin = self._time - self._n * p
            self._pacer = RealtimePacer(self.step, p, self._overran)
            for hook in hooks:
                hook(p, True)

    def set_encoder_mode(self, axis: int | str, mode: str) -> None:
        """Change how an axis's A/B encoder input is decoded (x1, x2, x4: "ab_x1" ..
        "ab_x4") on a running machine (MCC_SetENCInputRate): `reconfigure_axis` of
        encoder_mode, limited to the A/B modes of an A/B input. The same encoder then
        gives new/old multiplier counts per command pulse: the move ratio (feedback
        counts per command pulse, the error counter's scale) follows."""
        ax = self.axis(axis)
        if not isinstance(mode, str) or mode not in ("ab_x1", "ab_x2", "ab_x4"):
            raise MotionError(f"mode must be 'ab_x1', 'ab_x2' or 'ab_x4', got {mode!r}")
        if not ax.config.encoder_mode.startswith("ab"):
            raise MotionError(f"axis {ax.name}: encoder_mode {ax.config.encoder_mode!r} is "
                              "not an A/B input")
        k = ENCODER_MULTIPLIER[mode] / ENCODER_MULTIPLIER[ax.config.encoder_mode]
        self.reconfigure_axis(ax.index, encoder_mode=mode,
                              move_ratio=ax.config.move_ratio * k)

    def reconfigure_axis(self, axis: int | str, **changes: Any) -> None:
        """Change an axis's settings on a running machine while it is at rest (MCCL
        MCC_UpdateMachParam after MCC_SetMachParam): the mechanism ratio (pulses_per_rev,
        lead, gear_ratio), reverse, max_speed, the signal logic (`logic`: how the board
        reads its inputs; the switches themselves stay as wired), the pulse output format
        and the encoder decoding (encoder_mode, swap_ab, invert_a/b/z: the hardware's
        `configure_decoder`). Counters keep their pulse values; what they mean in user
        units follows the new ratio. Refused (MotionError, nothing changed) for other
        fields, an invalid value, a moving axis, a config hook's refusal (a group with
        commands) or hardware that cannot change its decoder."""
        ax = self.axis(axis)
        bad = sorted(set(changes) - set(RECONFIGURABLE))
        if bad:
            raise MotionError(f"{', '.join(bad)}: not changeable on a running machine "
                              f"(changeable: {', '.join(RECONFIGURABLE)})")
        cfg = dataclasses.replace(ax.config, **changes)  # validated (__post_init__)
        decode = any(getattr(cfg, k) != getattr(ax.config, k) for k in DECODER_FIELDS)
        setter = getattr(self.hardware, "configure_decoder", None)
        if decode and setter is None:
            raise MotionError("this hardware cannot change its encoder decoding")
        with self._lock:
            if ax.is_moving:
                raise MotionError(f"axis {ax.name}: cannot be reconfigured while it moves")
            hooks = list(self._config_hooks)
            for hook in hooks:
                hook(ax.index, cfg, False)
            if decode:
                setter(ax.index, cfg)
            if cfg.move_ratio != ax.config.move_ratio:
                ax.counters.set_move_ratio(cfg.move_ratio)
            ax.config = cfg
            ax._max_speed = min(cfg.max_speed_pps, MAX_PULSE_RATE)
            axes = list(self.config.axes)
            axes[ax.index] = cfg
            self.config = dataclasses.replace(self.config, axes=tuple(axes))
            self._nc[ax.index] = {s for s in ("pel", "mel", "org", "sd", "ltc", "ez", "alm",
                                              "inp", "rdy") if cfg.signal_logic(s) == "nc"}
            self._emg_nc = any(a.signal_logic("emg") == "nc" for a in self.config.axes)
            for hook in hooks:
                hook(ax.index, cfg, True)
