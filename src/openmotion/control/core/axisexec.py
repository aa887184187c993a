"""The run-time side of an `Axis`: its active motion, executed from the controller's cycle.

`Axis` validates and plans a command; `AxisEngine` installs the resulting motion (after the
controller vets it), hands the hardware the cubic piece of every cycle (through the
installed command transforms), and ends the motion: exactly on the profile's end position,
then waiting for the drive's INP and any done gate before the axis settles to Standstill.
A motion killed after the hardware cut the pulses itself (EdgeStopHardware) ends where the
pulses stopped, in the command position and the history.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ...hw.interface import AxisCommand
from ...profile.pcl import MoveSpec
from .counters import Counters
from .motion import ActiveMotion
from .states import AxisState, MotionDone, transition

if TYPE_CHECKING:
    from .axis import Axis
    from .controller import Controller

S = AxisState


class AxisEngine:
    """Base of `Axis`: motion installation and the per-cycle hooks (lock held)."""

    index: int
    name: str
    counters: Counters
    _ctl: Controller
    _state: AxisState
    _motion: ActiveMotion | None
    motion_ended_at: float | None
    _pos: float
    _vel: float
    _inp_enabled: bool
    _waiting_inp: bool
    _gated: bool
    command_transforms: list[Callable[[Axis, AxisCommand], AxisCommand]]
    done_gates: list[Callable[[Axis], int]]

    def _start(self, motion: ActiveMotion, state: AxisState) -> None:
        self._ctl._vet_motion(self, motion)
        self._state = transition(self._state, state, self.name)
        self._motion = motion
        self._ctl._motion_changed(self, motion)

    def _replace(self, old: ActiveMotion, profile: Any, spec: MoveSpec | None,
                 target: float | None, *, kind: str | None = None,
                 abs_target: float | None = None) -> None:
        m = ActiveMotion(profile, old.t_start, kind or old.kind, spec, target,
                         abs_target if abs_target is not None else old.abs_target,
                         old.limits, old.v_range)
        if m.kind != "stop":
            self._ctl._vet_motion(self, m)
        self._motion = m
        self._ctl._motion_changed(self, m)

    def _kill_motion(self) -> None:
        """End any motion at the current commanded position, at rest."""
        m = self._motion
        self._waiting_inp = False
        self._gated = False
        if m is None:
            return
        self._motion = None
        self._vel = 0.0
        self._ctl._motion_changed(self, None)
        self._cut_at_hardware_stop(m)

    def _cut_at_hardware_stop(self, m: ActiveMotion) -> None:
        """The hardware cut this axis's pulses itself at an edge in the last cycle
        (EdgeStopHardware): a motion killed now ends there too - command position and
        history - not at the cycle end, whoever kills it (fault, group, stop)."""
        stop_time = getattr(self._ctl.hardware, "stop_time", None)
        if stop_time is None:
            return
        ts = stop_time(self.index)
        if ts is None or ts < m.t_start or ts > self._ctl.time:
            return
        p = m.state(ts)[0]
        # the hardware holds the count it emitted (control.home.pulserule: within half a pulse of
        # p, one with the floor rule); the axis rests there, on a whole pulse
        count = self._ctl.hardware.read_axis(self.index).pulses_out - self.counters.out_offset
        self._pos = float(count) if abs(count - p) <= 1.0 else p
        self._ctl.history.truncate(self.index, ts, self._pos)

    # -- cycle hooks (called by the controller, lock held) --------------------------------
    def _command(self, t0: float, t1: float) -> AxisCommand | None:
        m = self._motion
        if m is None:
            if not self.command_transforms:
                return None  # the pulse generator holds its last end position
            cmd = AxisCommand(t0, t1 - t0, self._pos)
        else:
            p0, v0, a0, j, p1, v1 = m.piece(t0, t1)
            self._pos = p1
            self._vel = v1 if t1 < m.t_end or m.kind == "velocity" else 0.0
            cmd = AxisCommand(t0, t1 - t0, p0, v0, a0, j)
        for tr in self.command_transforms:
            cmd = tr(self, cmd)
        return cmd

    def _gate_code(self) -> int:
        for g in self.done_gates:
            code = g(self)
            if code:
                return code
        return MotionDone.STOPPED

    def _cycle_end(self, t1: float) -> None:
        m = self._motion
        if m is not None and m.finished(t1):
            self._motion = None
            self.motion_ended_at = m.t_end  # inside the cycle (an exact MCC_DelayMotion)
            self._vel = 0.0
            self._pos = m.profile.end.p
            if self._state is S.ERROR_STOP:
                pass  # a fault's decelerating stop ended: the axis stays in ErrorStop
            else:
                self._waiting_inp = m.kind != "stop" and self._inp_enabled
                self._gated = bool(self.done_gates)  # also after a stop: corrections settle
                if not (self._waiting_inp or self._gated):
                    self._settle()
        if self._waiting_inp and self._ctl.input_active(self.index, "inp"):
            self._waiting_inp = False
            if not self._gated:
                self._settle()
        if self._gated and not self._waiting_inp and self._gate_code() == 0:
            self._gated = False
            self._settle()

    def _settle(self) -> None:
        """A move is done: Standstill, except in Homing (the homing sequence goes on)."""
        if self._state is not S.HOMING:
            self._state = transition(self._state, S.STANDSTILL, self.name)
