"""Path execution: a chain of path elements -> a path-speed curve -> per-axis Profiles.

Three steps, all pure functions of geometry, limits and the interpolation period:

1. **Speed curve.** The look-ahead (`path.plan_speeds`) gives each element a trapezoid
   along its arc length. We keep it as a `SpeedCurve`: v**2 piecewise linear in the global
   path position s (constant tangential acceleration on each piece: d(v**2)/ds = 2a).
   Hold, continue and override are operations on such curves (min, max, a constant
   deceleration ramp); the pointwise min or max of two curves that each respect
   |d(v**2)/ds| <= 2*a_k on element k respects it too, and the min also keeps every speed
   cap both respect. So a re-planned curve never asks for more than the limits allow.
2. **s(t).** Each piece of the curve is one constant-acceleration segment of a Profile in
   s (time of a piece: (v1 - v0)/a, or ds/v when a = 0). The end is pinned to the exact
   path length.
3. **Axis profiles.** Knots: every interpolation period from t = 0, plus every break of
   s(t) (phase changes and element boundaries). At each knot the axis position is
   element.point(s) and its velocity tangent(s)*ds/dt; between knots each axis gets the
   cubic Hermite interpolant (the same formula as control/core/motion.py). On a line with a
   constant-acceleration s(t) the axis motion is a quadratic, so the cubic is exact; on an
   arc the deviation is the Hermite error, O(h**4) in position and O(h**2) relative in
   acceleration (about 1e-6 at 1 ms and 2 rad/s). The last knot is the element's end point,
   bit for bit, so a path ends exactly on its target.

Why Axis.run_profile and not a path-evaluating motion in control/core/motion.py: the knots are
cycle aligned, so the controller emits exactly these cubics; it needs no core change and
hold/override swap the profiles with `run_profile(replace_running=True)`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ... import _corner
from ...errors import InfeasibleError
from ...path import ElementSpeeds, Line, plan_speeds
from ...path.contour import contour_error  # noqa: F401 - re-exported (was defined here)
from ...path.geometry import PathElement
from ...path.lookahead import _curve_knots, speed_caps, tangential_accels
from ...profile.segments import Profile, State
from .pathpoints import ElementTable

#: plan_speeds' default tangential share of an arc's acceleration budget (lookahead step 1)
ARC_TANGENTIAL_RATIO = 0.5


# -------------------------------------------------------------------------- speed curves
@dataclass(frozen=True)
class SpeedCurve:
    """v**2 piecewise linear in s over knots `s` (increasing) with values `v2` (>= 0).
    `jump`: the path is at rest before s[0] and jumps to sqrt(v2[0]) there (a StrVel start,
    as a PCL6045 move starts); otherwise it arrives at s[0] with that speed."""

    s: np.ndarray
    v2: np.ndarray
    a_min: float = math.inf  # smallest tangential deceleration of the elements planned
    jump: bool = False

    def at(self, s: float) -> float:
        return float(np.interp(s, self.s, self.v2))

    def tail(self, s0: float) -> SpeedCurve:
        """The curve from s0 on."""
        keep = self.s > s0
        return SpeedCurve(np.concatenate([[s0], self.s[keep]]),
                          np.concatenate([[self.at(s0)], self.v2[keep]]))


def curve_from_speeds(speeds: Sequence[ElementSpeeds], s0: float = 0.0) -> SpeedCurve:
    """The trapezoids of the look-ahead as one curve, starting at path position s0
    (compiled: _chain.c `curve`; the Python oracle is tests/oracle_chain.py)."""
    out = np.empty((2, 3 * len(speeds) + 1))
    m = _corner.curve([sp.entry for sp in speeds], [sp.cruise for sp in speeds],
                      [sp.exit for sp in speeds], [sp.accel for sp in speeds],
                      [sp.decel for sp in speeds], [sp.length for sp in speeds], s0,
                      speeds[0].entry if speeds else 0.0, out)
    return SpeedCurve(out[0, :m].copy(), out[1, :m].copy())


def _combine(a: SpeedCurve, b: SpeedCurve, fn) -> SpeedCurve:
    """Pointwise fn (np.minimum/np.maximum) of two curves over a's range of s."""
    lo, hi = a.s[0], a.s[-1]
    grid = np.union1d(a.s, b.s[(b.s > lo) & (b.s < hi)])
    ya = np.interp(grid, a.s, a.v2)
    yb = np.interp(grid, b.s, b.v2, right=b.v2[-1])
    d = ya - yb
    cross = np.nonzero(d[:-1] * d[1:] < 0.0)[0]
    if len(cross):  # insert the crossings of two straight pieces
        f = d[cross] / (d[cross] - d[cross + 1])
        sx = grid[cross] + f * (grid[cross + 1] - grid[cross])
        grid = np.union1d(grid, sx)
        ya = np.interp(grid, a.s, a.v2)
        yb = np.interp(grid, b.s, b.v2, right=b.v2[-1])
    return SpeedCurve(grid, np.maximum(fn(ya, yb), 0.0))


