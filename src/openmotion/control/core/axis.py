"""One controlled axis: PLCopen state machine, counters, and single-axis motion commands.

Positions handed to the hardware are in the *raw pulse frame* (the hardware's unwrapped
pulses_out). The user-facing command counter is that frame plus an offset (see counters.py),
so setting a counter never moves anything. Public arguments are in pulses, pps and seconds;
pass `units=True` to give positions and speeds in the axis's user unit (AxisUnits).

Every command validates and plans completely before it changes anything: a refused command
(MotionError) leaves the state, counters and running motion exactly as they were. Running
the installed motion from the controller's cycle is axisexec.py (`AxisEngine`, the base);
the commands on a running motion (change_speed/position, stops) are axisrunning.py.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

from ...errors import MotionError, check_finite, check_nonnegative, check_positive
from ...hw.interface import AxisCommand
from ...limits import check_quantity
from ...profile.pcl import MoveSpec
from ...profile.segments import Profile
from ...units import MAX_PULSE_RATE, AxisUnits
from . import planning
from .axisexec import AxisEngine
from .axisrunning import AxisRunningCommands, _locked
from .counters import COUNTER_MAX, COUNTER_MIN, Counters
from .motion import ActiveMotion
from .states import AxisState, MotionDone, transition

if TYPE_CHECKING:
    from ...config import AxisConfig
    from .controller import Controller

S = AxisState


class SpeedGrid(Protocol):
    """What an axis asks of a speed model (control.cards.speed_range.SpeedModel, attached by
    `attach_speed_model`): the spec and the speed change the card really runs."""

    def move(self, spec: MoveSpec) -> MoveSpec: ...

    def change(self, new_vel: float, current_range: float) -> float: ...


class Axis(AxisRunningCommands, AxisEngine):
    """An axis of a `Controller`. Get it with `controller.axis(name_or_index)`."""

    def __init__(self, index: int, config: AxisConfig, controller: Controller) -> None:
        self.index = index
        self.name = config.name
        self.config = config
        self.units = AxisUnits.from_axis(config)
        self.counters = Counters(config.move_ratio, lambda: controller._sync(index))
        self._ctl = controller
        self._state = S.DISABLED
        self._fault: str | None = None
        self._powered = False
        self._motion: ActiveMotion | None = None
        self.motion_ended_at: float | None = None  # exact end time of the last motion
        self._pos = 0.0       # commanded position, raw pulse frame, at controller time
        self._vel = 0.0
        self._inp_enabled = False
        self._waiting_inp = False
        self._speed_range: float | None = None
        #: PCL6045 register grid (control.cards.speed_range.attach_speed_model), None = exact
        self.speed_model: SpeedGrid | None = None
        #: ALM reaction: False = stop at once (default), True = decelerate (HSL set_alm mode)
        self.alarm_decelerate = False
        self._max_speed = min(config.max_speed_pps, MAX_PULSE_RATE)
        # Additive hooks (control.loops.compensation, control.guard.inposition): each transform maps
        # the planned cubic piece to what the hardware gets (called every cycle, also at
        # rest, once any is installed); a gate holds a finished move "moving" while it
        # returns a non-zero motion_done code (0 = done).
        self.command_transforms: list[Callable[[Axis, AxisCommand], AxisCommand]] = []
        self.done_gates: list[Callable[[Axis], int]] = []
        self._gated = False

    # ------------------------------------------------------------------ status
    @property
    def state(self) -> AxisState:
        return self._state

    @property
    def fault(self) -> str | None:
        """Reason of the last fault (None until one happens; kept after reset)."""
        return self._fault

    @property
    def is_moving(self) -> bool:
        return self._motion is not None or self._waiting_inp or self._gated

    @property
    def position(self) -> float:
        """Commanded position in the command-counter frame (float, unwrapped)."""
        return self._pos + self.counters._cmd_off

    @property
    def velocity(self) -> float:
        """Commanded velocity (pps, signed)."""
        return self._vel

    @property
    def speed(self) -> float:
        """Current speed (pps, >= 0): HSL_M_get_current_speed."""
        return abs(self._vel)

    @property
    def motion_done(self) -> int:
        """HSL motion_done status: 0 stopped, 9 homing between moves, 10..13 moving, 14
        waiting for INP."""
        m = self._motion
        if m is not None:
            return m.done_code(self._ctl.time)
        if self._waiting_inp:
            return MotionDone.WAITING_INP
        if self._gated:
            return self._gate_code()
        return MotionDone.HOMING if self._state is S.HOMING else MotionDone.STOPPED

    @property
    def motion(self) -> ActiveMotion | None:
        """The motion being executed (profile anchored at `t_start`), if any."""
        return self._motion

    @property
    def raw_position(self) -> float:
        """Commanded position in the raw pulse frame (the hardware's unwrapped pulses_out
        frame, without the command counter's offset), at controller time."""
        return self._pos

    @property
    def powered(self) -> bool:
        """Whether the axis is powered (enabled; SVON on for a servo drive)."""
        return self._powered

    @property
    def max_speed(self) -> float:
        """Maximum safe speed (pps): the config's max_speed_pps, capped at the pulse rate."""
        return self._max_speed

    @property
    def speed_range(self) -> float | None:
        """The fixed speed range (pps) set by `fix_speed_range`, or None."""
        return self._speed_range

    # ------------------------------------------------------------------ power and faults
    @_locked
    def enable(self) -> None:
        """Power the axis (SVON on: the servo-on / drive-enable output every axis has, as on
        the HSL card; a stepper driver wires it to its enable input): Disabled -> Standstill.

        Refused while the emergency stop is active. Enabling an axis already enabled does
        nothing; an axis in ErrorStop needs `reset()`.
        """
        if self._state is S.ERROR_STOP:
            raise MotionError(f"axis {self.name}: in ErrorStop ({self._fault}); reset() first")
        if self._ctl.estop_active:
            raise MotionError(f"axis {self.name}: emergency stop is active")
        if self._state is not S.DISABLED:
            return
        self._ctl.hardware.write_output(self.index, "svon", True)
        self._powered = True
        self._state = transition(self._state, S.STANDSTILL, self.name)
        if self._ctl.alarm_active(self.index):
            self.fault_stop("servo alarm")

    @_locked
    def disable(self) -> None:
        """Power off: any motion stops immediately; SVON off. From ErrorStop the axis stays
        in ErrorStop (PLCopen) until reset."""
        self._kill_motion()
        self._ctl.hardware.write_output(self.index, "svon", False)
        self._powered = False
        if self._state is not S.ERROR_STOP:
            self._state = transition(self._state, S.DISABLED, self.name)

    @_locked
    def reset(self) -> None:
        """Leave ErrorStop (MC_Reset): to Standstill if powered, else Disabled.

        Refused while the cause persists (emergency stop or servo alarm still active).
        Does nothing in any other state.
        """
        if self._state is not S.ERROR_STOP:
            return
        if self._ctl.estop_active:
            raise MotionError(f"axis {self.name}: emergency stop still active; release it first")
        if self._ctl.alarm_active(self.index):
            raise MotionError(f"axis {self.name}: servo alarm still active")
        if self._motion is not None:
            raise MotionError(f"axis {self.name}: still stopping; wait for the stop to end")
        self._state = transition(self._state, S.STANDSTILL if self._powered else S.DISABLED,
                                 self.name)

    def fault_stop(self, reason: str, *, decelerate: bool = False,
                   at: float | None = None) -> None:
        """Stop and go to ErrorStop with `reason` (used by edge hooks and safety).

        Immediate by default. `decelerate=True`: decelerate to StrVel and stop (the running
        move's deceleration; jerk-limited/external: its stop limits), the stop spliced into
        the plan at absolute time `at` (an input edge's exact time, <= now; default now).
        The axis stays in ErrorStop when the stop ends. Then every fault hook runs.
        """
        with self._ctl._lock:
            m = self._motion
            if decelerate and m is not None:
                now = self._ctl.time
                t = now if at is None else min(max(float(at), m.t_start), now)
                self._replace(m, planning.decel_stop(m, t, None), m.spec, None, kind="stop")
            else:
                self._kill_motion()
            self._fault = reason
            #: when the fault happened: the edge's exact time if given, else now
            self.fault_time = self._ctl.time if at is None else float(at)
            self._state = transition(self._state, S.ERROR_STOP, self.name)
            for hook in tuple(self._ctl._fault_hooks):
                hook(self, reason)

    # ------------------------------------------------------------------ settings
    @_locked
    def fix_speed_range(self, max_vel: float, *, units: bool = False) -> None:
        """Fix the speed range: the maximum speed `change_speed` may reach (HSL 4.11)."""
        v = self.check_speed("max_vel", max_vel, units)
        if v <= 0.0:
            raise MotionError(f"max_vel must be > 0, got {max_vel!r}")
        self._speed_range = v

    @_locked
    def unfix_speed_range(self) -> None:
        """Release the range: each move's own MaxVel is again the change_speed maximum."""
        self._speed_range = None

    @_locked
    def set_move_ratio(self, ratio: float) -> None:
        """Feedback counts per command pulse (HSL_M_set_move_ratio)."""
        self.counters.set_move_ratio(ratio)

    @_locked
    def set_inp(self, enabled: bool) -> None:
        """When enabled, a positioning move is done only once the drive's INP is active."""
        if not isinstance(enabled, bool):
            raise MotionError(f"enabled must be a bool, got {enabled!r}")
        self._inp_enabled = enabled

    # ------------------------------------------------------------------ argument helpers
    def check_speed(self, name: str, value: float, units: bool = False) -> float:
        """`value` as a speed in pps (from user units/s with `units=True`), refused
        (MotionError naming `name`) unless finite and within the axis's maximum safe speed
        `max_speed`; the sign is kept. Changes nothing (homing checks its speeds with it)."""
        v = check_finite(name, value)
        v = float(self.units.scale_to_pulses(v)) if units else v
        if abs(v) > self._max_speed * (1.0 + 1e-9):
            raise MotionError(f"{name} on axis {self.name} must be <= "
                              f"{self.speed_text(self._max_speed, units)} "
                              f"(maximum safe speed), got {value!r}")
        return v

    def speed_text(self, pps: float, units: bool) -> str:
        """A speed for a message in the caller's units: "500000 pps", or with `units=True`
        "500 mm/s" (the value the caller gave is quoted beside it in the same units)."""
        if not units:
            return f"{pps:g} pps"
        return f"{abs(pps) / self.units.pulses_per_unit:.6g} {self.units.unit}/s"

    def _spec(self, shape: str, str_vel: float, max_vel: float, tacc: float,
              tdec: float | None, vs_acc: float, vs_dec: float, units: bool,
              dec_shape: str = "") -> MoveSpec:
        sv = self.check_speed("str_vel", str_vel, units)
        mv = self.check_speed("max_vel", max_vel, units)
        va = self.check_speed("vs_acc", vs_acc, units)
        vd = self.check_speed("vs_dec", vs_dec, units)
        td = tacc if tdec is None else tdec
        spec = MoveSpec(shape, sv, mv, tacc, td, va, vd, dec_shape)
        return spec if self.speed_model is None else self.speed_model.move(spec)

    def _check_can_start(self) -> None:
        st = self._state
        if st is S.ERROR_STOP:
            raise MotionError(f"axis {self.name}: in ErrorStop ({self._fault}); reset() first")
        if st is S.DISABLED:
            raise MotionError(f"axis {self.name}: disabled; enable() first")
        if st is S.STOPPING:
            raise MotionError(f"axis {self.name}: stopping; wait for Standstill")
        if st is S.HOMING:
            raise MotionError(f"axis {self.name}: homing in progress")
        if self._motion is not None or self._waiting_inp or self._gated:
            raise MotionError(
                f"axis {self.name}: a motion is running; use change_speed / change_position "
                "or stop it first")

    def _check_running(self, what: str) -> ActiveMotion:
        m = self._motion
        if m is None or self._state not in (S.DISCRETE_MOTION, S.CONTINUOUS_MOTION):
            raise MotionError(f"axis {self.name}: {what} needs a running move "
                              f"(state {self._state.value})")
        return m

    # ------------------------------------------------------------------ motion commands
    @_locked
    def move_velocity(self, velocity: float, *, str_vel: float = 0.0, tacc: float = 0.1,
                      shape: str = "T", vs_acc: float = 0.0, units: bool = False) -> None:
        """Velocity mode (HSL tv_move / sv_move): ramp from StrVel to `velocity` (signed,
        pps) in `tacc` and hold it until changed or stopped."""
        v = check_finite("velocity", velocity)
        self.check_speed("velocity", v, units)   # refused in the caller's units
        if units:  # signed: a reversed axis runs the other way in pulses
            v = float(self.units.velocity_to_pps(v))
        if v == 0.0:
            raise MotionError("velocity must be non-zero (its sign gives the direction)")
        check_quantity("velocity", abs(v), "pps")
        sv = self.check_speed("str_vel", str_vel, units)
        if abs(v) < sv:
            raise MotionError(f"velocity must satisfy |velocity| >= str_vel "
                              f"({self.speed_text(sv, units)}), "
                              f"got {velocity!r}")
        va = self.check_speed("vs_acc", vs_acc, units)
        spec = MoveSpec(shape, sv, abs(v), tacc, tacc, va, va)
        if self.speed_model is not None:
            spec = self.speed_model.move(spec)
        self._check_can_start()
        profile = planning.velocity_move(spec, 1.0 if v > 0 else -1.0, self._pos)
        self._start(ActiveMotion(profile, self._ctl.time, "velocity", spec),
                    S.CONTINUOUS_MOTION)

    @_locked
    def move_relative(self, distance: float, *, max_vel: float, str_vel: float = 0.0,
                      tacc: float = 0.1, tdec: float | None = None, shape: str = "T",
                      vs_acc: float = 0.0, vs_dec: float = 0.0, units: bool = False,
                      dec_shape: str = "") -> None:
        """Relative T/S move (HSL start_tr_move / start_sr_move) of `distance` pulses.

        The target is the command position plus the distance rounded to a whole pulse; the
        move ends exactly there. `tdec` defaults to `tacc`; `dec_shape` ('T'/'S', default
        `shape`) the deceleration's shape.
        """
        d = check_finite("distance", distance)
        d = float(self.units.to_pulses(d)) if units else d
        spec = self._spec(shape, str_vel, max_vel, tacc, tdec, vs_acc, vs_dec, units,
                          dec_shape)
        self._check_can_start()
        target = round(self._pos + d)
        self._start_discrete(spec, target, "relative", None)
        self.counters.add_target(round(d))

    @_locked
    def move_absolute(self, position: float, *, max_vel: float, str_vel: float = 0.0,
                      tacc: float = 0.1, tdec: float | None = None, shape: str = "T",
                      vs_acc: float = 0.0, vs_dec: float = 0.0, units: bool = False,
                      start_in: float = 0.0, dec_shape: str = "") -> None:
        """Absolute T/S move (HSL start_ta_move / start_sa_move) to `position` (command
        counter frame). As the HSL manual describes, the distance is measured from the
        *feedback* position converted through the move ratio: distance = position -
        feedback/ratio. `start_in` (0 <= s < one period): the move starts that long after
        now, inside the coming cycle, at rest until then (a command after an exact delay).
        `dec_shape` as in `move_relative`.
        """
        p = check_finite("position", position)
        p = float(self.units.to_pulses(p)) if units else p
        if not COUNTER_MIN <= p <= COUNTER_MAX:
            raise MotionError(f"position must be in [{COUNTER_MIN}, {COUNTER_MAX}] "
                              f"(28-bit counter), got {position!r}")
        lead = check_finite("start_in", start_in)
        if not 0.0 <= lead < self._ctl.period:
            raise MotionError(f"start_in must be in [0, period {self._ctl.period!r}) s, "
                              f"got {start_in!r}")
        spec = self._spec(shape, str_vel, max_vel, tacc, tdec, vs_acc, vs_dec, units,
                          dec_shape)
        self._check_can_start()
        d = p - self.counters.feedback_in_pulses()
        target = round(self._pos + d)
        self._start_discrete(spec, target, "absolute", p, lead)
        self.counters.add_target(p - self.counters.target)

    @_locked
    def move_jerk_limited(self, distance: float, *, v_max: float, a_max: float,
                          j_max: float, d_max: float | None = None, absolute: bool = False,
                          units: bool = False) -> None:
        """Time-optimal jerk-limited move (profile.jerk), relative or, with absolute=True, to
        a position measured like `move_absolute`. Limits in pps, pps^2, pps^3 (or user units
        with units=True). On-the-fly changes are not offered for this kind; stops are."""
        d = check_finite("distance", distance)
        vm = self.check_speed("v_max", v_max, units)
        am = check_positive("a_max", a_max)
        jm = check_positive("j_max", j_max)
        dm = None if d_max is None else check_positive("d_max", d_max)
        if units:
            d = float(self.units.to_pulses(d))
            am, jm = float(self.units.scale_to_pulses(am)), float(self.units.scale_to_pulses(jm))
            dm = None if dm is None else float(self.units.scale_to_pulses(dm))
        if absolute and not COUNTER_MIN <= d <= COUNTER_MAX:
            raise MotionError(f"distance (an absolute position) must be in [{COUNTER_MIN}, "
                              f"{COUNTER_MAX}], got {distance!r}")
        self._check_can_start()
        disp = d - self.counters.feedback_in_pulses() if absolute else d
        target = round(self._pos + disp)
        profile = planning.jerk_move(self._pos, float(target), vm, am, jm, dm)
        self._start(ActiveMotion(profile, self._ctl.time, "jerk", None, float(target),
                                 limits=(vm, max(am, dm or 0.0), jm)), S.DISCRETE_MOTION)
        self.counters.add_target(d - self.counters.target if absolute else round(d))

    @_locked
    def run_profile(self, profile: Profile, *, stop_accel: float, stop_jerk: float,
                    replace_running: bool = False, str_vel: float = 0.0) -> None:
        """Execute an externally planned Profile from now (for groups, homing, scripts).

        Positions are in the command-counter frame; the profile must start where the axis
        is (within 1e-6 pulse) and at its velocity (a replaced `run_profile` motion's, with
        `replace_running=True`, or a T/S positioning move's: a blended PtP). `str_vel`
        (pps, default 0) is the PCL6045 StrVel: like a T/S move (`MoveSpec.plan`), the
        profile may jump from rest to a speed <= str_vel at its start when the axis is at
        rest. Its end state (rest) is held; the last segment
        may end at a speed (a StrVel end jumps to rest, as a T/S move's does). A
        decelerating `stop()` uses `stop_accel` (pps^2) and `stop_jerk` (pps^3).
        """
        motion, start_p = self._prepare_profile(profile, stop_accel, stop_jerk,
                                                replace_running, str_vel)
        self._start_vetted(motion, start_p)

    def _start_vetted(self, motion: ActiveMotion, start_p: float) -> None:
        """Start a motion `_prepare_profile` vetted in this cycle (a group vets every axis
        with `_vet_profile`, then starts them all without planning each twice)."""
        if self._motion is not None or self._state is S.HOMING:
            # homing moves keep the axis in Homing; a replaced motion keeps its state
            self._motion = motion
            self._ctl._motion_changed(self, motion)
        else:  # already vetted: start without checking twice
            self._state = transition(self._state, S.DISCRETE_MOTION, self.name)
            self._motion = motion
            self._ctl._motion_changed(self, motion)
        self.counters.add_target(motion.profile.end.p - start_p)

    @_locked
    def check_profile(self, profile: Profile, *, stop_accel: float, stop_jerk: float,
                      replace_running: bool = False, str_vel: float = 0.0) -> None:
        """Raise exactly as `run_profile` would, changing nothing (a group checks every
        axis's new motion before it starts any of them)."""
        self._prepare_profile(profile, stop_accel, stop_jerk, replace_running, str_vel)

    def _vet_profile(self, profile: Profile, *, stop_accel: float, stop_jerk: float,
                     replace_running: bool = False,
                     str_vel: float = 0.0) -> tuple[ActiveMotion, float]:
        """`check_profile` that returns the vetted motion and its start position, for
        `_start_vetted` in the same cycle (lock held by the caller)."""
        return self._prepare_profile(profile, stop_accel, stop_jerk, replace_running, str_vel)

    def _prepare_profile(self, profile: Profile, stop_accel: float, stop_jerk: float,
                         replace_running: bool,
                         str_vel: float = 0.0) -> tuple[ActiveMotion, float]:
        """Validate a profile for `run_profile` and vet it; no side effects."""
        if not isinstance(profile, Profile):
            raise MotionError(f"profile must be a Profile, got {type(profile).__name__}")
        if profile.end.v != 0.0:
            raise MotionError(f"profile must end at rest (end.v == 0), got {profile.end.v!r}")
        sa = check_positive("stop_accel", stop_accel)
        sj = check_positive("stop_jerk", stop_jerk)
        sv = check_nonnegative("str_vel", str_vel)
        jump_tol = sv * 1e-9 + 1e-6  # pps: the float error of a planned StrVel
        m = self._motion
        homing = self._state is S.HOMING
        if replace_running and m is not None:
            if m.kind not in ("profile", "absolute", "relative") or \
                    self._state not in (S.DISCRETE_MOTION, S.HOMING):
                raise MotionError(f"axis {self.name}: replace_running needs a running "
                                  "run_profile or T/S positioning motion")
        elif not (homing and m is None and not self._waiting_inp and not self._gated):
            self._check_can_start()
        shifted = profile.shifted(-self.counters._cmd_off)
        st = shifted.state_at(0.0)
        if abs(st.p - self._pos) > 1e-6:
            raise MotionError(f"profile must start at the axis position {self.position!r}, "
                              f"starts at {profile.state_at(0.0).p!r}")
        if abs(st.v - self._vel) > 1e-6 * max(1.0, abs(self._vel)) and not (
                m is None and self._vel == 0.0 and abs(st.v) <= sv + jump_tol):
            raise MotionError(f"profile must start at the axis velocity {self._vel!r} "
                              f"(or jump from rest to at most str_vel={sv:g} pps), "
                              f"starts at {st.v!r}")
        motion = ActiveMotion(shifted, self._ctl.time, "profile", None, shifted.end.p,
                              limits=(math.inf, sa, sj))
        self._ctl._vet_motion(self, motion)
        return motion, st.p

    @_locked
    def begin_homing(self) -> None:
        """Standstill -> Homing (used by control.home.homing). While homing, motion commands are
        refused, `run_profile` runs the homing moves and a finished move leaves the axis in
        Homing; `end_homing` returns it to Standstill. stop/stop_immediately/faults end it."""
        self._check_can_start()
        self._state = transition(self._state, S.HOMING, self.name)

    @_locked
    def end_homing(self) -> None:
        """Homing -> Standstill (any homing move still running is cut at once)."""
        if self._state is S.HOMING:
            self._kill_motion()
            self._state = transition(self._state, S.STANDSTILL, self.name)

    # ------------------------------------------------------------------ internals
    def _start_discrete(self, spec: MoveSpec, target: int, kind: str,
                        abs_target: float | None, lead: float = 0.0) -> None:
        profile = planning.position_move(spec, self._pos, float(target))
        if lead > 0.0:
            from ...profile.segments import delayed

            profile = delayed(profile, lead)
        self._start(ActiveMotion(profile, self._ctl.time, kind, spec, float(target),
                                 abs_target), S.DISCRETE_MOTION)

    def snapshot(self) -> tuple:
        """Everything a refused command must leave unchanged (used by tests)."""
        m = self._motion
        return (self._state, self._fault, self._pos, self._vel, self._speed_range,
                self.counters.snapshot(), id(m),
                None if m is None else (m.t_start, m.kind, m.target, m.profile.duration))

