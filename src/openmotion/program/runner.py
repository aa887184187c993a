"""Run a motion program on a controller: canonical commands -> queued `Group` commands.

    ctl = Controller(); ctl.enable_all()
    run = ProgramRunner(ctl, "G21 G90 G1 X10 Y5 F600 M2")   # compiles + validates now
    run.start(); run.wait(timeout=60)                       # virtual time
    print(run.state, run.current_line, run.events)

The whole program is compiled (G-code front end) and converted to operations in machine
units (convert.py) in the constructor: any error raises before anything moves. The group is
opened with `units=` (signed pulses per machine unit of each axis), so F is the true tool
speed and G2/G3 are true arcs also on axes with different pulses per mm. Execution is a
controller cycle hook that streams the operations into the group queue and keeps it topped
up to `window` commands (default 1024). The group's look-ahead is lazy (groupexec.py): a
running chain holds the queued commands up to twice its braking distance and joins more
from the queue when it runs short, dropping the elements it has travelled, so a program of
any length runs as one chain without resting and the work per command stays bounded. The
window only has to hold what the chain needs ahead (twice the braking distance from the
feed: about 90 segments of 0.05 mm at 40 mm/s and acc_time 0.05 s); a smaller one still
streams, but joins a command or two at a time (a re-plan each). Semantics:

- G0: straight line at the rapid feed (convert.py); G1/G2/G3: group line/arc at the feed
  (machine units/s).
- G61/G61.1 disable blending, G64 [P] enables it; the change waits for the queued motion to
  end (the group applies blending when a chain starts).
- G4: group delay. M0 (and M1 with `optional_stop`): the queued motion ends, then PAUSED
  until resume(). M2/M30: end of one pass; `repeat` passes in all. M99 in the main
  program: the motion before it ends, then the program runs again from its top with its
  state kept (LinuxCNC's task), each restart a pass: endlessly (until abort()) unless
  `repeat` sets the passes.
- M64/M65: output set once the motion queued before it has ended (LinuxCNC's task waits
  for it, as for M68). M62/M63: set at the exact instant the group starts the next
  motion command (syncout.py: Group.start_time, through a compare-engine job).
  M3/M4/M5, M7/M8/M9: wait for the motion to end, then set their outputs. M6: logged,
  ignored. M100-M199: the motion before it ends, then its executable runs and the program
  waits for it (usermcodes.py; a non-zero exit or `user_m_timeout` stops the run).
  (MSG)/(DEBUG): logged.
- pause() holds the path (decelerating along it), resume() continues, abort() stops along
  the path and drops the rest; single_block pauses after every source line.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MotionError, show
from ..units import AxisUnits
from . import canon, runcompile, runqueue
from .analogout import AnalogOut
from .convert import Op, Scales
from .css import FeedMode, SpindleMode
from .interp import Session
from .options import AXIS_LETTERS, GCodeOptions
from .orient import Orient
from .probing import Probe, WaitInput
from .progunits import ProgramUnits
from .rigidtap import RigidTap
from .runahead import LinesAhead
from .runaxes import gcode_fields, machine_axes, travel_limits
from .runcompile import RunPass
from .runfeed import follow_per_rev
from .runoverride import SegmentState, check_adaptive, check_percent, feed_hold_step
from .runoverride import apply as apply_overrides
from .runoverride import due as override_due
from .runoverride import reset as reset_overrides
from .runoverride import step as override_step
from .runrequests import answer, begin_request, on_probe_edge
from .runtypes import RunEvent, RunOptions, RunState
from .runwait import InputWait, ProbeMove
from .source import read_program
from .spindle import OrientMove, SpindleDrive, SyncMove
from .splines import SplineFeed
from .syncout import SyncedAnalog, SyncedOutputs
from .trace import CycleTrace
from .usermcodes import UserCommand, UserMCode

__all__ = ["ProgramRunner", "RunEvent", "RunOptions", "RunState", "machine_axes",
           "run_program", "travel_limits"]

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from ..control.groups.group import Group
    from ..control.trigger.compare import CompareEngine
    from ..hw.interface import InputEdge


class ProgramRunner:
    """A G-code program (text, a pathlib path, or canonical commands) bound to a controller.

    axes: letter -> controller axis (default: axes named x, y, z, a, ...). gcode: extra
    GCodeOptions fields (parameters, tool_lengths, outputs, ...); axes, n_axes, start and
    machine_units are set by the runner. The program is compiled and validated here.
    """

    def __init__(self, ctl: Controller, program: str | os.PathLike[str] | Sequence[canon.Command],
                 *, axes: Mapping[str, int | str] | None = None,
                 options: RunOptions | None = None, gcode: Mapping[str, object] | None = None,
                 file: str = "", compare: CompareEngine | None = None) -> None:
        from ..control.trigger.analog import AnalogInputs, AnalogOutputs
        from ..control.trigger.compare import CompareEngine

        if compare is not None and (not isinstance(compare, CompareEngine)
                                    or compare.ctl is not ctl):
            raise MotionError("compare must be a CompareEngine of the same controller")
        self.options = RunOptions() if options is None else options
        if not isinstance(self.options, RunOptions):
            raise MotionError(f"options must be RunOptions, got {type(options).__name__}")
        self._ctl = ctl
        letters = machine_axes(ctl, axes)
        self.letters = sorted(letters, key=AXIS_LETTERS.index)
        self.axis_indices = [letters[k] for k in self.letters]
        units = [AxisUnits.from_axis(ctl.config.axes[i]) for i in self.axis_indices]
        lin_units = {u.unit for u, k in zip(units, self.letters, strict=True)
                     if k not in "ABC" and u.unit in ("mm", "inch")}
        self.machine_units = "inch" if lin_units == {"inch"} else "mm"
        self.scales = Scales.build(units, self.letters, self.machine_units)
        self._gextra = gcode_fields(gcode)
        if not isinstance(file, (str, os.PathLike)):
            raise MotionError(f"file must be a file name (str or path) for messages, got "
                              f"{show(file)}")
        file = os.fspath(file)
        self._gextra.setdefault("n_outputs", ctl.config.digital_outputs)
        self._gextra.setdefault("n_inputs", ctl.config.digital_inputs)
        self.analog_in = AnalogInputs(ctl)
        self._gextra.setdefault("n_analog_inputs", self.analog_in.count)
        self.analog = AnalogOutputs(ctl)
        self._gextra.setdefault("n_analog_outputs", self.analog.count)
        if self.options.user_m_path:  # M100-M199 are found when compiling
            self._gextra.setdefault("user_m_path", self.options.user_m_path)
        if "soft_limits" not in self._gextra:  # moves past the EL switches fail to compile
            lims = []
            for k, i in zip(self.letters, self.axis_indices, strict=True):
                t = travel_limits(ctl, i)
                f = abs(self.scales.ppu[self.letters.index(k)]) / units[
                    self.letters.index(k)].pulses_per_unit
                lims.append(None if t is None else (t[0] / f, t[1] / f))
            self._gextra["soft_limits"] = lims
        self.file = file
        self._text: str | None = None
        self._commands: list[canon.Command] | None = None
        if isinstance(program, os.PathLike):
            self.file = file or os.fspath(program)
            self._text = read_program(program, self._goptions(self._positions()).max_bytes)
        elif isinstance(program, str):
            self._text = program
        elif isinstance(program, Sequence):
            self._commands = list(program)
            bad_cmd = [c for c in self._commands
                       if not isinstance(c, canon.Command | Probe | WaitInput | Orient
                                                  | SplineFeed | AnalogOut | RigidTap
                                                  | SpindleMode | FeedMode | UserMCode)]
            if bad_cmd:
                raise MotionError(f"program must hold canonical commands, got {bad_cmd[0]!r}")
        else:
            raise MotionError(f"program must be G-code text, a path or commands, got "
                              f"{type(program).__name__}")
        self._pass = self._compile(self._positions())
        # G38.x / M66: the rest of the program depends on the machine's answer, so it is
        # interpreted piece by piece while running (interp.Session, runwait.py)
        # M99 in the main program restarts it with its state (runcompile.restart_pass)
        self.restarts = any(isinstance(c, canon.End) and c.restart for c in self.commands)
        self._live = self._text is not None and (self.restarts or any(
            isinstance(c, Probe | WaitInput) for c in self.commands))
        self._session: Session | None = None
        self._request: ProbeMove | InputWait | SyncMove | OrientMove | UserCommand | None \
            = None
        self._stray_trip: str | None = None
        self.spindle: SpindleDrive | None = None
        self.sync_moves: list[SyncMove] = []  # G33/G76 passes run against the spindle
        self.rigid_taps: list = []  # G33.1 taps run against the spindle (RigidTapMove)
        self._per_rev = False  # feeding a G95 stretch
        self._per_rev_ops: dict[int, float] = {}  # group index -> planned spindle rps
        self.feed_override = 100.0  # the operator's, % (set_feed_override)
        self.spindle_override = 100.0
        self.feed_override_on = self.spindle_override_on = True  # M48-M51 (overrides.py)
        self.feed_hold_on = True  # M53: the feed-stop switch obeyed (feed_hold_input)
        self.adaptive_feed_on = False  # M52 (adaptive_feed_input)
        self._seg = SegmentState()  # switches waiting for their command (runoverride.py)
        self._fh_check = False  # a feed-stop edge or an M53 to look at next cycle
        self._fh_paused = False  # paused by the feed-stop input (not by the operator)
        if self.options.feed_hold_input is not None:
            ctl.hardware.read_input(self.options.feed_hold_input)  # validates the input
        self._feed_tick = 0
        self._spindle_index: int | None = None
        if self.options.spindle_axis is not None:
            self._spindle_index = ctl.axis(self.options.spindle_axis).index
            if self._spindle_index in self.axis_indices:
                raise MotionError(f"spindle_axis {self.options.spindle_axis!r} is one of the "
                                  "program's axes")
        probe = next((c for c in self.commands if isinstance(c, Probe)), None)
        if probe is not None:
            if self.options.probe_input is None:
                raise MotionError(f"line {probe.line}: G{probe.code / 10:g} needs "
                                  "RunOptions(probe_input='di<n>'), the board input the "
                                  "probe is wired to")
            ctl.hardware.read_input(self.options.probe_input)  # validates the input
        check_adaptive(self)
        self.state = RunState.READY
        self.events: list[RunEvent] = []
        self.passes_done = 0
        self.group: Group | None = None
        self.error: str = ""
        self._line_of: dict[int, int] = {}
        self.op_of: dict[int, Op] = {}
        self.starts_of: dict[int, np.ndarray] = {}   # start point (pulses) of each move
        self._cursor = self._pass.start
        self.synced = SyncedOutputs(ctl, self.axis_indices, compare, self._set_output,
                                    self._record_synced)
        self.synced_analog = SyncedAnalog(self._write_analog)
        self._pushed = 0
        self._ahead = LinesAhead()  # the coming lines' geometry (runahead.py)
        self._last_line = 0
        self._exec_line = 0   # line of the last command the trace saw executing
        self._step_line: int | None = None
        self.t_start = self.t_end = 0.0
        self._trace = CycleTrace(self.axis_indices)  # per cycle (program/trace.py)

    # ------------------------------------------------------------------ compile
    def _positions(self) -> np.ndarray:
        return np.array([self._ctl.axes[i].position for i in self.axis_indices], dtype=float)

    def _goptions(self, start_pulses: np.ndarray) -> GCodeOptions:
        start = tuple(float(x) for x in start_pulses / self.scales.ppu)
        try:
            return GCodeOptions(axes={k: n for n, k in enumerate(self.letters)},
                                n_axes=len(self.letters), machine_units=self.machine_units,
                                start=start, **self._gextra)  # type: ignore[arg-type]
        except MotionError as e:  # a gcode= field (or the soft limits made of the axes')
            raise MotionError(f"gcode options: {e}") from None

    def _compile(self, start: np.ndarray) -> RunPass:
        return runcompile.compile_pass(self, start)

    def _live_pass(self, start: np.ndarray) -> RunPass:
        return runcompile.live_pass(self, start)

    def _convert(self, chunk: list[canon.Command], start: np.ndarray) -> list[Op]:
        return runcompile.convert_chunk(self, chunk, start)

    def _check_analog(self, cmds: Sequence[object]) -> None:
        runcompile.check_analog(self, cmds)

    @property
    def ops(self) -> list[Op]:
        return self._pass.ops

    @property
    def program_units(self) -> ProgramUnits:
        """The program's G20/G21 unit at its first motion (progunits.py); the machine's
        for a command list."""
        u = getattr(self.commands, "units", None)
        return u if isinstance(u, ProgramUnits) else ProgramUnits(self.machine_units)

    @property
    def passes(self) -> int | None:
        """Passes this run makes: RunOptions.repeat, else one, or None (until abort())
        when an M99 in the main program restarts it (LinuxCNC's endless main program)."""
        if self.options.repeat is not None:
            return self.options.repeat
        return None if self.restarts else 1

    # ------------------------------------------------------------------ control
    def start(self) -> None:
        """Open the group (the program's axes) and start streaming; returns at once."""
        from ..control.groups.group import Group

        if self.state is not RunState.READY:
            raise MotionError(f"start needs a ready runner (state {self.state.value})")
        pos = self._positions()
        if self._live:
            self._pass = self._live_pass(pos)
        elif not np.array_equal(pos, self._pass.start):
            self._pass = self._compile(pos)  # the axes moved since compiling
        self._cursor = self._pass.start
        # the group works in machine units (true feed and arcs on mixed pulse scales)
        self.group = Group(self._ctl, self.axis_indices, queue_size=self.options.window,
                           acc_time=self.options.acc_time,
                           feed=float(np.min(self.scales.vmax_units)),
                           units=self.scales.axis_units(self.letters))
        self.group.set_axis_limit_policy("slow")
        self.group.set_sys_max_speed(float(np.max(self.scales.vmax_units)))
        self.state = RunState.RUNNING
        self.t_start = self._ctl.time
        if self._spindle_index is not None:
            self.spindle = SpindleDrive(self._ctl, self._spindle_index,
                                        self.options.spindle_acc_time)
        self._ctl.add_cycle_hook(self._on_cycle, due=self._due)
        self._ctl.add_jump_observer(self._on_jump)
        self.synced.attach(self.group.start_time, self.group.start_of)
        reset_overrides(self)
        if self.options.probe_input is not None:
            self._ctl.add_edge_hook(self._on_probe_edge, signals=(self.options.probe_input,))
        if self.options.feed_hold_input is not None:
            self._ctl.add_edge_hook(self._on_feed_hold_edge,
                                    signals=(self.options.feed_hold_input,))

    def set_feed_override(self, percent: float) -> None:
        """The operator's feed override, 1 .. 200 % of the programmed feed, at any time
        (re-plans a running path); ignored while the program has it off (M50 P0, M49)."""
        self.feed_override = check_percent("feed override", percent)
        apply_overrides(self)

    def set_spindle_override(self, percent: float) -> None:
        """The operator's spindle-speed override, 1 .. 200 % of S (the spindle's maximum
        caps it); ignored while the program has it off (M51 P0, M49)."""
        self.spindle_override = check_percent("spindle override", percent)
        apply_overrides(self)

    def pause(self) -> None:
        """Hold: decelerate along the path and stop; resume() continues."""
        if self.state is not RunState.RUNNING:
            raise MotionError(f"pause needs a running program (state {self.state.value})")
        self._hold()
        self.state = RunState.PAUSED
        self._event("pause", self.current_line, "paused by the operator")

    def resume(self) -> None:
        """Continue a paused program (after pause(), M0/M1 or a single-block stop)."""
        from ..control.groups.group import GroupState

        if self.state is not RunState.PAUSED:
            raise MotionError(f"resume needs a paused program (state {self.state.value})")
        g = self.group
        assert g is not None
        if g.state is GroupState.HOLDING:
            raise MotionError("resume: the hold is still decelerating; wait until it rests")
        if g.state is GroupState.HELD:
            g.cont()
        self._step_line = None
        self.state = RunState.RUNNING
        self._fh_paused = False
        self._fh_check = True  # a feed-stop input still active holds again
        self._event("resume", self.current_line, "resumed")

    def abort(self) -> None:
        """Stop along the path, drop the rest of the program, release the axes at rest."""
        if self.state not in (RunState.RUNNING, RunState.PAUSED):
            raise MotionError(f"abort needs a running or paused program "
                              f"(state {self.state.value})")
        assert self.group is not None
        self.group.abort()
        self._finish(RunState.ABORTED, "aborted by the operator")

    def wait(self, timeout: float) -> bool:
        """Virtual time: run the controller until the program is no longer running (the
        state changes only inside the cycle's hooks, so virtual time may jump)."""
        return self._ctl.run_until(lambda: self.state is not RunState.RUNNING, timeout,
                                   event_driven=True)

    @property
    def running(self) -> bool:
        return self.state is RunState.RUNNING

    @property
    def current_line(self) -> int:
        """Source line of the command executing now (or last handled). With commands queued
        but none executing (before the first starts, or between two) the last one that
        executed, else the first queued: not the last handed to the queue, which is
        lines ahead (a progress display would jump forward and back)."""
        g = self.group
        if g is not None:
            idx = g.current_index
            if idx >= 0 and idx in self._line_of:
                return self._line_of[idx]
            if g.queue_length > 0:
                return self._exec_line or next(iter(self._line_of.values()), self._last_line)
        return self._last_line

    @property
    def progress(self) -> float:
        """Fraction of the operations handed to the group in this pass (0..1)."""
        n = len(self._pass.ops)
        return 1.0 if n == 0 else self._pass.pc / n

    def trace(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per cycle of the run: times (s), command index executing (-1: none), and the
        group axes' positions in machine units (rows = cycles)."""
        t, idx, p, _ = self._trace.arrays()
        return t, idx, p / self.scales.ppu

    def actual_trace(self) -> np.ndarray:
        """Per cycle of the run (the rows of `trace`): the group axes' actual (feedback)
        positions in machine units; trace()[2] minus this is the following error."""
        return self._trace.arrays()[3] / self.scales.ppu

    def line_of(self, index: int) -> int:
        """Source line of a group command index (0 if unknown)."""
        return self._line_of.get(index, 0)

    # ------------------------------------------------------------------ execution
    def _hold(self) -> None:
        from ..control.groups.group import GroupState

        g = self.group
        assert g is not None
        if g.state is GroupState.MOVING:
            g.hold()

    def _event(self, kind: str, line: int, text: str, **kw: object) -> None:
        self.events.append(RunEvent(self._ctl.time, kind, line, text, **kw))  # type: ignore[arg-type]

    def _set_output(self, op: Op, index: int, level: bool, kind: str,
                    t: float | None = None) -> None:
        runqueue.set_output(self, op, index, level, kind, t)

    def _write_analog(self, op: Op) -> None:
        runqueue.write_analog(self, op)

    def _record_synced(self, t: float, op: Op, index: int, level: bool) -> None:
        runqueue.record_synced(self, t, op, index, level)

    def _finish(self, state: RunState, text: str) -> None:
        if self._request is not None:  # disarm a probe / input wait in progress
            self._request.close()
            self._request = None
        if self.spindle is not None:  # M2/M30, abort and faults stop the spindle
            self.spindle.stop()
            self.spindle.close()
        self.state = state
        self.t_end = self._ctl.time
        self._event(state.value, self.current_line, text)
        self._ctl.remove_cycle_hook(self._on_cycle)
        self._ctl.remove_jump_observer(self._on_jump)
        if self.group is not None and any(ax.is_moving for ax in self.group.axes):
            self._ctl.add_cycle_hook(self._trace_to_rest)   # an abort's or fault's stop
        self.synced.detach()
        if self.options.probe_input is not None:
            self._ctl.remove_edge_hook(self._on_probe_edge)
        if self.options.feed_hold_input is not None:
            self._ctl.remove_edge_hook(self._on_feed_hold_edge)
        if self.group is not None:
            if state is not RunState.ABORTED:
                self.group.close()
            else:
                self._closing = True
                self._ctl.add_cycle_hook(self._close_when_idle, due=self._close_due)

    def _trace_to_rest(self, ctl: Controller, t: float) -> None:
        """After an abort or a fault the axes still decelerate: the trace goes on (as part
        of the command that was executing) until they are at rest, so the summary and the
        report show where the machine stopped."""
        g = self.group
        if g is None:
            ctl.remove_cycle_hook(self._trace_to_rest)
            return
        self._trace.add(t, self._trace.last_index(), [ax.position for ax in g.axes],
                        [ax.counters.actual() for ax in g.axes])
        if not any(ax.is_moving for ax in g.axes):
            ctl.remove_cycle_hook(self._trace_to_rest)

    def _close_due(self, ctl: Controller) -> float:
        from ..control.groups.group import GroupState

        g = self.group
        return -math.inf if g is not None and g.state in (GroupState.IDLE,
                                                          GroupState.ERROR) else math.inf

    def _close_when_idle(self, ctl: Controller, t: float) -> None:
        from ..control.groups.group import GroupState

        g = self.group
        if g is not None and g.state in (GroupState.IDLE, GroupState.ERROR):
            g.close()
            ctl.remove_cycle_hook(self._close_when_idle)

    def _idle(self) -> bool:
        return runqueue.idle(self)

    def _due(self, ctl: Controller) -> float:
        """When `_on_cycle` may next act beyond its trace (Controller.add_cycle_hook): now
        when the group is in error or `_feed` has work; an M62/M63/M67 bound to a move at
        the start of the move before it (syncout.py: the group's plan says when); otherwise
        the group's own hook acts first and this one follows in the same cycle, so never.
        The crossed cycles' trace comes from `_on_jump`."""
        from ..control.groups.group import GroupState

        g = self.group
        assert g is not None
        if g.state is GroupState.ERROR:
            return -math.inf
        synced = math.inf
        if self.synced.armed or self.synced_analog.armed:  # M62/M63/M67 bound to moves
            current = g.current_index
            synced = min(self.synced.due(current),
                         self.synced_analog.due(ctl, current, g.start_of))
            if synced == -math.inf:
                return synced
        req = self._request
        if (req is not None and not (isinstance(req, ProbeMove) and not req.tripped)) \
                or self._stray_trip is not None or self.spindle is not None or self._fh_check:
            # an M66 wait or a tripped probe move is polled every cycle; the spindle is
            # sampled. A probe move before its trip waits on its edge hook, which lands a
            # jump in the edge's cycle (where this hook then runs): it does not poll.
            return -math.inf
        t_sw = override_due(self)  # M48-M53 at their command's start, adaptive feed
        if self.state is not RunState.RUNNING:
            return min(synced, t_sw)
        return -math.inf if self._feed_ready(g) else min(synced, t_sw)

    def _feed_ready(self, g: Group) -> bool:
        return runqueue.feed_ready(self, g)

    def _on_jump(self, ctl: Controller, first: int, last: int,
                 positions: np.ndarray, actual: np.ndarray) -> None:
        """A jump crossed cycles first..last: their trace rows, as `_on_cycle` records."""
        assert self.group is not None
        self._trace.add_span(ctl, self.group, first, last, positions, actual)
        if last < first:
            return
        last_index = self.group.index_at(ctl._t_origin + last * ctl.period)
        if last_index >= 0:
            self._exec_line = self._line_of.get(last_index, self._exec_line)

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        from ..control.groups.group import GroupError, GroupState

        g = self.group
        assert g is not None
        if self._stray_trip is not None:  # LinuxCNC: a contact outside G38 stops the run
            g.abort()
            self.error = f"line {self.current_line}: {self._stray_trip}"
            self._event("fault", self.current_line, self._stray_trip)
            self._finish(RunState.ERROR, self.error)
            return
        if g.state is GroupState.ERROR:
            self.error = f"line {self.current_line}: {g.error_message}"
            self._event("fault", self.current_line, g.error_message)
            self._finish(RunState.ERROR, self.error)
            return
        override_step(self, g)
        if self.spindle is not None:
            self.spindle.sample(t)
            if self._request is None:
                follow_per_rev(self, g)
        self._trace.add(t, g.current_index, [ax.position for ax in g.axes],
                        [ax.counters.actual() for ax in g.axes])
        if g.current_index >= 0:
            self._exec_line = self._line_of.get(g.current_index, self._exec_line)
        self.synced.fire(g.current_index, self._idle_past)
        self.synced_analog.fire(g.current_index, self._idle_past)
        if self._fh_check:
            feed_hold_step(self, g)
        if self.state is not RunState.RUNNING:
            return
        try:
            if self._request is not None and not self._answer(g):
                return
            self._feed(g)
        except (GroupError, MotionError) as err:
            line = self._pass.ops[self._pass.pc].line if self._pass.pc < len(self._pass.ops) \
                else self._last_line
            g.abort()
            self.error = f"line {line}: {err}"
            self._event("fault", line, str(err))
            self._finish(RunState.ERROR, self.error)

    def _idle_past(self, index: int) -> bool:
        return runqueue.idle_past(self, index)

    def _feed(self, g: Group) -> None:
        runqueue.feed(self, g)

    def _on_feed_hold_edge(self, ctl: Controller, e: InputEdge) -> None:
        if e.axis is None and e.signal == self.options.feed_hold_input:
            self._fh_check = True

    def _on_probe_edge(self, ctl: Controller, e: InputEdge) -> None:
        on_probe_edge(self, ctl, e)

    def _begin_request(self, g: Group, op: Op) -> None:
        begin_request(self, g, op)

    def _answer(self, g: Group) -> bool:
        return answer(self, g)

    def _push(self, g: Group, op: Op) -> int:
        return runqueue.push(self, g, op)

    def _end_of_pass(self) -> None:
        runqueue.end_of_pass(self)


def run_program(ctl: Controller, program: str | os.PathLike[str] | Sequence[canon.Command], *,
                timeout: float = 3600.0, **kw: object) -> ProgramRunner:
    """Compile, start and run a program to its end in virtual time; returns the runner."""
    run = ProgramRunner(ctl, program, **kw)  # type: ignore[arg-type]
    run.start()
    run.wait(timeout)
    return run
