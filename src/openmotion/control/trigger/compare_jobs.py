"""Compare jobs, their sources and their actions (the engine is in compare.py).

Sources say what is compared (an axis's command or feedback position, or a path length),
jobs say against what (a list of values loaded one at a time, or 2-D/3-D points with a
window), actions say what a firing does to an output. See compare.py for the semantics.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import MotionError, check_finite, check_positive, show
from ...limits import as_array, check_pulses
from .compare_math import LevelValues, crossings_after, level_scan, window_scan

if TYPE_CHECKING:
    from .compare import CompareEngine

Array = NDArray[np.float64]
SOURCE_KINDS = ("dpos", "mpos")


# ---------------------------------------------------------------------------- sources
@dataclass(frozen=True)
class AxisSource:
    """One axis's command (dpos) or feedback (mpos) position."""

    axis: int
    kind: str = "dpos"


@dataclass(frozen=True)
class VectorSource:
    """Accumulated path length of `axes` (command positions); `scale` = pulses per unit."""

    axes: tuple[int, ...]
    scale: tuple[float, ...] | None = None

    @property
    def weights(self) -> Array:
        if self.scale is None:
            return np.ones(len(self.axes))
        return 1.0 / np.asarray(self.scale, dtype=np.float64)


Source = AxisSource | VectorSource


class LevelSeq:
    """start, start + step, ... (`count` values, or endless with count None)."""

    def __init__(self, start: float, step: float, count: int | None = None) -> None:
        self.start = check_finite("start", start)
        self.step = check_finite("step", step)
        if self.step == 0.0:
            raise MotionError("step must be != 0")
        if count is not None and (not isinstance(count, int) or count < 1):
            raise MotionError(f"count must be an int >= 1 or None, got {count!r}")
        self.count = count

    def __len__(self) -> int:
        return self.count if self.count is not None else 2**62

    def __getitem__(self, k: int) -> float:
        return self.start + k * self.step


# ---------------------------------------------------------------------------- actions
class Action(Protocol):
    """What a firing does. An action may also offer `apply_many(eng, times, hit0)`: the
    same as `apply(eng, times[k], hit0 + k)` for each k in order, returning the states
    (the built-in ones do, so a cycle's firings of a job reach the line in one call)."""

    output: int

    def apply(self, eng: CompareEngine, t: float, hit: int) -> bool:
        """Act at time t for the job's `hit`-th firing (0-based); return the output state."""


@dataclass
class Toggle:
    """The first firing drives `first`, each later one inverts (ZMotion modes 1, 3, 25, 35)."""

    output: int
    first: bool = True

    def apply(self, eng: CompareEngine, t: float, hit: int) -> bool:
        return self.apply_many(eng, [t], hit)[0]

    def apply_many(self, eng: CompareEngine, times: list[float], hit0: int) -> list[bool]:
        first, other = bool(self.first), not self.first
        levels = [first if (hit0 + k) % 2 == 0 else other for k in range(len(times))]
        eng.output(self.output).set_many(times, levels)
        return levels


@dataclass
class SetLevel:
    """Drive a fixed level at each firing."""

    output: int
    level: bool = True

    def apply(self, eng: CompareEngine, t: float, hit: int) -> bool:
        return self.apply_many(eng, [t], hit)[0]

    def apply_many(self, eng: CompareEngine, times: list[float], hit0: int) -> list[bool]:
        levels = [self.level] * len(times)
        eng.output(self.output).set_many(times, levels)
        return levels


@dataclass
class Pulse:
    """A pulse of `width` seconds at `active` level (HSL CMP pulse, fixed-time pulses)."""

    output: int
    width: float
    active: bool = True

    def __post_init__(self) -> None:
        self.width = check_positive("width", self.width)

    def apply(self, eng: CompareEngine, t: float, hit: int) -> bool:
        return self.apply_many(eng, [t], hit)[0]

    def apply_many(self, eng: CompareEngine, times: list[float], hit0: int) -> list[bool]:
        w, on, off = self.width, self.active, not self.active
        edges = [x for t in times for x in (t, t + w)]
        eng.output(self.output).set_many(edges, [on, off] * len(times))
        return [on] * len(times)


