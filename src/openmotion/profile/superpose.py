"""Superposed moves: one axis executing the rest of a running move and a next move at once.

MCCL's velocity blending of point-to-point commands (2.6.3 II: "each axis's speed and
trajectory continuous") starts the next move while the running one decelerates; each axis
then follows the sum of the two displacements. The sum of two constant-jerk pieces is a
constant-jerk piece, so the result is again an exact `Profile`: its breaks are both
profiles' breaks, its end position the running move's end plus the next move's distance
(the next move's exact target when it starts at the running move's end).
"""

from __future__ import annotations

import numpy as np

from ..errors import MotionError, check_finite
from .segments import Profile, State


def superpose(running: Profile, since: float, nxt: Profile, delay: float) -> Profile:
    """From time 0 = `since` seconds into `running`: `running`'s rest plus `nxt`'s
    displacement, `nxt` starting `delay` seconds from now (at rest before). `running` must
    end at rest and `nxt` start at rest; `nxt` may end moving (a first window of a longer
    motion) when it ends after `running` does: the result then ends in its state. The
    result starts at running's state at `since`."""
    s = check_finite("since", since)
    d = check_finite("delay", delay)
    if s < 0.0 or d < 0.0:
        raise MotionError(f"since and delay must be >= 0, got {since!r}, {delay!r}")
    if running.end.v != 0.0 or running.end.a != 0.0 or nxt.start.v != 0.0:
        raise MotionError("superpose needs a running move that ends at rest and a next "
                          "one that starts at rest")
    moving = nxt.end.v != 0.0 or nxt.end.a != 0.0
    if moving and d + nxt.duration < running.duration - s - 1e-12:
        raise MotionError("a next move that ends moving must end after the running one")
    dur = max(running.duration - s, 0.0, d + nxt.duration)
    cuts = np.concatenate([[0.0], running.t0 - s, [running.duration - s],
                           nxt.t0 + d, [d, d + nxt.duration]])
    cuts = np.unique(cuts[(cuts >= 0.0) & (cuts < dur)])
    if cuts.size and dur - cuts[-1] < 1e-12:
        cuts = cuts[:-1]
    if not cuts.size:
        p = nxt.end.p + (running.end.p - nxt.start.p)
        return Profile(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), 0.0,
                       State(p), State(p))
    ends = np.append(cuts[1:], dur)
    # each piece from its midpoint (strictly inside both profiles' segments, so a float
    # cut that lands a hair before a break never picks the wrong segment), back to its start
    h = 0.5 * (ends - cuts)
    ra, na = running.sample(cuts + h + s), nxt.sample(cuts + h - d)
    j = ra.j + na.j
    a = ra.a + na.a
    v = ra.v + na.v
    pm = ra.p + na.p - nxt.start.p
    a0 = a - j * h
    v0 = v - h * (a - j * h / 2.0)
    p0 = pm - h * (v - h * (a / 2.0 - j * h / 6.0))
    st = running.state_at(s)
    return Profile(t0=cuts, p0=p0, v0=v0, a0=a0, j=j, duration=dur,
                   start=State(float(p0[0]), st.v, st.a),
                   end=State(nxt.end.p + (running.end.p - nxt.start.p), nxt.end.v,
                             nxt.end.a), dt=ends - cuts)


def deceleration_start(p: Profile) -> float:
    """Profile time at which the final deceleration to rest begins: the start of the
    trailing run of segments in which the speed falls (the whole move for one that only
    slows down; its end for one ending at speed)."""
    n = p.n_segments
    if not n:
        return 0.0
    dt = p.dt if p.dt is not None else np.diff(np.append(p.t0, p.duration))
    v1 = p.v0 + dt * (p.a0 + dt * p.j / 2.0)
    falling = np.abs(v1) < np.abs(p.v0) - 1e-12 * np.maximum(1.0, np.abs(p.v0))
    k = n
    while k > 0 and falling[k - 1]:
        k -= 1
    return float(p.t0[k]) if k < n else p.duration
