"""Look-ahead: entry, cruise and exit speeds along a sequence of path elements.

Pure function of the geometry and the limits (anchors b1: grbl planner_recalculate,
Klipper LookAheadQueue.flush). Everything is in v**2, where constant acceleration a over a
length L is linear: v1**2 = v0**2 + 2*a*L.

1. Per element: the tangential acceleration `a_k` and the speed cap `vmax_k`.
   Lines: a_k = min(accel, amax_i/|u_i|), vmax_k = min(feed, vmax_i/|u_i|).
   Arcs: the total acceleration sqrt(a_t**2 + a_n**2) is split as in LinuxCNC (anchors b6):
   a_t = r*A, a_n = sqrt(1 - r**2)*A with r = arc_tangential_ratio and
   A = min(accel, amax_i/w_i), w_i >= sqrt(t_i**2 + n_i**2) along the arc, so every axis
   acceleration |a_t*t_i + a_n*n_i| <= A*w_i <= amax_i (Cauchy-Schwarz). Centripetal cap:
   kappa*v**2 <= a_n. Axis speeds: v*max|t_i| <= vmax_i.
2. Junction caps: the smaller of both neighbours' vmax and, when the tangent turns, the
   junction-deviation corner speed (blend.corner_speed) with the acceleration limited per
   axis along u2 - u1 (grbl's limit_value_by_axis_maximum), and v*|u2_i - u1_i| <= vjump_i
   (the step of axis i's velocity at the corner) when `axis_vjump` is given.
3. Backward pass from the end speed at the deceleration d_k (`decel`, default the
   acceleration), then forward pass from the start speed at the acceleration a_k.
4. Cruise: the highest speed reachable between entry and exit:
   v**2 = (d*vin**2 + a*vout**2 + 2*a*d*L)/(a + d), i.e. (vin**2+vout**2)/2 + a*L for d = a.
5. Minimum cruise ratio r (Klipper's minimum_cruise_ratio, anchors b1), when r > 0: steps
   3 and 4 run once more on lowered caps. A smoothed plan W (steps 3 with the pseudo
   acceleration a_s = (1 - r)*a_k) sets them. Each element of W is rising (W climbs by the
   full 2*a_s*L), falling (drops by it) or a peak (anything else); hills of W end at
   valleys, junctions with no rising element before and no falling element after them.
   On each hill the planned speed stays at or below the hill's top (the highest speed of
   W on it; Klipper's peak_cruise_v2), rises monotonically up to the hill's peak element
   and falls monotonically after it (Klipper only enforces the falling side). So a short
   element between two corners of equal speed v_c cruises for the fraction r of its
   length at v**2 = v_c**2 + a_s*L instead of accelerating and braking back to back, and
   a hill gives at most one speed maximum: lower r, more hills, more sign changes of the
   acceleration. W itself obeys every cap, so the result is never slower than W and obeys
   every limit of steps 1-3 (it is step 3 on lower caps); from a start speed W cannot
   brake from, the real braking curve stays allowed. r = 0 skips this step.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .. import _corner
from ..errors import InfeasibleError, MotionError, check_nonnegative, check_positive
from .arcs import Arc, Arc3D
from .blend import TANGENT_ANGLE, corner_speed
from .geometry import Array, Line, PathElement, vnorm

#: Element types checked by a plain isinstance (the Protocol check is slow).
_KNOWN = (Line, Arc, Arc3D)
#: openmotion's own element types found to be path elements: typing's runtime Protocol
#: check reads every member of the instance (properties included), ~18 us an element, so
#: each of ours (pathexec.Trimmed ...) is checked in full once; a user's type, whose
#: instances may differ, every time.
_ELEMENT_TYPES: set[type] = set(_KNOWN)


def _is_element(el: object) -> bool:
    if type(el) in _ELEMENT_TYPES:
        return True
    if isinstance(el, PathElement):
        if type(el).__module__.startswith("openmotion."):
            _ELEMENT_TYPES.add(type(el))
        return True
    return False


@dataclass(frozen=True)
class ElementSpeeds:
    """Planned speeds of one element: accelerate at `accel` from `entry` up to `cruise`,
    hold, decelerate at `decel` (default `accel`) to `exit` (trapezoid along the path)."""

    entry: float
    cruise: float
    exit: float
    accel: float
    vmax: float
    length: float
    decel: float = math.nan

    def __post_init__(self) -> None:
        if math.isnan(self.decel):
            object.__setattr__(self, "decel", self.accel)

    @property
    def duration(self) -> float:
        """Time of the trapezoid entry -> cruise -> exit over `length`."""
        if self.length == 0.0 or self.cruise == 0.0:
            return 0.0
        a, d, vc = self.accel, self.decel, self.cruise
        d_acc = (vc * vc - self.entry**2) / (2.0 * a)
        d_dec = (vc * vc - self.exit**2) / (2.0 * d)
        hold = max(0.0, self.length - d_acc - d_dec)
        return (vc - self.entry) / a + (vc - self.exit) / d + hold / vc


def _axis_limits(name: str, value: ArrayLike | None, dim: int) -> Array | None:
    if value is None:
        return None
    try:
        arr = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be {dim} positive numbers, got {value!r}") from None
    if arr.size != dim or np.any(np.isnan(arr)) or np.any(arr <= 0.0):
        raise MotionError(f"{name} must be {dim} numbers > 0 (inf = unlimited), got {value!r}")
    return arr


def _limit_along(limit: float, axis: Array | None, weight: Array) -> float:
    """min(limit, axis_i / weight_i) over axes with weight_i > 0 (compiled: _chain.c; the
    Python oracle is tests/oracle_chain.py). A denormal weight gives inf (no limit), as
    numpy's quotient does."""
    if axis is None:
        return limit
    try:
        return _corner.limit_along(limit, axis, weight)
    except (ValueError, TypeError, BufferError):  # not two float64 arrays (a user's type)
        return _corner.limit_along(limit, np.ascontiguousarray(axis, dtype=np.float64),
                                   np.ascontiguousarray(weight, dtype=np.float64))


