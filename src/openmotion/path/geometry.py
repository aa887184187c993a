"""Path elements for coordinated motion: the shared contract, helpers and the straight line.

A path element maps the path position s (arc length, 0 <= s <= length) to a point of
N >= 2 axes. Every element answers the same questions, vectorized over numpy arrays of s:
`point(s)`, `tangent(s)` (unit vector), `curvature(s)`, and the per-axis bounds the
look-ahead planner needs to turn axis limits into limits along the path. Points are float64
arrays that are never written to; `point(0)` is `start` and `point(length)` is `end`,
bit for bit, so a move ends exactly on its target.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import MotionError

Array = NDArray[np.float64]

#: Slack on s beyond [0, length], relative to max(length, 1); such s are clipped.
S_SLACK = 1e-9


class Direction(enum.IntEnum):
    """Turning sense in a plane; CCW turns from axis i to axis j. MCCL: CIR_CW 0, CIR_CCW 1."""

    CW = 0
    CCW = 1


@runtime_checkable
class PathElement(Protocol):
    """What every path element provides (Line, Arc, Arc3D)."""

    start: Array
    end: Array

    @property
    def length(self) -> float: ...
    @property
    def dim(self) -> int: ...
    @property
    def start_tangent(self) -> Array: ...
    @property
    def end_tangent(self) -> Array: ...
    @property
    def max_curvature(self) -> float: ...
    @property
    def max_abs_tangent(self) -> Array: ...
    @property
    def axis_accel_weight(self) -> Array: ...
    def point(self, s: ArrayLike) -> Array: ...
    def tangent(self, s: ArrayLike) -> Array: ...
    def curvature(self, s: ArrayLike) -> Any: ...


def as_point(name: str, value: ArrayLike, dim: int | None = None) -> Array:
    """A finite, read-only float64 copy of a point of >= 2 axes (or exactly `dim` axes)."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be a sequence of real numbers, got {value!r}") from None
    if arr.ndim != 1 or arr.size < 2:
        raise MotionError(f"{name} must be a 1-D point of at least 2 axes, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise MotionError(f"{name} must be finite in every axis, got {arr.tolist()}")
    if dim is not None and arr.size != dim:
        raise MotionError(f"{name} must have {dim} axes (like start), got {arr.size}")
    arr.flags.writeable = False
    return arr


def vnorm(v: Array) -> float:
    """np.linalg.norm of a 1-D float vector by its own formula, sqrt(v.v), without its
    dispatch overhead: bit for bit the same."""
    return math.sqrt(v.dot(v))


def frozen(arr: Array) -> Array:
    """Mark an internally computed array read-only and return it."""
    arr.flags.writeable = False
    return arr


def path_positions(s: ArrayLike, length: float) -> Array:
    """`s` as a float64 array inside [0, length]; refuses NaN/inf and s clearly outside."""
    try:
        arr = np.asarray(s, dtype=np.float64)
    except (TypeError, ValueError):
        raise MotionError(f"s must be real numbers, got {s!r}") from None
    if arr.size == 0:
        return arr
    if not np.all(np.isfinite(arr)):
        raise MotionError("s must be finite")
    slack = S_SLACK * max(length, 1.0)
    lo, hi = float(arr.min()), float(arr.max())
    if lo < -slack or hi > length + slack:
        raise MotionError(f"s must be in [0, length={length:.17g}], got values in [{lo}, {hi}]")
    return np.clip(arr, 0.0, length)


def snap_ends(s: Array, p: Array, length: float, start: Array, end: Array) -> Array:
    """Replace points at s == length / s == 0 by the exact end / start."""
    p = np.where((s >= length)[..., None], end, p)
    return np.where((s <= 0.0)[..., None], start, p)


def scalar_or_array(values: Array) -> Any:
    """A Python float for 0-d results, the array otherwise."""
    return float(values) if values.ndim == 0 else values


def parse_direction(value: Any) -> Direction:
    """Direction from a Direction, 0/1 (MCCL CIR_CW/CIR_CCW) or 'CW'/'CCW'."""
    if isinstance(value, str):
        key = value.strip().upper()
        if key in Direction.__members__:
            return Direction[key]
    elif isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value in (0, 1):
        return Direction(int(value))
    raise MotionError(f"direction must be Direction.CW/CCW, 0/1 or 'CW'/'CCW', got {value!r}")


@dataclass(frozen=True, eq=False)
class Line:
    """Straight segment from `start` to `end` (N >= 2 axes). Zero length is allowed."""

    start: Array
    end: Array
    length: float = field(init=False)
    #: Unit direction start -> end (all zeros for a zero-length line).
    direction: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        start = as_point("start", self.start)
        end = as_point("end", self.end, start.size)
        delta = end - start
        big = float(np.max(np.abs(delta)))
        # scaled so tiny (even subnormal) displacements do not underflow to length 0
        length = big * vnorm(delta / big) if big > 0.0 else 0.0
        u = delta / length if length > 0.0 else np.zeros_like(delta)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "end", end)
        object.__setattr__(self, "length", length)
        object.__setattr__(self, "direction", frozen(u))

    @classmethod
    def between(cls, start: Array, end: Array) -> Line:
        """The line between two points a planner computed itself: read-only float64 arrays
        of the same size, finite (not checked again). The same line as Line(start, end)."""
        obj = object.__new__(cls)
        delta = end - start
        # the largest |component| (finite values: the same as np.abs(delta).max(), whose
        # two array calls cost more than this on the few axes of a path)
        big = max(map(abs, delta.tolist()))
        if big > 0.0:
            q = delta / big
            length = big * math.sqrt(q.dot(q))  # (vnorm, inlined)
            u = delta / length
        else:
            length = 0.0
            u = np.zeros_like(delta)
        u.flags.writeable = False
        obj.__dict__.update(start=start, end=end, length=length, direction=u)
        return obj

    @classmethod
    def chain_of(cls, points: Array) -> list[Line]:
        """The lines between consecutive rows of `points` (an (m, N) float64 array of
        finite values a planner made, m >= 2), each the same as `between(points[k],
        points[k + 1])` bit for bit, made in one pass over the stretch (a program's run of
        lines). `points` is made read only; the lines' start, end and direction are its
        rows (shared: lines[k].end is lines[k + 1].start)."""
        points.flags.writeable = False
        delta = points[1:] - points[:-1]
        big = np.abs(delta).max(axis=1)
        flat = big == 0.0
        if flat.any():  # zero-length lines: length 0 and a zero direction, as between
            big[flat] = 1.0
        q = delta / big[:, None]
        lengths = [b * math.sqrt(r.dot(r)) for b, r in zip(big.tolist(), q, strict=True)]
        if flat.any():
            lengths = [0.0 if f else x for f, x in zip(flat.tolist(), lengths, strict=True)]
        length_col = np.array(lengths)
        if flat.any():
            length_col[flat] = 1.0
        u = delta / length_col[:, None]
        if flat.any():
            u[flat] = 0.0
        au = np.abs(u)
        u.flags.writeable = au.flags.writeable = False
        rows = list(points)
        out = []
        new = object.__new__
        for k, (length, d, a) in enumerate(zip(lengths, u, au, strict=True)):
            obj = new(cls)
            obj.__dict__.update(start=rows[k], end=rows[k + 1], length=length, direction=d,
                                _abs_dir=a)
            out.append(obj)
        return out

    @classmethod
    def _planned(cls, start: Array, end: Array, length: float, direction: Array,
                 abs_direction: Array) -> Line:
        """A line whose length and direction (and |direction|) a planner computed itself
        as `between` does (path/blend.py's compiled corner): read-only arrays, not checked."""
        obj = object.__new__(cls)
        obj.__dict__.update(start=start, end=end, length=length, direction=direction,
                            _abs_dir=abs_direction)
        return obj

    @property
    def dim(self) -> int:
        return int(self.start.size)

    @property
    def start_tangent(self) -> Array:
        return self.direction

    @property
    def end_tangent(self) -> Array:
        return self.direction

    @property
    def max_curvature(self) -> float:
        return 0.0

    @property
    def max_abs_tangent(self) -> Array:
        """Per axis, the largest |tangent component| along the element (computed once: the
        queue checks and the look-ahead ask for it on every line)."""
        out = self.__dict__.get("_abs_dir")
        if out is None:
            out = self.__dict__["_abs_dir"] = frozen(np.abs(self.direction))
        return out

    @property
    def axis_accel_weight(self) -> Array:
        """Per axis, max of sqrt(t_i**2 + n_i**2) (n: unit normal); bounds axis accelerations."""
        return self.max_abs_tangent

    def point(self, s: ArrayLike) -> Array:
        """Point at path position s; shape s.shape + (N,)."""
        ss = path_positions(s, self.length)
        p = self.start + ss[..., None] * self.direction
        return snap_ends(ss, p, self.length, self.start, self.end)

    def tangent(self, s: ArrayLike) -> Array:
        """Unit tangent at s (zeros for a zero-length line); shape s.shape + (N,)."""
        ss = path_positions(s, self.length)
        return np.broadcast_to(self.direction, ss.shape + (self.dim,)).copy()

    def curvature(self, s: ArrayLike) -> Any:
        """Always 0: a float for scalar s, an array shaped like s otherwise."""
        ss = path_positions(s, self.length)
        return scalar_or_array(np.zeros_like(ss))
