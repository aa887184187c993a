"""Time-overlap blending of consecutive commands (MCCL 2.6.3 II, velocity blending).

"The deceleration of first command and acceleration of second command is no more there":
with `Group.enable_overlap_blend()` every command is planned on its own from rest to rest
(a path alone, pathexec/pathmove; a point-to-point move per axis), and the next one starts
the moment the running one begins its final deceleration (that moment may fall inside a
cycle: the next motion rests until then). From then on every axis follows the sum of the
rest of the running motion and the displacement of the next (`profile.superpose`): speeds
add, position and speed stay continuous, and the corner between two lines or arcs is cut
by the overlap (figure 10: tangent speed and trajectory continuous, the path deviates from
the programmed corner). With equal deceleration and acceleration times of a T curve the
tangent speed of two collinear commands stays at the feed; a 90 degree corner dips to
feed / sqrt(2) in the middle of the overlap.

This module handles a path as the next command (its plan becomes the group's running
path once the overlay is over: holds, overrides and windows then act on it alone);
ptpblend.py handles a point-to-point command as the next one, on the same superposition.
A blend that would take an axis above its speed or acceleration cap (a reversal doubles
the acceleration on the axes that reverse) is not made: the two commands then run one
after the other. During the overlay (at most the running command's deceleration time) a
hold or an override waits until it is over (`GroupEngine._replan`), and a stop by
someone else stops each axis on its own (no single path to stop along).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

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


def start_path(engine: GroupEngine, r: _Run, cmd: _Cmd, t: float, start: float) -> bool:
    """Start path command `cmd` at `start` (t <= start < t + period) over the rest of the
    running motion; False (nothing changed) when it cannot be blended."""
    from .groupexec import PATH_WINDOW_S, _Run, _section

    try:
        rest = rest_profiles(engine, r, t)
        if rest is None:
            return False
        end = engine._units_of(np.array([p.end.p for p in rest]))
        plan = engine.plan_alone(cmd, start)
        if np.max(np.abs(end - np.asarray(plan.chain.elements[0].start))) > 1e-9 * max(
                1.0, float(np.max(np.abs(end)))):
            return False  # (the running motion does not end where the command starts)
        over = max(p.duration for p in rest)
        w = PATH_WINDOW_S + over  # the first window outlasts the overlay by a full one
        sp = plan.sprof
        windowed = sp.duration > w + 0.5 * PATH_WINDOW_S
        sp_w = _section(sp, 0.0, w) if windowed else sp
        nxt = engine._pulse_profiles(px.axis_profiles(plan.chain, sp_w, engine._ctl.period,
                                                      end))
        lead = max(start - t, 0.0)
        out = [superpose(p, 0.0, q, lead) for p, q in zip(rest, nxt, strict=True)]
        if not all(within_caps(engine, k, p) for k, p in enumerate(out)):
            return False
        engine._run_profiles(out)
    except MotionError:
        return False
    run = _Run("path", [cmd], t, plan, out, target=np.array(plan.chain.elements[-1].end),
               overlay_end=t + over)
    if windowed:
        run.window_end = start + sp_w.duration
    run.blend_at = path_blend_at(run)
    engine._run = run
    return True
