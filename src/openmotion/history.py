"""Motion history: per-axis constant-jerk records in absolute time (a trapq, anchors.md b2).

Every profile the controller executes is appended here, so later code can ask "where was
the axis at time t?" (latches, homing, plots) and "when did it pass position x?" (compare,
PSO, limits). As in Klipper's trapq, any time maps to exactly one record:

- record i covers [ts[i], ts[i+1]); the last record is open-ended. Its polynomial is
  p(dt) = p0 + v0*dt + a0*dt**2/2 + j*dt**3/6 with dt = t - ts[i].
- a profile appended at t_abs becomes one record per segment plus a *tail* record at
  t_abs + duration holding `profile.end` (exact target position, constant end velocity),
  so gaps between moves are standstill (or constant velocity after a velocity ramp).
- times before the oldest retained record read that record's start position at rest.

Memory is bounded (architecture.md "Memory is bounded"): records that ended more than
`window_s` before the newest append are dropped, and at most `max_records` records per axis
are kept (the oldest go first). Each axis stores its records in numpy arrays that are
compacted or grown in chunks, and shrunk again when at most an eighth of them is live, so
appending is amortised O(1) and memory follows what the window holds, not its high-water
mark: a 10-hour job runs in flat memory.

No degenerate records: a record shorter than `MIN_RECORD_S` (a zero-length segment with a
velocity or acceleration step, or a float sliver of 1e-14 s at a splice) covers no time
worth reading, so it is not stored; the record before it runs on for that instant (an
error below v * 1 ns, far under a pulse).
"""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .crossings import find_crossings
from .errors import MotionError, check_finite, check_positive
from .profile.segments import Profile, Samples, State

Array = NDArray[np.float64]

_MIN_CAPACITY = 32
#: Shortest record stored (s); shorter segments are dropped (see the module docstring).
MIN_RECORD_S = 1e-9
#: Default most records kept per axis (5 float64 columns: 40 bytes a record, 4 MB).
MAX_RECORDS = 100_000


class _Track:
    """One axis's records as five parallel arrays; live rows are [lo, hi)."""

    __slots__ = ("ts", "p0", "v0", "a0", "j", "lo", "hi")

    def __init__(self, t_start: float, p: float, capacity: int = _MIN_CAPACITY) -> None:
        self.ts = np.empty(capacity)
        self.p0 = np.empty(capacity)
        self.v0 = np.empty(capacity)
        self.a0 = np.empty(capacity)
        self.j = np.empty(capacity)
        self.lo = 0
        self.hi = 0
        self.push(t_start, p, 0.0, 0.0, 0.0)

    @property
    def capacity(self) -> int:
        return int(self.ts.size)

    def cols(self) -> tuple[Array, Array, Array, Array, Array]:
        lo, hi = self.lo, self.hi
        return self.ts[lo:hi], self.p0[lo:hi], self.v0[lo:hi], self.a0[lo:hi], self.j[lo:hi]

    def reserve(self, n: int) -> None:
        """Make room for n more rows at hi (compact in place, or grow by doubling)."""
        cap = self.capacity
        if self.hi + n <= cap:
            return
        live = self.hi - self.lo
        need = live + n
        # Compacting only when at most half the buffer is live keeps at least cap/2 free rows
        # afterwards, so every row moved is paid for by a later append: amortised O(1).
        new_cap = cap if 2 * need <= cap else max(2 * need, _MIN_CAPACITY)
        for name in ("ts", "p0", "v0", "a0", "j"):
            old = getattr(self, name)
            new = old if new_cap == cap else np.empty(new_cap)
            new[:live] = old[self.lo:self.hi]
            setattr(self, name, new)
        self.lo, self.hi = 0, live

    def shrink(self) -> None:
        """Give memory back when at most an eighth of the buffer is live."""
        live = self.hi - self.lo
        cap = self.capacity
        if cap <= 4 * _MIN_CAPACITY or 8 * live > cap:
            return
        new_cap = max(2 * live, _MIN_CAPACITY)
        for name in ("ts", "p0", "v0", "a0", "j"):
            new = np.empty(new_cap)
            new[:live] = getattr(self, name)[self.lo:self.hi]
            setattr(self, name, new)
        self.lo, self.hi = 0, live

    def push(self, t: float, p: float, v: float, a: float, j: float) -> None:
        self.reserve(1)
        i = self.hi
        self.ts[i], self.p0[i], self.v0[i], self.a0[i], self.j[i] = t, p, v, a, j
        self.hi = i + 1

    def index_at(self, t: float) -> int:
        """Absolute row index of the record covering t (lo - 1 when t is before them all)."""
        return self.lo + int(np.searchsorted(self.ts[self.lo:self.hi], t, side="right")) - 1

    def state_at(self, t: float) -> State:
        k = self.index_at(t)
        if k < self.lo:
            return State(float(self.p0[self.lo]), 0.0, 0.0)
        dt = t - float(self.ts[k])
        p0, v0, a0, j = float(self.p0[k]), float(self.v0[k]), float(self.a0[k]), float(self.j[k])
        return State(
            p0 + dt * (v0 + dt * (a0 / 2.0 + dt * j / 6.0)),
            v0 + dt * (a0 + dt * j / 2.0),
            a0 + dt * j,
        )


