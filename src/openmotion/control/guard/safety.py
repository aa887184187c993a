"""Motion I/O safety: end limits, slow-down, alarm, E-stop, ERC, INP/SVON/RDY, io_status.

Every `Controller` attaches one by default (`ctl.safety`; `Controller(safety=False)` to
opt out, then `Safety(ctl)` attaches one later; `Safety.of(ctl)` finds it).
It installs an edge hook, a cycle hook, a fault hook and a motion check on the controller
(nothing is active before; `detach()` removes them). It owns `safety.soft` (soft limits,
softlimits.py) and `safety.cmp` (comparators 3 and 4, comparators.py).

Reactions (HSL-4XMO 3, 4.8; MCCL 2.8):

- +EL / -EL (logic NO/NC from the axis config): on the edge to active, a moving axis stops
  immediately or (`set_el(axis, "decel")`) decelerates to StrVel and stops, the stop spliced
  into the plan at the edge's exact time. Direction-sensitive (default, HSL and MCCL mode 0):
  only the limit ahead of the motion stops it and the axis may move away; insensitive (MCCL
  mode 1): any limit becoming active stops any motion. Every motion kind is stopped (velocity,
  positioning, jerk-limited, `run_profile`: groups and homing included). The axis goes to
  ErrorStop with fault "+EL" / "-EL" (PLCopen: an axis error; `reset()` works while the limit
  is still active, so the axis can be moved off it). A motion into an active limit is
  refused (MotionError naming the limit), in both modes.
- Homing that uses a limit: `safety.suspend(axis, "pel")` (or "mel", "sd", "soft") turns the
  reaction and the start check for that signal off until `safety.resume(axis, "pel")`; also
  usable as `with safety.suspended(axis, "pel"): ...`.
- Group engines: `ctl.add_fault_hook(fn(axis, reason))` (alias `safety.on_axis_fault`) is
  called whenever any axis goes to ErrorStop: limits, alarms, E-stop, step loss, soft limits.
- SD (when enabled, `set_sd`): while active the axis runs at StrVel (HSL change of speed at
  the move's Tdec); released, it goes back to the speed it had (level mode) or stays slow
  until the motion ends (latched mode). `set_sd(..., stop=True)` (HSL sd_mode 1): SD
  active makes a decelerating stop instead (the motion ends, no fault). A motion without
  StrVel (jerk-limited, external) or with StrVel 0 makes a decelerating stop instead.
  Cycle resolution (one cycle late).
- ALM: the controller stops the axis (ErrorStop "servo alarm"); `set_alm(axis, "decel")`
  makes it a decelerating stop from the edge time. Motion is refused while ALM is active.
- EMG: the controller stops every axis at once; motion is refused until released + reset.
- ERC: `set_erc(axis, width_s)` arms a one-shot pulse on a limit, alarm or E-stop stop
  (when the stop is immediate: at once; when decelerating: as the stop ends);
  `pulse_erc(axis)` for home completion. The width is rounded up to whole cycles.
- INP: `set_inp(axis, True)` (Axis.set_inp): motion done only once INP is active.
- SVON/RDY: `set_servo(axis, on)` powers the axis (SVON); `set_rdy_check(axis, True)`
  refuses motion while RDY is inactive and stops a moving axis at once when RDY drops
  (ErrorStop "drive not ready").

Residual of the cycle model: the hardware has already executed the cycle in which an edge
happened, so an immediate stop ends where that cycle ended (at most one cycle of travel past
the edge; a real PCL6045 stops the pulses at the edge). With a back end implementing
`EdgeStopHardware` the pulses stop at the edge itself: EMG always armed (every axis), EL and
ALM immediate stops with `set_edge_stop(axis, True)`; the axis then ends at the cut.
A decelerating stop is planned from
the edge time; the next cycle's piece starts on that plan, so the pulse output corrects by
the difference between the old and the new plan over the rest of the edge's cycle (about
a*T^2/2, under a pulse at usual rates, plus StrVel*T when the stop ends inside that cycle).
"""

from __future__ import annotations

import contextlib
import math
import weakref
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ...errors import InfeasibleError, MotionError, check_nonnegative
from ...hw.interface import EdgeStopHardware, InputEdge
from ..core.states import AxisState
from .comparators import Comparators
from .softlimits import SoftLimits

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller
    from ..core.motion import ActiveMotion

