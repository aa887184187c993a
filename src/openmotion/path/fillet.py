"""Fillets: the circle tangent to a line or circular arc and the next one (the CAD fillet).

Used by `blend.blend_corner` for every corner that involves an arc. Both elements must lie
in one plane (helices and arcs in different planes are not filleted). The problem is
solved in plane coordinates centred on the corner P, x along the incoming tangent t1.
Near P each element is a curve through the origin with unit tangent t (t1 or t2), left
normal n and signed curvature k (> 0 turns left, 0 for a line). A fillet of radius r on the
side sigma = sign(turn) (h = sigma*r) has its centre on both offset curves

    F(p) = k*|p|**2 - 2*p.n + h*(2 - k*h) = 0

(the line p.n = h for k = 0, else the circle about n/k of radius 1/k - h). This form stays
well conditioned for nearly straight arcs (no far-away centres). Subtracting k2*F1 and
k1*F2 leaves a line, which is intersected with the curved one (a quadratic solved in its
stable form); of the candidates the one nearest the tangent-line guess is kept. The
tangent point follows from N = (n - k*C)/(1 - k*h) (the element's normal there), P_t = C - h*N,
and its distance along the element from the corner from N (or, for small angles, from
asin). The fillet turns sigma*(k1*d1 + turn + k2*d2) and its closest point to the corner is
at (|P_t|**2 + 2h*P_t.N)/(|C| + r) (no cancellation for large r).

The radius is the largest for which the fillet exists (inside an arc's circle: at most
99.9 % of its radius), its tangent points lie within `fraction` of each element from the
corner, it passes within the tolerance of the corner and stays within it of the elements
(15 inner points, checked on the result and, if needed, in a second bisection): these fail
from some radius on, so bracketing and bisection find it. The deviation counts what the
arcs' end corrections (an end only on the circle within tolerance, spread along s, see
arcs.py) and the model's rounding can add. The fillet is then built on the real elements
(their trim points and tangents, so the joints are exact) and its deviation measured
again; if that is beyond the tolerance, the radius is halved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import MotionError
from .arcs import Arc, Arc3D
from .geometry import Array, Line

#: Directions further than this from the common plane (per unit) mean "not coplanar".
PLANE_TOL = 1e-9
#: Bisection stops when the radius bracket is this narrow (relative).
_R_REL = 1e-12
_MAX_STEPS = 200
#: A fillet inside an arc's circle has at most (1 - _MIN_GAP) times its radius (beyond, the
#: tangent point runs away along the arc and the intersection is ill-conditioned).
_MIN_GAP = 1e-3
#: Rounding of the model, per unit of radius, counted into the deviation as
#: _ROUND*r*(1 + 1/sweep): a fillet that turns little meets its offset curves at a shallow
#: angle, so its centre (and tangent points) slide by about eps*r/sweep along them.
_ROUND = 1e-12
#: Halvings of the radius tried when the built fillet is beyond the tolerance.
_RETRIES = 8
#: The fillet's distance from the elements is checked at _SAMPLES - 1 inner points.
_SAMPLES = 16

Vec = tuple[float, float]


@dataclass(frozen=True)
class _Local:
    """One element near the corner, in plane coordinates."""

    t: Vec          # unit tangent at the corner (direction of travel)
    k: float        # signed curvature, > 0 turns left
    way: float      # -1: incoming (distance measured backwards), +1: outgoing
    reach: float    # largest allowed distance of the tangent point from the corner
    corr: float     # end correction of the element per unit of path length

    @property
    def n(self) -> Vec:
        return (-self.t[1], self.t[0])


@dataclass(frozen=True)
class _Solution:
    r: float
    sigma: float    # +1: the fillet turns left, -1: right
    centre: Vec
    p1: Vec
    p2: Vec
    d1: float       # path distance from the corner back to the first tangent point
    d2: float       # ... and on to the second
    sweep: float
    dev: float      # distance corner -> fillet (model, exact circles)
    bound: float    # dev plus what end corrections and rounding can add


def _dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1]


def _cross(a: Vec, b: Vec) -> float:
    return a[0] * b[1] - a[1] * b[0]


def _roots(a: float, b: float, c: float) -> list[float]:
    """Real roots of a*x**2 + b*x + c (a may be 0 or tiny), stable form."""
    if a == 0.0:
        return [-c / b] if b != 0.0 else []
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        if disc < -1e-12 * b * b:
            return []
        disc = 0.0
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    out = [c / q] if q != 0.0 else []
    out.append(q / a)
    return out


def _centres(e1: _Local, e2: _Local, h: float) -> list[Vec]:
    """Points on both offset curves F1 = F2 = 0 (see the module docstring)."""
    n1, n2 = e1.n, e2.n
    g1 = h * (2.0 - e1.k * h)
    g2 = h * (2.0 - e2.k * h)
    if e1.k == 0.0 and e2.k == 0.0:
        det = _cross(n1, n2)
        # p.n1 = g1/2, p.n2 = g2/2
        x = (0.5 * g1 * n2[1] - 0.5 * g2 * n1[1]) / det
        y = (0.5 * g2 * n1[0] - 0.5 * g1 * n2[0]) / det
        return [(x, y)]
    m = (e2.k * n1[0] - e1.k * n2[0], e2.k * n1[1] - e1.k * n2[1])
    c0 = 0.5 * (e2.k * g1 - e1.k * g2)
    mm = _dot(m, m)
    if mm == 0.0:
        return []
    p0 = (c0 * m[0] / mm, c0 * m[1] / mm)
    norm = math.sqrt(mm)
    w = (-m[1] / norm, m[0] / norm)
    el, g = (e1, g1) if abs(e1.k) >= abs(e2.k) else (e2, g2)
    n = el.n
    a = el.k
    b = 2.0 * (el.k * _dot(p0, w) - _dot(w, n))
    c = el.k * _dot(p0, p0) - 2.0 * _dot(p0, n) + g
    return [(p0[0] + lam * w[0], p0[1] + lam * w[1]) for lam in _roots(a, b, c)]


def _foot(el: _Local, centre: Vec, h: float) -> tuple[Vec, Vec, float] | None:
    """(tangent point, element normal there, distance from the corner) or None."""
    n = el.n
    den = 1.0 - el.k * h
    if den < _MIN_GAP:
        return None  # inside the arc's circle and (almost) as large: no useful fillet
    nx = (n[0] - el.k * centre[0]) / den
    ny = (n[1] - el.k * centre[1]) / den
    size = math.hypot(nx, ny)
    if abs(size - 1.0) > 1e-6:
        return None  # not on this offset curve (a spurious root)
    big_n = (nx / size, ny / size)
    p = (centre[0] - h * big_n[0], centre[1] - h * big_n[1])
    x = el.way * _dot(p, el.t)
    z = el.k * x
    if el.k == 0.0:
        d = x
    elif abs(z) < 0.5 and _dot(big_n, n) > 0.0:  # within a quarter turn: asin, no 1/k loss
        d = x * (math.asin(z) / z) if z != 0.0 else x
    else:
        d = el.way * math.atan2(_cross(n, big_n), _dot(n, big_n)) / el.k
    if not d > 0.0 or abs(el.k) * d >= math.pi:
        return None
    return p, big_n, d


def _solve(e1: _Local, e2: _Local, turn: float, r: float) -> _Solution | None:
    """The fillet of radius r, or None if it does not exist near the corner."""
    sigma = 1.0 if turn > 0.0 else -1.0
    h = sigma * r
    guess_line = _centres(_Local(e1.t, 0.0, -1.0, 0.0, 0.0), _Local(e2.t, 0.0, 1.0, 0.0, 0.0),
                          h)[0]
    cands = _centres(e1, e2, h)
    if not cands:
        return None
    centre = min(cands, key=lambda c: math.hypot(c[0] - guess_line[0], c[1] - guess_line[1]))
    f1 = _foot(e1, centre, h)
    f2 = _foot(e2, centre, h)
    if f1 is None or f2 is None:
        return None
    (p1, n1, d1), (p2, _, d2) = f1, f2
    sweep = sigma * (e1.k * d1 + turn + e2.k * d2)
    if not 0.0 < sweep < 2.0 * math.pi:
        return None
    # closest point of the fillet circle to the corner, if it lies on the fillet arc
    start = (-sigma * n1[0], -sigma * n1[1])   # unit, fillet centre -> p1 is -h*n1/r
    wv = (-centre[0], -centre[1])
    beta = math.atan2(sigma * _cross(start, wv), _dot(start, wv)) % (2.0 * math.pi)
    norm_c = math.hypot(*centre)
    if beta <= sweep:
        dev = abs(_dot(p1, p1) + 2.0 * h * _dot(p1, n1)) / (norm_c + r)
    else:
        dev = min(math.hypot(*p1), math.hypot(*p2))
    bound = dev + 2.0 * d1 * e1.corr + d2 * e2.corr + model_error(r, sweep)
    return _Solution(r, sigma, centre, p1, p2, d1, d2, sweep, dev, bound)


def model_error(radius: float, sweep: float) -> float:
    """Bound of the rounding in a fillet's computed geometry (see _ROUND)."""
    return _ROUND * radius * (1.0 + 1.0 / sweep)