#: Memo of `_element_limits`: one entry per element, its last parameters and result. The
#: elements are immutable and a streaming chain asks about the same ones at every re-plan
#: (most of a long chain's planning time otherwise). Weak keys: no element is kept alive.
_LIMITS: weakref.WeakKeyDictionary[Any, tuple[tuple, tuple[float, float]]] = \
    weakref.WeakKeyDictionary()


def _axes_key(vmax_ax: Array | None, amax_ax: Array | None) -> tuple:
    """The per-axis part of `_element_limits`' memo key (computed once per plan)."""
    return (None if vmax_ax is None else vmax_ax.tobytes(),
            None if amax_ax is None else amax_ax.tobytes())


def _element_limits(el: PathElement, feed: float, accel: float, vmax_ax: Array | None,
                    amax_ax: Array | None, ratio: float,
                    axes_key: tuple | None = None) -> tuple[float, float]:
    """(tangential accel, speed cap) of one element (memoized). `axes_key`: the
    caller's `_axes_key(vmax_ax, amax_ax)`, when it asks for many elements."""
    key = (feed, accel, ratio) + (_axes_key(vmax_ax, amax_ax) if axes_key is None
                                  else axes_key)
    try:
        hit = _LIMITS.get(el)
    except TypeError:  # an element that is not hashable or weak-referenceable
        return _limits_of(el, feed, accel, vmax_ax, amax_ax, ratio)
    if hit is not None and hit[0] == key:
        return hit[1]
    out = _limits_of(el, feed, accel, vmax_ax, amax_ax, ratio)
    _LIMITS[el] = (key, out)
    return out


#: Memo of `_tangential_decel` (as `_LIMITS`, for a deceleration set apart).
_DEC_LIMITS: weakref.WeakKeyDictionary[Any, tuple[tuple, float]] = weakref.WeakKeyDictionary()


def _tangential_decel(el: PathElement, decel: float, amax_ax: Array | None,
                      ratio: float) -> float:
    """Tangential deceleration of one element (`_element_limits`' first value with the
    deceleration; memoized separately so both stay cached)."""
    key = (decel, ratio, None if amax_ax is None else amax_ax.tobytes())
    try:
        hit = _DEC_LIMITS.get(el)
    except TypeError:
        return _limits_of(el, math.inf, decel, None, amax_ax, ratio)[0]
    if hit is not None and hit[0] == key:
        return hit[1]
    out = _limits_of(el, math.inf, decel, None, amax_ax, ratio)[0]
    _DEC_LIMITS[el] = (key, out)
    return out