def curve_min(a: SpeedCurve, b: SpeedCurve) -> SpeedCurve:
    return _combine(a, b, np.minimum)


def curve_max(a: SpeedCurve, b: SpeedCurve) -> SpeedCurve:
    return _combine(a, b, np.maximum)


def ramp(s0: float, v0: float, accel: float, s_end: float, floor: float = 0.0) -> SpeedCurve:
    """Decelerate at `accel` from v0 at s0 down to `floor`, then hold it, up to s_end."""
    v02, f2 = v0 * v0, floor * floor
    d = max(0.0, (v02 - f2) / (2.0 * accel))
    if s0 + d >= s_end:
        return SpeedCurve(np.array([s0, s_end]),
                          np.array([v02, max(0.0, v02 - 2.0 * accel * (s_end - s0))]))
    return SpeedCurve(np.array([s0, s0 + d, s_end]), np.array([v02, f2, f2]))


def stop_point(curve: SpeedCurve) -> float:
    """First s > s[0] where the curve reaches 0 (its end if it never does before)."""
    z = np.nonzero(curve.v2[1:] <= 0.0)[0]
    return float(curve.s[z[0] + 1]) if len(z) else float(curve.s[-1])


# -------------------------------------------------------------------------- s(t)
def s_profile(curve: SpeedCurve, s_end: float, breaks: Sequence[float], *,
              dwell: float = 0.0, lead: float = 0.0) -> Profile:
    """Constant-acceleration Profile of s following `curve` from its start to `s_end`
    (where the curve must be 0). `breaks` (element boundaries) become segment boundaries.
    The curve ends at 0 or at the speed a StrVel end jumps to rest from. A `jump` curve
    gives a profile at rest before t = 0 whose first segment starts at the curve's speed
    (`MoveSpec.plan`'s StrVel jump). `dwell` > 0 rests that long wherever the curve stops
    before its end (an exact-stop corner), `lead` > 0 rests that long before moving: a
    moving-average smoothing of s(t) then passes such a corner at rest (path/smoothing.py)."""
    brk = np.asarray(breaks, dtype=float)
    knots = np.union1d(curve.s, brk[(brk > curve.s[0]) & (brk < s_end)])
    knots = knots[(knots >= curve.s[0]) & (knots <= s_end)]
    v2 = np.maximum(np.interp(knots, curve.s, curve.v2), 0.0)
    v = np.sqrt(v2)
    # the pieces (ProfileBuilder's segments written out: direction +1, jerk 0, the same
    # float operations in the same order) in one compiled loop (_chain.c `s_pieces`; the
    # Python oracle is tests/oracle_chain.py)
    out = np.empty((6, 2 * len(knots) + 1))
    m, t = _corner.s_pieces(knots, v2, v, float(s_end), float(dwell), float(lead), out)
    if m < 0:
        raise InfeasibleError("path speed curve stalls at rest before its end")
    start = State(float(knots[0]), 0.0 if curve.jump else float(v[0]), 0.0)
    kind = out[5, :m]
    return Profile(t0=out[0, :m].copy(), p0=out[1, :m].copy(), v0=out[2, :m].copy(),
                   a0=out[3, :m].copy(), j=np.zeros(m), duration=t, start=start,
                   end=State(float(s_end), 0.0, 0.0), labels=_labels(kind),
                   dt=out[4, :m].copy())