def _ok(sol: _Solution | None, e1: _Local, e2: _Local, tol: float) -> bool:
    return sol is not None and sol.bound <= tol and sol.d1 <= e1.reach and sol.d2 <= e2.reach


def _distance(el: _Local, q: Vec) -> float:
    """Distance from q to the element near the corner (its curve on its own side of the
    corner; the corner itself when q projects beyond it)."""
    n, k = el.n, el.k
    qq = _dot(q, q)
    # the nearest point of the line/circle lies on the side of the corner where q.t has
    # its sign; off = ||q - c| - R| in a form without the far centre c = n/k
    off = abs(k * qq - 2.0 * _dot(q, n)) / (math.hypot(n[0] - k * q[0], n[1] - k * q[1]) + 1.0)
    return off if el.way * _dot(q, el.t) >= 0.0 else math.sqrt(qq)


def _contour(sol: _Solution, e1: _Local, e2: _Local) -> float:
    """Largest distance of the fillet from the two elements (15 points inside it)."""
    cx, cy = sol.centre
    ux, uy = (sol.p1[0] - cx) / sol.r, (sol.p1[1] - cy) / sol.r
    worst = 0.0
    for i in range(1, _SAMPLES):
        phi = sol.sigma * sol.sweep * i / _SAMPLES
        c, sn = math.cos(phi), math.sin(phi)
        q = (cx + sol.r * (c * ux - sn * uy), cy + sol.r * (sn * ux + c * uy))
        worst = max(worst, min(_distance(e1, q), _distance(e2, q)))
    return worst + (sol.bound - sol.dev)