def _limits_of(el: PathElement, feed: float, accel: float, vmax_ax: Array | None,
               amax_ax: Array | None, ratio: float) -> tuple[float, float]:
    vmax = _limit_along(feed, vmax_ax, el.max_abs_tangent)
    kappa = el.max_curvature
    if kappa == 0.0:
        return _limit_along(accel, amax_ax, el.max_abs_tangent), vmax
    total = _limit_along(accel, amax_ax, el.axis_accel_weight)
    a_n = math.sqrt(1.0 - ratio * ratio) * total
    return ratio * total, min(vmax, math.sqrt(a_n / kappa))


def _junction_cap(prev: PathElement, nxt: PathElement, accel: float, scv: float,
                  amax_ax: Array | None, vjump_ax: Array | None) -> float:
    u1, u2 = prev.end_tangent, nxt.start_tangent
    diff = u2 - u1
    chord = vnorm(diff)
    if 2.0 * math.asin(min(1.0, chord / 2.0)) < TANGENT_ANGLE:
        return math.inf
    a_j = _limit_along(accel, amax_ax, np.abs(diff) / chord)
    # Klipper's deviation is set by the nominal accel; a lower axis-limited accel lowers
    # v**2 proportionally: scale scv by sqrt(a_j/accel).
    v = corner_speed(u1, u2, a_j, scv * math.sqrt(a_j / accel),
                     lengths=(prev.length, nxt.length))
    # axis i's velocity steps by v*|u2_i - u1_i| at the corner
    return _limit_along(v, vjump_ax, np.abs(diff))


#: The compiled `_prepare`'s memo (_chain_prep.c): the last calls' elements, held weakly,
#: with their limits and junction caps; a streaming chain's re-plan recomputes only the
#: elements and junctions that are new or whose feed or acceleration changed.
_PREP_MEMO: list = []
#: Chords |u2 - u1| below this are tangent junctions (`_junction_cap` returns inf) however
#: numpy's dot product rounds: 2*asin(c/2) >= c, and the margin covers the few ulps by
#: which two summation orders of c**2 can differ.
_TANGENT_CHORD = TANGENT_ANGLE * (1.0 - 1e-9)
#: What the compiled prepare needs besides the arguments (its ctx).
_PREP_CTX = (_ELEMENT_TYPES, _is_element, Line, Arc, Arc3D, _TANGENT_CHORD, _junction_cap,
             _PREP_MEMO)


def _passes(jcap2: list[float], acc: list[float], length: list[float],
            start2: float, dec: list[float] | None = None) -> tuple[list[float], list[float]]:
    """Backward pass from the junction caps (v**2) at the decelerations `dec` (default
    `acc`), then forward pass from start2 at the accelerations (compiled: _chain.c; the
    Python oracle is tests/oracle_chain.py)."""
    return _corner.passes(jcap2, acc, length, start2, dec)