#: "segment k" for k = 0, 1, ... (s_profile's piece labels), grown as asked
_SEGMENT_LABELS: list[str] = []


def _labels(kind: np.ndarray) -> tuple[str, ...]:
    """s_profile's labels: "dwell" where `kind` is 1, else "segment k" (k: the row)."""
    m = len(kind)
    while len(_SEGMENT_LABELS) < m:
        _SEGMENT_LABELS.append(f"segment {len(_SEGMENT_LABELS)}")
    labels = _SEGMENT_LABELS[:m]
    for k in np.flatnonzero(kind).tolist():
        labels[k] = "dwell"
    return tuple(labels)


# -------------------------------------------------------------------------- chains
class Chain:
    """Elements laid end to end along a global path position s, with the feed, the path
    acceleration and the path deceleration each element was commanded with (None: the
    Limits' values; decels None: the accelerations)."""

    def __init__(self, elements: Sequence[PathElement], owners: Sequence[int],
                 feeds: Sequence[float] | None = None, accels: Sequence[float] | None = None,
                 decels: Sequence[float] | None = None,
                 *, cum: np.ndarray | None = None) -> None:
        self.elements = tuple(elements)
        self.owners = tuple(owners)  # command index of each element
        self.feeds = None if feeds is None else np.asarray(feeds, dtype=float)
        self.accels = None if accels is None else np.asarray(accels, dtype=float)
        self.decels = None if decels is None else np.asarray(decels, dtype=float)
        self.cum = cum if cum is not None else np.concatenate(
            [[0.0], np.cumsum([el.length for el in self.elements])])
        self._table: ElementTable | None = None

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    @property
    def table(self) -> ElementTable:
        """The elements' parameters as arrays, built once (pathpoints.py)."""
        if self._table is None:
            self._table = ElementTable(self.elements)
        return self._table

    def locate(self, s: float) -> int:
        k = int(np.searchsorted(self.cum, s, side="right")) - 1
        return min(max(k, 0), len(self.elements) - 1)

    def point(self, s: float) -> np.ndarray:
        k = self.locate(s)
        el = self.elements[k]
        if s >= self.cum[-1]:
            return np.array(self.elements[-1].end)
        return el.point(min(max(s - self.cum[k], 0.0), el.length))

    def joined(self, elements: Sequence[PathElement], owners: Sequence[int],
               feeds: Sequence[float] | None, accels: Sequence[float] | None,
               decels: Sequence[float] | None = None,
               replace_last: PathElement | None = None) -> Chain:
        """This chain (its last element replaced by `replace_last`, e.g. trimmed by a
        blend) followed by more elements; the s of the kept elements is unchanged."""
        head = self.elements[:-1] + (replace_last,) if replace_last is not None \
            else self.elements
        cum = self.cum[:-1] if replace_last is not None else self.cum
        start = float(cum[-1])
        lens = [el.length for el in ([replace_last] if replace_last is not None else [])
                + list(elements)]
        tail = start + np.cumsum(lens)
        if self.decels is None and decels is None:
            dec = None
        else:  # one side follows its accelerations
            dec = _cat(self.accels if self.decels is None else self.decels,
                       accels if decels is None else decels)
        out = Chain(head + tuple(elements), self.owners + tuple(owners),
                    _cat(self.feeds, feeds), _cat(self.accels, accels), dec,
                    cum=np.concatenate([cum, tail]))
        if self._table is not None and (elements or replace_last is not None):
            # the kept rows of this chain's table and a table of the new elements only
            kept = self._table.sliced(0, len(self.elements) - 1) \
                if replace_last is not None else self._table
            fresh = ([replace_last] if replace_last is not None else []) + list(elements)
            out._table = kept.concat(ElementTable(fresh))
        return out

    def dropped(self, k: int) -> tuple[Chain, float]:
        """The chain without its first k elements, s rebased to start at 0, and the offset
        subtracted (the same subtraction applied to a profile keeps both consistent)."""
        off = float(self.cum[k])
        chain = Chain(self.elements[k:], self.owners[k:],
                      None if self.feeds is None else self.feeds[k:],
                      None if self.accels is None else self.accels[k:],
                      None if self.decels is None else self.decels[k:],
                      cum=self.cum[k:] - off)
        if self._table is not None:
            chain._table = self._table.sliced(k)
        return chain, off

    def tail_elements(self, s0: float) -> tuple[list[PathElement], int]:
        """Elements from s0 on (the first trimmed) and the index of the first."""
        k = self.locate(s0)
        el = self.elements[k]
        local = s0 - float(self.cum[k])
        slack = 1e-9 * max(1.0, self.length)
        if el.length - local <= slack and k + 1 < len(self.elements):
            k, el, local = k + 1, self.elements[k + 1], 0.0  # at the end of an element
        if local <= slack:
            local = 0.0
        first: PathElement = el if local <= 0.0 else Trimmed(el, local)
        return [first, *self.elements[k + 1:]], k