def _best(e1: _Local, e2: _Local, turn: float, tol: float, r0: float) -> _Solution | None:
    """The largest-radius fillet that is _ok (bracket from r0, then bisect); if it strays
    more than tol from the elements (possible inside an arc), the largest that does not."""
    def cheap(r: float) -> _Solution | None:
        s = _solve(e1, e2, turn, r)
        return s if _ok(s, e1, e2, tol) else None

    def full(r: float) -> _Solution | None:
        s = cheap(r)
        return s if s is not None and _contour(s, e1, e2) <= tol else None

    sol = _largest(cheap, r0, math.inf)
    if sol is None or _contour(sol, e1, e2) <= tol:
        return sol
    return _largest(full, sol.r, sol.r)


def _largest(at: Any, r0: float, r_max: float) -> _Solution | None:
    """Largest r <= r_max with at(r) not None: bracket by doubling/halving from r0, then
    bisect (the conditions fail from some radius on)."""
    lo_sol = at(r0) if r0 < r_max else None
    if lo_sol is not None:
        lo, hi = r0, 2.0 * r0
        for _ in range(_MAX_STEPS):
            s = at(hi)
            if s is None:
                break
            lo, lo_sol, hi = hi, s, 2.0 * hi
        else:
            return lo_sol
    else:
        hi, lo = r0, 0.5 * r0
        for _ in range(_MAX_STEPS):
            lo_sol = at(lo)
            if lo_sol is not None:
                break
            hi, lo = lo, 0.5 * lo
        else:
            return None
    assert lo_sol is not None
    while hi - lo > _R_REL * hi:
        mid = 0.5 * (lo + hi)
        s = at(mid)
        if s is None:
            hi = mid
        else:
            lo, lo_sol = mid, s
    return lo_sol


def _plane(first: Any, second: Any, a: Array) -> Array | None:
    """Unit b completing the in-plane basis (a, b) of both elements, or None."""
    arcs = [el for el in (first, second) if not isinstance(el, Line)]
    e1, e2 = arcs[0].basis
    v = e1 if abs(float(e1 @ a)) <= abs(float(e2 @ a)) else e2
    b = v - float(v @ a) * a
    b = b / np.linalg.norm(b)

    def off(u: Array) -> float:
        return float(np.linalg.norm(u - float(u @ a) * a - float(u @ b) * b))

    dirs = [a]
    for el in (first, second):
        dirs += [el.direction] if isinstance(el, Line) else list(el.basis)
    return b if max(off(u) for u in dirs) <= PLANE_TOL else None


def _local(el: Any, a: Array, b: Array, way: float, fraction: float,
           tangent: Array) -> _Local:
    t = (float(tangent @ a), float(tangent @ b))
    size = math.hypot(*t)
    t = (t[0] / size, t[1] / size)
    reach = fraction * float(el.length)
    if isinstance(el, Line):
        return _Local(t, 0.0, way, reach, 0.0)
    e1, e2 = el.basis
    orient = float(e1 @ a) * float(e2 @ b) - float(e1 @ b) * float(e2 @ a)
    k = math.copysign(1.0 / el.radius, orient)
    return _Local(t, k, way, reach, el.end_correction / float(el.length))