def _cruise_caps(jcap2: list[float], cap2: list[float], acc: list[float],
                 length: list[float], ratio: float,
                 start2: float, dec: list[float] | None = None) -> tuple[list[float], list[float]]:
    """Element and junction caps (v**2) of the minimum cruise ratio (module doc, step 5).

    The smoothed plan W uses the pseudo-acceleration (1 - ratio)*a_k. Its elements are
    rising (W climbs by the full 2*a_s*L), falling (W drops by it) or peaks (anything
    else); a valley, where a hill ends, is a junction with no rising element before it
    and no falling element after it. Within a hill, the junction caps become running
    minima towards the hill's peak element and at most the hill's top (the highest
    smoothed speed on it), rising elements are capped by their exit junction, falling
    ones by their entry junction, the peak element by the top. The braking curve from the
    start speed at the real acceleration is always allowed, so a feasible start stays
    feasible.
    """
    n = len(length)
    dec = acc if dec is None else dec
    acc_s = [(1.0 - ratio) * a for a in acc]
    dec_s = acc_s if dec is acc else [(1.0 - ratio) * d for d in dec]
    _, w = _passes(jcap2, acc_s, length, start2, dec_s)
    top = [min(cap2[k], _peak2(w[k], w[k + 1], acc_s[k], dec_s[k], length[k]))
           for k in range(n)]
    kind = []  # +1 rising, -1 falling, 0 peak
    for k in range(n):
        d = 2.0 * acc_s[k] * length[k]
        dd = d if dec_s is acc_s else 2.0 * dec_s[k] * length[k]
        tol = 1e-12 * (max(w[k], w[k + 1]) + max(d, dd))
        kind.append(1 if w[k] + d <= w[k + 1] + tol else
                    -1 if w[k + 1] + dd <= w[k] + tol else 0)
    new_cap = cap2[:]
    new_j = jcap2[:]
    lo = 0
    while lo < n:  # one hill: elements lo .. hi-1
        hi = lo + 1
        while hi < n and (kind[hi - 1] == 1 or kind[hi] == -1):
            hi += 1
        t = max(top[lo:hi])
        p = lo + top[lo:hi].index(t)
        run = t
        for j in range(p, lo, -1):  # rising side: junctions lo+1 .. p
            run = min(run, jcap2[j])
            new_j[j] = run
        run = t
        for j in range(p + 1, hi):  # falling side: junctions p+1 .. hi-1
            run = min(run, jcap2[j])
            new_j[j] = run
        for k in range(lo, hi):
            new_cap[k] = min(cap2[k], new_j[k + 1] if k < p else t if k == p else new_j[k])
        lo = hi
    # the braking curve from the start speed (the smoothed plan may not start that fast)
    brake = start2
    for k in range(n):
        if brake <= 0.0:
            break
        new_cap[k] = max(new_cap[k], min(cap2[k], brake))
        new_j[k] = max(new_j[k], min(jcap2[k], brake))
        brake -= 2.0 * dec[k] * length[k]
    for k in range(1, n):
        new_j[k] = min(new_j[k], new_cap[k - 1], new_cap[k])
    new_j[0] = min(new_j[0], new_cap[0])
    new_j[n] = min(new_j[n], new_cap[n - 1])
    return new_cap, new_j


def _peak2(in2: float, out2: float, a: float, d: float, length: float) -> float:
    """v**2 of the highest point of accelerating at a from in2 and decelerating at d to
    out2 over `length`: in2 + 2*a*x = out2 + 2*d*(length - x)."""
    if a == d:
        return 0.5 * (in2 + out2) + a * length
    return (d * in2 + a * out2 + 2.0 * a * d * length) / (a + d)


def _per_element(name: str, value: float | Sequence[float], n: int) -> list[float]:
    """One positive value per element from a scalar or a sequence of n values."""
    if isinstance(value, (int, float, np.floating)) and not isinstance(value, bool):
        return [check_positive(name, value)] * n
    try:
        vals = [float(x) for x in value]  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise MotionError(f"{name} must be a number > 0 or {n} of them, got {value!r}") from None
    if len(vals) != n:
        raise MotionError(f"{name} must be a number > 0 or {n} of them, got {len(vals)} values")
    if all(0.0 < x < math.inf for x in vals):  # (NaN fails too) all good: no message built
        return vals
    return [check_positive(f"{name}[{k}]", x) for k, x in enumerate(vals)]


def check_planner_limits(dim: int, square_corner_velocity: float, start_speed: float,
                         end_speed: float, axis_vmax, axis_amax, axis_vjump,
                         arc_tangential_ratio: float, min_cruise_ratio: float) -> tuple:
    """The look-ahead's scalar and per-axis limits checked once (shared by `plan_speeds`
    and `plan_polyline`): (scv, v_start, v_end, vmax_ax, amax_ax, vjump_ax, ratio, mcr)."""
    scv = check_nonnegative("square_corner_velocity", square_corner_velocity)
    v_start = check_nonnegative("start_speed", start_speed)
    v_end = check_nonnegative("end_speed", end_speed)
    vmax_ax = _axis_limits("axis_vmax", axis_vmax, dim)
    amax_ax = _axis_limits("axis_amax", axis_amax, dim)
    vjump_ax = _axis_limits("axis_vjump", axis_vjump, dim)
    ratio = check_positive("arc_tangential_ratio", arc_tangential_ratio)
    if ratio >= 1.0:
        raise MotionError(f"arc_tangential_ratio must be in (0, 1), got {arc_tangential_ratio!r}")
    mcr = check_nonnegative("min_cruise_ratio", min_cruise_ratio)
    if mcr >= 1.0:
        raise MotionError(f"min_cruise_ratio must be in [0, 1), got {min_cruise_ratio!r}")
    return scv, v_start, v_end, vmax_ax, amax_ax, vjump_ax, ratio, mcr


