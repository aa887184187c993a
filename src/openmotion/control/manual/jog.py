"""Jog (MCCL 2.6.2 III): by pulses, by a short stroke, or continuously.

- `jog_pulse(axis, pulses)`: a small move of at most 2048 pulses, only at standstill.
- `jog_space(axis, distance, ratio)`: a short stroke in the axis's user unit at `ratio` % of
  the axis's maximum safe speed (as PtP speed ratios are defined).
- `jog_conti(axis, direction, ratio)`: runs until `stop_jog` / `Axis.stop`, or until the
  limit switch in its direction turns active (then a decelerating stop), or until the
  optional `border` (user unit, command position) where it stops exactly.

All three refuse an axis that belongs to an open group (jog the group's axes through the
group's own commands) or that is not at standstill. Speeds ramp in `tacc` seconds (T-curve).

The continuous jog's watch declares when it acts (`_due`), so virtual time jumps while a
jog runs: it acts at once when a watched limit is already active or a jog ended, else not
before the next PEL/MEL edge (a no-op edge hook declares those signals, so such an edge
always lands a jump and the watch runs in that very cycle) or motion change.
"""

from __future__ import annotations

import math
import weakref
from typing import TYPE_CHECKING

from ...errors import COUNTER28_MAX, MotionError, check_finite, check_positive
from ...limits import PPS_MIN
from ..core.states import AxisState

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller

#: Largest pulse jog (MCCL MCC_JogPulse).
MAX_JOG_PULSES = 2048


def _axis(ctl: Controller, key: int | str) -> Axis:
    from ..groups.groupexec import OWNERS as _OWNERS

    ax = ctl.axis(key)
    if ax.index in _OWNERS.get(ctl, {}):
        raise MotionError(f"axis {ax.name} belongs to an open group; close the group first")
    if ax.state is not AxisState.STANDSTILL or ax.is_moving:
        raise MotionError(f"axis {ax.name} must be at standstill to jog "
                          f"(state {ax.state.value})")
    return ax


def _ratio_speed(ax: Axis, ratio: float) -> float:
    r = check_finite("ratio", ratio)
    v = ax.config.max_speed_pps * r / 100.0  # the config caps it at the pulse rate
    if not 0.0 < r <= 100.0 or v < PPS_MIN:
        raise MotionError(f"ratio must be in (0, 100] percent and give at least {PPS_MIN:g} "
                          f"pps, got {ratio!r}")
    return v


def jog_pulse(ctl: Controller, axis: int | str, pulses: int, *, speed: float | None = None,
              tacc: float = 0.01) -> None:
    """Move `pulses` (integer, 1..2048 in size) at standstill only."""
    if isinstance(pulses, bool) or not isinstance(pulses, int):
        raise MotionError(f"pulses must be an integer, got {pulses!r}")
    if not 0 < abs(pulses) <= MAX_JOG_PULSES:
        raise MotionError(f"pulses must be non-zero and at most {MAX_JOG_PULSES} in size, "
                          f"got {pulses!r}")
    ax = _axis(ctl, axis)
    v = _ratio_speed(ax, 10.0) if speed is None else check_positive("speed", speed)
    ax.move_relative(float(pulses), max_vel=v, tacc=tacc)


def jog_space(ctl: Controller, axis: int | str, distance: float, ratio: float, *,
              tacc: float = 0.05) -> None:
    """Short-stroke jog of `distance` user units at `ratio` % of the maximum safe speed."""
    d = check_finite("distance", distance)
    if d == 0.0:
        raise MotionError("distance must be non-zero")
    ax = _axis(ctl, axis)
    v = _ratio_speed(ax, ratio)
    ax.move_relative(float(ax.units.to_pulses(d)), max_vel=v, tacc=tacc)


def jog_conti(ctl: Controller, axis: int | str, direction: int, ratio: float, *,
              tacc: float = 0.05, border: float | None = None) -> None:
    """Continuous jog: direction 0 positive, 1 negative (as MCC_JogConti); stops at the
    limit switch ahead (decelerating) or exactly at `border` (user units) when given."""
    if direction not in (0, 1) or isinstance(direction, bool):
        raise MotionError(f"direction must be 0 (positive) or 1 (negative), got {direction!r}")
    ax = _axis(ctl, axis)
    v = _ratio_speed(ax, ratio)
    sign = 1.0 if direction == 0 else -1.0
    if border is not None:
        b = float(ax.units.to_pulses(check_finite("border", border)))
        if abs(b) > COUNTER28_MAX:
            raise MotionError(f"border must lie within the 28-bit position counter "
                              f"(|border| <= {COUNTER28_MAX} pulses), got {border!r}")
        if (b - ax.position) * sign <= 0.0:
            raise MotionError(f"border must lie ahead of the axis in the jog direction, "
                              f"got {border!r}")
        ax.move_absolute(b, max_vel=v, tacc=tacc)
        return
    ax.move_velocity(sign * v, tacc=tacc)
    jogs = _JOGS.get(ctl)
    if jogs is None:  # one permanent hook per controller: hooks are never removed mid-cycle
        jogs = _JOGS[ctl] = {}
        ctl.add_edge_hook(_limit_edge, signals=("pel", "mel"))
        ctl.add_cycle_hook(_watch, due=_due)
    jogs[ax.index] = (ax, "pel" if sign > 0 else "mel")


_JOGS: weakref.WeakKeyDictionary[Controller, dict[int, tuple[Axis, str]]] = \
    weakref.WeakKeyDictionary()


def _watch(ctl: Controller, t: float) -> None:
    """Stop continuous jogs whose limit switch ahead turned active; forget finished ones."""
    jogs = _JOGS.get(ctl, {})
    for idx, (ax, signal) in list(jogs.items()):
        if ax.motion is None or ax.state is not AxisState.CONTINUOUS_MOTION:
            del jogs[idx]
        elif ctl.input_active(ax.index, signal):
            ax.stop()
            del jogs[idx]


def _due(ctl: Controller) -> float:
    """When `_watch` next acts: now when a watched jog ended or its limit ahead is active,
    else not before an edge or a motion change (math.inf)."""
    for ax, signal in _JOGS.get(ctl, {}).values():
        if ax.motion is None or ax.state is not AxisState.CONTINUOUS_MOTION \
                or ctl.input_active(ax.index, signal):
            return -math.inf
    return math.inf


def _limit_edge(ctl: Controller, edge: object) -> None:
    """Nothing to do in the edge itself: registered with signals PEL/MEL so a limit edge
    ends a virtual-time jump and `_watch` sees the limit in that cycle."""


def stop_jog(ctl: Controller, axis: int | str) -> None:
    """Decelerating stop of a jog (MCC_AbortMotion for a jog)."""
    ctl.axis(axis).stop()