def _cat(a: np.ndarray | None, b: Sequence[float] | None) -> np.ndarray | None:
    if a is None and b is None:
        return None
    if a is None or b is None:
        raise ValueError("feeds/accels must be given for every element or for none")
    return np.concatenate([a, np.asarray(b, dtype=float)])


class Trimmed:
    """The part of an element from local position `offset` on, `length` long (default: to
    its end), for re-planning mid-element and for splitting a curve at a guard zone's
    edge. The look-ahead bounds (max curvature, per-axis weights) are the whole element's:
    valid."""

    def __init__(self, base: PathElement, offset: float, length: float | None = None) -> None:
        self.base = base
        self.offset = float(offset)
        self._stop = base.length if length is None else min(base.length,
                                                               self.offset + float(length))
        self.length = max(0.0, self._stop - self.offset)
        self.dim = base.dim
        self.start = base.point(self.offset)
        self.end = base.end if length is None else base.point(self._stop)
        self.start_tangent = base.tangent(self.offset)
        self.end_tangent = base.end_tangent if length is None else base.tangent(self._stop)
        self.max_curvature = base.max_curvature
        self.max_abs_tangent = base.max_abs_tangent
        self.axis_accel_weight = base.axis_accel_weight

    def _local(self, s):  # noqa: ANN001, ANN202
        return np.minimum(np.asarray(s, dtype=float) + self.offset, self._stop)

    def point(self, s):  # noqa: ANN001, ANN201 - same contract as PathElement
        return self.base.point(self._local(s))

    def tangent(self, s):  # noqa: ANN001, ANN201
        return self.base.tangent(self._local(s))

    def curvature(self, s):  # noqa: ANN001, ANN201
        return self.base.curvature(self._local(s))


@dataclass(frozen=True)
class Limits:
    """Path limits: feed (vector speed), tangential accel, per-axis speed/accel caps, the
    corner speed of sharp junctions (square corner velocity, 0: exact stop) with the
    per-axis velocity step it may cause (`axis_vjump`, None: unbounded), and the minimum
    cruise ratio of the look-ahead (path.plan_speeds).

    With a chain that carries its own feeds/accels, `feed` is the cap on every element's
    feed (the system maximum) and each element's feed is multiplied by `scale` (the
    override) first; `accel` is then unused. `str_vel`: the speed a path ends at before it
    jumps to rest (0: ends at rest)."""

    feed: float
    accel: float
    axis_vmax: np.ndarray
    axis_amax: np.ndarray
    square_corner_velocity: float = 0.0
    axis_vjump: np.ndarray | None = None
    min_cruise_ratio: float = 0.0
    scale: float = 1.0
    str_vel: float = 0.0


def _chain_limits(chain: Chain, k0: int, lim: Limits) -> tuple[Any, Any, Any]:
    """Feeds, accelerations and decelerations (None: the accelerations) of the elements
    from index k0 on (scalars when uniform)."""
    if chain.feeds is None or chain.accels is None:
        return lim.feed, lim.accel, None
    return (np.minimum(chain.feeds[k0:] * lim.scale, lim.feed).tolist(),
            chain.accels[k0:].tolist(),
            None if chain.decels is None else chain.decels[k0:].tolist())