def plan_speeds(elements: Sequence[PathElement], feed: float | Sequence[float],
                accel: float | Sequence[float], *,
                square_corner_velocity: float = 0.0, start_speed: float = 0.0,
                end_speed: float = 0.0, axis_vmax: ArrayLike | None = None,
                axis_amax: ArrayLike | None = None,
                axis_vjump: ArrayLike | None = None, arc_tangential_ratio: float = 0.5,
                min_cruise_ratio: float = 0.0,
                decel: float | Sequence[float] | None = None) -> tuple[ElementSpeeds, ...]:
    """Entry/cruise/exit speeds for each element (see the module docstring).

    `feed` is the path speed cap, `accel` the path acceleration limit: one value for the
    whole path or one per element (a program that changes F keeps blending). `decel`
    (default: `accel`) is the path deceleration limit, used where the speed falls (the
    backward pass); the acceleration is used where it rises (the forward pass). Corners where the
    tangent turns are crossed at most at the junction-deviation speed of
    `square_corner_velocity` (0: exact stop). The path starts at exactly `start_speed` and
    ends at a speed <= `end_speed`. `axis_vmax`/`axis_amax` (N values, inf = unlimited)
    bound every axis's speed and acceleration; `axis_vjump` (N values) bounds the step of
    every axis's velocity at a corner crossed at speed. `min_cruise_ratio` (0 <= r < 1, 0: off) lets
    short elements cruise for about that fraction instead of accelerating and braking
    back to back (module doc, step 5). Zero-length elements keep the speed of the
    junction they sit on. Raises InfeasibleError if `start_speed` is too high to obey the
    limits ahead.
    """
    pr = _prepare(elements, feed, accel, square_corner_velocity, start_speed, end_speed,
                  axis_vmax, axis_amax, axis_vjump, arc_tangential_ratio, min_cruise_ratio,
                  decel)
    feeds, accels, decels, live, acc, cap, length, dec, jcap2, v_start, mcr = pr
    n = len(live)
    if n == 0:
        return tuple(ElementSpeeds(0.0, 0.0, 0.0, a, f, 0.0, d)
                     for f, a, d in zip(feeds, accels, decels, strict=True))
    ccap = cap  # cruise caps (lowered by the minimum cruise ratio)
    back, fwd = _passes(jcap2, acc, length, v_start * v_start, dec)
    if v_start * v_start > back[0] * (1.0 + 1e-12):
        raise InfeasibleError(f"start_speed {v_start:g} exceeds the highest speed the path "
                              f"allows at its start, {math.sqrt(back[0]):.6g}")
    if mcr > 0.0:
        cap2, jcap2 = _cruise_caps(jcap2, [c * c for c in cap], acc, length, mcr,
                                   v_start * v_start, dec)
        ccap = [math.sqrt(c) for c in cap2]
        back, fwd = _passes(jcap2, acc, length, v_start * v_start, dec)

    entry, cruise, exit_ = _corner.speeds(fwd, acc, dec, ccap, length)  # step 4
    planned = [ElementSpeeds(entry[k], cruise[k], exit_[k], acc[k], cap[k], length[k],
                             dec[k]) for k in range(n)]

    out: list[ElementSpeeds] = []
    nxt = 0
    for k in range(len(elements)):
        if nxt < n and live[nxt] == k:
            out.append(planned[nxt])
            nxt += 1
        else:  # zero length: sits on the junction before live element nxt
            v = planned[nxt].entry if nxt < n else planned[-1].exit
            out.append(ElementSpeeds(v, v, v, accels[k], feeds[k], 0.0, decels[k]))
    return tuple(out)


