"""The per-cycle trace of a program run: time, command index, command and actual positions.

A program run (runner.py) records one row per cycle: from its cycle hook for the cycles it
runs, and from the controller's jump observer for the cycles a jump crosses
(control/core/jump.py). A jump crosses up to a few hundred cycles at once; recording them
row by row (a command-index lookup and four list appends per cycle) was the largest part
of a landing's Python work in real time. Here a crossed span is recorded as one block of
arrays: the positions are column picks of the observer's arrays, and the command indices
are looked up in one vectorised pass over the cycle ends of all the spans one plan ran
(`Group.index_lookup`: the very values `Group.index_at` gives cycle by cycle), when the
next plan's first span arrives or the trace is read - once per plan, not per landing.
Single rows are gathered in lists and turned into a block when a span arrives, so the
rows keep their cycle order.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..control.core.controller import Controller
    from ..control.groups.group import Group


class CycleTrace:
    """Rows (time, command index, command positions, actual positions) of the group axes
    `axes` (controller axis indices), in pulses, one per cycle, in cycle order."""

    def __init__(self, axes: Sequence[int]) -> None:
        self._axes = np.asarray(axes, dtype=np.intp)
        # (times, command indices or the lookup that gives them, positions, actual)
        self._blocks: list[tuple[np.ndarray, Any, np.ndarray, np.ndarray]] = []
        self._pending: list[int] = []  # blocks whose indices `_lookup` gives (one run/plan)
        self._lookup: Any = None
        self._t: list[float] = []
        self._i: list[int] = []
        self._p: list[list[float]] = []
        self._a: list[list[float]] = []
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def add(self, t: float, index: int, positions: list[float], actual: list[float]) -> None:
        """One cycle's row (a cycle the run's hook saw)."""
        self._t.append(t)
        self._i.append(index)
        self._p.append(positions)
        self._a.append(actual)
        self._count += 1

    def last_index(self) -> int:
        """The command index of the last traced cycle (-1 before any): an abort's or
        fault's stop is traced as part of the command that was executing."""
        if self._i:
            return self._i[-1]
        self._resolve()
        for block in reversed(self._blocks):
            if len(block[1]):
                return int(block[1][-1])
        return -1

    def add_span(self, ctl: Controller, group: Group, first: int, last: int,
                 positions: np.ndarray, actual: np.ndarray) -> None:
        """The rows of cycles first..last a jump crossed (`Controller.add_jump_observer`:
        every axis's positions per crossed cycle, rows = cycles)."""
        m = last - first + 1
        if m <= 0:
            return
        self._flush()
        lookup = group.index_lookup()
        if lookup is not self._lookup:  # another run or plan: look the last one's up now
            self._resolve()
            self._lookup = lookup
        t = ctl._t_origin + np.arange(first, last + 1) * ctl.period
        self._pending.append(len(self._blocks))
        self._blocks.append((t, None, positions[:m, self._axes], actual[:m, self._axes]))
        self._count += m

    def _resolve(self) -> None:
        """The command indices of the pending spans, in one pass over their times."""
        if not self._pending:
            return
        ts = [self._blocks[k][0] for k in self._pending]
        idx = self._lookup(np.concatenate(ts) if len(ts) > 1 else ts[0])
        at = 0
        for k, t in zip(self._pending, ts, strict=True):
            b = self._blocks[k]
            self._blocks[k] = (b[0], idx[at:at + len(t)], b[2], b[3])
            at += len(t)
        self._pending = []

    def _flush(self) -> None:
        if self._t:
            n = len(self._axes)
            self._blocks.append((np.array(self._t, dtype=float),
                                 np.array(self._i, dtype=np.int64),
                                 np.array(self._p, dtype=float).reshape(-1, n),
                                 np.array(self._a, dtype=float).reshape(-1, n)))
            self._t, self._i, self._p, self._a = [], [], [], []

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """All rows: times (s), command indices, command and actual positions (pulses)."""
        self._flush()
        self._resolve()
        n = len(self._axes)
        if not self._blocks:
            return (np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros((0, n)),
                    np.zeros((0, n)))
        if len(self._blocks) > 1:  # keep one block: later reads cost nothing again
            self._blocks = [tuple(np.concatenate(c) for c in zip(*self._blocks,
                                                                strict=True))]  # type: ignore[list-item]
        t, i, p, a = self._blocks[0]
        return t.copy(), i.copy(), p.copy(), a.copy()