def plan_curve(chain: Chain, s0: float, v0: float, lim: Limits,
               old: SpeedCurve | None = None, *, window: float = 0.0,
               jump: bool = False) -> SpeedCurve:
    """Speed curve for the rest of `chain` from s0 at speed v0, ending at rest or, with a
    StrVel (`lim.str_vel`), at a speed <= StrVel from which it jumps to rest.

    `jump=True`: the path is at rest and starts with a jump to v0 (StrVel), lowered to the
    highest start speed the limits ahead allow (feed x override, axis caps, a stop ahead).
    When v0 is above what the new limits allow (a lower override), the path decelerates at
    the smallest tangential acceleration of the remaining elements until it meets the new
    plan, and never exceeds the `old` curve it was following (see the module doc).
    `window` > 0 (an S path's smoothing window tj, see `guarded`) holds every speed cap and
    tangential acceleration cap*tj/2 beyond its element or corner. The curve's `a_min` is
    the smallest tangential deceleration of the remaining elements (what a hold may use
    everywhere). A chain with its own decelerations brakes at them (the backward pass).
    """
    if window > 0.0:  # the elements the executed position may still be on cap what follows
        k0 = chain.locate(max(0.0, s0 - _top_feed(chain, lim) * window))
        feeds, accels, decels = _chain_limits(chain, k0, lim)
        els, feeds, accels, decels = guarded_limits(
            list(chain.elements[k0:]), feeds, accels, lim, window,
            cut=s0 - float(chain.cum[k0]), decels=decels)
    else:
        els, k0 = chain.tail_elements(s0)
        feeds, accels, decels = _chain_limits(chain, k0, lim)
    kw = dict(square_corner_velocity=lim.square_corner_velocity, end_speed=lim.str_vel,
              axis_vmax=lim.axis_vmax, axis_amax=lim.axis_amax, axis_vjump=lim.axis_vjump,
              min_cruise_ratio=lim.min_cruise_ratio)
    if decels is not None:
        kw["decel"] = decels
    try:
        fast = _curve_knots(els, feeds, accels, s0, start_speed=v0, **kw)
        if fast is not None:  # the plan's knots in one compiled pass (_chain.c)
            return _pinned(SpeedCurve(*fast), chain.length, jump=jump and v0 > 0.0)
        sp = plan_speeds(els, feeds, accels, start_speed=v0, **kw)
        return _with_amin(_pinned(curve_from_speeds(sp, s0), chain.length,
                                  jump=jump and v0 > 0.0), sp)
    except InfeasibleError:
        if old is None and not jump:
            raise
    lo = _highest_start(els, feeds, accels, v0, kw)
    sp = plan_speeds(els, feeds, accels, start_speed=lo, **kw)
    if jump:
        return _with_amin(_pinned(curve_from_speeds(sp, s0), chain.length, jump=lo > 0.0), sp)
    assert old is not None
    a_min = min(x.decel for x in sp if x.length > 0.0)
    new = curve_from_speeds(sp, s0)
    # the new plan starts at lo < v0: join it with a ramp from v0 (max), under the old curve
    down = ramp(s0, v0, a_min, chain.length)
    joined = curve_max(down, new)
    return _with_amin(_pinned(curve_min(joined, old.tail(s0)), chain.length), sp)


def _top_feed(chain: Chain, lim: Limits) -> float:
    """The highest feed any element of the chain may run at (override included)."""
    if chain.feeds is None:
        return lim.feed
    return min(lim.feed, float(np.max(chain.feeds)) * lim.scale)


def _highest_start(els: Sequence[PathElement], feeds: Any, accels: Any, v0: float,
                   kw: dict) -> float:
    """The highest start speed <= v0 the look-ahead accepts on `els` (bisection)."""
    lo, hi = 0.0, v0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        try:
            plan_speeds(els, feeds, accels, start_speed=mid, **kw)
            lo = mid
        except InfeasibleError:
            hi = mid
    return lo


