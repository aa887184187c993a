"""Per-axis profiles of a path: the cubic Hermite knots an axis follows along a chain.

Step 3 of pathexec.py (see its module doc): knots every interpolation period plus every
break of s(t) and every element boundary s(t) crosses; positions from the elements, velocities
tangent*ds/dt; on lines acceleration and jerk from s(t) exactly; the last knot is the chain's
end point bit for bit. The knots' positions and coefficients of a chain of lines and arcs
are one compiled call (`_profile.axis_knots`, src/openmotion/_profile_knots.c, the same
floats as `_knots_numpy`, which is its test oracle and evaluates other element kinds).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ... import _corner
from ...profile.segments import Profile, Samples, State

try:  # the compiled knots (setup.py builds them; absent in an unbuilt source tree)
    from ... import _profile
except ImportError:  # pragma: no cover - depends on the build
    _profile = None

if TYPE_CHECKING:
    from .pathexec import Chain
    from .pathpoints import ElementTable


def axis_profiles(chain: Chain, sp: Profile, period: float,
                  starts: Sequence[float]) -> list[Profile]:
    """Per-axis Profiles (positions in the element frame plus nothing else) following
    chain.point(s(t)); see the module doc. `starts` are the axis positions at t = 0 (the
    first knot uses them, so a replacement starts exactly where the axis is)."""
    dur = sp.duration
    n = int(math.floor(dur / period + 1e-9))
    grid = np.arange(n + 1) * period
    brk = np.union1d(sp.t0, [dur])
    # the instants s(t) crosses an element boundary are knots too (a smoothed S path's
    # breaks are not there): an interval then never straddles a change of curvature, which
    # the cubic would smear into an acceleration overshoot
    cross = _crossings(sp, chain.cum[1:-1])
    brk = np.union1d(brk, cross[~_near(cross, brk, 1e-6 * period)]) if len(cross) else brk
    # grid knots closer than 1e-6 period to a break of s(t) are dropped: a tiny interval
    # would make the Hermite coefficients (divided by h**2, h**3) lose all precision
    near = _near(grid, brk, 1e-6 * period)
    t = np.union1d(grid[(grid < dur) & ~near], brk)
    smp = sp.sample(t)
    s = np.clip(smp.p, sp.start.p, sp.end.p)
    sd = smp.v
    sd[-1] = _end_speed(sp)  # the speed just before the end (a StrVel end jumps from it)
    s[-1] = sp.end.p
    dim = chain.elements[0].dim
    if len(t) < 2:  # nothing left to move: hold the start
        p0 = np.array(chain.elements[-1].end if sp.end.p >= chain.length else starts,
                      dtype=float)
        return [Profile(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), 0.0,
                        State(float(x), 0.0, 0.0), State(float(x), 0.0, 0.0), (),
                        np.zeros(0)) for x in p0]
    table = chain.table  # every element's parameters as arrays (pathpoints.py)
    # s(t) at the interval midpoints: the element an interval lies on
    s_mid = sp.sample(0.5 * (t[:-1] + t[1:])).p
    out = _knots_compiled(chain, table, t, s, sd, s_mid, smp, starts)
    if out is None:
        out = _knots_numpy(chain, table, t, s, sd, s_mid, smp, starts)
    pos, v0, a0, jj = out
    profiles = []
    dts = np.diff(t)
    labels = ("path",) * len(dts)
    for i in range(dim):
        profiles.append(Profile(
            t0=t[:-1].copy(), p0=pos[:-1, i].copy(), v0=v0[:, i].copy(), a0=a0[:, i].copy(),
            j=jj[:, i].copy(), duration=float(dur),
            start=State(float(pos[0, i]), float(v0[0, i]) if sp.start.v else 0.0, 0.0),
            end=State(float(pos[-1, i]), 0.0, 0.0), labels=labels, dt=dts.copy()))
    return profiles


def _knots_compiled(chain: Chain, table: ElementTable, t: np.ndarray, s: np.ndarray,
                    sd: np.ndarray, s_mid: np.ndarray, smp: Samples,
                    starts: Sequence[float]) -> tuple[np.ndarray, ...] | None:
    """`_knots_numpy` compiled (_profile_knots.c: the same floats); None when the chain
    has an element the compiled version does not evaluate."""
    packed = table.packed
    if _profile is None or packed is None:
        return None
    n, dim = len(t), table.start.shape[1]
    end = np.asarray(chain.elements[-1].end, dtype=float) if s[-1] >= chain.length \
        else np.zeros(0)
    pos = np.empty((n, dim))
    v0, a0, jj = np.empty((n - 1, dim)), np.empty((n - 1, dim)), np.empty((n - 1, dim))
    done = _profile.axis_knots(
        packed, np.ascontiguousarray(chain.cum, dtype=float), t, s, sd, s_mid,
        np.ascontiguousarray(smp.a[:-1]), np.ascontiguousarray(smp.j[:-1]),
        np.ascontiguousarray(starts, dtype=float), end, pos, v0, a0, jj)
    return (pos, v0, a0, jj) if done else None


def _knots_numpy(chain: Chain, table: ElementTable, t: np.ndarray, s: np.ndarray,
                 sd: np.ndarray, s_mid: np.ndarray, smp: Samples,
                 starts: Sequence[float]) -> tuple[np.ndarray, ...]:
    """Knot positions and each interval's v0, a0, j per axis (the oracle of the compiled
    version, and what evaluates other element kinds)."""
    n_el = len(chain.elements)
    cum = chain.cum
    lens = table.lengths
    # positions per knot (continuous: consecutive elements join bit for bit)
    k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, n_el - 1)
    pos = table.point(k, np.clip(s - cum[k], 0.0, lens[k]))
    pos[0] = starts
    if s[-1] >= chain.length:
        pos[-1] = chain.elements[-1].end
    # velocities per interval, from the element the interval lies on: at a corner taken at
    # speed (junction deviation) the velocity jumps between two intervals, not inside one
    km = np.clip(np.searchsorted(cum, s_mid, side="right") - 1, 0, n_el - 1)
    # (the tangents at both ends of every interval in one evaluation: row by row the same)
    m = len(km)
    kk = np.concatenate((km, km))
    tg = table.tangent(kk, np.clip(np.concatenate((s[:-1], s[1:])) - cum[kk], 0.0, lens[kk]))
    v0 = tg[:m] * sd[:-1][:, None]
    v1 = tg[m:] * sd[1:][:, None]
    h = np.diff(t)[:, None]
    dp = np.diff(pos, axis=0)
    a0 = (6.0 * dp - h * (4.0 * v0 + 2.0 * v1)) / (h * h)
    jj = (6.0 * h * (v0 + v1) - 12.0 * dp) / (h * h * h)
    # on a line the axis motion is u*s(t) exactly: take a and j from s(t), not the fit
    # (s(t) at the knots but the last: smp.a, smp.j are the samples of t[:-1] plus one)
    straight = table.curvature[km] == 0.0
    if np.any(straight):
        u = table.line_tangents(km[straight])
        a0[straight] = smp.a[:-1][straight][:, None] * u
        jj[straight] = smp.j[:-1][straight][:, None] * u
    return pos, v0, a0, jj


def _crossings(sp: Profile, levels: np.ndarray) -> np.ndarray:
    """Times at which a non-decreasing s(t) reaches each of `levels` inside its range
    (bisection in the segment that holds the level)."""
    lv = levels[(levels > sp.start.p) & (levels < sp.end.p)]
    n = sp.n_segments
    if not len(lv) or not n:
        return np.zeros(0)
    k = np.clip(np.searchsorted(sp.p0, lv, side="right") - 1, 0, n - 1)
    dts = sp.dt if sp.dt is not None else np.diff(np.append(sp.t0, sp.duration))
    def vec(x: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(x, dtype=np.float64)

    hi = vec(np.asarray(dts, dtype=float)[k])  # (a fancy index: a fresh array)
    # 60 halvings per level, compiled (_chain.c; the oracle is tests/oracle_chain.py)
    _corner.crossings(vec(sp.p0[k]), vec(sp.v0[k]), vec(sp.a0[k]), vec(sp.j[k]), hi, vec(lv))
    return np.unique(sp.t0[k] + hi)


def _end_speed(sp: Profile) -> float:
    """Path speed just before the end of s(t): 0 for a stop at rest (within the rounding of
    the last segment), else the speed a StrVel end jumps to rest from."""
    if not sp.n_segments or sp.end.v != 0.0:
        return float(sp.end.v)
    dt = float(sp.dt[-1]) if sp.dt is not None else sp.duration - float(sp.t0[-1])
    v = float(sp.v0[-1] + dt * (sp.a0[-1] + dt * sp.j[-1] / 2.0))
    return v if v > 1e-9 * max(1.0, float(np.max(np.abs(sp.v0)))) else 0.0


def scaled(p: Profile, k: float) -> Profile:
    """The profile with every position, velocity, acceleration and jerk times k (a change
    of units; k < 0 also mirrors it)."""
    return Profile(p.t0, p.p0 * k, p.v0 * k, p.a0 * k, p.j * k, p.duration,
                   State(p.start.p * k, p.start.v * k, p.start.a * k),
                   State(p.end.p * k, p.end.v * k, p.end.a * k), p.labels, p.dt)


def _near(grid: np.ndarray, brk: np.ndarray, tol: float) -> np.ndarray:
    """Which grid values lie within tol of a value of the sorted array brk."""
    k = np.clip(np.searchsorted(brk, grid), 1, len(brk) - 1)
    return np.minimum(np.abs(grid - brk[k - 1]), np.abs(grid - brk[k])) <= tol
