"""Simulated board analog inputs (hw.interface.AnalogInputHardware) for SimMachine.

A bank of ADC channels `ai0..ai<n-1>` (default 4, as LinuxCNC's default
motion.analog-in-00..03), all reading 0 until a scenario sets them
(`Scenario.set_analog_input(channel, value, at=...)`, at an exact machine time);
`configure_analog_inputs` changes the count before use.
"""

from __future__ import annotations

import math

from openmotion.errors import MotionError

#: Channels of a SimMachine unless `configure_analog_inputs` says otherwise.
DEFAULT_INPUTS = 4


class SimAnalogInputs:
    """Mixin of SimMachine: analog inputs (its state is made on first use)."""

    def _ai(self) -> list[float]:
        st = self.__dict__.get("_analog_in")
        if st is None:
            st = self.__dict__["_analog_in"] = [0.0] * DEFAULT_INPUTS
        return st

    def configure_analog_inputs(self, channels: int = DEFAULT_INPUTS) -> None:
        """Set the number of analog inputs (0 .. 64); all read 0 afterwards."""
        if isinstance(channels, bool) or not isinstance(channels, int) \
                or not 0 <= channels <= 64:
            raise MotionError(f"channels must be an integer in 0..64, got {channels!r}")
        self.__dict__["_analog_in"] = [0.0] * channels

    @property
    def n_analog_inputs(self) -> int:
        return len(self._ai())

    def _ai_channel(self, channel: int) -> int:
        n = self.n_analog_inputs
        if isinstance(channel, bool) or not isinstance(channel, int) or not 0 <= channel < n:
            raise MotionError(f"analog input channel must be an integer in 0..{n - 1}, got "
                              f"{channel!r}" if n else "this machine has no analog inputs")
        return channel

    def read_analog_input(self, channel: int) -> float:
        return self._ai()[self._ai_channel(channel)]

    def _check_ai(self, channel: int, value: float) -> tuple[int, float]:
        k = self._ai_channel(channel)
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            raise MotionError(f"value of ai{k} must be a finite number, got {value!r}")
        return k, float(value)

    def _set_ai(self, channel: int, value: float) -> None:
        self._ai()[channel] = value