def _curve_knots(elements: Sequence[PathElement], feed: float | Sequence[float],
                 accel: float | Sequence[float], s0: float, *,
                 square_corner_velocity: float = 0.0, start_speed: float = 0.0,
                 end_speed: float = 0.0, axis_vmax: ArrayLike | None = None,
                 axis_amax: ArrayLike | None = None, axis_vjump: ArrayLike | None = None,
                 arc_tangential_ratio: float = 0.5, min_cruise_ratio: float = 0.0,
                 decel: float | Sequence[float] | None = None
                 ) -> tuple[np.ndarray, np.ndarray, float] | None:
    """`plan_speeds`' plan as the knots (s from s0, v**2) of its trapezoids
    (pathexec.curve_from_speeds) and the smallest tangential deceleration, in one compiled
    call and without an ElementSpeeds per element: the streaming join's re-plan. None
    where `plan_speeds` does more than that (no element of length > 0, a minimum cruise
    ratio) or raises (a start too fast): the caller plans the slow way."""
    if type(elements) in (list, tuple):  # compiled (_chain_prep.c) where it can
        out = np.empty((2, 3 * len(elements) + 1))
        got = _corner.prepare_curve(_PREP_CTX, elements, feed, accel, decel,
                                    square_corner_velocity, start_speed, end_speed,
                                    axis_vmax, axis_amax, axis_vjump, arc_tangential_ratio,
                                    min_cruise_ratio, s0, out)
        if got is not None:
            m, dmin = got
            return None if m < 0 else (out[0, :m].copy(), out[1, :m].copy(), dmin)
    pr = _prepare(elements, feed, accel, square_corner_velocity, start_speed, end_speed,
                  axis_vmax, axis_amax, axis_vjump, arc_tangential_ratio, min_cruise_ratio,
                  decel)
    _, _, _, live, acc, cap, length, dec, jcap2, v_start, mcr = pr
    n = len(live)
    if n == 0 or mcr > 0.0:
        return None
    out = np.empty((2, 3 * n + 1))
    m = _corner.chain_curve(jcap2, acc, dec, cap, length, v_start * v_start, s0, out)
    if m < 0:
        return None
    return out[0, :m].copy(), out[1, :m].copy(), min(dec)


def _prepare(elements: Sequence[PathElement], feed: float | Sequence[float],
             accel: float | Sequence[float], square_corner_velocity: float,
             start_speed: float, end_speed: float, axis_vmax: ArrayLike | None,
             axis_amax: ArrayLike | None, axis_vjump: ArrayLike | None,
             arc_tangential_ratio: float, min_cruise_ratio: float,
             decel: float | Sequence[float] | None, compiled: bool = True) -> tuple:
    """`plan_speeds`' arguments checked and its steps 1-2 (module doc) on the elements of
    length > 0: (feeds, accels, decels, live, acc, cap, length, dec, jcap2, v_start, mcr)
    (live: their indices; the rest per live element, jcap2 per junction). Compiled
    (_chain_prep.c, memoized) where it can; `compiled=False`: the Python path alone."""
    got = _corner.prepare(_PREP_CTX, elements, feed, accel, decel, square_corner_velocity,
                          start_speed, end_speed, axis_vmax, axis_amax, axis_vjump,
                          arc_tangential_ratio, min_cruise_ratio) if compiled else None
    if got is not None:
        live, acc, cap, length, dec, jcap2, v_start, mcr = got
        n = len(elements)
        feeds = _per_element("feed", feed, n)
        accels = _per_element("accel", accel, n)
        decels = accels if decel is None else _per_element("decel", decel, n)
        return feeds, accels, decels, live, acc, cap, length, dec, jcap2, v_start, mcr
    if isinstance(elements, (str, bytes)) or not isinstance(elements, Sequence) \
            or len(elements) == 0:
        raise MotionError("elements must be a non-empty sequence of path elements")
    for k, el in enumerate(elements):
        if not _is_element(el):
            raise MotionError(f"elements[{k}] must be a path element (Line, Arc, Arc3D), "
                              f"got {type(el).__name__}")
    dim = elements[0].dim
    for k, el in enumerate(elements):
        if el.dim != dim:
            raise MotionError(f"elements[{k}] must have {dim} axes like elements[0], "
                              f"got {el.dim}")
    feeds = _per_element("feed", feed, len(elements))
    accels = _per_element("accel", accel, len(elements))
    decels = accels if decel is None else _per_element("decel", decel, len(elements))
    scv, v_start, v_end, vmax_ax, amax_ax, vjump_ax, ratio, mcr = check_planner_limits(
        dim, square_corner_velocity, start_speed, end_speed, axis_vmax, axis_amax, axis_vjump,
        arc_tangential_ratio, min_cruise_ratio)

    live = [k for k, el in enumerate(elements) if el.length > 0.0]
    n = len(live)
    if n == 0:
        if v_start > 0.0:
            raise InfeasibleError(f"start_speed {v_start:g} cannot be stopped on a path of "
                                  "length 0")
        return feeds, accels, decels, live, [], [], [], [], [], v_start, mcr
    els = [elements[k] for k in live]
    axes_key = _axes_key(vmax_ax, amax_ax)
    lim = [_element_limits(el, feeds[k], accels[k], vmax_ax, amax_ax, ratio, axes_key)
           for el, k in zip(els, live, strict=True)]
    acc = [x[0] for x in lim]
    cap = [x[1] for x in lim]
    length = [el.length for el in els]
    # tangential decelerations: the same limits with the deceleration (the speed caps,
    # centripetal included, stay the acceleration's)
    dec = acc if decels is accels else [
        x if decels[k] == accels[k] else _tangential_decel(el, decels[k], amax_ax, ratio)
        for x, el, k in zip(acc, els, live, strict=True)]

    # jcap2[k]: v**2 cap at the entry of live element k (k = n: the end of the path).
    jcap2 = [0.0] * (n + 1)
    jcap2[0] = cap[0] ** 2
    jcap2[n] = min(v_end, cap[n - 1]) ** 2
    for k in range(1, n):
        a_j = min(accels[live[k - 1]], accels[live[k]])
        vj = min(cap[k - 1], cap[k], _junction_cap(els[k - 1], els[k], a_j, scv, amax_ax,
                                                   vjump_ax))
        jcap2[k] = vj * vj
    return feeds, accels, decels, live, acc, cap, length, dec, jcap2, v_start, mcr


