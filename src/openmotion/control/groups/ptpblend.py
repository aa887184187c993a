"""Velocity blending of point-to-point commands (MCCL 2.6.3 II, "continuous trajectory of
point to point motion: each axis's speed and trajectory continuous").

With blending on, the next PtP command does not wait for the running one to stop: it
starts when the running command's last axis begins its final deceleration (the moment
may fall inside a cycle: the new moves rest until then), and every axis follows the sum of
the rest of its running move and its new move (`profile.superpose`), so speed and
position stay continuous and the deceleration of one command and the acceleration of the
next overlap. The axes end exactly on the new targets. A blend that would take an axis
above its speed or acceleration cap is not made: the commands then run one after the
other, as without blending.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...errors import MotionError
from ...profile.segments import Profile, delayed, empty_profile
from ...profile.superpose import deceleration_start, superpose
from ..core import planning

if TYPE_CHECKING:
    from .groupexec import GroupEngine, _Cmd

_TOL = 1e-9


def blend_at(engine: GroupEngine) -> float | None:
    """Absolute time the running PtP's last axis starts its final deceleration."""
    ends = [m.t_start + deceleration_start(m.profile)
            for a in engine.axes if (m := a.motion) is not None]
    return max(ends) if ends else None


def blended_profiles(engine: GroupEngine, cmd: _Cmd, t: float, start: float
                     ) -> list[Profile | None] | None:
    """Each axis's profile from `t` (command-counter frame) running the rest of its move
    and `cmd`'s move from `start` >= t; None for an axis that neither moves nor will;
    None in all when a cap would be passed."""
    assert cmd.target is not None
    target = engine._pulses_of(cmd.target)
    lead = max(start - t, 0.0)
    out: list[Profile | None] = []
    for k, a in enumerate(engine.axes):
        m = a.motion
        off = a.counters._cmd_off  # raw pulse frame of the motion -> command frame
        old_end = (m.profile.end.p + off) if m is not None else a.position
        spec = cmd.specs[k]
        if engine._ptp_override != 1.0:
            spec = spec.derived(max_vel=min(a.max_speed, spec.max_vel * engine._ptp_override))
        nxt = planning.position_move(spec, old_end, float(target[k])) \
            if target[k] != old_end else None
        if m is None:
            out.append(None if nxt is None else
                       (delayed(nxt, lead) if lead > 1e-12 else nxt))
            continue
        if m.profile.end.v != 0.0:
            return None  # only moves that end at rest blend
        prof = superpose(m.profile.shifted(off), t - m.t_start,
                         empty_profile(old_end) if nxt is None else nxt, lead)
        if not within_caps(engine, k, prof):
            return None
        out.append(prof)
    return out


def within_caps(engine: GroupEngine, k: int, prof: Profile) -> bool:
    """Whether axis k's profile stays within the group's speed and acceleration caps."""
    if not prof.n_segments:
        return True
    a = engine.axes[k]
    vcap = min(a.max_speed, float(engine._vmax[k]))
    acap = float(engine._amax[k])
    t = np.concatenate([prof.t0, prof.t0 + (prof.dt if prof.dt is not None else 0.0)])
    # speed extrema lie at segment ends or where the acceleration crosses zero
    tz = []
    for t0, a0, j, d in zip(prof.t0, prof.a0, prof.j, prof.dt if prof.dt is not None
                            else np.diff(np.append(prof.t0, prof.duration)), strict=True):
        if j != 0.0 and 0.0 < -a0 / j < d:
            tz.append(t0 - a0 / j)
    s = prof.sample(np.concatenate([t, tz]).clip(0.0, max(prof.duration - 1e-12, 0.0)))
    return bool(np.abs(s.v).max() <= vcap * (1 + _TOL) and
                np.abs(s.a).max() <= acap * (1 + _TOL) + 1e-9)


def start_blend(engine: GroupEngine, cmd: _Cmd, t: float, start: float) -> bool:
    """Start `cmd` blended into the running PtP (all axes or none); False: not blended."""
    try:
        profs = blended_profiles(engine, cmd, t, start)
    except MotionError:
        return False
    if profs is None:
        return False
    args = []
    for a, p, spec in zip(engine.axes, profs, cmd.specs, strict=True):
        if p is None:
            continue
        dec = spec.max_vel / spec.tdec
        kw = {"stop_accel": dec, "stop_jerk": dec * 1000.0,
              "replace_running": a.motion is not None}
        args.append((a, p, kw))
    for a, p, kw in args:
        try:
            a.check_profile(p, **kw)
        except MotionError:
            return False
    with engine._commanding():
        for a, p, kw in args:
            a.run_profile(p, **kw)
    return True
