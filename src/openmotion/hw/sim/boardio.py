"""SimMachine's board I/O (a mixin of SimMachine): axis outputs (SVON, ERC), the board's
digital outputs `do<n>` (at once or at exact times, `write_output_at`: hw.interface.
TimedOutputHardware) and inputs (`di<n>`, EMG), with every output edge kept in
`output_record` at its exact time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from openmotion.errors import MotionError, check_finite
from openmotion.hw.interface import AXIS_OUTPUTS

if TYPE_CHECKING:
    from .outputs import OutputRecord, TimedOutputs
    from .scenario import Scenario
    from .simaxis import SimAxis


class SimBoardIO:
    """Mixin of SimMachine: outputs and digital I/O (the state is SimMachine's)."""

    _t: float
    _do: list[bool]
    _di: list[bool]
    _emg_active: bool
    _emg_nc: bool
    _pending: list[tuple[float, int | None, str, bool, int | None]]
    _timed: TimedOutputs
    output_record: OutputRecord
    scenario: Scenario

    if TYPE_CHECKING:
        def _axis(self, axis: int) -> SimAxis: ...
        def _index(self, axis: int) -> int: ...
        __dict__: dict[str, Any]

    def write_output(self, axis: int | None, signal: str, level: bool) -> None:
        if not isinstance(level, bool):
            raise MotionError(f"level must be a bool, got {level!r}")
        if axis is None:
            self._set_do(self._t, signal, level)
            return
        ax = self._axis(axis)
        if signal not in AXIS_OUTPUTS:
            raise MotionError(f"signal must be one of {AXIS_OUTPUTS} for an axis, got {signal!r}")
        if ax.outputs[signal] == level:
            return
        self.output_record.add(self._t, axis, signal, level)
        before = {s: ax.level(s) for s in ("rdy", "inp")}
        ax.outputs[signal] = level
        if ax.is_servo:
            ax.plant.set_outputs(self._t, ax.gen, ax.outputs["svon"], ax.alarm,
                                 erc=(signal == "erc" and level))
        if ax.is_dc:
            ax.plant.svon = ax.outputs["svon"]
        for s, lv in before.items():
            if ax.level(s) != lv:
                self._pending.append((self._t, axis, s, not lv, ax.decoder.count))

    def write_output_at(self, t: float, axis: int | None, signal: str, level: bool) -> None:
        """Drive an output at time t >= now (hw.interface.TimedOutputHardware): executed
        inside `advance` at t exactly (an axis output cuts the run there, as a scenario
        action does, so the drive sees it at t); `output_record` shows the edge at t."""
        t = check_finite("t", t)
        if t < self._t:
            raise MotionError(f"t must be >= the current time {self._t!r}, got {t!r}")
        if not isinstance(level, bool):
            raise MotionError(f"level must be a bool, got {level!r}")
        if axis is None:
            self._board_index(signal, "do", len(self._do))
        else:
            self._index(axis)
            if signal not in AXIS_OUTPUTS:
                raise MotionError(f"signal must be one of {AXIS_OUTPUTS} for an axis, "
                                  f"got {signal!r}")
        if t == self._t:
            self.write_output(axis, signal, level)
        elif axis is None:
            self._timed.push(t, None, signal, level)
        else:
            self.scenario._push(t, lambda raw: self._timed_axis_output(axis, signal, level, raw))

    def write_outputs_at(self, times: Sequence[float], axis: int | None, signal: str,
                         levels: Sequence[bool]) -> None:
        """`write_output_at(times[k], axis, signal, levels[k])` for every k in order, in one
        call (the compare engine hands a cycle's edges of one line this way). Everything is
        checked first: on refusal nothing is scheduled."""
        if len(times) != len(levels):
            raise MotionError(f"times and levels must have one entry each, got {len(times)} "
                              f"times and {len(levels)} levels")
        if not all(map(math.isfinite, times)):
            raise MotionError(f"times must be finite, got {list(times)!r}")
        if not times:
            return
        first = min(times)
        if first < self._t:
            raise MotionError(f"t must be >= the current time {self._t!r}, got {first!r}")
        if not set(map(type, levels)) <= {bool}:
            raise MotionError(f"levels must be bools, got {list(levels)!r}")
        if axis is None:
            self._board_index(signal, "do", len(self._do))
            now = self._t
            if first != now:
                self._timed.push_many(list(times), None, signal, list(levels))
                return
            for t, lv in zip(times, levels, strict=True):  # those at `now` go out at once
                if t == now:
                    self.write_output(None, signal, lv)
            later = [k for k, t in enumerate(times) if t != now]
            self._timed.push_many([times[k] for k in later], None, signal,
                                  [levels[k] for k in later])
            return
        for t, lv in zip(times, levels, strict=True):
            self.write_output_at(t, axis, signal, lv)

    def write_outputs_many(self, times: Sequence[float], signals: Sequence[str],
                           levels: Sequence[bool]) -> None:
        """`write_output_at(times[k], None, signals[k], levels[k])` for every k in order, in
        one call (the compare engine's edges of a cycle, every line at once). Everything is
        checked first: on refusal nothing is scheduled."""
        n = len(times)
        if len(signals) != n or len(levels) != n:
            raise MotionError(f"times, signals and levels must have one entry each, got "
                              f"{n} times, {len(signals)} signals and {len(levels)} levels")
        if not n:
            return
        if not all(map(math.isfinite, times)):
            raise MotionError(f"times must be finite, got {list(times)!r}")
        now = self._t
        first = min(times)
        if first < now:
            raise MotionError(f"t must be >= the current time {now!r}, got {first!r}")
        if not set(map(type, levels)) <= {bool}:
            raise MotionError(f"levels must be bools, got {list(levels)!r}")
        slots = self.__dict__.setdefault("_do_slots", {})  # (as _set_do)
        for signal in set(signals).difference(slots):
            slots[signal] = self._board_index(signal, "do", len(self._do))
        if first == now:  # (a write at the present instant goes out at once)
            for t, signal, lv in zip(times, signals, levels, strict=True):
                self.write_output_at(t, None, signal, lv)
            return
        self._timed.push_flat(list(times), list(signals), list(levels))

    def _timed_axis_output(self, axis: int, signal: str, level: bool, raw: list) -> None:
        self.write_output(axis, signal, level)
        raw.extend(self._pending)  # RDY/INP edges it caused belong to this advance
        self._pending.clear()

    def _do_due(self, t: float) -> None:
        """The timed board writes due by t (`_set_do` of each, in their order)."""
        slots = self.__dict__.setdefault("_do_slots", {})
        do, add = self._do, self.output_record._edges.append
        for tk, sig, lv in self._timed.pop_due(t):
            k = slots.get(sig)
            if k is None:
                k = slots[sig] = self._board_index(sig, "do", len(do))
            if do[k] != lv:
                do[k] = lv
                add((tk, None, sig, lv))

    def _set_do(self, t: float, signal: str, level: bool) -> None:
        slots = self.__dict__.setdefault("_do_slots", {})  # signal -> index, parsed once
        k = slots.get(signal)
        if k is None:
            k = slots[signal] = self._board_index(signal, "do", len(self._do))
        if self._do[k] != level:
            self._do[k] = level
            self.output_record.add(t, None, signal, level)

    def read_input(self, signal: str) -> bool:
        if signal == "emg":
            return self._emg_active != self._emg_nc
        return self._di[self._board_index(signal, "di", len(self._di))]

    def read_output(self, axis: int | None, signal: str) -> bool:
        """Level last written to an output (`svon`/`erc` of an axis, or `do<n>`)."""
        if axis is None:
            return self._do[self._board_index(signal, "do", len(self._do))]
        ax = self._axis(axis)
        if signal not in AXIS_OUTPUTS:
            raise MotionError(f"signal must be one of {AXIS_OUTPUTS} for an axis, got {signal!r}")
        return ax.outputs[signal]

    @staticmethod
    def _board_index(signal: str, prefix: str, n: int) -> int:
        if isinstance(signal, str) and signal.startswith(prefix) and signal[len(prefix):].isdigit():
            k = int(signal[len(prefix):])
            if k < n:
                return k
        raise MotionError(f"signal must be {prefix}0..{prefix}{n - 1}, got {signal!r}")