# ---------------------------------------------------------------------------- jobs
class CompareJob:
    """Common bookkeeping: id, source, action, next point index, hit count, armed time."""

    def __init__(self, action: Action, name: str = "") -> None:
        if not hasattr(action, "apply") or not hasattr(action, "output"):
            raise MotionError(f"action must have .output and .apply(), got {action!r}")
        self.action = action
        self.name = name
        self.id = -1
        self.index = 0
        self.hits = 0
        self.t_armed = -math.inf
        self.active = True

    @property
    def size(self) -> int:
        raise NotImplementedError

    @property
    def remaining(self) -> int:
        """Points not yet fired (buffer entries still in use)."""
        return max(self.size - self.index, 0) if self.active else 0

    @property
    def buffer_use(self) -> int:
        """Buffer entries held: the points left (an endless generator holds one)."""
        return self.remaining

    @property
    def done(self) -> bool:
        return self.index >= self.size

    def scan(self, eng: CompareEngine, ta: float, t1: float) -> list[tuple[float, int, float]]:
        raise NotImplementedError

    def arm(self, eng: CompareEngine) -> None:
        """Called when added (validation against the engine, start state)."""


class LevelJob(CompareJob):
    """Compare a source against `levels` in order; direction +1 up, -1 down, 0 either.

    `after_final` (HSL 4.12): the value loaded after the last point; it fires too if the
    motion reaches it. `repeat=True`: a single value, armed again after every firing.
    """

    def __init__(self, source: Source, levels: ArrayLike | LevelSeq, action: Action, *,
                 direction: int = 0, repeat: bool = False, after_final: float | None = None,
                 monotonic: bool = False, name: str = "") -> None:
        super().__init__(action, name)
        if not isinstance(source, AxisSource | VectorSource):
            raise MotionError(f"source must be an AxisSource or VectorSource, got {source!r}")
        if direction not in (-1, 0, 1):
            raise MotionError(f"direction must be -1, 0 or +1, got {direction!r}")
        if isinstance(levels, LevelSeq):
            self.levels: Array | LevelSeq = levels
        else:
            arr = as_array("levels", levels).reshape(-1)
            if arr.size == 0:
                raise MotionError("levels must not be empty")
            if monotonic and arr.size > 1:
                d = np.diff(arr)
                want = direction if direction else (1 if isinstance(source, VectorSource) else 0)
                if want > 0 and not np.all(d > 0):
                    raise MotionError("levels must be strictly increasing for this mode")
                if want < 0 and not np.all(d < 0):
                    raise MotionError("levels must be strictly decreasing for this mode")
            self.levels = arr
        if repeat and len(self.levels) != 1:
            raise MotionError("repeat needs exactly one level")
        self.after_final = None if after_final is None else check_finite("after_final",
                                                                         after_final)
        self.source = source
        self.direction = direction
        self.repeat = repeat
        self.skipped = 0

    @property
    def size(self) -> int:
        if self.repeat:
            return 1 if self.active else 0
        return len(self.levels) + (self.after_final is not None)

    @property
    def remaining(self) -> int:
        if self.repeat:
            return 1 if self.active else 0
        return super().remaining

    @property
    def buffer_use(self) -> int:
        if isinstance(self.levels, LevelSeq) and self.levels.count is None:
            return 1 if self.active else 0
        return self.remaining

    @property
    def done(self) -> bool:
        return False if self.repeat else self.index >= self.size

    def level(self, k: int) -> float:
        n = len(self.levels)
        return float(self.levels[k]) if k < n else float(self.after_final)  # type: ignore[arg-type]

    @property
    def value(self) -> float | None:
        """The compare value loaded now (HSL check_compare_data), None when exhausted."""
        if self.repeat:
            return self.level(0)
        return self.level(self.index) if self.index < self.size else None

    def arm(self, eng: CompareEngine) -> None:
        if isinstance(self.source, VectorSource):
            # the vector distance only grows: points already behind it can never fire
            s = eng.vector_moved(self.source)
            while self.index < self.size and self.level(self.index) <= s:
                self.index += 1
                self.skipped += 1

    def _values(self) -> tuple[LevelValues, int, float | None]:
        """The value list as the solvers take it: (array or (start, step), count, after)."""
        lv = self.levels
        if isinstance(lv, LevelSeq):
            return (lv.start, lv.step), len(lv), self.after_final
        if not lv.flags.c_contiguous or lv.dtype != np.float64:
            self.levels = lv = np.ascontiguousarray(lv, dtype=np.float64)
        return lv, lv.size, self.after_final

    def scan(self, eng: CompareEngine, ta: float, t1: float) -> list[tuple[float, int, float]]:
        ta = max(ta, self.t_armed)
        if ta >= t1:
            return []
        src = self.source
        if self.repeat:
            lvl = self.level(0)
            if isinstance(src, VectorSource):
                vals, n, after = self._values()
                return [(tf, 0, v) for tf, v in
                        eng.vector_cycle(src).scan(vals, n, after, 0, ta, True)]
            if eng.reachable(src, lvl):
                times = crossings_after(eng.track(src), lvl, ta, t1, self.direction).tolist()
            else:
                times = []
            return [(float(t), 0, lvl) for t in times]
        if self.index >= self.size:
            return []
        vals, n, after = self._values()
        if isinstance(src, VectorSource):
            found = eng.vector_cycle(src).scan(vals, n, after, self.index, ta, False)
        else:
            found = level_scan(eng.track(src), eng.track_range(src), vals, n, after,
                               self.index, ta, t1, self.direction)
        k0 = self.index
        self.index += len(found)
        return [(tf, k0 + i, v) for i, (tf, v) in enumerate(found)]