def _check_times(name: str, times: ArrayLike) -> Array:
    try:
        ts = np.asarray(times, dtype=np.float64)
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be real numbers, got {times!r}") from None
    if not np.all(np.isfinite(ts)):
        raise MotionError(f"{name} must all be finite")
    return ts


class MotionHistory:
    """Time-indexed per-axis segment store (Klipper trapq model), bounded by a time window.

    `positions` are the axes' positions before any motion (default 0); the initial standstill
    record starts at `t_start`.
    """

    def __init__(self, n_axes: int, window_s: float = 60.0, *,
                 positions: Sequence[float] | None = None, t_start: float = 0.0,
                 max_records: int = MAX_RECORDS) -> None:
        if not isinstance(n_axes, Integral) or isinstance(n_axes, bool) or n_axes < 1:
            raise MotionError(f"n_axes must be an integer >= 1, got {n_axes!r}")
        self.window_s = check_positive("window_s", window_s)
        if isinstance(max_records, bool) or not isinstance(max_records, Integral) or \
                not 16 <= max_records <= 10**9:
            raise MotionError(f"max_records must be an integer in [16, 1e9], "
                              f"got {max_records!r}")
        self.max_records = int(max_records)
        t_start = check_finite("t_start", t_start)
        if positions is None:
            pos = [0.0] * int(n_axes)
        else:
            if len(positions) != n_axes:
                raise MotionError(
                    f"positions must have n_axes={n_axes} entries, got {len(positions)}"
                )
            pos = [check_finite(f"positions[{i}]", p) for i, p in enumerate(positions)]
        self.n_axes = int(n_axes)
        self._tracks = [_Track(t_start, p) for p in pos]

    # ------------------------------------------------------------------ checks
    def _axis(self, axis: int) -> _Track:
        if type(axis) is int and 0 <= axis < self.n_axes:  # fast path
            return self._tracks[axis]
        if not isinstance(axis, Integral) or isinstance(axis, bool):
            raise MotionError(f"axis must be an integer, got {axis!r}")
        if not 0 <= axis < self.n_axes:
            raise MotionError(f"axis must be in [0, {self.n_axes - 1}], got {axis!r}")
        return self._tracks[int(axis)]

    # ------------------------------------------------------------------ writing
    def append(self, axis: int, t_abs: float, profile: Profile) -> None:
        """Add `profile` starting at absolute time `t_abs` (its time 0).

        Records at or after `t_abs` are cut first, so a re-planned profile splices onto the
        running motion. Records older than `t_abs - window_s` are then forgotten.
        """
        tr = self._axis(axis)
        t_abs = check_finite("t_abs", t_abs)
        if not isinstance(profile, Profile):
            raise MotionError(f"profile must be a Profile, got {type(profile).__name__}")
        n = profile.n_segments
        first = float(profile.t0[0]) if n else profile.duration
        self._cut(tr, t_abs)
        tr.reserve(n + 2)
        if first > MIN_RECORD_S:
            # Profile semantics before its first segment: the start state at constant speed.
            tr.push(t_abs, profile.start.p, profile.start.v, 0.0, 0.0)
        t_end = t_abs + profile.duration
        if n:
            ts = t_abs + profile.t0
            gaps = np.empty(n)  # np.diff(ts, append=t_end), without its generic machinery
            np.subtract(ts[1:], ts[:-1], out=gaps[:-1])
            gaps[-1] = t_end - ts[-1]
            keep = gaps > MIN_RECORD_S
            if not keep.all():  # drop zero-length and sub-nanosecond segments
                idx = np.flatnonzero(keep)
                ts = ts[idx]
                cols = (profile.p0[idx], profile.v0[idx], profile.a0[idx], profile.j[idx])
            else:
                cols = (profile.p0, profile.v0, profile.a0, profile.j)
            m = ts.size
            sl = slice(tr.hi, tr.hi + m)
            tr.ts[sl] = ts
            tr.p0[sl], tr.v0[sl], tr.a0[sl], tr.j[sl] = cols
            tr.hi += m
        end = profile.end
        tr.push(t_end, end.p, end.v, 0.0, 0.0)
        self._forget(tr, t_abs - self.window_s)
        if tr.hi - tr.lo > self.max_records:
            tr.lo = tr.hi - self.max_records

    def truncate(self, axis: int, t_abs: float, hold: float | None = None) -> State:
        """Cut everything after `t_abs`; the axis holds its position there at rest (or
        `hold`: a hardware stop holds the pulse count, up to half a pulse off the plan).

        Returns the state the axis had at `t_abs` (before the cut), e.g. for an immediate
        stop's report.
        """
        tr = self._axis(axis)
        t_abs = check_finite("t_abs", t_abs)
        hold_p = None if hold is None else check_finite("hold", hold)
        st = tr.state_at(t_abs)
        self._cut(tr, t_abs)
        tr.push(t_abs, st.p if hold_p is None else hold_p, 0.0, 0.0, 0.0)
        return st

    @staticmethod
    def _cut(tr: _Track, t_abs: float) -> None:
        """Drop records starting at or after t_abs (the one covering t_abs now ends there),
        and one that would be left shorter than MIN_RECORD_S (unless it is the oldest)."""
        live = tr.ts[tr.lo:tr.hi]
        k = tr.lo + int(np.searchsorted(live, t_abs - MIN_RECORD_S, side="left"))
        if k == tr.lo:
            k = tr.lo + int(np.searchsorted(live, t_abs, side="left"))
        tr.hi = k

    def forget_before(self, t: float, axis: int | None = None) -> None:
        """Drop records that ended at or before `t` (all axes unless `axis` is given).

        The record covering `t` is kept, so every time from `t` on still reads exactly.
        """
        t = check_finite("t", t)
        tracks = self._tracks if axis is None else [self._axis(axis)]
        for tr in tracks:
            self._forget(tr, t)

    def expire(self, now: float) -> None:
        """Forget what is older than the window: `forget_before(now - window_s)`."""
        self.forget_before(check_finite("now", now) - self.window_s)

    @staticmethod
    def _forget(tr: _Track, t: float) -> None:
        k = tr.index_at(t)
        if k > tr.lo:
            tr.lo = k
            tr.shrink()

    # ------------------------------------------------------------------ reading
    def state_at(self, axis: int, t: float) -> State:
        """(p, v, a) of `axis` at absolute time `t`."""
        tr = self._axis(axis)
        return tr.state_at(check_finite("t", t))

    def sample(self, axis: int, times: ArrayLike) -> Samples:
        """Position, velocity, acceleration, jerk at absolute `times` (vectorized)."""
        tr = self._axis(axis)
        t = _check_times("times", times)
        shape = t.shape
        t = t.reshape(-1)
        ts, p0, v0, a0, j0 = tr.cols()
        k = np.searchsorted(ts, t, side="right") - 1
        before = k < 0
        np.maximum(k, 0, out=k)
        dt = t - ts[k]
        dt[before] = 0.0
        vk, ak, jk = v0[k], a0[k], j0[k]
        vk[before] = 0.0
        ak[before] = 0.0
        jk[before] = 0.0
        p = p0[k] + dt * (vk + dt * (ak / 2.0 + dt * jk / 6.0))
        v = vk + dt * (ak + dt * jk / 2.0)
        a = ak + dt * jk
        return Samples(p.reshape(shape), v.reshape(shape), a.reshape(shape), jk.reshape(shape))

    def position_at(self, axis: int, times: ArrayLike) -> Array | float:
        """Position at `times`: a float for a scalar time, else an array shaped like times."""
        p = self.sample(axis, times).p
        return float(p) if p.ndim == 0 else p

    def end_time(self, axis: int) -> float:
        """Start of the last (open-ended) record: after it the axis holds its end state."""
        tr = self._axis(axis)
        return float(tr.ts[tr.hi - 1])

    def end_state(self, axis: int) -> State:
        """The state of the last record at its start (exact target position of the last move)."""
        tr = self._axis(axis)
        i = tr.hi - 1
        return State(float(tr.p0[i]), float(tr.v0[i]), float(tr.a0[i]))

    def start_time(self, axis: int) -> float:
        """Start of the oldest retained record; earlier times read its start position."""
        tr = self._axis(axis)
        return float(tr.ts[tr.lo])

    def n_records(self, axis: int) -> int:
        return self._axis(axis).hi - self._axis(axis).lo

    def capacity(self, axis: int) -> int:
        """Rows allocated for `axis` (for memory checks)."""
        return self._axis(axis).capacity

    def records(self, axis: int) -> dict[str, Array]:
        """Copies of the retained records: ts, p0, v0, a0, j (each record to the next ts)."""
        ts, p0, v0, a0, j = self._axis(axis).cols()
        return {"ts": ts.copy(), "p0": p0.copy(), "v0": v0.copy(), "a0": a0.copy(),
                "j": j.copy()}

    def rows(self, axis: int, t0: float,
             t1: float) -> tuple[Array, Array, Array, Array, Array]:
        """The records covering [t0, t1] plus the one before t0's (the state leading in):
        ts, p0, v0, a0, j as read-only views of the store, not copies, so a per-cycle
        reader touches only a few rows. Valid until the next append / truncate / expire."""
        tr = self._axis(axis)
        t0 = check_finite("t0", t0)
        t1 = check_finite("t1", t1)
        lo = max(tr.index_at(t0) - 1, tr.lo)
        hi = max(tr.index_at(t1), lo) + 1
        return tuple(_read_only(c[lo:hi]) for c in (tr.ts, tr.p0, tr.v0, tr.a0, tr.j))

    def record_at(self, axis: int, t: float) -> tuple[float, float, float, float, float] | None:
        """(ts, p0, v0, a0, j) of the record in force at `t`; None before the oldest one."""
        tr = self._axis(axis)
        k = tr.index_at(check_finite("t", t))
        if k < tr.lo:
            return None
        return (float(tr.ts[k]), float(tr.p0[k]), float(tr.v0[k]), float(tr.a0[k]),
                float(tr.j[k]))

    # ------------------------------------------------------------------ events
    def crossings(self, axis: int, level: float, t0: float, t1: float,
                  direction: int = 0) -> Array:
        """Exact times in [t0, t1] where the position reaches `level`.

        direction=+1: position < level just before and >= level at the time (upward);
        -1: > level just before and <= level at the time; 0: both. A tangent touch counts as
        reaching the level from the side it came from; a dwell at the level counts once, on
        arrival. Times are found by solving each record's cubic on its monotone pieces.
        """
        times, dirs = self.crossing_events(axis, level, t0, t1)
        if direction not in (-1, 0, 1):
            raise MotionError(f"direction must be -1, 0 or +1, got {direction!r}")
        return times if direction == 0 else times[dirs == direction]

    def crossing_events(self, axis: int, level: float, t0: float,
                        t1: float) -> tuple[Array, NDArray[np.int8]]:
        """Like `crossings` with direction 0, plus each event's direction (+1/-1)."""
        tr = self._axis(axis)
        level = check_finite("level", level)
        t0 = check_finite("t0", t0)
        t1 = check_finite("t1", t1)
        if t1 < t0:
            raise MotionError(f"t1 must be >= t0, got t0={t0!r}, t1={t1!r}")
        return find_crossings(*tr.cols(), level, t0, t1)


def _read_only(view: Array) -> Array:
    view.flags.writeable = False  # the view only: the store's own arrays stay writable
    return view