def _with_amin(curve: SpeedCurve, sp: Sequence[ElementSpeeds]) -> SpeedCurve:
    """The curve with the smallest tangential deceleration of the elements (a hold's)."""
    acc = [x.decel for x in sp if x.length > 0.0]
    return SpeedCurve(curve.s, curve.v2, min(acc) if acc else math.inf, curve.jump)


def guarded(els: list[PathElement], feeds: Any, accels: Any, lim: Limits, tj: float,
            cut: float = 0.0) -> tuple[list[PathElement], list[float], list[float]]:
    """`guarded_limits` without decelerations: the elements, feeds and accelerations."""
    out, of, oa, _ = guarded_limits(els, feeds, accels, lim, tj, cut)
    return out, of, oa


def guarded_limits(els: list[PathElement], feeds: Any, accels: Any, lim: Limits, tj: float,
                   cut: float = 0.0, decels: Any = None
                   ) -> tuple[list[PathElement], list[float], list[float], list[float] | None]:
    """Elements on which a raw path speed keeps, after a moving average of window tj, every
    speed cap and tangential acceleration of the elements it is averaged over.

    Why a cap c of an element E (or of a corner crossed at speed) must hold c*tj/2 beyond
    E: if the raw speed is <= c within d = c*tj/2 of E, a window whose average position
    (the executed one) lies on E holds only raw positions within d of E. (Had the raw
    motion reached d beyond E at time tau <= t, it would have moved at <= c before tau, so
    its average over [t - tj, t] would be at least the far end of E. The same holds behind
    E.) The executed speed and acceleration are averages of raw ones in the window, so
    they keep E's cap and E's tangential acceleration when the raw motion keeps them over
    that reach. An arc's speed cap bounds its centripetal acceleration, its tangential
    share the rest, so axis accelerations stay within the limits there too.

    Each element's cap and tangential acceleration therefore hold over a zone c*tj/2 around
    it (a corner's junction speed too). Elements are split at the zone edges of their
    neighbours, so only the part a neighbour reaches is slowed. Exact-stop
    corners (junction cap 0) are barriers: the raw motion rests tj there (s_profile's
    dwell), so no window holds raw positions of both sides. The elements before path
    position `cut` (from the start of `els`) cap what follows within their zones and are
    then dropped (a re-plan mid-chain: the executed position lags behind the raw one).
    `decels` (None: the accelerations) are guarded like the accelerations and come back
    as the fourth value (None when not given)."""
    n = len(els)
    fl = [float(x) for x in feeds] if isinstance(feeds, list) else [float(feeds)] * n
    al = [float(x) for x in accels] if isinstance(accels, list) else [float(accels)] * n
    dl = None if decels is None else (
        [float(x) for x in decels] if isinstance(decels, list) else [float(decels)] * n)
    caps, jcaps = speed_caps(els, fl, al, square_corner_velocity=lim.square_corner_velocity,
                             axis_vmax=lim.axis_vmax, axis_amax=lim.axis_amax,
                             axis_vjump=lim.axis_vjump)
    tacc = np.asarray(tangential_accels(els, al, axis_amax=lim.axis_amax))
    tdec = tacc if dl is None else np.asarray(tangential_accels(els, dl,
                                                                axis_amax=lim.axis_amax))
    cum = np.concatenate([[0.0], np.cumsum([el.length for el in els])])
    cap = np.minimum(np.asarray(caps), fl)
    jc = np.asarray(jcaps)  # jc[k]: at the start of element k (jc[0] = inf)
    # zones: every element, and every corner crossed at a finite speed > 0
    corners = np.nonzero((jc > 0.0) & np.isfinite(jc))[0]
    z_cap = np.concatenate([cap, jc[corners]])
    z_acc = np.concatenate([tacc, np.full(len(corners), np.inf)])
    z_dec = z_acc if dl is None else np.concatenate([tdec, np.full(len(corners), np.inf)])
    reach = z_cap * (0.5 * tj * (1.0 + 1e-9))
    z_lo = np.concatenate([cum[:-1], cum[corners]]) - reach
    z_hi = np.concatenate([cum[1:], cum[corners]]) + reach
    # sections between exact stops clip the zones (the chain's ends bound them too)
    stops = np.concatenate([[0], np.nonzero(jc[1:] <= 0.0)[0] + 1, [n]])
    owner = np.concatenate([np.arange(n), corners])
    q = np.searchsorted(stops, owner, side="right")
    z_lo = np.maximum(z_lo, cum[stops[q - 1]])
    z_hi = np.minimum(z_hi, cum[stops[q]])

    def low(x0: float, x1: float) -> tuple[float, float, float]:
        """Smallest cap, tangential acceleration and deceleration of the zones
        overlapping (x0, x1) by more than the rounding slack."""
        hit = (z_lo < x1 - slack) & (z_hi > x0 + slack)
        return float(np.min(z_cap[hit])), float(np.min(z_acc[hit])), \
            float(np.min(z_dec[hit]))

    def accel_for(k: int, a_low: float, base: list[float] = al,
                  tang: np.ndarray = tacc) -> float:
        """The path acceleration (or deceleration: `base`, `tang`) to give element k so
        its tangential one is <= a_low."""
        if a_low >= tang[k]:
            return base[k]
        if els[k].max_curvature == 0.0:
            return min(base[k], a_low)
        return min(base[k], a_low / ARC_TANGENTIAL_RATIO)  # lowers the arc's whole budget

    slack = 1e-9 * max(1.0, float(cum[-1]))
    out: list[PathElement] = []
    of: list[float] = []
    oa: list[float] = []
    od: list[float] = []
    for k, el in enumerate(els):
        a, b = float(cum[k]), float(cum[k + 1])
        if b <= cut + slack or el.length <= 0.0:
            continue
        a0 = max(a, cut)
        inner = np.concatenate([z_lo, z_hi])  # split at the zone edges inside it
        cuts = np.unique(np.concatenate([[a0], inner[(inner > a0 + slack)
                                                     & (inner < b - slack)], [b]]))
        pieces: list[tuple[float, float, float, float, float]] = []
        for x0, x1 in zip(cuts[:-1], cuts[1:], strict=True):
            c, am, dm = low(float(x0), float(x1))
            f, acc = min(fl[k], c), accel_for(k, am)
            dec = acc if dl is None else accel_for(k, dm, dl, tdec)
            if pieces and pieces[-1][2:] == (f, acc, dec):
                pieces[-1] = (pieces[-1][0], float(x1), f, acc, dec)
            else:
                pieces.append((float(x0), float(x1), f, acc, dec))
        for x0, x1, f, acc, dec in pieces:
            if x0 <= a and x1 >= b:
                piece: PathElement = el
            elif isinstance(el, Line):
                piece = Line(el.start if x0 <= a else el.point(x0 - a),
                             el.end if x1 >= b else el.point(x1 - a))
            else:
                piece = Trimmed(el, x0 - a, None if x1 >= b else x1 - x0)
            out.append(piece)
            of.append(f)
            oa.append(acc)
            od.append(dec)
    return out, of, oa, None if dl is None else od


def _pinned(curve: SpeedCurve, length: float, *, jump: bool = False) -> SpeedCurve:
    """The curve with its last knot exactly at the chain length (sums round differently)."""
    s = curve.s.copy()
    s[-1] = length
    keep = np.concatenate([np.diff(s) > 0.0, [True]])
    keep[0] = True
    return SpeedCurve(s[keep], curve.v2[keep], curve.a_min, jump)


def hold_curve(old: SpeedCurve, s0: float, v0: float, accel: float) -> SpeedCurve:
    """Decelerate from (s0, v0) at `accel` to rest, never faster than `old`."""
    return curve_min(old.tail(s0), ramp(s0, v0, accel, float(old.s[-1])))


def travel_time(curve: SpeedCurve) -> float:
    """Duration of following `curve` from its start to its end."""
    v = np.sqrt(np.maximum(curve.v2, 0.0))
    vm = v[:-1] + v[1:]
    ds = np.diff(curve.s)
    ok = ds > 0.0
    return float(np.sum(2.0 * ds[ok] / vm[ok]))


# the axis-profile step lives in pathaxes.py; re-exported for existing callers
from .pathaxes import axis_profiles, scaled  # noqa: E402,F401
