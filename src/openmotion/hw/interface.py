"""The hardware boundary: the one narrow interface the control layer talks to.

The control layer never knows whether the hardware is simulated. Each cycle it:

1. hands every axis the commanded motion for the coming cycle as one cubic piece
   (`AxisCommand`): a pulse generator emits pulses exactly where that polynomial crosses
   each count's half-pulse point, so the command is exact between cycles, not only at
   cycle ends;
2. calls `advance(t)`, which moves the hardware to time t and returns every input edge that
   happened since the last call, each with its exact time (`InputEdge`);
3. reads counters and input levels (`read_axis`), and writes outputs.

Signal levels crossing this boundary are *electrical* (True = contact closed / line
active-high as wired). Logic (normally open / closed, active high / low) is applied by the
control layer from the machine configuration, as a real controller's registers do.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

#: Names of the per-axis motion input signals (HSL-4XMO chapter 3).
AXIS_INPUTS = ("pel", "mel", "org", "sd", "ltc", "ez", "alm", "inp", "rdy")
#: Names of the per-axis motion output signals.
AXIS_OUTPUTS = ("svon", "erc")


@dataclass(frozen=True, slots=True)
class AxisCommand:
    """Commanded pulse position over [t0, t0 + dt]: p0 + v0*s + a0*s**2/2 + j*s**3/6.

    Positions are in command pulses (float); the pulse output is the command rounded to
    the nearest count (pulse k leaves at k - 1/2 going up, k + 1/2 going down; a back end
    that counts otherwise sets `half_pulse = False`, see control/pulserule.py).
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

    The control layer arms it (control/safety.py) and, when an immediate stop follows an
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
    to `Hardware.write_output` once per cycle.
    """

    def write_output_at(self, t: float, axis: int | None, signal: str, level: bool) -> None:
        """Drive an output (as `write_output`) at time t (>= the hardware time). Writes are
        executed in time order (equal times in call order) inside `advance`. MotionError for
        t in the past or a bad signal/level; nothing is scheduled then."""