def acceleration_reversals(plan: Sequence[ElementSpeeds], rel: float = 1e-9) -> int:
    """How often the path acceleration of `plan` changes sign (holds at constant speed do
    not count as a sign): a saw-tooth of accelerating and braking scores high.

    A phase counts when its speed changes by more than `rel` of the cruise speed."""
    signs: list[int] = []
    for sp in plan:
        if sp.length == 0.0:
            continue
        tol = rel * sp.cruise
        for sign, other in ((1, sp.entry), (-1, sp.exit)):
            if sp.cruise - other > tol and (not signs or signs[-1] != sign):
                signs.append(sign)
    return max(0, len(signs) - 1)

def speed_caps(elements: Sequence[PathElement], feed: float | Sequence[float],
               accel: float | Sequence[float], *, square_corner_velocity: float = 0.0,
               axis_vmax: ArrayLike | None = None, axis_amax: ArrayLike | None = None,
               axis_vjump: ArrayLike | None = None,
               arc_tangential_ratio: float = 0.5) -> tuple[list[float], list[float]]:
    """The speed caps `plan_speeds` uses: one per element (feed, axis speeds, centripetal
    limit) and one per junction (`[k]` at the start of element k; `[0]` is inf): the
    junction-deviation corner speed, 0 where the path must stop."""
    n = len(elements)
    dim = elements[0].dim if n else 0
    feeds = _per_element("feed", feed, n)
    accels = _per_element("accel", accel, n)
    scv = check_nonnegative("square_corner_velocity", square_corner_velocity)
    vmax_ax = _axis_limits("axis_vmax", axis_vmax, dim)
    amax_ax = _axis_limits("axis_amax", axis_amax, dim)
    vjump_ax = _axis_limits("axis_vjump", axis_vjump, dim)
    caps = [_element_limits(el, f, a, vmax_ax, amax_ax, arc_tangential_ratio)[1]
            if el.length > 0.0 else f for el, f, a in zip(elements, feeds, accels, strict=True)]
    jcaps = [math.inf]
    for k in range(1, n):
        prev, nxt = elements[k - 1], elements[k]
        if prev.length == 0.0 or nxt.length == 0.0:
            jcaps.append(math.inf)
            continue
        jcaps.append(_junction_cap(prev, nxt, min(accels[k - 1], accels[k]), scv, amax_ax,
                                   vjump_ax))
    return caps, jcaps


def tangential_accels(elements: Sequence[PathElement], accel: float | Sequence[float], *,
                      axis_amax: ArrayLike | None = None,
                      arc_tangential_ratio: float = 0.5) -> list[float]:
    """The tangential acceleration `plan_speeds` allows on each element (step 1 of the
    module doc): the path acceleration, lowered by the axis limits, times the tangential
    share on curved elements."""
    n = len(elements)
    dim = elements[0].dim if n else 0
    accels = _per_element("accel", accel, n)
    amax_ax = _axis_limits("axis_amax", axis_amax, dim)
    return [_element_limits(el, a, a, None, amax_ax, arc_tangential_ratio)[0]
            if el.length > 0.0 else a for el, a in zip(elements, accels, strict=True)]
