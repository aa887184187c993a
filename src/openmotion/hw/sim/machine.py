"""SimMachine: the simulated machine behind the `Hardware` boundary.

Per axis (simaxis.py, `SimAxis`): a pulse generator (the commanded cubic), a drive/motor
plant, the transmission (backlash, pitch error), switches at mechanical positions, and the
encoder as decoded by the board. `advance(t)` cuts [now, t] at scenario action times, lets
every axis run (its plant's monotone motor pieces, every switch/index edge on them at the
exact crossing time) and gives each edge every axis's decoded encoder count at its instant.
The machine itself is the board: the Hardware protocol, E-stop and the scenario's actions
here; outputs and digital I/O in boardio.py (`SimBoardIO`), the per-axis extras tests and
tools read (effort, edge stops, readouts, pulse rule and record, decoder) in axisextras.py
(`SimAxisExtras`), analog I/O in analog.py / analog_in.py: mixins of `SimMachine`.

Signal levels are electrical: a switch's level is (active XOR contact is NC), where the
contact type is AxisConfig.logic[signal] ("no" default). The SD/LTC pin is one input: with
no separate LTC switch placed, every SD edge is also reported as an LTC edge.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence

import numpy as np

from openmotion.config import MachineConfig
from openmotion.errors import MotionError, check_finite, check_nonnegative
from openmotion.hw.interface import (
    AXIS_INPUTS,
    AxisCommand,
    AxisReadback,
    InputEdge,
    PieceBlock,
    QueueRun,
)

from . import kernel
from .analog import SimAnalogOutputs
from .analog_in import SimAnalogInputs
from .axisextras import SimAxisExtras
from .boardio import SimBoardIO
from .cubic import Cubic
from .encoder import EncoderWiring
from .outputs import OutputRecord, TimedOutputs
from .piecequeue import PieceQueue
from .pieces import JumpPiece
from .scenario import Scenario
from .simaxis import SimAxis
from .switches import Switch

SWITCH_SIGNALS = ("pel", "mel", "org", "sd", "ltc")


class SimMachine(SimBoardIO, SimAxisExtras, SimAnalogOutputs, SimAnalogInputs):
    """A simulated multi-axis machine implementing `openmotion.hw.interface.Hardware`.

    `wiring` optionally overrides the physical encoder of some axes (axis -> EncoderWiring)
    to model a board set up differently from how the encoder is wired.
    """

    def __init__(self, config: MachineConfig,
                 wiring: dict[int, EncoderWiring] | None = None) -> None:
        if not isinstance(config, MachineConfig):
            raise MotionError(f"config must be a MachineConfig, got {type(config).__name__}")
        wiring = dict(wiring or {})
        for k in wiring:
            if not isinstance(k, int) or not 0 <= k < len(config.axes):
                raise MotionError(f"wiring keys must be axis indices 0..{len(config.axes) - 1},"
                                  f" got {k!r}")
        for name in ("digital_inputs", "digital_outputs"):
            n = getattr(config, name)
            if not isinstance(n, int) or n < 0:
                raise MotionError(f"{name} must be an int >= 0, got {n!r}")
        self.config = config
        self._ax = [SimAxis(i, a, wiring.get(i)) for i, a in enumerate(config.axes)]
        # the compiled kernel's arrays (hw/sim/kernel.py), kept between runs while nothing
        # but the kernel changes the axes; `_stale`: they are newer than the axis objects
        self._ks: kernel.KernelState | None = None
        self._stale = False
        self._t = 0.0
        self._emg_active = False
        self._emg_armed: bool | None = None  # level at which EMG cuts every axis's pulses
        # EMG is a board input; its contact type may be given in any axis's logic table
        self._emg_nc = any(a.logic.get("emg") == "nc" for a in config.axes)
        self._di = [False] * config.digital_inputs
        self._do = [False] * config.digital_outputs
        self._pending: list[tuple[float, int | None, str, bool, int | None]] = []
        self._timed = TimedOutputs()  # do<n> writes at exact times (write_output_at)
        self.output_record = OutputRecord()  # every output edge at its exact time
        self.scenario = Scenario(self)
        self._queues = [PieceQueue() for _ in self._ax]  # QueuedHardware
        #: run quiet cycles of `run_cycles` in the compiled kernel (hw/sim/kernel.py) when
        #: it is built and models every axis; False: every cycle in Python (the reference)
        self.native = True
        # inputs derived from axis positions (probe.py): raw edges -> board edges
        self._edge_filters: list[Callable[[list], list]] = []

    # -- the axes' state: kernel arrays or objects ----------------------------------------------
    def _objects(self) -> list[SimAxis]:
        """The axis objects with their state current (the kernel's arrays written back if
        they are newer), for reading."""
        if self._stale:
            assert self._ks is not None
            self._ks.write_back(self._ax)
            self._stale = False
        return self._ax

    @property
    def _axes(self) -> list[SimAxis]:
        """The axis objects, current and free to change: the kernel's arrays are dropped
        (rebuilt from the objects before the next kernel run). Every Python path of the
        machine goes through here, so the kernel never runs on an outdated copy."""
        axes = self._objects()
        self._ks = None
        return axes

    def _index(self, axis: int) -> int:
        """`axis` checked (MotionError), without touching the axes' state."""
        if type(axis) is int and 0 <= axis < len(self._ax):
            return axis
        if isinstance(axis, bool) or not isinstance(axis, int) or not 0 <= axis < len(self._ax):
            raise MotionError(f"axis must be an int in 0..{len(self._ax) - 1}, got {axis!r}")
        return axis

    # -- Hardware protocol --------------------------------------------------------------------
    @property
    def n_axes(self) -> int:
        return len(self._ax)

    @property
    def time(self) -> float:
        return self._t

    def command(self, axis: int, cmd: AxisCommand) -> None:
        """Set the commanded cubic of `axis` over [cmd.t0, cmd.t0 + cmd.dt].

        Before cmd.t0 the command holds cmd.p0, after the end it holds the end position. If
        the command at the current time is a whole pulse or more away from the pulses
        emitted, the difference is emitted at once (a jump; a real stepper loses it).
        """
        i = self._index(axis)
        if not isinstance(cmd, AxisCommand):
            raise MotionError(f"cmd must be an AxisCommand, got {type(cmd).__name__}")
        for f in ("t0", "p0", "v0", "a0", "j"):
            check_finite(f"cmd.{f}", getattr(cmd, f))
        check_nonnegative("cmd.dt", cmd.dt)
        ks = self._ks
        if ks is not None and not ks.recording:  # into the kernel's arrays (stepping)
            t0 = float(cmd.t0)
            ks.set_command(i, float(cmd.p0), float(cmd.v0), float(cmd.a0), float(cmd.j), t0,
                           t0 + float(cmd.dt))
            self._stale = True
            return
        self._set_command(self._axes[i], cmd)

    def _set_command(self, ax: SimAxis, cmd: AxisCommand) -> None:
        t0 = float(cmd.t0)
        ax.set_command(Cubic(float(cmd.p0), float(cmd.v0), float(cmd.a0), float(cmd.j)),
                       t0, t0 + float(cmd.dt), self._t)

    # -- QueuedHardware -------------------------------------------------------------------------
    def queue_pieces(self, axis: int, pieces: Sequence[AxisCommand] | PieceBlock) -> None:
        """Append timed pieces (AxisCommands or a PieceBlock of arrays) to the queue of
        `axis` (hw.interface.QueuedHardware); each becomes the pulse generator's command at
        its t0, as `command` would make it."""
        self._queues[self._index(axis)].extend(pieces, self._t)

    def clear_queue(self, axis: int) -> None:
        """Drop the pieces of `axis` not started yet."""
        self._queues[self._index(axis)].clear()

    def queued(self, axis: int) -> int:
        """Pieces of `axis` not started yet."""
        return len(self._queues[self._index(axis)])

    def run_cycles(self, origin: float, period: float, start: int, stop: int,
                   wake: Collection[str] | None = None, trace: bool = False) -> QueueRun:
        """Run cycles start+1 .. stop on the grid origin + k * period (hw.interface.
        QueuedHardware), starting queued pieces at their t0; stop after the first cycle
        with an input edge on a signal in `wake` (None: any) or an armed stop. Stretches
        with nothing to run (every axis a stepper holding its end, no piece and no scenario
        action due) are crossed in one step. Quiet cycles run in the compiled kernel
        (hw/sim/kernel.py) when `native` is on and it models every axis. `trace`: the
        readback at the end of every cycle run, in QueueRun.trace."""
        origin = check_finite("origin", origin)
        period = check_finite("period", period)
        if period <= 0.0:
            raise MotionError(f"period must be > 0 s, got {period!r}")
        for name, k in (("start", start), ("stop", stop)):
            if isinstance(k, bool) or not isinstance(k, int):
                raise MotionError(f"{name} must be an int cycle number, got {k!r}")
        if stop < start:
            raise MotionError(f"stop must be >= start ({start}), got {stop!r}")
        queues = self._queues
        had = [len(q) > 0 for q in queues]
        k = start
        edges: list[InputEdge] = []
        rows: list[np.ndarray | tuple[np.ndarray, int]] = []
        first = True
        paced = kernel.pacing()  # real time: every cycle at its wall-clock slot
        while k < stop:
            hold = self._holding()
            if not first and hold and not paced:
                k0 = k
                k, edges = self._skip_idle(origin, period, k, stop)
                if trace and k > k0:  # a held readback: one row, seen k - k0 times
                    rows.append((self._trace_row(), k - k0))
                if edges or k >= stop:
                    break
            first = False
            ks = self._kernel_state() if self.native and (not hold or paced) \
                and not self._pending else None
            if ks is not None:
                k0 = k
                k, self._t, tr, edges = kernel.run_quiet(ks, self._ax, queues, origin, period,
                                                         k, stop, self._t, self._next_action(),
                                                         wake, trace)
                if k > k0:
                    self._timed_done()
                    if not ks.recording:
                        self._stale = True
                if tr is not None and len(tr):
                    rows.append(tr)
                found, edges = edges, self._filtered(edges)
                if found and not (edges and (wake is None or any(e.signal in wake
                                                                 for e in edges))
                                  or ks.stopped()):
                    # a cycle with edges on other signals only (or a probe's hidden
                    # switches that left its input as it was): run on
                    edges = []
                    continue
                if edges or k >= stop or (paced and kernel.interrupted()):
                    break
            if paced:
                kernel.wait_slot(k + 1)
            k += 1
            edges = self.advance(origin + k * period)
            if trace:
                rows.append(self._trace_row())
            if edges and (wake is None or any(e.signal in wake for e in edges)
                          or any(ax.stop_time is not None for ax in self._axes)):
                break
            edges = []
        drained = tuple(i for i, q in enumerate(queues) if had[i] and not q)
        tr = kernel.joined_trace(rows, len(self._ax)) if trace else None
        return QueueRun(k, edges, drained, tr)

    def _kernel_state(self) -> kernel.KernelState | None:
        """The kernel's arrays (built from the axes if dropped), or None when the kernel
        does not model this machine."""
        ks = self._ks
        if ks is None and kernel.usable(self._ax):  # not stale: the objects are current
            ks = self._ks = kernel.KernelState(self._ax)
        return ks

    def paced_cycles(self) -> bool:
        """True when `run_cycles` runs every cycle in compiled code (the kernel models
        every axis), so a real-time pacing context (control/core/realtime.py) can pace
        each cycle to the wall clock without Python; False: real time steps in Python."""
        return self.native and kernel.usable(self._objects())

    def _trace_row(self) -> np.ndarray:
        """[1, axis, 3]: pulse count, decoded count and input level bits of every axis."""
        ks = self._ks
        if ks is not None:
            return ks.readback_row()
        return self.read_axes().reshape(1, -1, 3)

    def _next_action(self) -> float:
        """Time of the next scenario action (inf: none; an axis output at a time is one):
        the kernel stops before the cycle it falls in. Board outputs at a time
        (`write_output_at(t, None, ...)`) touch no axis: the kernel runs through them and
        `_timed_done` emits them after its run, in their (time, order) sequence."""
        return self.scenario._heap[0][0] if self.scenario._heap else math.inf

    def _timed_done(self) -> None:
        """The board outputs due by now (after a kernel run), at their exact times."""
        if len(self._timed):
            self._do_due(self._t)

    def _holding(self) -> bool:
        """Nothing moves by itself: steppers only, each holding its command's end."""
        if self._pending:
            return False
        t = self._t
        if self._ks is not None:  # steppers only (kernel.usable)
            return not any(len(q) for q in self._queues) and self._ks.at_rest(t)
        for ax, q in zip(self._ax, self._queues, strict=True):
            if ax.is_servo or ax.is_dc or ax.gen.te > t or len(q):
                return False
        return True

    def _skip_idle(self, origin: float, period: float, k: int, stop: int
                   ) -> tuple[int, list[InputEdge]]:
        """Cross the cycles before the one in which the next scenario action falls (up to
        `stop`) in one advance; returns the cycle reached (and edges, never expected)."""
        heap = self.scenario._heap
        last = stop
        if heap:
            ta = heap[0][0]
            # the cycle whose end is the first >= ta runs normally
            n = max(k, math.ceil((ta - origin) / period) - 1)
            while n > k and origin + n * period >= ta:
                n -= 1
            while origin + (n + 1) * period < ta:
                n += 1
            last = min(stop, n)
        if last > k:  # one stretch (in the kernel when it models the machine)
            return last, self.advance(origin + last * period)
        return k, []

    def advance(self, t: float) -> list[InputEdge]:
        """Move every plant to time t; return the input edges since the last call. Queued
        pieces (queue_pieces) become their axis's command at their t0 on the way."""
        t = check_finite("t", t)
        if t < self._t:
            raise MotionError(f"t must be >= the current time {self._t!r}, got {t!r}")
        ks = self._kernel_state() if self.native and not self._pending else None
        if ks is not None:
            edges = self._advance_native(t)
            if edges is not None:
                return edges
        return self._advance_python(t)

    def _advance_native(self, t: float) -> list[InputEdge] | None:
        """`advance(t)` in the kernel: the stretch [now, t] as one cycle, every edge
        reported. A scenario action due in it cuts it into parts: the kernel runs up to the
        action's instant, the action applies to the axes as the kernel left them (written
        back), and the kernel runs on from the state the action left (the arrays rebuilt:
        a cut command, a moved switch, an enable). The stop times of one Python stretch
        (since the last piece start, `_advance`) are carried across the parts. None when
        the kernel ran nothing (a count beyond its exact range: the Python path runs the
        stretch); a later part the kernel refuses runs in Python."""
        heap = self.scenario._heap
        queues = self._queues
        n = len(self._ax)
        edges: list[InputEdge] = []
        carry: list[float | None] | None = None  # stop times of the parts before
        first = True
        while True:
            ks = self._kernel_state()
            if ks is None:  # (an action left a machine the kernel does not model)
                return edges + self._advance_rest(t, carry)
            ta = heap[0][0] if heap else math.inf
            end = t if ta > t else max(ta, self._t)
            left = sum(map(len, queues))
            k, t1, _, part = kernel.run_quiet(ks, self._ax, queues, end, 1.0, -1, 0, self._t,
                                              math.inf, None, report=True, paced=False)
            if k != 0:  # a count left the exact range: Python from here
                return None if first else edges + self._advance_rest(t, carry)
            first = False
            self._t = t1
            if not ks.recording:
                self._stale = True
            edges += self._filtered(part)
            stops = [ks.stop_time(x) for x in range(n)]
            if carry is not None and sum(map(len, queues)) == left:
                # no piece started in this part: one Python stretch with the parts before
                # (their stop times stand where this part cut nothing)
                stops = [c if s is None else s for s, c in zip(stops, carry, strict=True)]
            if ta > t:
                self._set_stops(stops)
                self._timed_done()
                return edges
            edges += self._filtered(self._act(end))
            if self._ks is None:  # an action changed the axes (objects current)
                carry = [ax.stop_time if ax.stop_time is not None else s
                         for ax, s in zip(self._ax, stops, strict=True)]
            else:
                carry = stops
            if end >= t and not (heap and heap[0][0] <= t):  # (a zero stretch is a no-op)
                self._set_stops(carry)
                self._timed_done()
                return edges

    def _act(self, tk: float) -> list[InputEdge]:
        """The scenario actions due at time tk (now); their edges with every axis's decoded
        count now. An action that changes an axis reaches it through `_axes` (the kernel's
        arrays written back and dropped: rebuilt from the objects for the next part); one
        that touches no axis (a board input, an E-stop with no armed EMG stop, an analog
        input) leaves the arrays as they are."""
        raw: list = []
        for _, action in self.scenario.pop_due(tk):
            action(raw)
        if not raw:
            return []
        ks = self._ks
        if ks is not None:  # no axis touched (an axis's own edge would have dropped ks)
            counts = tuple(ks.readback_rows()[:, 1].tolist())
            return [InputEdge(tm, axis, sig, lv, counts) for tm, axis, sig, lv, _ in raw]
        now = [ax.decoder.count for ax in self._ax]  # (current: `_axes` wrote them back)
        return [InputEdge(tm, axis, sig, lv, tuple(
            own if (j == axis and own is not None) else c for j, c in enumerate(now)))
            for tm, axis, sig, lv, own in raw]

    def _filtered(self, edges: list[InputEdge]) -> list[InputEdge]:
        """The kernel's edges (time-ordered) through the machine's edge filters (probe.py:
        hidden switch edges become edges of a board input, with every axis's count at
        that instant), as `_advance` filters its raw edges."""
        if not self._edge_filters or not edges:
            return edges
        out = []
        for e in edges:
            raw = [(e.time, e.axis, e.signal, e.level, None)]
            for f in self._edge_filters:
                raw = f(raw)
            for tm, axis, sig, lv, _ in raw:
                out.append(e if axis == e.axis and sig == e.signal
                           else InputEdge(tm, axis, sig, lv, e.encoders))
        return out

    def _set_stops(self, stops: list[float | None]) -> None:
        """The stop times of the last stretch: into the kernel's arrays when they are
        kept, and into the axis objects unless those are older than the arrays (with a
        pulse record the kernel writes its state back at once: both are current)."""
        ks = self._ks
        if ks is not None:
            ks.ad[:, kernel.D_STOP] = [math.nan if s is None else s for s in stops]
        if ks is None or not self._stale:
            for ax, s in zip(self._ax, stops, strict=True):
                ax.stop_time = s

    def _advance_rest(self, t: float, carry: list[float | None] | None) -> list[InputEdge]:
        """The rest of a stretch in the Python path, after parts run in the kernel."""
        left = sum(map(len, self._queues))
        edges = self._advance_python(t)
        if carry is not None and sum(map(len, self._queues)) == left:
            self._set_stops([ax.stop_time if ax.stop_time is not None else c
                             for ax, c in zip(self._axes, carry, strict=True)])
        return edges

    def _advance_python(self, t: float) -> list[InputEdge]:
        """`advance(t)` in the Python pipeline (the oracle; machines the kernel does not
        model)."""
        queues = self._queues
        if not any(len(q) for q in queues):
            return self._advance(t)
        edges: list[InputEdge] = []
        while True:
            for ax, q in zip(self._axes, queues, strict=True):
                while len(q) and q.next_start() <= self._t:
                    t0, dt, p0, v0, a0, j = q.pop()
                    ax.set_command(Cubic(p0, v0, a0, j), t0, t0 + dt, self._t)
            tn = min(min(q.next_start() for q in queues), t)
            edges += self._advance(tn)
            if tn >= t:
                return edges

    def _advance(self, t: float) -> list[InputEdge]:
        raw = self._pending
        self._pending = []
        ta = self._t
        for ax in self._axes:
            ax.stop_time = None
        for tk, action in self.scenario.pop_due(t):
            tk = max(tk, ta)
            self._run(ta, tk, raw)
            self._t = tk
            action(raw)
            ta = tk
        self._run(ta, t, raw)
        self._t = t
        if len(self._timed):
            self._do_due(t)
        raw.sort(key=lambda e: e[0])
        for f in self._edge_filters:
            raw = f(raw)
        n = len(self._axes)
        edges = []
        for tm, axis, sig, lv, own in raw:
            enc = tuple(own if (j == axis and own is not None) else self._axes[j].encoder_at(tm)
                        for j in range(n))
            edges.append(InputEdge(tm, axis, sig, lv, enc))
        for ax in self._axes:
            ax.record = []
            ax.run_start = (ax.trans.z, ax._dec_state())
        return edges

    def read_axis(self, axis: int) -> AxisReadback:
        if self._ks is not None:  # the kernel's arrays are current (objects maybe not)
            pulses, enc, bits = self._ks.readback(self._index(axis))
            return AxisReadback(pulses, enc, kernel.level_dict(bits))
        ax = self._objects()[self._index(axis)]
        return AxisReadback(ax.gen.count, ax.decoder.count,
                            dict(zip(AXIS_INPUTS, ax.levels(), strict=True)))

    def read_axes(self) -> np.ndarray:
        """int64 [n_axes, 3]: pulses out, decoded count and input level bits of every axis
        (hw.interface.BulkReadback; `read_axis` of each in one call)."""
        ks = self._ks
        if ks is not None:  # the kernel's arrays are current (objects maybe not)
            return ks.readback_rows()
        return np.array([(ax.gen.count, ax.decoder.count, kernel.level_bits(ax))
                         for ax in self._objects()], dtype=np.int64).reshape(-1, 3)

    # -- internals ----------------------------------------------------------------------------
    def _axis(self, axis: int) -> SimAxis:
        """Axis `axis` (checked), free to change (see `_axes`)."""
        return self._axes[self._index(axis)]

    def _view(self, axis: int) -> SimAxis:
        """Axis `axis` (checked), current, for reading only."""
        return self._objects()[self._index(axis)]

    def _run(self, ta: float, tb: float, raw: list) -> None:
        """Move every axis over [ta, tb], appending raw edges."""
        for ax in self._axes:
            ax.run(ta, tb, raw)

    # -- scenario actions (called by Scenario at their time, inside advance) ------------------
    def _edge(self, raw: list, ax: SimAxis, sig: str, before: bool) -> None:
        lv = ax.level(sig)
        if lv != before:
            raw.append((self._t, ax.index, sig, lv, ax.decoder.count))
            ax.armed_hit(sig, lv, self._t)

    def _place(self, axis: int, signal: str, spec: tuple[float, float, float] | None,
               raw: list) -> None:
        ax = self._axes[axis]
        sigs = ("sd", "ltc") if signal in ("sd", "ltc") else (signal,)
        before = {s: ax.level(s) for s in sigs}
        if spec is None:
            ax.switches.pop(signal, None)
        else:
            ax.switches[signal] = Switch(*spec, ax.y)
        for s in sigs:
            self._edge(raw, ax, s, before[s])

    def _set_alarm(self, axis: int, on: bool, raw: list) -> None:
        ax = self._axes[axis]
        before = {s: ax.level(s) for s in ("alm", "rdy", "inp")}
        ax.alarm = on
        if ax.is_servo:
            ax.plant.set_outputs(self._t, ax.gen, ax.outputs["svon"], on, erc=False)
        else:
            ax.plant.enabled = not on
        for s, lv in before.items():
            self._edge(raw, ax, s, lv)

    def _set_emg(self, on: bool, raw: list) -> None:
        before = self.read_input("emg")
        self._emg_active = on
        lv = self.read_input("emg")
        if lv != before:
            raw.append((self._t, None, "emg", lv, None))
            if self._emg_armed is not None and lv == self._emg_armed:
                for ax in self._axes:
                    ax.cut_pulses(self._t)

    def _set_di(self, signal: str, level: bool, raw: list) -> None:
        k = self._board_index(signal, "di", len(self._di))
        if self._di[k] != level:
            self._di[k] = level
            raw.append((self._t, None, signal, level, None))

    def _set_ready(self, axis: int, ready: bool, raw: list) -> None:
        ax = self._axes[axis]
        before = ax.level("rdy")
        ax.not_ready = not ready
        self._edge(raw, ax, "rdy", before)

    def _knock(self, axis: int, counts: float, raw: list) -> None:
        """Move a dc_servo motor `counts` command pulses back (a following error)."""
        ax = self._axes[axis]
        plant = ax.plant
        m0 = plant.motor(ax.gen)
        plant.dc.theta -= counts / plant.scale
        ax.scan([JumpPiece(self._t, m0, plant.motor(ax.gen))], raw)

    def _step_loss(self, axis: int, pulses: int, raw: list) -> None:
        ax = self._axes[axis]
        plant = ax.plant
        m0 = plant.motor(ax.gen)
        plant.lost += pulses
        if pulses:
            ax.scan([JumpPiece(self._t, m0, m0 - pulses)], raw)

