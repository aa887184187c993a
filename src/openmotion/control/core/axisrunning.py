"""Commands on an axis's running motion: on-the-fly speed and target changes, and stops.

A mixin of `axis.Axis` (the state and the move commands live there): HSL v_change /
p_change (`change_speed`, `change_position`), the decelerating stop (sd_stop, MC_Stop),
the stop along a group's path and the immediate stop (emg_stop). Each re-plans or cuts
the motion in force through the engine's `_replace` / `_kill_motion` (axisexec.py).
`_locked`, which serialises every public axis call with the cycle loop, is defined here
and used by axis.py too.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import wraps
from typing import TYPE_CHECKING, Any, TypeVar

from ...errors import InfeasibleError, MotionError, check_finite, check_flags, check_positive
from ...profile.onthefly import final_decel_start
from ...profile.segments import Profile
from . import planning
from .counters import COUNTER_MAX, COUNTER_MIN
from .states import AxisState, transition

if TYPE_CHECKING:
    from ...units import AxisUnits
    from .axis import Axis
    from .controller import Controller
    from .counters import Counters
    from .motion import ActiveMotion

F = TypeVar("F", bound=Callable[..., Any])
S = AxisState


def _locked(fn: F) -> F:
    """Serialise a public call with the cycle loop (real-time mode runs on a thread)."""

    @wraps(fn)
    def wrapper(self: Axis, *args: Any, **kwargs: Any) -> Any:
        check_flags(kwargs)
        with self._ctl._lock:
            return fn(self, *args, **kwargs)

    return wrapper  # type: ignore[return-value]


class AxisRunningCommands:
    """Mixin of `Axis`: change_speed, change_position, stop, stop_immediately."""

    name: str
    units: AxisUnits
    counters: Counters
    speed_model: Any
    _ctl: Controller
    _state: AxisState
    _motion: ActiveMotion | None
    _speed_range: float | None

    @_locked
    def change_speed(self, new_vel: float, tacc: float, *, units: bool = False) -> None:
        """Change speed on the fly (HSL v_change), for velocity and positioning moves.

        The new speed may not exceed the fixed speed range (`fix_speed_range`) or, when none
        is fixed, the move's own MaxVel. Refused (InfeasibleError, motion unchanged) when a
        positioning move has too few pulses left to reach the speed and still stop. A
        change to the speed the move already runs or ramps to changes nothing (a legacy loop
        re-issuing v_change while a sensor stays on keeps its first ramp).
        """
        v = abs(self.check_speed("new_vel", new_vel, units))
        ta = check_positive("tacc", tacc)
        m = self._check_running("change_speed")
        if m.spec is None:
            raise MotionError(f"axis {self.name}: change_speed applies to T/S and velocity "
                              "moves, not jerk-limited ones")
        limit = self._speed_range if self._speed_range is not None else m.v_range
        if v > limit * (1.0 + 1e-12):
            raise InfeasibleError(
                f"new_vel must be <= the speed range {self.speed_text(limit, units)} "
                f"(fix_speed_range to allow more), got {new_vel!r}")
        if self.speed_model is not None:
            v = self.speed_model.change(v, limit)
        t = self._ctl.time
        if v == m.spec.max_vel and t - m.t_start < final_decel_start(m.profile):
            return  # already running (or ramping) to this speed: the registers stay as set
        profile, spec = planning.change_speed(m, t, v, ta, limit)
        self._replace(m, profile, spec, m.target)

    @_locked
    def change_position(self, new_position: float, *, units: bool = False) -> None:
        """Change the target of a running absolute move on the fly (HSL p_change).

        Refused (InfeasibleError, motion unchanged) during the final deceleration or when
        the new target is too close to stop at; a target already passed makes the axis stop
        and come back ("go back").
        """
        p = check_finite("new_position", new_position)
        p = float(self.units.to_pulses(p)) if units else p
        if not COUNTER_MIN <= p <= COUNTER_MAX:
            lo, hi = (COUNTER_MIN, COUNTER_MAX) if not units else sorted(
                float(self.units.to_units(c)) for c in (COUNTER_MIN, COUNTER_MAX))
            raise MotionError(f"new_position must be in [{lo:.10g}, {hi:.10g}]"
                              f"{' ' + self.units.unit if units else ''}, "
                              f"got {new_position!r}")
        m = self._check_running("change_position")
        if m.kind != "absolute":
            raise MotionError(f"axis {self.name}: change_position applies to absolute moves "
                              "only (HSL 4.11)")
        new_target = round(m.target + (p - m.abs_target))
        profile, spec = planning.change_position(m, self._ctl.time, new_target)
        self._replace(m, profile, spec, float(new_target), abs_target=p)
        self.counters.add_target(p - self.counters.target)

    @_locked
    def stop(self, tdec: float | None = None) -> None:
        """Decelerating stop (HSL sd_stop / PLCopen MC_Stop) from any motion.

        `tdec` is the deceleration time of the move's parameters (MaxVel -> StrVel); by
        default the running move's own Tdec. Stopping an axis at rest does nothing.
        """
        td = None if tdec is None else check_positive("tdec", tdec)
        m = self._motion
        if m is None and self._state is S.HOMING:  # homing between two moves: abort it
            self.end_homing()
            return
        if m is None or self._state is S.STOPPING and td is None:
            return
        t = self._ctl.time
        profile = planning.decel_stop(m, t, td)
        self._replace(m, profile, m.spec, None, kind="stop")
        self._state = transition(self._state, S.STOPPING, self.name)

    def _stop_along(self, tail: Profile) -> None:
        """Decelerating stop that follows `tail` (command-counter frame, time 0 = now, ends
        at rest) instead of the axis's own deceleration: a group stopping along its path
        when one of its axes is stopped. The axis is STOPPING (or stays in ErrorStop)."""
        m = self._motion
        if m is None:
            return
        shifted = tail.shifted(-self.counters._cmd_off)
        self._replace(m, m.profile.splice(self._ctl.time - m.t_start, shifted), m.spec, None,
                      kind="stop")
        if self._state is not S.ERROR_STOP:
            self._state = transition(self._state, S.STOPPING, self.name)

    @_locked
    def stop_immediately(self) -> None:
        """Immediate stop (HSL emg_stop): the pulse output stops at once, at any state."""
        self._kill_motion()
        if self._state in (S.DISCRETE_MOTION, S.CONTINUOUS_MOTION, S.STOPPING, S.HOMING):
            self._state = transition(self._state, S.STANDSTILL, self.name)