S = AxisState
#: io_status bits (seed-facts 2.4, HSL get_io_status).
IO_STATUS_BITS = {"rdy": 0, "alm": 1, "pel": 2, "mel": 3, "org": 4, "dir": 5, "emg": 6,
                  "pcs": 7, "erc": 8, "ez": 9, "clr": 10, "ltc": 11, "sd": 12, "inp": 13,
                  "svon": 14}
SUSPENDABLE = ("pel", "mel", "sd", "soft")
LIMIT_REASONS = {"pel": "+EL", "mel": "-EL"}
#: Faults after which an armed ERC pulse is sent (HSL 3: EL and ALM; also E-stop).
ERC_REASONS = ("+EL", "-EL", "servo alarm", "emergency stop")
# controller -> weak reference to its Safety: a strong value would keep its key (the
# controller, which the Safety references) alive for ever
_INSTALLED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass
class AxisSafety:
    """Per-axis settings (read them as `safety.settings(axis)`)."""

    el_enabled: bool = True
    el_decelerate: bool = False
    el_direction_sensitive: bool = True
    sd_enabled: bool = False
    sd_latched: bool = False
    erc_width: float = 0.0       # s; 0 = no automatic ERC pulse
    rdy_required: bool = False
    edge_stop: bool = False      # immediate EL/ALM stops cut the pulses in the hardware
    suspended: set[str] = field(default_factory=set)
    sd_stop: bool = False        # SD mode 1: slow down and stop (a decelerating stop)


@dataclass(frozen=True)
class StopRecord:
    """Why and where an axis was stopped by a fault (get_abnormal_stop_status style)."""

    axis: int
    reason: str
    time: float       # the edge time when an input caused it, else the cycle time
    position: float   # planned command position (command counter frame) at `time`
    velocity: float   # planned velocity at `time` (pps)


def io_status(ctl: Controller, axis: int | str) -> int:
    """HSL get_io_status word of an axis (seed-facts 2.4): logical levels (NO/NC applied).

    bit 0 RDY, 1 ALM, 2 +EL, 3 -EL, 4 ORG, 5 DIR (commanded velocity > 0: DIR high is the
    positive direction), 6 EMG, 7 PCS (not modelled: 0), 8 ERC (output level), 9 EZ,
    10 CLR (not modelled: 0), 11 LTC, 12 SD, 13 INP, 14 SVON (output level).
    """
    ax = ctl.axis(axis)
    i = ax.index
    word = 0
    for sig in ("rdy", "alm", "pel", "mel", "org", "ez", "ltc", "sd", "inp"):
        if ctl.input_active(i, sig):
            word |= 1 << IO_STATUS_BITS[sig]
    if ax.velocity > 0.0:
        word |= 1 << IO_STATUS_BITS["dir"]
    if ctl.estop_active:
        word |= 1 << IO_STATUS_BITS["emg"]
    read_out = getattr(ctl.hardware, "read_output", None)
    for sig in ("erc", "svon"):
        if read_out is not None and read_out(i, sig):
            word |= 1 << IO_STATUS_BITS[sig]
    return word


def motion_direction(ax: Axis, m: ActiveMotion, t: float) -> int:
    """+1 / -1 / 0: the way motion `m` of `ax` goes at time t (velocity, else acceleration,
    else its remaining displacement)."""
    _, v, a = m.state(t)
    if v != 0.0:
        return 1 if v > 0.0 else -1
    if a != 0.0:
        return 1 if a > 0.0 else -1
    d = m.profile.end.p - m.state(t)[0]
    return 0 if abs(d) < 0.5 else (1 if d > 0.0 else -1)


