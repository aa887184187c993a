"""The motion an axis is executing, and how the cycle loop reads it.

An `ActiveMotion` is a `Profile` anchored at an absolute controller time. Each cycle the
controller asks it for the cubic piece covering [t0, t1] (`piece`): when the cycle lies
inside one profile segment that piece *is* the segment, re-based at t0, so the hardware
emits exactly the planned pulses. When a cycle straddles a segment boundary (or the end of
the move) no single cubic is exact; the piece is then the cubic Hermite interpolant of the
profile's position and velocity at both cycle ends, which lands exactly on the planned
position at t1 (the move's exact target on its last cycle), so nothing accumulates:

    given p0, v0 (just after t0), p1, v1 (just before t1), h = t1 - t0:
      a0 = (6*(p1 - p0) - h*(4*v0 + 2*v1)) / h**2
      j  = (6*h*(v0 + v1) - 12*(p1 - p0)) / h**3

The segment arrays are copied to Python lists once per motion and a cursor walks them
forward, so the hot path does no numpy calls and no searching.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field

import numpy as np

from ...profile.pcl import MoveSpec
from ...profile.segments import Profile
from .states import MotionDone

try:  # the compiled inner loops (setup.py builds them; absent in an unbuilt source tree)
    from ... import _kernel
except ImportError:  # pragma: no cover - depends on the build
    _kernel = None

#: Motion kinds. velocity: runs until changed or stopped (ContinuousMotion); relative,
#: absolute, jerk (jerk-limited) and profile (an external Profile, `Axis.run_profile`): end
#: at `target` (DiscreteMotion); stop: a decelerating stop (Stopping).
KINDS = ("velocity", "relative", "absolute", "jerk", "profile", "stop")


@dataclass(eq=False)
class ActiveMotion:
    """A profile being executed from absolute time `t_start` (profile time 0)."""

    profile: Profile
    t_start: float
    kind: str
    spec: MoveSpec | None = None
    target: float | None = None     # end position, raw pulse frame (discrete moves)
    abs_target: float | None = None  # the absolute target as commanded (absolute moves)
    limits: tuple[float, float, float] | None = None  # (v, a, j) of a jerk-limited move
    v_range: float = 0.0  # MaxVel as first commanded: the change_speed cap when not fixed
    _t0: list[float] = field(init=False, repr=False)
    _p0: list[float] = field(init=False, repr=False)
    _v0: list[float] = field(init=False, repr=False)
    _a0: list[float] = field(init=False, repr=False)
    _j: list[float] = field(init=False, repr=False)
    _k: int = field(init=False, default=0, repr=False)
    _seg_array: np.ndarray | None = field(init=False, default=None, repr=False)
    _left_end: float = field(init=False, default=0.0, repr=False)
    # pieces computed ahead by a virtual-time jump (control/core/jump.py `_ahead`)
    _ahead: tuple | None = field(init=False, default=None, repr=False)
    _done_at: tuple[float, int] = field(init=False, default=(math.nan, 0), repr=False)
    _end_cycle: tuple[float, float, int] | None = field(init=False, default=None, repr=False)

    def __post_init__(self) -> None:
        if not self.v_range and self.spec is not None:
            self.v_range = self.spec.max_vel
        pr = self.profile
        self._t0 = pr.t0.tolist()
        self._p0 = pr.p0.tolist()
        self._v0 = pr.v0.tolist()
        self._a0 = pr.a0.tolist()
        self._j = pr.j.tolist()

    @property
    def t_end(self) -> float:
        """Absolute time at which the profile reaches its end state."""
        return self.t_start + self.profile.duration

    @property
    def str_vel(self) -> float:
        return self.spec.str_vel if self.spec is not None else 0.0

    def finished(self, t: float) -> bool:
        """True once a motion with a rest end state has reached it."""
        return self.kind != "velocity" and t >= self.t_end

    # -- evaluation ----------------------------------------------------------------------
    def _seg(self, u: float) -> int:
        """Index of the segment holding profile time u (0 <= u < duration), cursor based."""
        ts = self._t0
        k = self._k
        if u < ts[k]:
            k = bisect_right(ts, u) - 1
        n = len(ts)
        while k + 1 < n and ts[k + 1] <= u:
            k += 1
        self._k = k
        return k

    def _eval(self, k: int, u: float) -> tuple[float, float, float]:
        s = u - self._t0[k]
        j = self._j[k]
        a = self._a0[k]
        v = self._v0[k]
        return (self._p0[k] + s * (v + s * (a * 0.5 + s * j / 6.0)),
                v + s * (a + s * j * 0.5), a + s * j)

    def state(self, t: float) -> tuple[float, float, float]:
        """(p, v, a) at absolute time t; right limit at a jump."""
        u = t - self.t_start
        pr = self.profile
        if u >= pr.duration or not self._t0:
            end = pr.end
            return end.p + end.v * (u - pr.duration), end.v, 0.0
        if u < 0.0:
            st = pr.start
            return st.p + st.v * u, st.v, 0.0
        return self._eval(self._seg(u), u)

    def _left(self, u: float) -> tuple[float, float]:
        """(p, v) at profile time u approached from below (0 < u <= duration)."""
        k = max(0, bisect_left(self._t0, u) - 1)
        p, v, _ = self._eval(k, u)
        return p, v

    def piece(self, t0: float, t1: float) -> tuple[float, float, float, float, float, float]:
        """(p0, v0, a0, j, p1, v1) of the cubic to command over [t0, t1]; see module doc."""
        u0 = t0 - self.t_start
        u1 = t1 - self.t_start
        pr = self.profile
        dur = pr.duration
        if u0 >= dur or not self._t0:
            end = pr.end
            p0 = end.p + end.v * (u0 - dur)
            return p0, end.v, 0.0, 0.0, p0 + end.v * (u1 - u0), end.v
        k = self._seg(u0)
        p0, v0, a0 = self._eval(k, u0)
        ts = self._t0
        nxt = ts[k + 1] if k + 1 < len(ts) else dur
        if u1 <= nxt and u1 < dur:
            j = self._j[k]
            s = u1 - u0
            return (p0, v0, a0, j, p0 + s * (v0 + s * (a0 * 0.5 + s * j / 6.0)),
                    v0 + s * (a0 + s * j * 0.5))
        if u1 >= dur:
            end = pr.end
            p1 = end.p + end.v * (u1 - dur)  # exact target, no float sum
            v1 = self._left(dur)[1] if u1 == dur else end.v
        else:
            p1, v1 = self._left(u1)
        h = u1 - u0
        dp = p1 - p0
        a0 = (6.0 * dp - h * (4.0 * v0 + 2.0 * v1)) / (h * h)
        j = (6.0 * h * (v0 + v1) - 12.0 * dp) / (h * h * h)
        return p0, v0, a0, j, p1, v1

    def pieces(self, t0: float, origin: float, period: float, n: int, m: int
               ) -> tuple[np.ndarray, np.ndarray]:
        """`piece` for the m cycles n+1 .. n+m at once (cycle k ends at origin + k * period,
        the first starts at t0): rows (t0, dt, p0, v0, a0, j) and ends (p1, v1), the very
        floats `piece` gives one cycle at a time. The compiled kernel (openmotion._kernel)
        computes them when it is built; otherwise `piece` runs per cycle."""
        rows = np.empty((m, 6))
        ends = np.empty((m, 2))
        if _kernel is not None:
            if self._seg_array is None:
                pr = self.profile
                self._seg_array = np.array([pr.t0, pr.p0, pr.v0, pr.a0, pr.j], dtype=float)
                self._left_end = self._left(pr.duration)[1] if self._t0 else 0.0
            end = self.profile.end
            _kernel.pieces(self._seg_array, self.t_start, self.profile.duration, end.p, end.v,
                           self._left_end, t0, origin, period, n, rows, ends)
            return rows, ends
        ta = t0
        for i in range(m):
            t1 = origin + (n + 1 + i) * period
            p0, v0, a0, j, p1, v1 = self.piece(ta, t1)
            rows[i] = (ta, t1 - ta, p0, v0, a0, j)
            ends[i] = (p1, v1)
            ta = t1
        return rows, ends

    def done_code(self, t: float) -> int:
        """HSL motion_done code while this motion runs (seed-facts 2.5)."""
        at, code = self._done_at
        if at == t:  # polled again at the same time (a motion never changes)
            return code
        code = self._done_code(t)
        self._done_at = (t, code)
        return code

    def _done_code(self, t: float) -> int:
        _, v, a = self.state(t)
        speed = abs(v)
        tol = 1e-9 * max(1.0, speed)
        if abs(a) > tol:
            return MotionDone.ACCELERATING if a * v >= 0.0 else MotionDone.DECELERATING
        if abs(speed - self.str_vel) <= tol:
            return MotionDone.AT_STRVEL
        return MotionDone.AT_MAXVEL
