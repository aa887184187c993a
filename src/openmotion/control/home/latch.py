"""Position latch (HSL-4XMO 4.8 SD/LTC) and PLCopen-style touch probes (MC_TouchProbe).

Both capture positions at the *exact* time of an input edge, not at the cycle: the
hardware reports the edge time and every axis's encoder count at that instant
(`InputEdge.encoders`), and the controller's MotionHistory gives the command position at
that time. From those the four counters are rebuilt as they read at the edge:

  command  = pulses emitted at te (the planned position at te counted by the hardware's
             pulse rule, control.home.pulserule) + the command counter's offset;
  feedback = encoder at te + feedback offset;  error = command - feedback/ratio (+ offset);
  general  = its source at te (command pulses, encoder, CLK/2 of te; manual: its offset).

`Latch` is the HSL latch: always armed, on the configured LTC edge ("on": becoming active,
"off": becoming inactive, after the NO/NC logic), last capture read back with `data(axis)`.
`TouchProbe` arms on any axis input or board input (di<n>), optionally only inside a
position window [first, last] (PLCopen WindowOnly), once ("single") or every time
("continuous", kept in a bounded list).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import MotionError, check_finite, check_int, show
from ...hw.interface import AXIS_INPUTS, InputEdge
from .pulserule import half_pulse, pulse_count

if TYPE_CHECKING:
    from ..core.controller import Controller

EDGES = ("on", "off", "both")


@dataclass(frozen=True)
class LatchData:
    """The four counters of one axis at an edge's exact time, plus the exact position."""

    time: float
    command: int
    feedback: int
    error: int
    general: int
    position: float   # exact (float) command position, command-counter frame


def capture(ctl: Controller, axis: int, edge: InputEdge) -> LatchData:
    """Counters of `axis` as they read at `edge.time` (see the module doc)."""
    ax = ctl.axes[axis]
    cnt = ax.counters
    st = ctl.history.state_at(axis, edge.time)
    pulses = pulse_count(st.p, st.v, half_pulse(ctl.hardware))
    enc = edge.encoders[axis] if edge.encoders else cnt.encoder_raw()
    command, feedback, error, general = cnt.readings_at(pulses, enc, edge.time)
    return LatchData(edge.time, command, feedback, error, general, st.p + cnt.command_offset)


def _edge_wanted(active: bool, edge: str) -> bool:
    return edge == "both" or active == (edge == "on")


class Latch:
    """HSL position latch of every axis on its LTC input (HSL_M_set_ltc_logic /
    HSL_M_get_latch_data). Attach once per controller: `Latch(ctl)`."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        n = len(ctl.axes)
        self._edge = ["on"] * n
        self._data: list[LatchData | None] = [None] * n
        self._fresh = [False] * n
        ctl.add_edge_hook(self._on_edge)

    def set_edge(self, axis: int | str, edge: str) -> None:
        """Latch on the LTC becoming active ("on", default) or inactive ("off")."""
        i = self.ctl.axis(axis).index
        if not isinstance(edge, str) or edge not in ("on", "off"):
            raise MotionError(f"edge must be 'on' or 'off', got {edge!r}")
        self._edge[i] = edge

    def data(self, axis: int | str) -> LatchData | None:
        """The last capture of `axis` (None before any); reading clears `latched`."""
        i = self.ctl.axis(axis).index
        self._fresh[i] = False
        return self._data[i]

    def latched(self, axis: int | str) -> bool:
        """True if a capture arrived since the last `data` read (io_status LTC flag)."""
        return self._fresh[self.ctl.axis(axis).index]

    def close(self) -> None:
        """Detach from the controller."""
        self.ctl.remove_edge_hook(self._on_edge)

    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if e.axis is None or e.signal != "ltc":
            return
        cfg = ctl.axes[e.axis].config
        active = e.level != (cfg.signal_logic("ltc") == "nc")
        if _edge_wanted(active, self._edge[e.axis]):
            data = capture(ctl, e.axis, e)
            self._data[e.axis] = data
            self._fresh[e.axis] = True
            ctl.events.record("latch", e.axis, e.time, data.position, "LTC")


class TouchProbe:
    """PLCopen MC_TouchProbe: record `axis` when `trigger` makes its edge.

    trigger: (axis, signal) for an axis input (signal one of AXIS_INPUTS) or a board input
    name "di<n>"; edge "on"/"off"/"both" of the logical level (board inputs: the electrical
    level). window: (first, last) command positions; edges outside it are ignored.
    mode "single" disarms after the first capture; "continuous" keeps the last `capacity`.
    """

    def __init__(self, ctl: Controller, axis: int | str, trigger: tuple[int | str, str] | str,
                 *, edge: str = "on", window: tuple[float, float] | None = None,
                 mode: str = "single", capacity: int = 10_000) -> None:
        self.ctl = ctl
        self.axis = ctl.axis(axis).index
        if isinstance(trigger, str):
            if not trigger.startswith("di"):
                raise MotionError(f"trigger must be (axis, signal) or 'di<n>', got {trigger!r}")
            ctl.hardware.read_input(trigger)  # validates the name
            self._src: tuple[int | None, str] = (None, trigger)
        else:
            if not (isinstance(trigger, tuple) and len(trigger) == 2):
                raise MotionError(f"trigger must be (axis, signal) or 'di<n>', got {trigger!r}")
            if trigger[1] not in AXIS_INPUTS:
                raise MotionError(f"trigger signal must be one of {AXIS_INPUTS}, "
                                  f"got {trigger[1]!r}")
            self._src = (ctl.axis(trigger[0]).index, trigger[1])
        if not isinstance(edge, str) or edge not in EDGES:
            raise MotionError(f"edge must be one of {EDGES}, got {show(edge)}")
        if not isinstance(mode, str) or mode not in ("single", "continuous"):
            raise MotionError(f"mode must be 'single' or 'continuous', got {show(mode)}")
        if window is not None and (not isinstance(window, (tuple, list)) or len(window) != 2):
            raise MotionError(f"window must be (first, last) or None, got {show(window)}")
        if window is not None:
            lo = check_finite("window[0]", window[0])
            hi = check_finite("window[1]", window[1])
            if lo > hi:
                raise MotionError(f"window must be (first, last) with first <= last, "
                                  f"got {window!r}")
            window = (lo, hi)
        check_int("capacity", capacity, 1)
        self.edge = edge
        self.window = window
        self.mode = mode
        self.records: deque[LatchData] = deque(maxlen=capacity)
        self.armed = True
        ctl.add_edge_hook(self._on_edge)

    @property
    def done(self) -> bool:
        """Single mode: a position was recorded (PLCopen Done)."""
        return bool(self.records)

    @property
    def recorded_position(self) -> float | None:
        """The last recorded exact command position (PLCopen RecordedPosition)."""
        return self.records[-1].position if self.records else None

    def abort(self) -> None:
        """MC_AbortTrigger: disarm and detach."""
        self.armed = False
        self.ctl.remove_edge_hook(self._on_edge)

    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if not self.armed or (e.axis, e.signal) != self._src:
            return
        if e.axis is None:
            active = e.level
        else:
            active = e.level != (ctl.axes[e.axis].config.signal_logic(e.signal) == "nc")
        if not _edge_wanted(active, self.edge):
            return
        rec = capture(ctl, self.axis, e)
        if self.window is not None and not self.window[0] <= rec.position <= self.window[1]:
            return
        self.records.append(rec)
        self.ctl.events.record("latch", self.axis,
                               rec.time, rec.position, "touch probe")
        if self.mode == "single":
            self.abort()
