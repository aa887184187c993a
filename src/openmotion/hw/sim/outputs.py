"""Simulated board outputs switched at exact times, and the record of every output edge.

`TimedOutputs` holds the writes scheduled with `SimMachine.write_output_at`
(hw.interface.TimedOutputHardware), in time order (equal times in call order); the machine
executes them inside `advance` at their own instants. `OutputRecord` keeps every level
change of every output (time, axis or None, signal, level): the "scope" a test reads to see
where the edges landed on the physical line and how wide the pulses came out.
"""

from __future__ import annotations

import heapq
import itertools
from collections import deque

import numpy as np
from numpy.typing import NDArray


class TimedOutputs:
    """Pending timed writes: (time, seq, axis, signal, level), a min-heap by (time, seq)."""

    def __init__(self) -> None:
        self._heap: list[tuple[float, int, int | None, str, bool]] = []
        self._seq = itertools.count()

    def push(self, t: float, axis: int | None, signal: str, level: bool) -> None:
        heapq.heappush(self._heap, (t, next(self._seq), axis, signal, level))

    def push_many(self, times: list[float], axis: int | None, signal: str,
                  levels: list[bool]) -> None:
        """`push(times[k], axis, signal, levels[k])` for every k, in order."""
        seq = self._seq
        items = [(t, next(seq), axis, signal, lv) for t, lv in zip(times, levels, strict=True)]
        if len(items) > 4:  # one heapify beats pushing one by one (same (time, seq) order)
            self._heap.extend(items)
            heapq.heapify(self._heap)
        else:
            for it in items:
                heapq.heappush(self._heap, it)

    def push_lines(self, writes: list[tuple[list[float], str, list[bool]]]) -> None:
        """`push(t, None, signal, level)` for every edge of every (times, signal, levels),
        in order (the heap entries are built by zip, one heapify for all)."""
        heap, seq = self._heap, self._seq
        for times, sig, levels in writes:
            heap.extend(zip(times, seq, itertools.repeat(None), itertools.repeat(sig), levels,
                            strict=False))
        heapq.heapify(heap)

    def next_time(self) -> float | None:
        return self._heap[0][0] if self._heap else None

    def pop_due(self, t: float) -> list[tuple[float, int | None, str, bool]]:
        """The writes due at or before t, in execution order."""
        out = []
        while self._heap and self._heap[0][0] <= t:
            tk, _, axis, sig, lv = heapq.heappop(self._heap)
            out.append((tk, axis, sig, lv))
        return out

    def __len__(self) -> int:
        return len(self._heap)


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
