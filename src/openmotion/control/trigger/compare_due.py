"""When the compare engine may next act, so virtual time can jump (control/core/jump.py).

The engine scans each cycle's motion for triggers. A cycle in which no job can fire and no
output edge falls is a no-op for it, so `engine_due` bounds the first instant anything can
happen from the present motion of the compared axes:

- an output line with a scheduled edge (a pulse's end, a pulse timer): that edge's time;
- a command-position job (`LevelJob` on an `AxisSource(..., "dpos")`, a dpos `WindowJob`):
  the axis is at distance d from the level (or outside the window by d), and its command
  speed never exceeds v_max (the largest |v| any segment of its profile reaches), so no
  hit comes before now + d / v_max (with margins, so the bound is never late);
- a tracked path length (VECTOR_MOVED, ZPso keeps one for its BASE) and the jobs on it:
  nothing while all its axes stand still (their last command record started and has no
  motion), every cycle while one moves: the length is accumulated cycle by cycle, and one
  integral over several cycles would round differently;
- anything whose state moves every cycle (speed PWMs, whose duty list grows each cycle;
  active MPOS jobs, whose following-error model is interpolated between cycle ends; a line
  with a late edge or a level the physical line does not show yet) or a job kind not known
  here: every cycle (-inf). The error model is kept only while an MPOS job is active.

The cycles jumped over are then exactly the ones the engine would have scanned without a
hit; the landing cycle is scanned over (previous cycle end, landing] as cycle by cycle,
so event times are the same (tests/test_jump_equivalence.py).
"""

from __future__ import annotations

import bisect
import math
from typing import TYPE_CHECKING

import numpy as np

from .compare_jobs import AxisSource, CompareJob, LevelJob, VectorSource, WindowJob

if TYPE_CHECKING:
    from .compare import CompareEngine
    from .compare_io import OutputLine


def engine_due(eng: CompareEngine) -> float:
    """Earliest time the engine's hooks may act (see the module docstring)."""
    if eng._pwms or eng._mpos_err:
        return -math.inf
    now = eng.ctl.time
    for src in eng._vectors:  # VECTOR_MOVED stays put while its axes stand still
        if not all(_at_rest(eng, a, now) for a in src.axes):
            return -math.inf
    due = math.inf
    for line in eng._lines.values():
        due = min(due, _line_due(line, now))
    for job in eng._jobs.values():
        if job.active:
            due = min(due, _job_due(eng, job, now))
        if due <= now:
            return -math.inf
    return due


def _at_rest(eng: CompareEngine, axis: int, now: float) -> bool:
    """Does the axis's command stand still from `now` on (its last record started by now
    and has no velocity, acceleration or jerk)? Then every later cycle's track is constant
    until a command or hook appends motion, which happens only in cycles that run."""
    h = eng.ctl.history
    if h.end_time(axis) > now:
        return False
    rec = h.record_at(axis, now)
    return rec is not None and rec[2] == 0.0 and rec[3] == 0.0 and rec[4] == 0.0


def _line_due(line: OutputLine, now: float) -> float:
    if line._late or line._hold or line.level_at(now) != line._written:
        return -math.inf  # the next cycle writes the physical line
    ts = line._t  # time-ordered
    k = bisect.bisect_right(ts, now)
    return ts[k] if k < len(ts) else math.inf


def _job_due(eng: CompareEngine, job: CompareJob, now: float) -> float:
    if isinstance(job, WindowJob):
        if job.kind != "dpos":
            return -math.inf
        if job.index >= job.size:
            return math.inf
        centre = job.points[job.index]
        return max(_reach(eng, a, float(c), job.maxerr, now)
                   for a, c in zip(job.axes, centre, strict=True))
    if isinstance(job, LevelJob):
        src = job.source
        if isinstance(src, VectorSource):  # (engine_due: its axes stand still)
            return math.inf
        if not isinstance(src, AxisSource) or src.kind != "dpos":
            return -math.inf
        lvl = job.value
        return math.inf if lvl is None else _reach(eng, src.axis, lvl, 0.0, now)
    return -math.inf


def _reach(eng: CompareEngine, axis: int, centre: float, width: float, now: float) -> float:
    """A lower bound of the first time the axis's command position (DPOS frame) comes
    within `width` of `centre` (-inf: it may be there now)."""
    ctl = eng.ctl
    # the scalar state_at: the same p as position_at (one formula), without its array path
    x = ctl.history.state_at(axis, now).p + eng._cmd_offset(axis)
    d = abs(x - centre) - width - 1e-6 * (abs(centre) + width + 1.0)
    if d <= 0.0:
        return -math.inf
    vb = _speed_bound(eng, axis)
    if vb == 0.0:
        return math.inf
    return now + d / vb * (1.0 - 1e-9) - 1e-9


def _speed_bound(eng: CompareEngine, axis: int) -> float:
    """The largest |v| the axis's present motion can reach (0 without motion); cached
    per profile object (profiles are immutable)."""
    m = eng.ctl.axes[axis].motion
    if m is None:
        return 0.0
    pr = m.profile
    cache = eng.__dict__.setdefault("_speed_bounds", {})
    hit = cache.get(id(pr))
    if hit is not None and hit[0] is pr:
        return hit[1]
    vb = max(abs(pr.start.v), abs(pr.end.v))
    if pr.n_segments:
        dt = pr.dt if pr.dt is not None else np.diff(np.append(pr.t0, pr.duration))
        seg = np.abs(pr.v0) + np.abs(pr.a0) * dt + 0.5 * np.abs(pr.j) * dt * dt
        vb = max(vb, float(np.max(seg)))
    vb *= 1.0 + 1e-9
    if len(cache) > 64:
        cache.clear()
    cache[id(pr)] = (pr, vb)
    return vb
