"""Corners: arc blends within a path tolerance, junction speed limits, arc speed limits.

Blend (LinuxCNC G64 P, anchors b6). A corner with an arc on either side gets the circle
tangent to both elements (fillet.py); two lines get this closed form. Two lines meet at
the corner P with unit directions u1 (in) and u2 (out). With the half-angle theta of the
corner's interior angle 2*theta:

    cos(theta) = |u1 - u2| / 2,  sin(theta) = |u1 + u2| / 2     (no acos, exact near 0/90 deg)

a circle tangent to both lines at distance d from P has radius R = d*tan(theta), centre
P + n*d/cos(theta) (n: unit bisector (u2 - u1)/|u2 - u1|), and its midpoint lies
    dev = d/cos(theta) - R = d*(1 - sin(theta))/cos(theta)
from P: that is the largest distance between the blend and the programmed corner. dev <= T
gives d_tol = T*cos(theta)/(1 - sin(theta)) = T*(1 + sin(theta))/cos(theta); d is also at most
BLEND_DIST_FRACTION of each line, so two blends never overlap on a line.

Junction speed (grbl/Klipper, anchors b1), with Klipper's half-angle phi (cos(phi) = -u1.u2):
    sin(phi/2) = |u1 + u2|/2,  cos(phi/2) = |u1 - u2|/2
    R_jd = sin(phi/2)/(1 - sin(phi/2)) = sin(phi/2)*(1 + sin(phi/2))/cos(phi/2)**2
    delta = scv**2*(sqrt(2) - 1)/accel    (scv: speed allowed through a 90 degree corner)
    v**2 = accel*delta*R_jd,  and v**2 <= 0.5*L*accel*tan(phi/2) for each adjoining length L
(the approximating circle touches each move no further than its middle).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .. import _corner
from ..errors import MotionError, check_nonnegative, check_positive
from .arcs import Arc, Arc3D
from .fillet import fillet
from .geometry import Line, PathElement, as_point
from .geometry import vnorm as _norm

#: A blend may use at most this fraction of each line (LinuxCNC BLEND_DIST_FRACTION).
BLEND_DIST_FRACTION = 0.5
#: Turn angles below this (radians) are treated as straight: no blend, no corner limit.
#: Generous on purpose: the directions of short lines far from the origin carry rounding
#: of eps*|coordinate|/length, and a kink of 1e-6 rad changes the velocity by 1e-6*v.
TANGENT_ANGLE = 1e-6
#: Corners whose lines are within this angle (radians) of a full reversal need an exact stop.
REVERSAL_ANGLE = 1e-6
_SQRT2_M1 = math.sqrt(2.0) - 1.0
#: The most axes the compiled corner (openmotion._corner) takes.
_corner_max_dim = 64


@dataclass(frozen=True, eq=False)
class Blend:
    """A rounded corner: `first` trimmed, the tangent `arc`, `second` trimmed (a Line stays
    a Line, an Arc/Arc3D becomes a shorter one on the same circle)."""

    first: PathElement
    arc: Arc3D
    second: PathElement
    #: Distance between the programmed corner and the blend arc's closest point to it
    #: (how far the rounded path passes from the corner; <= the tolerance).
    deviation: float

    @property
    def elements(self) -> tuple[PathElement, Arc3D, PathElement]:
        return (self.first, self.arc, self.second)


def _unit(name: str, value: ArrayLike, dim: int | None = None) -> np.ndarray:
    v = as_point(name, value, dim)
    norm = float(np.linalg.norm(v))
    if norm == 0.0:
        raise MotionError(f"{name} must be a non-zero direction")
    return v / norm


def blend_corner(first: PathElement, second: PathElement, tolerance: float, *,
                 fraction: float = BLEND_DIST_FRACTION) -> Blend | None:
    """Round the corner first.end == second.start with an arc at most `tolerance` from it.

    first and second are Line, Arc or Arc3D elements. Two lines get the closed form above;
    a corner with an arc gets the fillet tangent to both (path/fillet.py), each element
    trimmed at its tangent point within `fraction` of its length from the corner.
    Returns None when no blend is wanted: tolerance 0, a zero-length element, a tangent
    corner (turn below TANGENT_ANGLE: nothing to round), a reversal (the path must stop
    exactly at the corner), a helix or elements not in one plane, or no fillet that fits.
    """
    kinds = (Line, Arc, Arc3D)
    if not isinstance(first, kinds) or not isinstance(second, kinds):
        raise MotionError("first and second must be Line, Arc or Arc3D elements")
    if first.dim != second.dim:
        raise MotionError(f"second must have {first.dim} axes like first, got {second.dim}")
    t = check_nonnegative("tolerance", tolerance)
    frac = check_positive("fraction", fraction)
    if frac > 0.5:
        raise MotionError(f"fraction must be in (0, 0.5], got {fraction!r}")
    if second.start is not first.end:
        g = second.start - first.end
        gap = _norm(g)
        scale = max(1.0, float(np.max(np.abs(first.end))))
        if gap > 1e-9 * scale:
            raise MotionError(f"second.start must equal first.end, they are {gap:.6g} apart")
    if t == 0.0 or first.length == 0.0 or second.length == 0.0:
        return None
    if isinstance(first, Line) and isinstance(second, Line):
        return _line_line(first, second, t, frac)
    u1, u2 = first.end_tangent, second.start_tangent
    cos_t = _norm(u1 - u2) / 2.0
    sin_t = _norm(u1 + u2) / 2.0
    turn = 2.0 * math.atan2(cos_t, sin_t)  # angle between u1 and u2
    if turn < TANGENT_ANGLE or math.pi - turn < REVERSAL_ANGLE:
        return None
    f = fillet(first, second, t, cos_t, sin_t, frac)
    return None if f is None else Blend(f.first, f.arc, f.second, f.deviation)


def _line_line(first: Line, second: Line, t: float, frac: float) -> Blend | None:
    """The closed form of the module doc for two lines (None for a straight corner or a
    reversal), computed by the compiled helper
    (`openmotion._corner`, one call per corner) and wrapped in the elements.
    tests/oracle_blend.py keeps the numpy construction this repeats (equal within
    rounding)."""
    dim = first.dim
    if dim > _corner_max_dim:
        return _line_line_numpy(first, second, t, frac)
    out = np.empty((_ROWS, dim))
    res = _corner.line_blend(out, first.start, first.end, second.end, first.direction,
                             second.direction, first.length, second.length, t, frac)
    if res is None:
        return None
    out.flags.writeable = False
    len1, len2, radius, turn, length, kappa, dev = res
    first_, arc, second_ = _pieces(list(out), first.start, second.end, len1, len2, radius,
                                   turn, length, kappa)
    return Blend(first_, arc, second_, dev)


#: Rows per corner of the compiled blend (src/openmotion/_blend.c, its module doc).
_ROWS = 15
_zeros: dict[int, np.ndarray] = {}


def _helix(dim: int) -> np.ndarray:
    """The helix of a blend arc (none: zeros), one read-only vector per axis count."""
    out = _zeros.get(dim)
    if out is None:
        out = _zeros[dim] = np.zeros(dim)
        out.flags.writeable = False
    return out


def _pieces(rows: list[np.ndarray], start: np.ndarray, end: np.ndarray, len1: float,
            len2: float, radius: float, turn: float, length: float, kappa: float
            ) -> tuple[Line, Arc3D, Line]:
    """The trimmed first line (from `start`), the blend arc and the trimmed second line (to
    `end`) around the rows of one compiled corner (read-only views)."""
    (centre, e1, e2, a_start, a_end, via, lin, t_start, t_end, mat, aaw, u1, au1, u2,
     au2) = rows
    arc = Arc3D._blend_arc(centre, e1, e2, radius, turn, _helix(centre.size), a_start, a_end,
                           via, length, lin, t_start, t_end, kappa, mat, aaw)
    return (Line._planned(start, a_start, len1, u1, au1), arc,
            Line._planned(a_end, end, len2, u2, au2))


def _line_run(first: Line, lines: Sequence[Line], tol: float,
              frac: float = BLEND_DIST_FRACTION, accel: Sequence[float] | None = None,
              feed: Sequence[float] | None = None
              ) -> list[tuple[Line, Arc3D, Line] | None]:
    """The corners first -> lines[0] -> lines[1] -> ... rounded one after the other, each
    corner's first line the second of the one before (trimmed when that one was rounded):
    per corner (trimmed first, arc, trimmed second) or None, what `blend_corner` gives
    corner after corner, bit for bit. For lines a planner made itself (1 to 64 axes,
    tol > 0, frac in (0, 0.5]: not checked again); the run stops before the first line
    that does not start exactly where the line before it ends (the result is shorter: that
    corner is `blend_corner`'s, with its gap check). With `accel` and `feed` (per corner)
    a blend is kept only where it pays (groupstream._blend_pays without a corner
    velocity). The whole run in one compiled call (openmotion._corner.line_run)."""
    m = len(lines)
    dim = first.start.size
    # per line its start, end and direction, one row each (the layout line_run reads)
    geo = np.array([first.start, first.end, first.direction,
                    *[v for ln in lines for v in (ln.start, ln.end, ln.direction)]])
    lengths = np.array([first.length, *[ln.length for ln in lines]])
    out = np.empty((m * _ROWS, dim))
    scal = np.empty((m, 8))
    acc = None if accel is None else np.array(accel, dtype=np.float64)
    fd = None if feed is None else np.array(feed, dtype=np.float64)
    done = _corner.line_run(out, scal, geo, lengths, acc, fd, tol, frac)
    out.flags.writeable = False
    rows = list(out)
    helix = _helix(dim)
    arc_of, line_of = Arc3D._blend_arc, Line._planned
    result: list[tuple[Line, Arc3D, Line] | None] = []
    start = first.start
    k = 0
    for ln, (keep, len1, len2, radius, turn, length, kappa, _) in zip(
            lines[:done], scal[:done].tolist(), strict=True):
        if keep:  # (_pieces, inlined: a join makes one per corner)
            (centre, e1, e2, a_start, a_end, via, lin, t_start, t_end, mat, aaw, u1, au1, u2,
             au2) = rows[k:k + _ROWS]
            result.append((line_of(start, a_start, len1, u1, au1),
                           arc_of(centre, e1, e2, radius, turn, helix, a_start, a_end, via,
                                  length, lin, t_start, t_end, kappa, mat, aaw),
                           line_of(a_end, ln.end, len2, u2, au2)))
            start = a_end
        else:
            result.append(None)
            start = ln.start
        k += _ROWS
    return result


def _line_line_numpy(first: Line, second: Line, t: float, frac: float) -> Blend | None:
    """`_line_line` in numpy (more axes than the compiled helper takes)."""
    u1, u2 = first.end_tangent, second.start_tangent
    cos_t = _norm(u1 - u2) / 2.0
    sin_t = _norm(u1 + u2) / 2.0
    turn = 2.0 * math.atan2(cos_t, sin_t)  # angle between u1 and u2
    if turn < TANGENT_ANGLE or math.pi - turn < REVERSAL_ANGLE:
        return None
    corner = first.end
    d_tol = t * (1.0 + sin_t) / cos_t
    d = min(frac * first.length, frac * second.length, d_tol)
    radius = d * sin_t / cos_t
    diff = u2 - u1
    normal = diff / _norm(diff)
    centre = corner + normal * (d / cos_t)
    a_start = corner - u1 * d
    a_end = corner + u2 * d
    # centre -> arc start is -(u1*d + normal*d/cos): built from unit vectors, not from
    # differences of (possibly large) coordinates, so tiny blends keep exact tangents.
    e1 = -(u1 * cos_t + normal)
    e1 = e1 - (e1 @ u1) * u1
    e1 = e1 / _norm(e1)
    e2 = u1 - (u1 @ e1) * e1
    e2 = e2 / _norm(e2)
    # everything here is the planner's own, finite and checked by construction
    arc = Arc3D._planned(centre, e1, e2, radius, turn, a_start, a_end)
    dev = d * (1.0 - sin_t) / cos_t
    return Blend(Line.between(first.start, a_start), arc, Line.between(a_end, second.end),
                 dev)


def corner_speed(u1: ArrayLike, u2: ArrayLike, accel: float, square_corner_velocity: float,
                 *, lengths: tuple[float, float] | None = None) -> float:
    """Junction-deviation speed limit for a sharp corner from direction u1 to u2.

    `square_corner_velocity` is the speed allowed through a 90 degree corner (Klipper);
    `lengths` (of the two moves) adds the "circle touches each move no further than its
    middle" cap. Straight on: inf. Full reversal: 0 (exact stop).
    """
    a = _unit("u1", u1)
    b = _unit("u2", u2, a.size)
    acc = check_positive("accel", accel)
    scv = check_nonnegative("square_corner_velocity", square_corner_velocity)
    caps = ()
    if lengths is not None:
        try:
            caps = tuple(check_nonnegative("lengths", x) for x in lengths)
        except TypeError:
            raise MotionError(f"lengths must be two lengths, got {lengths!r}") from None
        if len(caps) != 2:
            raise MotionError(f"lengths must be two lengths, got {lengths!r}")
    sin_h = float(np.linalg.norm(a + b)) / 2.0
    cos_h = float(np.linalg.norm(a - b)) / 2.0
    if cos_h == 0.0:
        return math.inf
    v2 = scv * scv * _SQRT2_M1 * sin_h * (1.0 + sin_h) / (cos_h * cos_h)
    tan_h = sin_h / cos_h
    for length in caps:
        v2 = min(v2, 0.5 * length * acc * tan_h)
    return math.sqrt(v2)


def centripetal_speed(radius: float, normal_accel: float) -> float:
    """Fastest speed on a curve of `radius` with at most `normal_accel` sideways: sqrt(a*R)."""
    r = check_nonnegative("radius", radius)
    a = check_nonnegative("normal_accel", normal_accel)
    return math.sqrt(a * r)
