"""Simulated board outputs switched at exact times, and the record of every output edge.

`TimedOutputs` holds the writes scheduled with `SimMachine.write_output_at`
(hw.interface.TimedOutputHardware), in time order (equal times in call order); the machine
executes them inside `advance` at their own instants. `OutputRecord` keeps every level
change of every output (time, axis or None, signal, level): the "scope" a test reads to see
where the edges landed on the physical line and how wide the pulses came out.
"""

from __future__ import annotations

from collections import deque

import numpy as np
from numpy.typing import NDArray


class TimedOutputs:
    """Pending timed board writes (time, signal, level) as three flat lists in push order;
    `pop_due` hands them out sorted by (time, push order). A cycle's compare edges come
    as one extend of ~100 entries and all go out at the next advance: a stable sort of
    the flat lists then costs far less than a heap of tuples (push + pop per entry)."""

    def __init__(self) -> None:
        self._t: list[float] = []
        self._sig: list[str] = []
        self._lv: list[bool] = []

    def push(self, t: float, axis: int | None, signal: str, level: bool) -> None:
        self._t.append(t)
        self._sig.append(signal)
        self._lv.append(level)

    def push_many(self, times: list[float], axis: int | None, signal: str,
                  levels: list[bool]) -> None:
        """`push(times[k], axis, signal, levels[k])` for every k, in order."""
        self._t.extend(times)
        self._sig.extend([signal] * len(times))
        self._lv.extend(levels)

    def push_flat(self, times: list[float], signals: list[str], levels: list[bool]) -> None:
        """`push(times[k], None, signals[k], levels[k])` for every k, in order."""
        self._t.extend(times)
        self._sig.extend(signals)
        self._lv.extend(levels)

    def next_time(self) -> float | None:
        return min(self._t) if self._t else None

    def pop_due(self, t: float) -> list[tuple[float, str, bool]]:
        """The writes due at or before t as (time, signal, level), in execution order."""
        ts = self._t
        if not ts:
            return []
        sig, lv = self._sig, self._lv
        order = sorted(range(len(ts)), key=ts.__getitem__)  # stable: equal times in order
        n = len(order)
        if ts[order[-1]] > t:  # some stay for later
            n = 0
            while n < len(order) and ts[order[n]] <= t:
                n += 1
            rest = order[n:]
            rest.sort()  # (push order again)
            self._t, self._sig, self._lv = ([ts[i] for i in rest], [sig[i] for i in rest],
                                            [lv[i] for i in rest])
        else:
            self._t, self._sig, self._lv = [], [], []
        return [(ts[i], sig[i], lv[i]) for i in order[:n]]

    def __len__(self) -> int:
        return len(self._t)


class OutputRecord:
    """Every output level change (time, axis | None, signal, level); the newest `capacity`."""

    def __init__(self, capacity: int = 1_000_000) -> None:
        self._edges: deque[tuple[float, int | None, str, bool]] = deque(maxlen=capacity)

    def add(self, t: float, axis: int | None, signal: str, level: bool) -> None:
        self._edges.append((t, axis, signal, level))

    def clear(self) -> None:
        self._edges.clear()

    def edges(self, signal: str, axis: int | None = None) -> list[tuple[float, bool]]:
        """(time, new level) of every change of one output, time-ordered."""
        return [(t, lv) for t, a, s, lv in self._edges if s == signal and a == axis]

    def pulse_widths(self, signal: str, active: bool = True,
                     axis: int | None = None) -> NDArray[np.float64]:
        """Durations of the completed `active`-level intervals of one output."""
        e = self.edges(signal, axis)
        t = np.array([x[0] for x in e], dtype=np.float64)
        lv = np.array([x[1] for x in e], dtype=bool)
        starts = np.flatnonzero(lv == active)
        starts = starts[starts + 1 < t.size]
        return t[starts + 1] - t[starts]
