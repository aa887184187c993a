"""Time-overlap blending of consecutive commands (MCCL 2.6.3 II, velocity blending).

"The deceleration of first command and acceleration of second command is no more there":
with `Group.enable_overlap_blend()` every command is planned on its own from rest to rest
(a path alone, pathexec/pathmove; a point-to-point move per axis), and the next one starts
the moment the running one begins its final deceleration (that moment may fall inside a
cycle: the next motion rests until then), or later when its own acceleration is shorter
than that deceleration: then both ramps end together, so the speeds add up to no more than
the faster command's (an arc ramps at half the path acceleration, the look-ahead's arc
rule; S and T ramps of equal times overlap exactly). From then on every axis follows the
sum of the rest of the running motion and the displacement of the next
(`profile.superpose`): speeds add, position and speed stay continuous, and the corner
between two lines or arcs is cut by the overlap (figure 10: tangent speed and trajectory
continuous, the path deviates from the programmed corner). With equal deceleration and
acceleration times of a T curve the tangent speed of two collinear commands stays at the
feed; a 90 degree corner dips to feed / sqrt(2) in the middle of the overlap.

This module handles a path as the next command (its plan becomes the group's running path
once the overlay is over: holds, overrides and windows then act on it alone); ptpblend.py
handles a point-to-point command as the next one, on the same superposition. A blend that
would take an axis above its speed or acceleration cap (a reversal doubles the
acceleration on the axes that reverse) is not made: the two commands then run one after
the other. During the overlay (at most the running command's deceleration time) a hold or
an override waits until it is over (`GroupEngine._replan`), and a stop by someone else
stops each axis on its own (no single path to stop along).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import MotionError
from ...profile.segments import Profile, State
from ...profile.superpose import deceleration_start, superpose
from . import pathexec as px
from .pathmove import tail
from .ptpblend import within_caps

if TYPE_CHECKING:
    from .groupexec import GroupEngine, _Cmd, _Run


def path_blend_at(r: _Run) -> float | None:
    """When the next command may start over a running path: the start of its final
    deceleration, not before the overlay of an earlier blend is over."""
    plan = r.plan
    if plan is None:
        return None
    at = plan.t0 + deceleration_start(plan.sprof)
    return at if r.overlay_end is None else max(at, r.overlay_end)


def acceleration_end(p: Profile) -> float:
    """Profile time at which the first acceleration from rest ends: the end of the
    leading run of segments in which the speed rises."""
    n = p.n_segments
    dt = p.dt if p.dt is not None else np.diff(np.append(p.t0, p.duration))
    v1 = p.v0 + dt * (p.a0 + dt * p.j / 2.0)
    k = 0
    while k < n and (abs(v1[k]) > abs(p.v0[k]) + 1e-12 * max(1.0, abs(p.v0[k])) or
                     dt[k] == 0.0):
        k += 1
    return float(p.t0[k]) if k < n else p.duration


def _still(p: float) -> Profile:
    return Profile(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), 0.0,
                   State(p), State(p), (), np.zeros(0))


def rest_profiles(engine: GroupEngine, r: _Run, t: float) -> list[Profile] | None:
    """Each axis's remaining motion from time t (command pulses, time 0 = t), ending at
    rest: its own running profile, or for a windowed path the rest of the path's plan;
    None when neither ends at rest."""
    out: list[Profile] = []
    from_plan: list[Profile] | None = None
    for k, a in enumerate(engine.axes):
        m = a.motion
        if m is None:
            out.append(_still(a.position))
            continue
        since = t - m.t_start
        prof = m.profile.shifted(a.counters._cmd_off)  # raw pulse frame -> command frame
        if prof.end.v == 0.0 and prof.end.a == 0.0:
            out.append(_still(prof.end.p) if since >= prof.duration else tail(prof, since))
            continue
        if r.plan is None or r.overlay_end is not None and t < r.overlay_end:
            return None
        if from_plan is None:
            plan = r.plan
            sec = tail(plan.sprof, max(t - plan.t0, 0.0))
            from_plan = engine._pulse_profiles(px.axis_profiles(
                plan.chain, sec, engine._ctl.period, engine.position))
        out.append(from_plan[k])
    return out


#: Later starts tried when a blend would pass a cap or the feed: the overlap shortened in
#: these steps, down to none (then the commands run apart).
SHIFTS = 8


def start_path(engine: GroupEngine, r: _Run, cmd: _Cmd, t: float, start: float) -> bool:
    """Start path command `cmd` at `start` (t <= start < t + period) over the rest of the
    running motion, or at the earliest later start (SHIFTS steps towards the running
    motion's end) at which no axis passes its caps and the path speed not the larger of
    the two motions' speeds; a start in a later cycle is left in `r.blend_at`. False
    (nothing changed) when it cannot be blended now."""
    from .groupexec import _Run

    try:
        rest = rest_profiles(engine, r, t)
        if rest is None:
            return False
        end = engine._units_of(np.array([p.end.p for p in rest]))
        over = max(p.duration for p in rest)
        plan = engine.plan_alone(cmd, start)
        if np.max(np.abs(end - np.asarray(plan.chain.elements[0].start))) > 1e-9 * max(
                1.0, float(np.max(np.abs(end)))):
            return False  # (the running motion does not end where the command starts)
        # a shorter ramp than the running one's deceleration: both end together
        first = max(start, t + over - acceleration_end(plan.sprof))
        v_top = max(_speed(engine, rest, np.zeros(1)), float(np.max(plan.sprof.v0,
                                                                     initial=0.0)))
        for k in range(SHIFTS):
            at = first + (t + over - first) * k / SHIFTS
            if at >= t + engine._ctl.period - 1e-12:
                r.blend_at = at  # (a later cycle)
                return False
            got = _blended(engine, cmd, rest, end, over, t, at, v_top)
            if got is not None:
                break
        else:
            return False
        plan, out, window_end = got
        engine._run_profiles(out)
    except MotionError:
        return False
    run = _Run("path", [cmd], t, plan, out, target=np.array(plan.chain.elements[-1].end),
               overlay_end=t + over, window_end=window_end)
    run.blend_at = path_blend_at(run)
    engine._run = run
    return True


def _blended(engine: GroupEngine, cmd: _Cmd, rest: list[Profile], end: np.ndarray,
             over: float, t: float, start: float, v_top: float
             ) -> tuple[Any, list[Profile], float | None] | None:
    """(plan, every axis's summed profile, its window end) with `cmd` starting at
    `start`, or None when an axis would pass a cap or the path speed `v_top`."""
    from .groupexec import PATH_WINDOW_S, _section

    plan = engine.plan_alone(cmd, start)
    w = PATH_WINDOW_S + over  # the first window outlasts the overlay by a full one
    sp = plan.sprof
    windowed = sp.duration > w + 0.5 * PATH_WINDOW_S
    sp_w = _section(sp, 0.0, w) if windowed else sp
    nxt = engine._pulse_profiles(px.axis_profiles(plan.chain, sp_w, engine._ctl.period,
                                                  end))
    lead = max(start - t, 0.0)
    out = [superpose(p, 0.0, q, lead) for p, q in zip(rest, nxt, strict=True)]
    if not all(within_caps(engine, k, p) for k, p in enumerate(out)):
        return None
    ts = np.unique(np.concatenate([p.t0 for p in out] + [p.t0[:-1] + 0.5 * np.diff(p.t0)
                                                          for p in out if p.n_segments > 1]))
    if _speed(engine, out, ts) > v_top * (1.0 + 1e-9):
        return None
    return plan, out, (start + sp_w.duration if windowed else None)


def _speed(engine: GroupEngine, profiles: list[Profile], ts: np.ndarray) -> float:
    """The largest path speed (logical units/s) of the axes' profiles at times ts."""
    v = np.stack([p.sample(ts.clip(0.0, max(p.duration, 0.0))).v if p.n_segments
                  else np.zeros(len(ts)) for p in profiles])
    return float(np.max(np.linalg.norm(v / engine._k[:, None], axis=0), initial=0.0))
