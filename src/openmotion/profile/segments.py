"""The motion profile: an immutable list of constant-jerk polynomial segments.

Every move in openmotion, single-axis or along a path, is a `Profile`. A segment holds its
start time, start state (position, velocity, acceleration) and constant jerk, so inside it

    p(dt) = p0 + v0*dt + a0*dt**2/2 + j*dt**3/6

Acceleration and velocity may jump between segments (a T-curve's corners, a PCL6045 move
that starts at StrVel). Outside [0, duration] a profile holds a constant-velocity state:
before 0 it is `start` (at rest for a move, the old speed for a velocity ramp), after the
end it is `end`, whose position is the exact target, not a float sum of segment distances.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import check_finite
from ..limits import as_array, check_pulses

try:  # the compiled sampler (setup.py builds it; absent in an unbuilt source tree)
    from .. import _profile as _c
except ImportError:  # pragma: no cover - depends on the build
    _c = None

Array = NDArray[np.float64]


class State(NamedTuple):
    """Kinematic state of one axis: position, velocity, acceleration."""

    p: float
    v: float = 0.0
    a: float = 0.0


class Samples(NamedTuple):
    """Profile sampled at given times; arrays shaped like the times."""

    p: Array
    v: Array
    a: Array
    j: Array


class Phase(NamedTuple):
    """One segment as a person reads it (for printing and plots)."""

    label: str
    t_start: float
    duration: float
    v_start: float
    v_end: float
    a_start: float
    jerk: float
    distance: float


@dataclass(frozen=True, eq=False)
class Profile:
    """Piecewise-cubic motion of one axis. Build it with `ProfileBuilder`."""

    t0: Array
    p0: Array
    v0: Array
    a0: Array
    j: Array
    duration: float
    start: State
    end: State
    labels: tuple[str, ...] = field(default=())
    #: Exact segment durations (differences of t0 lose precision late in long profiles).
    dt: Array | None = None

    # ------------------------------------------------------------------ queries
    @property
    def n_segments(self) -> int:
        return int(self.t0.size)

    @property
    def distance(self) -> float:
        """Net displacement from start to end."""
        return self.end.p - self.start.p

    def sample(self, t: ArrayLike) -> Samples:
        """Position, velocity, acceleration and jerk at time(s) `t` (vectorized)."""
        fast = isinstance(t, np.ndarray) and t.dtype == np.float64
        ts = t if fast else as_array("t", t, None)
        if _c is not None and self.t0.size:
            # compiled: the same floats as `_sample_numpy` (_profile_sample.c)
            shape = ts.shape
            flat = np.ascontiguousarray(ts.reshape(-1))
            m = flat.size
            p, v, a, j = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
            st, en = self.start, self.end
            try:
                _c.sample(self.t0, self.p0, self.v0, self.a0, self.j, flat, p, v, a, j,
                          st.p, st.v, en.p, en.v, self.duration)
            except (TypeError, ValueError, BufferError):
                pass  # columns that are not contiguous float64: the numpy version
            else:
                return Samples(p.reshape(shape), v.reshape(shape), a.reshape(shape),
                               j.reshape(shape))
        return self._sample_numpy(ts)

    def _sample_numpy(self, ts: Array) -> Samples:
        """`sample` with numpy (the oracle of the compiled version), ts float64."""
        shape = ts.shape
        ts = ts.reshape(-1)
        p = np.empty_like(ts)
        v = np.empty_like(ts)
        a = np.zeros_like(ts)
        j = np.zeros_like(ts)
        before = ts < 0.0
        after = ts >= self.duration
        inside = ~(before | after)
        p[before] = self.start.p + self.start.v * ts[before]
        v[before] = self.start.v
        p[after] = self.end.p + self.end.v * (ts[after] - self.duration)
        v[after] = self.end.v
        if self.n_segments and inside.any():
            ti = ts[inside]
            k = np.searchsorted(self.t0, ti, side="right") - 1
            np.clip(k, 0, self.n_segments - 1, out=k)
            dt = ti - self.t0[k]
            jk = self.j[k]
            ak = self.a0[k]
            vk = self.v0[k]
            p[inside] = self.p0[k] + dt * (vk + dt * (ak / 2.0 + dt * jk / 6.0))
            v[inside] = vk + dt * (ak + dt * jk / 2.0)
            a[inside] = ak + dt * jk
            j[inside] = jk
        return Samples(p.reshape(shape), v.reshape(shape), a.reshape(shape), j.reshape(shape))

    def state_at(self, t: float) -> State:
        """Scalar (p, v, a) at time t, cheaper than `sample` for one instant."""
        if type(t) is not float or not math.isfinite(t):
            t = check_finite("t", t)
        if t < 0.0:
            return State(self.start.p + self.start.v * t, self.start.v, 0.0)
        if t >= self.duration or not self.n_segments:
            return State(self.end.p + self.end.v * (t - self.duration), self.end.v, 0.0)
        k = int(np.searchsorted(self.t0, t, side="right")) - 1
        k = min(max(k, 0), self.n_segments - 1)
        dt = t - float(self.t0[k])
        jk, ak, vk = float(self.j[k]), float(self.a0[k]), float(self.v0[k])
        return State(
            float(self.p0[k]) + dt * (vk + dt * (ak / 2.0 + dt * jk / 6.0)),
            vk + dt * (ak + dt * jk / 2.0),
            ak + dt * jk,
        )

    def segment_end(self, k: int) -> State:
        """State at the end of segment k (before any jump into segment k+1)."""
        dt = self.segment_duration(k)
        jk, ak, vk = float(self.j[k]), float(self.a0[k]), float(self.v0[k])
        return State(
            float(self.p0[k]) + dt * (vk + dt * (ak / 2.0 + dt * jk / 6.0)),
            vk + dt * (ak + dt * jk / 2.0),
            ak + dt * jk,
        )

    def segment_duration(self, k: int) -> float:
        if self.dt is not None:
            return float(self.dt[k])
        nxt = float(self.t0[k + 1]) if k + 1 < self.n_segments else self.duration
        return nxt - float(self.t0[k])

    def phases(self) -> list[Phase]:
        """The segments as readable phases (label, times, velocities, distance)."""
        out = []
        for k in range(self.n_segments):
            e = self.segment_end(k)
            out.append(
                Phase(
                    self.labels[k] if k < len(self.labels) else f"segment {k}",
                    float(self.t0[k]),
                    self.segment_duration(k),
                    float(self.v0[k]),
                    e.v,
                    float(self.a0[k]),
                    float(self.j[k]),
                    e.p - float(self.p0[k]),
                )
            )
        return out

    # ----------------------------------------------------------- composition
    def splice(self, t: float, tail: Profile) -> Profile:
        """This profile up to time `t`, then `tail` (whose own time 0 starts at `t`).

        Used by on-the-fly changes: the running move is cut at the instant of the change and
        the re-planned motion continues from there.
        """
        t = min(max(t, 0.0), self.duration)
        keep = self.t0 < t
        shift = t
        n_keep = int(keep.sum())
        head_dt = np.array([self.segment_duration(k) for k in range(n_keep)])
        if n_keep:
            head_dt[-1] = t - float(self.t0[n_keep - 1])
        tail_dt = (tail.dt if tail.dt is not None
                   else np.array([tail.segment_duration(k) for k in range(tail.n_segments)]))
        return Profile(
            t0=np.concatenate([self.t0[keep], tail.t0 + shift]),
            p0=np.concatenate([self.p0[keep], tail.p0]),
            v0=np.concatenate([self.v0[keep], tail.v0]),
            a0=np.concatenate([self.a0[keep], tail.a0]),
            j=np.concatenate([self.j[keep], tail.j]),
            duration=shift + tail.duration,
            start=self.start,
            end=tail.end,
            labels=tuple(lb for lb, k in zip(self.labels, keep, strict=False) if k)
            + tail.labels,
            dt=np.concatenate([head_dt, tail_dt]),
        )

    def shifted(self, dp: float) -> Profile:
        """The same motion displaced by `dp` in position."""
        return Profile(
            self.t0, self.p0 + dp, self.v0, self.a0, self.j, self.duration,
            State(self.start.p + dp, self.start.v, self.start.a),
            State(self.end.p + dp, self.end.v, self.end.a),
            self.labels, self.dt,
        )


class ProfileBuilder:
    """Accumulates segments from a start state; `build()` freezes them into a `Profile`.

    `direction` (+1/-1) mirrors every velocity, acceleration and jerk, so planners work
    with positive quantities and negative moves come out right: all velocities,
    accelerations and jerks passed in (and `state`) are in the move's own frame, positive
    along `direction`; positions are absolute.
    """

    def __init__(self, p: float = 0.0, v: float = 0.0, a: float = 0.0,
                 *, direction: float = 1.0, v_before: float | None = None) -> None:
        self._dir = 1.0 if direction >= 0 else -1.0
        self._p, self._v, self._a = float(p), float(v) * self._dir, float(a) * self._dir
        vb = self._v if v_before is None else float(v_before) * self._dir
        self._start = State(float(p), vb, 0.0)
        self._t = 0.0
        self._rows: list[tuple[float, float, float, float, float]] = []
        self._dts: list[float] = []
        self._labels: list[str] = []

    @property
    def time(self) -> float:
        return self._t

    @property
    def state(self) -> State:
        """Current state in the builder's own (direction-normalised) frame."""
        return State(self._p, self._v / self._dir, self._a / self._dir)

    def set_velocity(self, v: float) -> ProfileBuilder:
        """Jump the velocity (a stepper starting or stopping at StrVel)."""
        self._v = float(v) * self._dir
        return self

    def set_acceleration(self, a: float) -> ProfileBuilder:
        """Jump the acceleration (the corners of a T-curve)."""
        self._a = float(a) * self._dir
        return self

    def segment(self, duration: float, jerk: float = 0.0, *, accel: float | None = None,
                label: str = "") -> ProfileBuilder:
        """Append a constant-jerk segment; `accel` jumps the acceleration at its start.

        Zero-length segments are dropped, so planners can append degenerate phases freely.
        """
        if accel is not None:
            self.set_acceleration(accel)
        if duration <= 0.0:
            return self
        j = float(jerk) * self._dir
        p, v, a, dt = self._p, self._v, self._a, float(duration)
        self._rows.append((self._t, p, v, a, j))
        self._dts.append(dt)
        self._labels.append(label or f"segment {len(self._labels)}")
        self._p = p + dt * (v + dt * (a / 2.0 + dt * j / 6.0))
        self._v = v + dt * (a + dt * j / 2.0)
        self._a = a + dt * j
        self._t += dt
        return self

    def build(self, *, end_p: float | None = None, end_v: float = 0.0) -> Profile:
        """Freeze. `end_p` is the exact target; `end_v` the velocity held after the end."""
        rows = np.array(self._rows, dtype=np.float64).reshape(-1, 5)
        end = State(self._p if end_p is None else float(end_p), float(end_v) * self._dir, 0.0)
        if end_p is None and end_v == 0.0 and rows.size == 0:
            end = State(self._p, 0.0, 0.0)
        return Profile(
            t0=rows[:, 0].copy(), p0=rows[:, 1].copy(), v0=rows[:, 2].copy(),
            a0=rows[:, 3].copy(), j=rows[:, 4].copy(), duration=self._t,
            start=self._start, end=end, labels=tuple(self._labels),
            dt=np.array(self._dts, dtype=np.float64),
        )


def empty_profile(p: float = 0.0) -> Profile:
    """A profile that stays at `p` (zero-distance move)."""
    p = check_pulses("p", p)
    return ProfileBuilder(p).build(end_p=p)


def delayed(p: Profile, lead: float) -> Profile:
    """`p` starting `lead` seconds later, at rest on its start position until then (a
    command that starts between two cycles: an exact MCC_DelayMotion)."""
    rest = ProfileBuilder(p.start.p)
    rest.segment(lead, 0.0, accel=0.0, label="delay")
    return rest.build(end_p=p.start.p).splice(lead, p)