class Safety:
    """The motion I/O reactions of one controller (see the module docstring)."""

    def __init__(self, controller: Controller) -> None:
        from ..core.controller import Controller

        if not isinstance(controller, Controller):
            raise MotionError(f"controller must be a Controller, got "
                              f"{type(controller).__name__}")
        if Safety.of(controller) is not None:
            raise MotionError("this controller already has a Safety attached")
        self.ctl = controller
        n = len(controller.axes)
        self._cfg = [AxisSafety() for _ in range(n)]
        self._sd_saved: list[float | None] = [None] * n
        self._sd_latch = [False] * n
        self._erc_off: list[float | None] = [None] * n
        self._erc_after_stop = [False] * n
        self._edge_time: float | None = None
        # logical EL levels, kept from the edges (no hardware read per cycle)
        self._el = [{s: controller.input_active(i, s) for s in ("pel", "mel")}
                    for i in range(n)]
        #: every fault stop, oldest first
        self.stops: list[StopRecord] = []
        self.soft = SoftLimits(controller, self._is_suspended)
        self.cmp = Comparators(controller)
        controller.add_edge_hook(self._on_edge, signals=("pel", "mel", "sd", "rdy"))
        controller.add_cycle_hook(self._on_cycle, due=self._due)
        controller.add_fault_hook(self._on_fault)
        controller.add_motion_check(self._check_motion)
        _INSTALLED[controller] = weakref.ref(self)
        hw = controller.hardware
        self._hw_stop = isinstance(hw, EdgeStopHardware)
        if self._hw_stop:
            hw.arm_stop(None, "emg", controller.estop_input_level)
        for i in range(n):
            self._arm(i)

    @staticmethod
    def of(controller: Controller) -> Safety | None:
        """The Safety attached to `controller`, or None."""
        ref = _INSTALLED.get(controller)
        return None if ref is None else ref()

    def detach(self) -> None:
        """Remove every hook this object installed (reactions off)."""
        c = self.ctl
        c.remove_edge_hook(self._on_edge)
        c.remove_cycle_hook(self._on_cycle)
        c.remove_fault_hook(self._on_fault)
        c.remove_motion_check(self._check_motion)
        _INSTALLED.pop(c, None)
        if self._hw_stop:
            c.hardware.arm_stop(None, "emg", None)
            for i in range(len(c.axes)):
                for sig in ("pel", "mel", "alm"):
                    c.hardware.arm_stop(i, sig, None)
            self._hw_stop = False

    def _arm(self, i: int) -> None:
        """Arm the hardware's own edge stops (EdgeStopHardware) as the settings say:
        immediate EL stops (direction-sensitive: the limit ahead only) and immediate ALM
        stops; decelerating stops and suspended limits stay with the cycle-level reaction."""
        if not self._hw_stop:
            return
        hw = self.ctl.hardware
        c = self._cfg[i]
        cfg = self.ctl.axes[i].config
        for sig, sgn in (("pel", 1), ("mel", -1)):
            on = c.edge_stop and c.el_enabled and not c.el_decelerate and sig not in c.suspended
            d = sgn if c.el_direction_sensitive else 0
            hw.arm_stop(i, sig, (cfg.signal_logic(sig) != "nc") if on else None, d)
        on = c.edge_stop and not self.ctl.axes[i].alarm_decelerate
        hw.arm_stop(i, "alm", (cfg.signal_logic("alm") != "nc") if on else None, 0)

    # ------------------------------------------------------------------ settings
    def _idx(self, axis: int | str) -> int:
        return self.ctl.axis(axis).index

    def settings(self, axis: int | str) -> AxisSafety:
        """The settings of an axis (a copy: change them with the set_* methods)."""
        c = self._cfg[self._idx(axis)]
        return AxisSafety(c.el_enabled, c.el_decelerate, c.el_direction_sensitive,
                          c.sd_enabled, c.sd_latched, c.erc_width, c.rdy_required,
                          c.edge_stop, set(c.suspended), c.sd_stop)

    def set_el(self, axis: int | str, mode: str | int) -> None:
        """HSL_M_set_el: stop mode at an end limit, "immediate" (0) or "decel" (1: to StrVel
        then stop)."""
        i = self._idx(axis)
        self._cfg[i].el_decelerate = _mode(mode, "mode")
        self._arm(i)

    def set_limit_check(self, axis: int | str, enabled: bool = True, *,
                        direction_sensitive: bool = True) -> None:
        """MCC_EnableLimitSwitchCheck: limits checked at all, and mode 0 (direction
        sensitive, default) or mode 1 (any active limit stops any motion)."""
        i = self._idx(axis)
        _bool("enabled", enabled)
        _bool("direction_sensitive", direction_sensitive)
        self._cfg[i].el_enabled = enabled
        self._cfg[i].el_direction_sensitive = direction_sensitive
        self._arm(i)

    def set_edge_stop(self, axis: int | str, enabled: bool) -> bool:
        """Let the hardware cut this axis's pulses at the exact EL / ALM edge time (immediate
        modes; a PCL6045 does). Off by default: an axis of an interpolating group would stop
        at the edge while the others stop at the cycle end (off the path by up to v*T).
        Returns whether the hardware can (EdgeStopHardware); E-stop is always armed."""
        _bool("enabled", enabled)
        i = self._idx(axis)
        self._cfg[i].edge_stop = enabled
        self._arm(i)
        return self._hw_stop

    def set_sd(self, axis: int | str, enabled: bool, *, latched: bool = False,
               stop: bool = False) -> None:
        """HSL_M_set_sd: slow-down on/off, level (default) or latched mode; `stop` (sd_mode
        1): SD active makes a decelerating stop instead of slowing to StrVel. The SD logic is
        the axis config's (logic["sd"])."""
        i = self._idx(axis)
        _bool("enabled", enabled)
        _bool("latched", latched)
        _bool("stop", stop)
        c = self._cfg[i]
        c.sd_enabled, c.sd_latched, c.sd_stop = enabled, latched, stop
        if not enabled:
            self._sd_latch[i] = False

    def set_alm(self, axis: int | str, mode: str | int) -> None:
        """HSL_M_set_alm mode: "immediate" (0) or "decel" (1) stop on a servo alarm."""
        ax = self.ctl.axis(axis)
        ax.alarm_decelerate = _mode(mode, "mode")
        self._arm(ax.index)

    def set_erc(self, axis: int | str, width: float) -> None:
        """HSL_M_set_erc: ERC one-shot width in seconds (0 = no automatic pulse)."""
        i = self._idx(axis)
        self._cfg[i].erc_width = check_nonnegative("width", width)

    def set_inp(self, axis: int | str, enabled: bool) -> None:
        """HSL_M_set_inp: wait for INP before a positioning move is done."""
        self.ctl.axis(axis).set_inp(enabled)

    def set_servo(self, axis: int | str, on: bool) -> None:
        """HSL_M_set_servo: SVON on (enable the axis) or off (disable it)."""
        _bool("on", on)
        ax = self.ctl.axis(axis)
        if on:
            ax.enable()
        else:
            ax.disable()

    def set_rdy_check(self, axis: int | str, required: bool) -> None:
        """Refuse motion while the drive's RDY input is inactive."""
        _bool("required", required)
        self._cfg[self._idx(axis)].rdy_required = required

    def suspend(self, axis: int | str, signal: str) -> None:
        """Turn the reaction to `signal` ("pel", "mel", "sd", "soft") off for `axis`
        (homing that uses a limit); `resume` turns it back on."""
        i = self._idx(axis)
        self._cfg[i].suspended.add(_signal(signal))
        self._arm(i)

    def resume(self, axis: int | str, signal: str) -> None:
        i = self._idx(axis)
        self._cfg[i].suspended.discard(_signal(signal))
        self._arm(i)

    @contextlib.contextmanager
    def suspended(self, axis: int | str, *signals: str) -> Iterator[None]:
        """`with safety.suspended(axis, "pel", "soft"): ...`"""
        for s in signals:
            _signal(s)
        i = self._idx(axis)
        before = set(self._cfg[i].suspended)
        self._cfg[i].suspended |= set(signals)
        self._arm(i)
        try:
            yield
        finally:
            self._cfg[i].suspended = before
            self._arm(i)

    def _is_suspended(self, axis: int, signal: str) -> bool:
        return signal in self._cfg[axis].suspended

    def on_axis_fault(self, hook: Callable[[Axis, str], None]) -> None:
        """Call `hook(axis, reason)` when any axis goes to ErrorStop (ctl.add_fault_hook)."""
        self.ctl.add_fault_hook(hook)

    # ------------------------------------------------------------------ status
    def io_status(self, axis: int | str) -> int:
        """See the module function `io_status`."""
        return io_status(self.ctl, axis)

    def last_stop(self, axis: int | str) -> StopRecord | None:
        """The latest fault stop of an axis (reason, time, position), or None."""
        i = self._idx(axis)
        for r in reversed(self.stops):
            if r.axis == i:
                return r
        return None

    def pulse_erc(self, axis: int | str, width: float | None = None) -> None:
        """Send one ERC pulse now (e.g. at home completion); width defaults to set_erc's."""
        i = self._idx(axis)
        w = self._cfg[i].erc_width if width is None else check_nonnegative("width", width)
        if w <= 0.0:
            raise MotionError("width must be > 0 (set_erc or the width argument)")
        self.ctl.hardware.write_output(i, "erc", True)
        self._erc_off[i] = self.ctl.time + w

    # ------------------------------------------------------------------ motion check
    def _check_motion(self, ax: Axis, m: ActiveMotion) -> None:
        ctl = self.ctl
        i = ax.index
        if ctl.estop_active:
            raise MotionError(f"axis {ax.name}: emergency stop is active")
        if ctl.input_active(i, "alm"):
            raise MotionError(f"axis {ax.name}: servo alarm (ALM) is active")
        c = self._cfg[i]
        if c.rdy_required and not ctl.input_active(i, "rdy"):
            raise MotionError(f"axis {ax.name}: drive not ready (RDY inactive)")
        if c.el_enabled:
            d = motion_direction(ax, m, ctl.time)
            for sig, sgn in (("pel", 1), ("mel", -1)):
                if d == sgn and sig not in c.suspended and ctl.input_active(i, sig):
                    raise MotionError(f"axis {ax.name}: {LIMIT_REASONS[sig]} is active; "
                                      f"motion towards it is refused")
        self.soft.check_motion(ax, m)

    # ------------------------------------------------------------------ hooks
    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if e.axis is None:
            return
        ax = ctl.axes[e.axis]
        sig = e.signal
        if sig == "rdy":
            self._rdy_edge(ax, e)
            return
        active = e.level != (ax.config.signal_logic(sig) == "nc") if sig in (
            "pel", "mel", "sd") else False
        if sig in ("pel", "mel"):
            self._el[e.axis][sig] = active
        if not active:
            return
        c = self._cfg[e.axis]
        if sig == "sd":
            if c.sd_enabled and c.sd_latched and "sd" not in c.suspended:
                self._sd_latch[e.axis] = True
            return
        m = ax.motion
        if not c.el_enabled or sig in c.suspended or m is None:
            return
        if ax.state is S.ERROR_STOP and ax.fault == LIMIT_REASONS[sig]:
            return  # already reacting to this limit (its decelerating stop)
        d = motion_direction(ax, m, e.time)
        if c.el_direction_sensitive and d != (1 if sig == "pel" else -1):
            return
        self._fault(ax, LIMIT_REASONS[sig], c.el_decelerate, e.time)

    def _rdy_edge(self, ax: Axis, e: InputEdge) -> None:
        """RDY lost while moving, with the RDY check on: the drive cannot follow, so the
        axis stops at once (ErrorStop "drive not ready"), as for an alarm."""
        if not self._cfg[ax.index].rdy_required or not ax.is_moving:
            return
        if e.level != (ax.config.signal_logic("rdy") == "nc"):
            return  # RDY became active
        self._fault(ax, "drive not ready", False, e.time)

    def _fault(self, ax: Axis, reason: str, decelerate: bool, t: float) -> None:
        self._edge_time = t
        try:
            ax.fault_stop(reason, decelerate=decelerate, at=t)
        finally:
            self._edge_time = None

    def _on_fault(self, ax: Axis, reason: str) -> None:
        ctl = self.ctl
        i = ax.index
        t = ctl.time if self._edge_time is None else self._edge_time
        st = ctl.history.state_at(i, t)
        off = ax.position - ax.counters.pulses_from_command(ax.position)
        self.stops.append(StopRecord(i, reason, t, st.p + off, st.v))
        if self._cfg[i].erc_width > 0.0 and reason in ERC_REASONS:
            if ax.motion is None:
                self.pulse_erc(i)
            else:
                self._erc_after_stop[i] = True

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        for ax in ctl.axes:
            i = ax.index
            off = self._erc_off[i]
            if off is not None and t >= off - 1e-12:
                ctl.hardware.write_output(i, "erc", False)
                self._erc_off[i] = None
            if self._erc_after_stop[i] and ax.motion is None:
                self._erc_after_stop[i] = False
                self.pulse_erc(i)
            m = ax.motion
            if m is None:
                self._sd_saved[i] = None
                self._sd_latch[i] = False
                continue
            c = self._cfg[i]
            if ax.state is not S.ERROR_STOP and c.el_enabled:
                self._limit_level_check(ax, c)
            if c.sd_enabled and "sd" not in c.suspended and ax.motion is not None:
                self._sd_cycle(ax, c)
        self.soft.on_cycle(t)
        self.cmp.on_cycle(t)

    def _due(self, ctl: Controller) -> float:
        """When `_on_cycle` may next act (Controller.add_cycle_hook): an ERC pulse's end;
        every cycle while a limit or SD input is active under a motion, an SD slow-down is
        saved, or an ERC pulse waits for a stop to end; soft limits and comparators as they
        say; otherwise not before something happens (math.inf)."""
        due = math.inf
        for ax in ctl.axes:
            i = ax.index
            off = self._erc_off[i]
            if off is not None:
                due = min(due, off - 1e-12)
            m = ax.motion
            if m is None:
                if self._erc_after_stop[i] or self._sd_saved[i] is not None \
                        or self._sd_latch[i]:
                    return -math.inf
                continue
            c = self._cfg[i]
            if c.el_enabled and ax.state is not S.ERROR_STOP and any(self._el[i].values()):
                return -math.inf
            if c.sd_enabled and "sd" not in c.suspended and (
                    self._sd_saved[i] is not None or self._sd_latch[i]
                    or ctl.input_active(i, "sd")):
                return -math.inf
        return min(due, self.soft.due(), self.cmp.due())

    def _limit_level_check(self, ax: Axis, c: AxisSafety) -> None:
        """A motion heading into a limit that is already active (the reaction was suspended
        when the edge came, or the motion turned around on the limit) stops now."""
        v = ax.velocity
        if v == 0.0:
            return
        for sig, sgn in (("pel", 1), ("mel", -1)):
            if sig in c.suspended or not self._el[ax.index][sig]:
                continue
            if v * sgn > 0.0 or not c.el_direction_sensitive:
                self._fault(ax, LIMIT_REASONS[sig], c.el_decelerate, self.ctl.time)
                return

    def _sd_cycle(self, ax: Axis, c: AxisSafety) -> None:
        i = ax.index
        m = ax.motion
        assert m is not None
        active = self.ctl.input_active(i, "sd") or self._sd_latch[i]
        running = ax.state in (S.DISCRETE_MOTION, S.CONTINUOUS_MOTION)
        saved = self._sd_saved[i]
        if active and saved is None and running:
            if c.sd_stop or m.spec is None or m.spec.str_vel <= 0.0:
                ax.stop()  # sd_mode 1, or nothing to slow to: a decelerating stop
                return
            self._sd_saved[i] = m.spec.max_vel
            if ax.speed > m.spec.str_vel:
                with contextlib.suppress(InfeasibleError):
                    ax.change_speed(m.spec.str_vel, m.spec.tdec)
        elif not active and saved is not None:
            self._sd_saved[i] = None
            if running and m.spec is not None:
                with contextlib.suppress(InfeasibleError):
                    ax.change_speed(saved, m.spec.tacc)


def _mode(mode: str | int, name: str) -> bool:
    """"immediate"/0 -> False, "decel"/1 -> True."""
    if mode in ("immediate", 0) and not isinstance(mode, bool):
        return False
    if mode in ("decel", 1) and not isinstance(mode, bool):
        return True
    raise MotionError(f"{name} must be 'immediate' (0) or 'decel' (1), got {mode!r}")


def _bool(name: str, value: object) -> None:
    if not isinstance(value, bool):
        raise MotionError(f"{name} must be a bool, got {value!r}")


def _signal(signal: str) -> str:
    if signal not in SUSPENDABLE:
        raise MotionError(f"signal must be one of {SUSPENDABLE}, got {signal!r}")
    return signal