class WindowJob(CompareJob):
    """2-D/3-D points (n x k) compared with a +-maxerr window per axis, in table order."""

    def __init__(self, axes: Sequence[int], points: ArrayLike, maxerr: float, action: Action,
                 *, kind: str = "dpos", name: str = "") -> None:
        super().__init__(action, name)
        if isinstance(axes, (str, bytes)) or not isinstance(axes, Sequence) \
                or not all(isinstance(a, int) and not isinstance(a, bool) and a >= 0
                           for a in axes):
            raise MotionError(f"axes must be a sequence of axis indices, got {show(axes)}")
        if not axes:
            raise MotionError("axes must name at least one axis")
        self.axes = tuple(axes)
        pts = as_array("points", points)
        if pts.ndim != 2 or pts.shape[1] != len(self.axes) or pts.shape[0] == 0:
            raise MotionError(f"points must be a non-empty (n, {len(self.axes)}) table, "
                              f"got shape {pts.shape}")
        self.maxerr = check_positive("maxerr", maxerr)
        if kind not in SOURCE_KINDS:
            raise MotionError(f"kind must be one of {SOURCE_KINDS}, got {kind!r}")
        self.points = np.ascontiguousarray(pts, dtype=np.float64)  # the solver reads it as is
        self.kind = kind

    @property
    def size(self) -> int:
        return self.points.shape[0]

    @property
    def value(self) -> Array | None:
        return self.points[self.index] if self.index < self.size else None

    def scan(self, eng: CompareEngine, ta: float, t1: float) -> list[tuple[float, int, float]]:
        ta = max(ta, self.t_armed)
        if ta > t1:
            return []
        if self.index >= self.size:
            return []
        tracks, ranges = eng.window_inputs(self.axes, self.kind)
        found = window_scan(tracks, ranges, self.points, self.maxerr, self.index, ta, t1)
        k0 = self.index
        self.index += len(found)
        return [(tf, k0 + i, float(k0 + i)) for i, tf in enumerate(found)]


def every_distance(source: VectorSource, interval: float, action: Action, *,
                   start: float | None = None, end: float | None = None) -> LevelJob:
    """Fire every `interval` of path length, from `start` (default `interval`) up to `end`
    (default endless): the enable window [start, end] is in the source's VECTOR_MOVED."""
    iv = check_positive("interval", interval)
    s = iv if start is None else check_pulses("start", start)
    count = None
    if end is not None:
        e = check_pulses("end", end)
        if e < s:
            what = "start" if start is not None else "start (default: interval)"
            raise MotionError(f"end must be >= {what}, got start={s!r} (interval={iv!r}), "
                              f"end={end!r}")
        count = int(math.floor((e - s) / iv * (1 + 1e-12))) + 1
    return LevelJob(source, LevelSeq(s, iv, count), action, direction=1, name="distance")
