"""The hardware boundary: the one narrow interface the control layer talks to.

The control layer never knows whether the hardware is simulated. Each cycle it:

1. hands every axis the commanded motion for the coming cycle as one cubic piece
   (`AxisCommand`): a pulse generator emits pulses exactly where that polynomial crosses
   each count's half-pulse point, so the command is exact between cycles, not only at
   cycle ends;
2. calls `advance(t)`, which moves the hardware to time t and returns every input edge that
   happened since the last call, each with its exact time (`InputEdge`);
3. reads counters and input levels (`read_axis`), and writes outputs.

A back end that implements `QueuedHardware` also takes motion ahead of time: a queue of
timed cubic pieces per axis (a whole stretch of a profile, planned ahead), which it executes
by itself over many cycles (`run_cycles`), reporting back only what the control layer must
act on: the cycle in which input edges happened (with the edges, at their exact times) and
the axes whose queue ran empty. The control layer then skips the cycles in between
(virtual time jumps, control/core/jump.py); back ends without it get one command per cycle.

Signal levels crossing this boundary are *electrical* (True = contact closed / line
active-high as wired). Logic (normally open / closed, active high / low) is applied by the
control layer from the machine configuration, as a real controller's registers do.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

#: Names of the per-axis motion input signals (HSL-4XMO chapter 3).
AXIS_INPUTS = ("pel", "mel", "org", "sd", "ltc", "ez", "alm", "inp", "rdy")
#: Names of the per-axis motion output signals.
AXIS_OUTPUTS = ("svon", "erc")


@dataclass(frozen=True, slots=True)
class AxisCommand:
    """Commanded pulse position over [t0, t0 + dt]: p0 + v0*s + a0*s**2/2 + j*s**3/6.

    Positions are in command pulses (float); the pulse output is the command rounded to
    the nearest count (pulse k leaves at k - 1/2 going up, k + 1/2 going down; a back end
    that counts otherwise sets `half_pulse = False`, see control/home/pulserule.py).
    """

    t0: float
    dt: float
    p0: float
    v0: float = 0.0
    a0: float = 0.0
    j: float = 0.0


@dataclass(frozen=True, slots=True)
class InputEdge:
    """An input changed level at an exact time. `axis` is None for board-level inputs
    (emergency stop `emg`, general inputs `di<n>`)."""

    time: float
    axis: int | None
    signal: str
    level: bool
    encoders: tuple[int, ...] = ()  # every axis's encoder count at `time` (for latches)


@dataclass(frozen=True, slots=True)
class AxisReadback:
    """What the hardware reports for one axis at the current time."""

    pulses_out: int          # pulses emitted so far (signed, not wrapped)
    encoder: int             # encoder counts as decoded by the input mode (signed, not wrapped)
    inputs: dict[str, bool]  # electrical levels of AXIS_INPUTS


@runtime_checkable
class Hardware(Protocol):
    """What a back end (the simulator, or a real board driver) provides."""

    @property
    def n_axes(self) -> int: ...

    @property
    def time(self) -> float: ...

    def command(self, axis: int, cmd: AxisCommand) -> None:
        """Set the commanded motion of `axis` for the coming cycle."""

    def advance(self, t: float) -> list[InputEdge]:
        """Move the hardware to time t (>= current time); return the edges, time-ordered."""

    def read_axis(self, axis: int) -> AxisReadback:
        """Counters and input levels of `axis` at the current time."""

    def write_output(self, axis: int | None, signal: str, level: bool) -> None:
        """Drive an output: per-axis `svon`/`erc`, or board-level `do<n>` (axis None)."""

    def read_input(self, signal: str) -> bool:
        """Board-level input level: `emg` or `di<n>`."""


@runtime_checkable
class EffortHardware(Protocol):
    """Optional extension: a back end with motor-effort outputs (PWM duty / analog torque
    command) for axes whose position loop is closed in the control layer (dc_servo).

    Not part of `Hardware`, so back ends without such outputs stay valid; the control layer
    checks `isinstance(hw, EffortHardware)` before attaching a servo loop.
    """

    def command_effort(self, axis: int, t0: float, value: float) -> None:
        """Hold motor effort `value` (duty, clamped to [-1, 1]) from time t0 (>= the
        hardware time) until the next call. MotionError for an axis without an effort
        output (not a dc_servo axis) or a bad value; nothing changes then."""


@runtime_checkable
class EdgeStopHardware(Protocol):
    """Optional extension: the pulse output stops by itself at an input edge, at the edge's
    exact time, as a PCL6045 does at EL/EMG/ALM (HSL-4XMO 3.3, 4.8) - not one cycle later.

    The control layer arms it (control/guard/safety.py) and, when an immediate stop follows an
    edge, asks `stop_time` whether the hardware already cut the pulses there, so that its
    command position and history end at the same instant.
    """

    def arm_stop(self, axis: int | None, signal: str, level: bool | None,
                 direction: int = 0) -> None:
        """When input `signal` of `axis` changes to electrical `level` while the axis moves
        in `direction` (+1, -1; 0 = either), stop that axis's pulse output at once (the
        command holds where it was at the edge). `axis` None with `signal` "emg": every
        axis. `level` None disarms."""

    def stop_time(self, axis: int) -> float | None:
        """Time at which an armed stop cut the pulse output of `axis` during the last
        `advance`, or None."""


@runtime_checkable
class TimedOutputHardware(Protocol):
    """Optional extension: outputs switched by the hardware at an exact future time (a
    board's output FIFO / timed compare output), so an edge lands on the physical line at
    its computed instant instead of at a cycle boundary.

    The control layer checks `isinstance(hw, TimedOutputHardware)` and otherwise falls back
    to `Hardware.write_output` once per cycle. A back end may also offer
    `write_outputs_at(times, axis, signal, levels)` (the same for several edges of one
    output, in order, checked as a whole first): the compare engine then hands a cycle's
    edges of a line in one call (the simulator has it; it is looked up, not required).
    """

    def write_output_at(self, t: float, axis: int | None, signal: str, level: bool) -> None:
        """Drive an output (as `write_output`) at time t (>= the hardware time). Writes are
        executed in time order (equal times in call order) inside `advance`. MotionError for
        t in the past or a bad signal/level; nothing is scheduled then."""


@runtime_checkable
class AnalogInputHardware(Protocol):
    """Optional extension: board analog inputs `ai<n>` (an ADC, in the unit the board reports),
    as LinuxCNC's motion.analog-in-NN pins that M66 E reads. The control layer checks
    `isinstance(hw, AnalogInputHardware)`; a back end without analog inputs lacks these."""

    @property
    def n_analog_inputs(self) -> int:
        """Number of analog inputs (channels 0 .. n - 1)."""

    def read_analog_input(self, channel: int) -> float:
        """The value of channel `channel` now (MotionError for a channel out of range)."""


@runtime_checkable
class AnalogOutputHardware(Protocol):
    """Optional extension: board analog outputs `ao<n>` (a DAC: volts, or the unit the
    board's range is given in), as LinuxCNC's motion.analog-out-NN pins that M67/M68 drive.

    The control layer checks `isinstance(hw, AnalogOutputHardware)`; a back end without
    analog outputs simply lacks these methods.
    """

    @property
    def n_analog_outputs(self) -> int:
        """Number of analog outputs (channels 0 .. n - 1)."""

    @property
    def analog_range(self) -> tuple[float, float]:
        """The (lowest, highest) value a channel can hold."""

    def write_analog(self, channel: int, value: float) -> None:
        """Set channel `channel` to `value` now. MotionError for a channel out of range or
        a value that is not finite or outside `analog_range`; nothing changes then."""

    def read_analog_output(self, channel: int) -> float:
        """The value channel `channel` holds now."""


@dataclass(frozen=True, slots=True, eq=False)
class PieceBlock:
    """Many timed pieces at once: `rows` is an (n, 6) float array (numpy), row k the piece
    AxisCommand(*rows[k]) = (t0, dt, p0, v0, a0, j). The planner hands a whole chunk of
    cycles across the boundary this way, without one Python object per piece. A float64
    C-contiguous array is queued as it is (not copied): do not change it afterwards."""

    rows: Any


@dataclass(frozen=True, slots=True)
class QueueRun:
    """What `QueuedHardware.run_cycles` reports: the cycle it stopped at (its end time is
    origin + cycle * period), the input edges of that cycle (time-ordered, as `advance`
    returns them; empty when it ran to the last cycle asked for) and the axes whose queue ran
    empty during the run (the last piece started; the command holds its end after it)."""

    cycle: int
    edges: list[InputEdge]
    drained: tuple[int, ...] = ()
    #: with run_cycles(..., trace=True): int64 array [cycle - start, n_axes, 3], the
    #: readback at the end of each cycle run (pulses_out, encoder, electrical input levels
    #: as bits, bit i = AXIS_INPUTS[i]); the recorder reads jumped cycles from it
    trace: Any = None


@runtime_checkable
class BulkReadback(Protocol):
    """Optional extension: every axis's readback in one call, encoded as a QueueRun.trace
    row (the recorder reads it at each recorded cycle instead of one `read_axis` per axis).
    """

    def read_axes(self) -> Any:
        """int64 array [n_axes, 3]: pulses_out, encoder and the electrical input levels as
        bits (bit i = AXIS_INPUTS[i]) of every axis now, what `read_axis` gives."""


@runtime_checkable
class QueuedHardware(Protocol):
    """Optional extension: a queue of timed cubic pieces per axis, executed by the back end.

    Each piece is an `AxisCommand` (a cubic with its time span); a piece becomes the axis's
    command at its t0, exactly as `Hardware.command` would make it, and stays it until the
    next piece starts. The back end runs cycle by cycle on the controller's grid (cycle k
    ends at origin + k * period, computed that way, never accumulated), so everything it
    does is what the same pieces handed over one per cycle would have done; it only returns
    early, at the end of the first cycle that produced input edges, so that the control
    layer reacts in that cycle as it would have cycle by cycle. Compare firing stays in the
    control layer for now (a back end may add it as a further capability).
    """

    def queue_pieces(self, axis: int, pieces: Sequence[AxisCommand] | PieceBlock) -> None:
        """Append pieces to the queue of `axis` (a sequence of AxisCommand, or a PieceBlock
        of arrays), each with finite fields,
        dt >= 0, t0 >= the hardware time, t0 >= the end of the piece queued before it.
        MotionError naming the piece and the rule otherwise; the queue is unchanged then."""

    def clear_queue(self, axis: int) -> None:
        """Drop the pieces of `axis` that have not started (the current command stays)."""

    def queued(self, axis: int) -> int:
        """Number of pieces of `axis` that have not started yet."""

    def run_cycles(self, origin: float, period: float, start: int, stop: int,
                   wake: Collection[str] | None = None, trace: bool = False) -> QueueRun:
        """From the end of cycle `start` (= the hardware time) run cycles start+1 .. stop,
        each ending at origin + k * period (as `advance` would), starting queued pieces at
        their t0; return at the end of the first cycle with an input edge on a signal in
        `wake` (None: any signal) or a stop cut by an armed edge (EdgeStopHardware), with
        every edge of that cycle; edges on other signals in earlier cycles are dropped (the
        control layer declared it ignores them). With `trace`, QueueRun.trace holds the
        readback at the end of every cycle run. MotionError for bad arguments."""