@dataclass(frozen=True, eq=False)
class Fillet:
    """Result of `fillet`: the trimmed elements, the fillet arc and its deviation."""

    first: Any
    arc: Arc3D
    second: Any
    deviation: float


def fillet(first: Any, second: Any, tolerance: float, turn_cos: float, turn_sin: float,
           fraction: float) -> Fillet | None:
    """Fillet the corner first.end == second.start (validated by the caller; at least one
    element an Arc/Arc3D). `turn_cos`/`turn_sin`: cos and sin of half the interior angle.
    None when the elements are not coplanar circles/lines or no fillet fits."""
    for el in (first, second):
        if isinstance(el, (Arc, Arc3D)) and not el.is_planar:
            return None
    a = np.array(first.end_tangent, dtype=float)
    b = _plane(first, second, a)
    if b is None:
        return None
    e1 = _local(first, a, b, -1.0, fraction, first.end_tangent)
    e2 = _local(second, a, b, 1.0, fraction, second.start_tangent)
    turn = math.atan2(e2.t[1], e2.t[0])
    # tangent-line radius for the tolerance (the line-line closed form) to start from
    r0 = tolerance * turn_sin * (1.0 + turn_sin) / (turn_cos * turn_cos)
    sol = _best(e1, e2, turn, tolerance, r0)
    for _ in range(_RETRIES):
        if sol is None:
            return None
        try:
            out = _build(first, second, a, b, sol, tolerance)
        except MotionError:  # degenerate trim or frame (rounding at the limits)
            out = None
        if out is not None:
            return out
        # the built fillet came out beyond the tolerance (rounding in an ill-conditioned
        # corner): a smaller one
        sol = _solve(e1, e2, turn, 0.5 * sol.r)
        sol = sol if _ok(sol, e1, e2, tolerance) else None
    return None


def _build(first: Any, second: Any, a: Array, b: Array, sol: _Solution,
           tolerance: float) -> Fillet | None:
    corner = first.end
    if isinstance(first, Line):
        p1 = corner - first.direction * sol.d1
        f_first: Any = Line(first.start, p1)
    else:
        f_first = first.sub(0.0, max(0.0, first.length - sol.d1))
    if isinstance(second, Line):
        p2 = corner + second.direction * sol.d2
        f_second: Any = Line(p2, second.end)
    else:
        f_second = second.sub(min(sol.d2, second.length), second.length)
    if f_first.length == 0.0 or f_second.length == 0.0:
        return None
    t1 = np.array(f_first.end_tangent)
    t2 = np.array(f_second.start_tangent)
    tx, ty = float(t1 @ a), float(t1 @ b)
    side = sol.sigma * (-ty * a + tx * b)   # towards the fillet centre
    side = side - float(side @ t1) * t1
    side = side / np.linalg.norm(side)
    e1 = -side
    sweep = math.atan2(float(t2 @ side), float(t2 @ t1))
    sweep += 2.0 * math.pi * round((sol.sweep - sweep) / (2.0 * math.pi))
    if not 0.0 < sweep <= 2.0 * math.pi:
        return None
    # A fillet is no longer than the two stretches it replaces (equal for a straight
    # corner, (turn/2)/tan(turn/2) of them between lines). A huge nearly flat fillet
    # (unbounded G64 between two nearly tangent arcs) can come out the long way round
    # when rounding flips the tiny sweep: refuse it.
    if sol.r * sweep > 2.0 * (sol.d1 + sol.d2) + 1e-9 * max(1.0, sol.r):
        return None
    p_start = np.array(f_first.end)
    centre = p_start + side * sol.r
    ideal_end = centre + sol.r * (math.cos(sweep) * e1 + math.sin(sweep) * t1)
    p_end = np.array(f_second.start)
    miss = float(np.linalg.norm(p_end - ideal_end))
    shift = float(np.linalg.norm(p_start - (corner + sol.p1[0] * a + sol.p1[1] * b)))
    deviation = sol.dev + shift + miss
    scale = 1e-12 * max(1.0, float(np.max(np.abs(corner))))
    if deviation > tolerance * (1.0 + 1e-9) + scale:
        return None  # the model and the elements disagree beyond rounding
    arc = Arc3D.from_frame(centre, e1, t1, sol.r, sweep, start=p_start, end=p_end,
                           end_slack=miss)
    return Fillet(f_first, arc, f_second, deviation)
