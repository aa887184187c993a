"""A record of every pulse one axis's generator emitted, for accuracy checks.

The generator already cuts its command into monotone `Stretch`es with the exact count at
each end; the record keeps those (a few per cycle, not one entry per pulse) and expands
them on demand: pulse k of a stretch left when its cubic reached k - d*half (d the
direction, half 0.5 or 0), a root found by vectorized bisection. The expansion is kept: a
later call expands only the stretches added since (a rewind below it starts again). It
also keeps every command the generator was given, so the commanded position is known at
any instant.
Recording is opt-in (`SimMachine.record_pulses`) and stops at `capacity` entries.
"""

from __future__ import annotations

import numpy as np

from openmotion.errors import MotionError

from .cubic import Cubic
from .pulses import Stretch

#: Bisection steps: the bracket (at most one cycle) shrinks below 1e-15 s.
_STEPS = 60


class PulseRecord:
    """Stretches and commands of one generator since recording started (see module doc)."""

    __slots__ = ("start_count", "capacity", "_rows", "_cmds", "_dropped", "_done", "_t", "_k")

    def __init__(self, start_count: int, capacity: int, t: float, cubic: Cubic, tc: float,
                 te: float) -> None:
        self.start_count = start_count
        self.capacity = capacity
        self._rows: list[tuple[Stretch, float]] = []
        # (time set, p0, v0, a0, j, tc, te): the command in force from that time on
        self._cmds: list[tuple[float, float, float, float, float, float, float]] = []
        self._dropped = False
        # pulses() of the first `_done` rows, kept: rows are only appended (or rewound), and
        # each pulse depends on its own stretch alone, so a later call expands the new rows
        self._done = 0
        self._t = np.zeros(0)
        self._k = np.zeros(0, dtype=np.int64)
        self.command(t, cubic, tc, te)

    @property
    def complete(self) -> bool:
        """False once the record filled its capacity and stopped recording."""
        return not self._dropped

    def add(self, st: Stretch, half: float) -> None:
        if st.c1 == st.c0 or self._dropped:
            return
        if len(self._rows) >= self.capacity:
            self._dropped = True  # full: stop here; the record is no longer complete
            return
        self._rows.append((st, half))

    def command(self, t: float, cubic: Cubic, tc: float, te: float) -> None:
        """The generator follows `cubic` (held outside [tc, te]) from time t on."""
        if self._dropped:
            return
        if len(self._cmds) >= self.capacity:
            self._dropped = True
            return
        self._cmds.append((t, *cubic, tc, te))

    def mark(self) -> int:
        return len(self._rows)

    def rewind(self, mark: int) -> None:
        """Forget the stretches added after `mark` (a dry run the machine undid)."""
        del self._rows[mark:]
        if mark < self._done:
            self._done, self._t, self._k = 0, np.zeros(0), np.zeros(0, dtype=np.int64)

    def pulses(self) -> tuple[np.ndarray, np.ndarray]:
        """(times, counts): every pulse in time order, with the count just after it."""
        if self._done < len(self._rows):
            t, k = _expand(self._rows[self._done:])
            self._t, self._k = np.concatenate([self._t, t]), np.concatenate([self._k, k])
            self._done = len(self._rows)
        return self._t.copy(), self._k.copy()

    def command_at(self, times: np.ndarray) -> np.ndarray:
        """The command position (float pulses) the generator followed at each time."""
        t = np.asarray(times, dtype=float)
        cm = np.array(self._cmds, dtype=float)
        i = np.clip(np.searchsorted(cm[:, 0], t, side="right") - 1, 0, len(cm) - 1)
        ts, p0, v0, a0, j, tc, te = cm[i].T
        s = np.clip(t - tc, 0.0, te - tc)
        return p0 + s * (v0 + s * (a0 / 2.0 + s * j / 6.0))


def check_capacity(capacity: object) -> int:
    if isinstance(capacity, bool) or not isinstance(capacity, int) or capacity < 1:
        raise MotionError(f"capacity must be an int >= 1, got {capacity!r}")
    return capacity


def _expand(rows: list[tuple[Stretch, float]]) -> tuple[np.ndarray, np.ndarray]:
    """(times, counts) of the pulses of `rows`, in row order (PulseRecord.pulses)."""
    ks, lv, idx = [], [], []
    for n, (st, half) in enumerate(rows):
        d = 1 if st.c1 > st.c0 else -1
        k = np.arange(st.c0 + d, st.c1 + d, d, dtype=np.int64)
        ks.append(k)
        lv.append(k - d * half)
        idx.append(np.full(len(k), n))
    if not ks:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    k, level, row = np.concatenate(ks), np.concatenate(lv), np.concatenate(idx)
    # per stretch: (t0, t1, tc, p0, v0, a0, j, up); a jump has no cubic: all at t0
    tab = np.array([(st.t0, st.t1 if st.cubic is not None else st.t0, st.tc,
                     *(st.cubic or (0.0, 0.0, 0.0, 0.0)), st.c1 > st.c0)
                    for st, _ in rows], dtype=float)[row]
    lo, hi, tc = tab[:, 0] - tab[:, 2], tab[:, 1] - tab[:, 2], tab[:, 2]
    p0, v0, a0, j, up = tab[:, 3], tab[:, 4], tab[:, 5], tab[:, 6], tab[:, 7] > 0.0
    # bisection for the first time the command reaches the level; a count reached
    # within EPS_PULSE of its level never brackets it and lands on the stretch end
    for _ in range(_STEPS):
        mid = 0.5 * (lo + hi)
        p = p0 + mid * (v0 + mid * (a0 / 2.0 + mid * j / 6.0))
        reached = np.where(up, p >= level, p <= level)
        hi = np.where(reached, mid, hi)
        lo = np.where(reached, lo, mid)
    return tc + hi, k
