"""Circular arcs and helices: `Arc` in two chosen axes, `Arc3D` through three points.

Both are evaluated by one circle frame that works in any number of axes:

    phi(s)  = s * sweep / length
    point   = centre + R*(cos(phi)*e1 + sin(phi)*e2) + (s/length) * lin
    tangent = (sweep/length) * R*(-sin(phi)*e1 + cos(phi)*e2) + helix/length   (normalized)

e1, e2 are orthonormal (e1 points from the centre to the start, e2 is the direction of
motion at the start), `helix` is the straight displacement of the axes outside the plane
(orthogonal to e1, e2), so length = sqrt((R*sweep)**2 + |helix|**2) and the curvature is
R / (R**2 + c**2) with c = |helix| / sweep. `lin` = helix + a correction of at most `tol`*R
that makes the last point the commanded end although the end was only on the circle within
tolerance (the correction is spread linearly along s, so the path stays continuous).
Seeds: HSL-4XMO manual sec. 4.6 "Circular interpolation for 2 axes"; MCCL 2.6.2 II.B/C
(MCC_ArcXY/YZ/ZX, MCC_ArcXYZ through a reference point, MCC_CircleXY, "arc command error").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import MotionError, check_finite, check_nonnegative, check_positive
from ..limits import COUNT_MAX
from .geometry import (
    Array,
    Direction,
    as_point,
    frozen,
    parse_direction,
    path_positions,
    scalar_or_array,
    snap_ends,
    vnorm,
)

#: Smallest arc radius (path units): below it the tangent and curvature lose all precision.
RADIUS_MIN = 1e-9

TWO_PI = 2.0 * math.pi
#: Default end-point tolerance, relative to the radius.
ARC_TOL = 1e-6
#: Three points whose chords make an angle below this (radians) are collinear.
COLLINEAR_SIN = 1e-12


def _max_abs_cos(beta: Array, sweep: float) -> Array:
    """max |cos(phi + beta)| for phi in [0, sweep], per element of beta."""
    if sweep >= math.pi:
        return np.ones_like(beta)
    a = beta
    b = beta + sweep
    # |cos| reaches 1 where (a, b] contains a multiple of pi (a itself is in `ends`).
    contains = np.floor(b / math.pi) > np.floor(a / math.pi)
    ends = np.maximum(np.abs(np.cos(a)), np.abs(np.cos(b)))
    return np.where(contains, 1.0, ends)


@dataclass(frozen=True, eq=False)
class _Frame:
    """The circle (or helix) evaluator shared by Arc and Arc3D; see the module docstring."""

    centre: Array
    e1: Array
    e2: Array
    radius: float
    sweep: float
    helix: Array
    start: Array
    end: Array
    length: float = field(init=False)
    lin: Array = field(init=False)
    t_start: Array = field(init=False)
    t_end: Array = field(init=False)

    def __post_init__(self) -> None:
        h = vnorm(self.helix)
        length = math.hypot(self.radius * self.sweep, h)
        c, sn = math.cos(self.sweep), math.sin(self.sweep)
        last = self.centre + self.radius * (c * self.e1 + sn * self.e2) + self.helix
        object.__setattr__(self, "length", length)
        object.__setattr__(self, "lin", frozen(self.helix + (self.end - last)))
        object.__setattr__(self, "t_start", frozen(self._tangent_one(0.0)))
        object.__setattr__(self, "t_end", frozen(self._tangent_one(length)))

    def sub(self, s0: float, s1: float) -> _Frame:
        """The part [s0, s1] (0 <= s0 < s1 <= length) as a frame of its own: the same circle,
        radius and turning sense and the same points; the helix and the end correction
        `lin` are carried over pro rata, the kept original ends bit for bit."""
        k = self.sweep / self.length
        phi0 = s0 * k
        c, sn = math.cos(phi0), math.sin(phi0)
        e1 = c * self.e1 + sn * self.e2
        e2 = c * self.e2 - sn * self.e1
        e1 = e1 / np.linalg.norm(e1)
        e2 = e2 - (e2 @ e1) * e1
        e2 = e2 / np.linalg.norm(e2)
        part = (s1 - s0) / self.length
        centre = self.centre if s0 == 0.0 else self.centre + (s0 / self.length) * self.lin
        start = self.start if s0 == 0.0 else frozen(np.array(self.point(s0)))
        end = self.end if s1 >= self.length else frozen(np.array(self.point(s1)))
        return _Frame(frozen(centre), frozen(e1), frozen(e2), self.radius, (s1 - s0) * k,
                      frozen(self.helix * part), start, end)

    def point(self, s: ArrayLike) -> Array:
        ss = path_positions(s, self.length)
        phi = (ss * (self.sweep / self.length))[..., None]
        p = (self.centre + self.radius * (np.cos(phi) * self.e1 + np.sin(phi) * self.e2)
             + (ss / self.length)[..., None] * self.lin)
        return snap_ends(ss, p, self.length, self.start, self.end)

    def tangent(self, s: ArrayLike) -> Array:
        ss = path_positions(s, self.length)
        return self._tangent_at(ss)

    def _tangent_one(self, s: float) -> Array:
        """`_tangent_at` at one s: the same operations on the (N,) vectors without the
        broadcasting and np.linalg.norm dispatch (bit for bit, tests/test_arcs_fast.py)."""
        phi = s * (self.sweep / self.length)
        t = self.radius * self.sweep * (np.cos(phi) * self.e2 - np.sin(phi) * self.e1) \
            + self.helix
        return t / math.sqrt(np.add.reduce(t * t))

    def _tangent_at(self, ss: Array) -> Array:
        phi = (ss * (self.sweep / self.length))[..., None]
        t = self.radius * self.sweep * (np.cos(phi) * self.e2 - np.sin(phi) * self.e1) + self.helix
        return t / np.linalg.norm(t, axis=-1, keepdims=True)

    @property
    def kappa(self) -> float:
        pitch = vnorm(self.helix) / self.sweep
        return self.radius / (self.radius**2 + pitch**2)

    def curvature(self, s: ArrayLike) -> Any:
        ss = path_positions(s, self.length)
        return scalar_or_array(np.full_like(ss, self.kappa))

    def max_abs_tangent(self) -> Array:
        # In-plane part of t_i is k*A_i*cos(phi + beta_i) with A_i = |(e1_i, e2_i)|,
        # beta_i = atan2(e1_i, e2_i), k = R*sweep/length; the helix part is constant.
        k = self.radius * self.sweep / self.length
        amp = np.hypot(self.e1, self.e2)
        beta = np.arctan2(self.e1, self.e2)
        return frozen(k * amp * _max_abs_cos(beta, self.sweep) + np.abs(self.helix) / self.length)

    def axis_accel_weight(self) -> Array:
        # t_i**2 + n_i**2 <= A_i**2 in the plane (n = -(cos e1 + sin e2)); add the helix part.
        return frozen(np.hypot(self.e1, self.e2) + np.abs(self.helix) / self.length)


class _ArcQueries:
    """Queries common to Arc and Arc3D, answered by their `_frame`."""

    _frame: _Frame
    start: Array
    end: Array

    @property
    def dim(self) -> int:
        return int(self.start.size)

    @property
    def length(self) -> float:
        """Path length (for a helix, including the linear axes)."""
        return self._frame.length

    @property
    def radius(self) -> float:
        return self._frame.radius

    @property
    def sweep(self) -> float:
        """Angle turned about the centre, radians (> 0; 2*pi for a full circle)."""
        return self._frame.sweep

    @property
    def circle_centre(self) -> Array:
        """Centre of the circle at the start (N axes)."""
        return self._frame.centre

    @property
    def basis(self) -> tuple[Array, Array]:
        """(e1, e2): unit vectors centre->start and direction of motion at the start."""
        return self._frame.e1, self._frame.e2

    @property
    def start_tangent(self) -> Array:
        return self._frame.t_start

    @property
    def end_tangent(self) -> Array:
        return self._frame.t_end

    @property
    def max_curvature(self) -> float:
        out = self.__dict__.get("_kappa")
        if out is None:
            out = self.__dict__["_kappa"] = self._frame.kappa
        return out

    @property
    def max_abs_tangent(self) -> Array:
        """Per axis, the largest |tangent component| along the arc (exact for circles;
        computed once: the look-ahead asks for it at every re-plan)."""
        out = self.__dict__.get("_mat")
        if out is None:
            out = self.__dict__["_mat"] = self._frame.max_abs_tangent()
        return out

    @property
    def axis_accel_weight(self) -> Array:
        """Per axis, an upper bound of sqrt(t_i**2 + n_i**2) along the arc (n: unit normal;
        computed once)."""
        out = self.__dict__.get("_aaw")
        if out is None:
            out = self.__dict__["_aaw"] = self._frame.axis_accel_weight()
        return out

    def point(self, s: ArrayLike) -> Array:
        """Point at path position s; shape s.shape + (N,)."""
        return self._frame.point(s)

    def tangent(self, s: ArrayLike) -> Array:
        """Unit tangent at s; shape s.shape + (N,)."""
        return self._frame.tangent(s)

    def curvature(self, s: ArrayLike) -> Any:
        """Curvature 1/R (R/(R**2+c**2) for a helix): float for scalar s, else an array."""
        return self._frame.curvature(s)

    @property
    def is_planar(self) -> bool:
        """True for a circular arc (no helix: every axis outside the circle's plane fixed)."""
        return not np.any(self._frame.helix)

    @property
    def end_correction(self) -> float:
        """Length of the end correction spread along the arc (0 up to rounding when the end
        was exactly on the circle; up to `tol`*R for an Arc whose end was off it)."""
        f = self._frame
        return float(np.linalg.norm(f.lin - f.helix))

    def sub(self, s0: float, s1: float) -> Any:
        """The part of the arc between path positions s0 < s1, as an arc of the same type
        with the same circle, radius and direction; it passes through the same points, and
        an end kept from this arc (s0 = 0, s1 = length) is that end bit for bit."""
        a = check_finite("s0", s0)
        b = check_finite("s1", s1)
        if not 0.0 <= a < b <= self.length:
            raise MotionError(f"s0 and s1 must satisfy 0 <= s0 < s1 <= length="
                              f"{self.length:.17g}, got s0={s0!r}, s1={s1!r}")
        if a == 0.0 and b == self.length:
            return self
        return self._with_frame(self._frame.sub(a, b))

    def _with_frame(self, frame: _Frame) -> Any:
        raise NotImplementedError


def _plane_axes(plane: Any, dim: int) -> tuple[int, int]:
    try:
        i, j = (int(k) for k in plane)
        ok = all(float(k) == int(k) for k in plane)
    except (TypeError, ValueError):
        raise MotionError(f"plane must be two axis indices, got {plane!r}") from None
    if not ok or i == j or not (0 <= i < dim and 0 <= j < dim):
        raise MotionError(f"plane must be two different axis indices in [0, {dim - 1}], "
                          f"got {plane!r}")
    return i, j


@dataclass(frozen=True, eq=False)
class Arc(_ArcQueries):
    """Circular arc in the plane of axes `plane` = (i, j); other axes move linearly (helix).

    `centre` gives the centre's plane coordinates: either 2 values (c_i, c_j) or a full point
    of N axes (only axes i, j are used). `end` is a full point; its plane coordinates must
    lie on the circle through `start` within `tol` * radius, else "arc command error".
    End equal to start in the plane (within tol * radius) means a full circle; `turns` adds
    whole extra turns. CCW turns from axis i towards axis j.
    """

    start: Array
    centre: Array
    end: Array
    plane: tuple[int, int] = (0, 1)
    direction: Direction = Direction.CCW
    turns: int = 0
    tol: float = ARC_TOL
    _frame: _Frame = field(init=False, repr=False)

    def __post_init__(self) -> None:
        start = as_point("start", self.start)
        n = start.size
        end = as_point("end", self.end, n)
        centre_in = as_point("centre", self.centre)
        if centre_in.size not in (2, n):
            raise MotionError(f"centre must have 2 (plane) or {n} axes, got {centre_in.size}")
        i, j = _plane_axes(self.plane, n)
        direction = parse_direction(self.direction)
        if isinstance(self.turns, bool) or not isinstance(self.turns, (int, np.integer)) \
                or not 0 <= self.turns <= COUNT_MAX:
            raise MotionError(f"turns must be an integer with 0 <= n <= {COUNT_MAX}, "
                              f"got {self.turns!r}")
        tol = check_nonnegative("tol", self.tol)
        cp = centre_in if centre_in.size == 2 else centre_in[[i, j]]
        centre = start.copy()
        centre[[i, j]] = cp
        rs = start[[i, j]] - cp
        radius = math.hypot(rs[0], rs[1])
        if not radius >= RADIUS_MIN:
            raise MotionError(f"centre must differ from start in the plane (radius > 0, at "
                              f"least {RADIUS_MIN:g}: a smaller circle is a point), got "
                              f"radius {radius:g}")
        re = end[[i, j]] - cp
        miss = abs(math.hypot(re[0], re[1]) - radius)
        if miss > tol * radius:
            raise MotionError(
                f"arc command error: end is {miss:.6g} from the circle of radius {radius:.6g} "
                f"(tol {tol:g} x radius = {tol * radius:.6g})")
        sign = 1.0 if direction is Direction.CCW else -1.0
        e1 = np.zeros(n)
        e2 = np.zeros(n)
        e1[[i, j]] = rs / radius
        e2[i], e2[j] = -sign * e1[j], sign * e1[i]
        chord = math.hypot(*(end[[i, j]] - start[[i, j]]))
        if chord <= tol * radius:
            sweep = TWO_PI
        else:
            sweep = math.atan2(float(re @ e2[[i, j]]), float(re @ e1[[i, j]])) % TWO_PI
            if sweep == 0.0:  # chord > tol*R rules this out except for rounding
                sweep = TWO_PI
        sweep += TWO_PI * int(self.turns)
        helix = end - start
        helix[[i, j]] = 0.0
        frame = _Frame(frozen(centre), frozen(e1), frozen(e2), radius, sweep, frozen(helix),
                       start, end)
        for name, value in (("start", start), ("end", end), ("centre", frozen(centre)),
                            ("plane", (i, j)), ("direction", direction),
                            ("turns", int(self.turns)), ("tol", tol), ("_frame", frame)):
            object.__setattr__(self, name, value)

    def _with_frame(self, frame: _Frame) -> Arc:
        obj = object.__new__(Arc)
        turns = max(0, math.ceil(frame.sweep / TWO_PI - 1e-12) - 1)
        for name, value in (("start", frame.start), ("end", frame.end),
                            ("centre", frame.centre), ("plane", self.plane),
                            ("direction", self.direction), ("turns", turns), ("tol", self.tol),
                            ("_frame", frame)):
            object.__setattr__(obj, name, value)
        return obj

    @classmethod
    def relative(cls, start: ArrayLike, centre_offset: ArrayLike, end_offset: ArrayLike,
                 plane: tuple[int, int] = (0, 1), direction: Direction = Direction.CCW,
                 turns: int = 0, tol: float = ARC_TOL) -> Arc:
        """Arc from offsets relative to `start` (HSL start_r_arc / G-code I, J convention).

        `centre_offset` has 2 (plane) or N values; `end_offset` has N values.
        """
        st = as_point("start", start)
        co = as_point("centre_offset", centre_offset)
        if co.size not in (2, st.size):
            raise MotionError(f"centre_offset must have 2 (plane) or {st.size} axes, "
                              f"got {co.size}")
        eo = as_point("end_offset", end_offset, st.size)
        i, j = _plane_axes(plane, st.size)
        centre = st[[i, j]] + (co if co.size == 2 else co[[i, j]])
        return cls(st, centre, st + eo, plane=(i, j), direction=direction, turns=turns, tol=tol)


@dataclass(frozen=True, eq=False)
class Arc3D(_ArcQueries):
    """Arc from `start` through `via` to `end` in any orientation (MCCL MCC_ArcXYZ).

    Works for N >= 2 axes (the circle lies in the 2-plane of the three points). The three
    points must be distinct and not collinear, else "arc command error".
    """

    start: Array
    via: Array
    end: Array
    _frame: _Frame = field(init=False, repr=False)

    def __post_init__(self) -> None:
        p0 = as_point("start", self.start)
        p1 = as_point("via", self.via, p0.size)
        p2 = as_point("end", self.end, p0.size)
        a = p1 - p0
        b = p2 - p0
        aa, bb, ab = float(a @ a), float(b @ b), float(a @ b)
        if aa == 0.0 or bb == 0.0 or float((p2 - p1) @ (p2 - p1)) == 0.0:
            raise MotionError("arc command error: start, via and end must be three "
                              "distinct points")
        gram = aa * bb - ab * ab
        if gram <= (COLLINEAR_SIN**2) * aa * bb:
            raise MotionError("arc command error: start, via and end are collinear "
                              "(no circle passes through them)")
        # Centre c = p0 + alpha*a + beta*b with |c-p0| = |c-p1| = |c-p2|:
        #   [aa ab; ab bb] [alpha; beta] = [aa/2; bb/2]
        alpha = 0.5 * bb * (aa - ab) / gram
        beta = 0.5 * aa * (bb - ab) / gram
        centre = p0 + alpha * a + beta * b
        r0 = p0 - centre
        radius = float(np.linalg.norm(r0))
        e1 = r0 / radius
        w = b - (b @ e1) * e1
        if float(np.linalg.norm(w)) <= 1e-9 * math.sqrt(bb):  # end opposite start: use via
            w = a - (a @ e1) * e1
        w = w / np.linalg.norm(w)

        def angle(p: Array) -> float:
            q = p - centre
            return math.atan2(float(q @ w), float(q @ e1)) % TWO_PI

        phi_via, phi_end = angle(p1), angle(p2)
        if phi_via < phi_end:
            e2, sweep = w, phi_end
        else:
            e2, sweep = -w, TWO_PI - phi_end
        frame = _Frame(frozen(centre), frozen(e1), frozen(e2), radius, sweep,
                       frozen(np.zeros_like(p0)), p0, p2)
        for name, value in (("start", p0), ("via", p1), ("end", p2), ("_frame", frame)):
            object.__setattr__(self, name, value)

    def _with_frame(self, frame: _Frame) -> Arc3D:
        obj = object.__new__(Arc3D)
        mid = frozen(np.array(frame.point(0.5 * frame.length)))
        for name, value in (("start", frame.start), ("via", mid), ("end", frame.end),
                            ("_frame", frame)):
            object.__setattr__(obj, name, value)
        return obj

    @classmethod
    def from_frame(cls, centre: ArrayLike, e1: ArrayLike, e2: ArrayLike, radius: float,
                   sweep: float, *, start: ArrayLike | None = None,
                   end: ArrayLike | None = None, end_slack: float = 0.0) -> Arc3D:
        """Arc of `radius` about `centre` from centre + R*e1, turning `sweep` towards e2.

        e1, e2 must be orthonormal; exact `start`/`end` (off the circle points by rounding
        only: 1e-9*R + 1e-12*|centre|) may be given so neighbouring elements join bit for bit.
        `end_slack` (>= 0) lets `end` be that much further off; the miss is spread linearly
        along s like an Arc's end tolerance (a fillet between arcs that are slight spirals).
        """
        c = as_point("centre", centre)
        u = as_point("e1", e1, c.size)
        v = as_point("e2", e2, c.size)
        r = check_positive("radius", radius)
        sw = check_positive("sweep", sweep)
        if sw > TWO_PI:
            raise MotionError(f"sweep must be <= 2*pi, got {sweep!r}")
        extra = check_nonnegative("end_slack", end_slack)
        if abs(u @ u - 1.0) > 1e-9 or abs(v @ v - 1.0) > 1e-9 or abs(u @ v) > 1e-9:
            raise MotionError("e1 and e2 must be orthonormal")
        p0 = c + r * u
        p2 = c + r * (math.cos(sw) * u + math.sin(sw) * v)
        mid = c + r * (math.cos(sw / 2) * u + math.sin(sw / 2) * v)
        slack = 1e-9 * r + 1e-12 * max(1.0, float(np.max(np.abs(c))))
        if start is not None:
            p0 = _near("start", start, p0, slack)
        if end is not None:
            p2 = _near("end", end, p2, slack + extra)
        obj = object.__new__(cls)
        frame = _Frame(c, u, v, r, sw, frozen(np.zeros_like(c)), frozen(p0), frozen(p2))
        for name, value in (("start", frozen(p0)), ("via", frozen(mid)), ("end", frozen(p2)),
                            ("_frame", frame)):
            object.__setattr__(obj, name, value)
        return obj

    @classmethod
    def _planned(cls, centre: Array, e1: Array, e2: Array, radius: float, sweep: float,
                 start: Array, end: Array) -> Arc3D:
        """`from_frame` for an arc a planner built itself (path/blend.py): the same arc,
        without checking again what it made (orthonormal e1/e2, ends on the circle,
        finite read-only float64 arrays)."""
        for a in (centre, e1, e2, start, end):
            a.flags.writeable = False
        r, sw = float(radius), float(sweep)
        mid = centre + r * (math.cos(sw / 2) * e1 + math.sin(sw / 2) * e2)
        obj = object.__new__(cls)
        frame = _Frame(centre, e1, e2, r, sw, frozen(np.zeros_like(centre)), start, end)
        for name, value in (("start", start), ("via", frozen(mid)), ("end", end),
                            ("_frame", frame)):
            object.__setattr__(obj, name, value)
        return obj


    @classmethod
    def _blend_arc(cls, centre: Array, e1: Array, e2: Array, radius: float, sweep: float,
                   helix: Array, start: Array, end: Array, via: Array, length: float,
                   lin: Array, t_start: Array, t_end: Array, kappa: float,
                   max_abs_tangent: Array, axis_accel_weight: Array) -> Arc3D:
        """`_planned` with every derived value computed by the caller (path/blend.py's
        compiled corner: read-only arrays, the same formulas as `_Frame`'s)."""
        frame = object.__new__(_Frame)
        # (the instance dicts filled directly: what the frozen dataclasses' object.__setattr__
        # would store, at a third of its cost; a streaming join makes one arc per corner)
        frame.__dict__.update(centre=centre, e1=e1, e2=e2, radius=radius, sweep=sweep,
                              helix=helix, start=start, end=end, length=length, lin=lin,
                              t_start=t_start, t_end=t_end)
        obj = object.__new__(cls)
        obj.__dict__.update(start=start, via=via, end=end, _frame=frame,
                            _mat=max_abs_tangent, _aaw=axis_accel_weight, _kappa=kappa)
        return obj


def _near(name: str, value: ArrayLike, expected: Array, slack: float) -> Array:
    p = np.array(as_point(name, value, expected.size))
    miss = float(np.linalg.norm(p - expected))
    if miss > slack:
        raise MotionError(f"arc command error: {name} is {miss:.6g} from the arc "
                          f"(allowed {slack:.3g})")
    return p
