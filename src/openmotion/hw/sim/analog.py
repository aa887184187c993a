"""Simulated board analog outputs (hw.interface.AnalogOutputHardware) for SimMachine.

A bank of DAC channels `ao0..ao<n-1>` (default 4 channels of +-10 V, as LinuxCNC's
default motion.analog-out-00..03); every write lands at the machine's current time and is
kept in `analog_record` (time, channel, value): the scope a test reads. `configure_analog`
changes the count or the range before use (a machine file has no analog section yet).
"""

from __future__ import annotations

import math

from openmotion.errors import MotionError

#: Channels and range of a SimMachine unless `configure_analog` says otherwise.
DEFAULT_CHANNELS = 4
DEFAULT_RANGE = (-10.0, 10.0)


class SimAnalogOutputs:
    """Mixin of SimMachine: analog outputs (its state is made on first use)."""

    _t: float

    def _ao(self) -> dict:
        st = self.__dict__.get("_analog")
        if st is None:
            st = self.__dict__["_analog"] = {
                "values": [0.0] * DEFAULT_CHANNELS, "range": DEFAULT_RANGE, "record": []}
        return st

    def configure_analog(self, channels: int = DEFAULT_CHANNELS,
                         value_range: tuple[float, float] = DEFAULT_RANGE) -> None:
        """Set the number of channels (0 .. 64) and their range; all channels read 0 (or
        the range's nearest value) afterwards."""
        if isinstance(channels, bool) or not isinstance(channels, int) \
                or not 0 <= channels <= 64:
            raise MotionError(f"channels must be an integer in 0..64, got {channels!r}")
        try:
            lo, hi = (float(v) for v in value_range)
        except (TypeError, ValueError):
            raise MotionError(f"value_range must be (low, high), got {value_range!r}") \
                from None
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise MotionError(f"value_range must be finite with low < high, got "
                              f"{value_range!r}")
        zero = min(max(0.0, lo), hi)
        st = self._ao()
        st["values"] = [zero] * channels
        st["range"] = (lo, hi)

    @property
    def n_analog_outputs(self) -> int:
        return len(self._ao()["values"])

    @property
    def analog_range(self) -> tuple[float, float]:
        return self._ao()["range"]

    def _channel(self, channel: int) -> int:
        n = self.n_analog_outputs
        if isinstance(channel, bool) or not isinstance(channel, int) or not 0 <= channel < n:
            raise MotionError(f"analog channel must be an integer in 0..{n - 1}, got "
                              f"{channel!r}" if n else "this machine has no analog outputs")
        return channel

    def write_analog(self, channel: int, value: float) -> None:
        k = self._channel(channel)
        lo, hi = self.analog_range
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value) or not lo <= value <= hi:
            raise MotionError(f"analog value of ao{k} must be a number in [{lo:g}, {hi:g}], "
                              f"got {value!r}")
        st = self._ao()
        st["values"][k] = float(value)
        st["record"].append((self._t, k, float(value)))

    def read_analog_output(self, channel: int) -> float:
        return self._ao()["values"][self._channel(channel)]

    @property
    def analog_record(self) -> list[tuple[float, int, float]]:
        """Every analog write (time, channel, value), in order."""
        return list(self._ao()["record"])
