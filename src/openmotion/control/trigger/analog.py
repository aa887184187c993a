"""Analog outputs of the board (M67/M68, a laser power or a pump speed set from a program),
and its analog inputs (M66 E: `AnalogInputs`, hw.interface.AnalogInputHardware).

`AnalogOutputs(ctl)` is the control layer's view of the back end's analog outputs
(hw.interface.AnalogOutputHardware): it validates in the user's terms (channel number,
value within the board's range) before anything is written, and keeps the time of every
write. A back end without analog outputs has none (`count` 0): every `set` is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import MotionError
from ...hw.interface import AnalogInputHardware, AnalogOutputHardware

if TYPE_CHECKING:
    from ..core.controller import Controller


@dataclass(frozen=True)
class AnalogWrite:
    """One write: controller time, channel, value."""

    t: float
    channel: int
    value: float


class AnalogOutputs:
    """Set and read the analog outputs `ao<n>` of a controller's hardware."""

    def __init__(self, ctl: Controller) -> None:
        self._ctl = ctl
        hw = ctl.hardware
        self._hw = hw if isinstance(hw, AnalogOutputHardware) else None
        self.writes: list[AnalogWrite] = []

    @property
    def count(self) -> int:
        """Number of analog outputs (0: the hardware has none)."""
        return 0 if self._hw is None else int(self._hw.n_analog_outputs)

    @property
    def value_range(self) -> tuple[float, float]:
        """(low, high) a channel can hold; (0, 0) without analog outputs."""
        return (0.0, 0.0) if self._hw is None else tuple(self._hw.analog_range)  # type: ignore[return-value]

    def check(self, channel: object, value: object) -> tuple[int, float]:
        """(channel, value) validated, or MotionError naming the parameter and the rule."""
        n = self.count
        if n == 0:
            raise MotionError("this hardware has no analog outputs")
        if isinstance(channel, bool) or not isinstance(channel, int) or not 0 <= channel < n:
            raise MotionError(f"channel must be an integer in 0..{n - 1}, got {channel!r}")
        lo, hi = self.value_range
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value) or not lo <= value <= hi:
            raise MotionError(f"value of ao{channel} must be a number in [{lo:g}, {hi:g}], "
                              f"got {value!r}")
        return channel, float(value)

    def set(self, channel: int, value: float) -> None:
        """Write `value` to output `channel` now (the current cycle)."""
        k, v = self.check(channel, value)
        assert self._hw is not None
        self._hw.write_analog(k, v)
        self.writes.append(AnalogWrite(self._ctl.time, k, v))

    def value(self, channel: int) -> float:
        """The value output `channel` holds."""
        n = self.count
        if isinstance(channel, bool) or not isinstance(channel, int) or not 0 <= channel < n:
            raise MotionError(f"channel must be an integer in 0..{max(n - 1, 0)}, got "
                              f"{channel!r}" if n else "this hardware has no analog outputs")
        assert self._hw is not None
        return float(self._hw.read_analog_output(channel))


class AnalogInputs:
    """Read the analog inputs `ai<n>` of a controller's hardware (M66 E)."""

    def __init__(self, ctl: Controller) -> None:
        hw = ctl.hardware
        self._hw = hw if isinstance(hw, AnalogInputHardware) else None

    @property
    def count(self) -> int:
        """Number of analog inputs (0: the hardware has none)."""
        return 0 if self._hw is None else int(self._hw.n_analog_inputs)

    def read(self, channel: int) -> float:
        """The value of input `channel` now; MotionError naming the rule otherwise."""
        n = self.count
        if n == 0:
            raise MotionError("this hardware has no analog inputs")
        if isinstance(channel, bool) or not isinstance(channel, int) or not 0 <= channel < n:
            raise MotionError(f"channel must be an integer in 0..{n - 1}, got {channel!r}")
        assert self._hw is not None
        return float(self._hw.read_analog_input(channel))
