"""The runner's side of G38.x and M66: a probe move watched on the probe input, and a wait
on a digital input, each ending in the result the interpreter continues with.

`ProbeMove`: an edge hook on the probe input captures every program axis (control.home.latch's
`capture`, as a touch probe does) at the edge into the state the move seeks (contact for
G38.2/G38.3, contact lost for G38.4/G38.5): each axis's exact command position at the
edge's exact time. The runner then stops the group along its path (decelerating) and, at
rest, hands `result()` to the interpreter. A probe already in the sought state when the
move starts is LinuxCNC's error for G38.2/G38.4 ("Probe is already tripped when starting
G38.2 or G38.3 move"); G38.3/G38.5 then trip at once where they stand.

`InputWait`: M66 P L Q on board input di<P>: L0 reads at once; L1/L2 wait for a rising /
falling edge, L3/L4 for a high / low level (satisfied at once if it already is); after Q
seconds the result is -1 (LinuxCNC). Levels are electrical, as the hardware reports them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..control.home.latch import LatchData, capture
from ..errors import MotionError
from ..hw.interface import InputEdge
from .probing import InputResult, Probe, ProbeResult, WaitInput

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from ..control.trigger.analog import AnalogInputs


class ProbeMove:
    """A G38.x move in progress (see the module doc). `ppu`: pulses per machine unit of
    each program axis; `start`: the axes' position (pulses) when it begins."""

    def __init__(self, ctl: Controller, axes: list[int], signal: str, probe: Probe,
                 start: np.ndarray, ppu: np.ndarray) -> None:
        self.probe = probe
        self._ppu = ppu
        self._start = start.copy()
        sought = ctl.hardware.read_input(signal) == probe.contact
        gword = f"G{probe.code / 10:g}"
        if sought and probe.must_trip:
            raise MotionError(
                f"{gword}: Probe is already tripped when starting G38.2 or G38.3 move"
                if probe.contact else
                f"{gword}: Probe is already clear when starting G38.4 or G38.5 move")
        self.at_start = sought  # G38.3/G38.5 in the sought state: trips where it stands
        self.stopping = False
        self._ctl = ctl
        self._axes = axes
        self._signal = signal
        self._trip: list[LatchData] | None = None
        self._hooked = not sought
        if self._hooked:
            ctl.add_edge_hook(self._on_edge, signals=(signal,))

    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if self._trip is None and e.axis is None and e.signal == self._signal \
                and e.level == self.probe.contact:
            self._trip = [capture(ctl, a, e) for a in self._axes]
            ctl.events.record("latch", self._axes[0], e.time, self._trip[0].position,
                              "G38 probe")

    @property
    def tripped(self) -> bool:
        return self.at_start or self._trip is not None

    @property
    def trip_time(self) -> float | None:
        return None if self._trip is None else self._trip[0].time

    def result(self, rest: np.ndarray) -> ProbeResult:
        """The answer once the axes are at rest at `rest` (pulses)."""
        stop = tuple(float(v) for v in rest / self._ppu)
        if self.at_start:
            return ProbeResult(True, tuple(float(v) for v in self._start / self._ppu), stop)
        if not self.tripped:
            return ProbeResult(False, stop, stop)
        assert self._trip is not None
        pos = np.array([d.position for d in self._trip], dtype=float)
        return ProbeResult(True, tuple(float(v) for v in pos / self._ppu), stop)

    def close(self) -> None:
        if self._hooked:
            self._ctl.remove_edge_hook(self._on_edge)
            self._hooked = False


class InputWait:
    """An M66 wait on a digital input (see the module doc)."""

    def __init__(self, ctl: Controller, wait: WaitInput,
                 analog: AnalogInputs | None = None) -> None:
        self._ctl = ctl
        self.wait = wait
        self._hooked = False
        if wait.analog:  # M66 E: L0 only (checked when compiled): the reading now
            if analog is None or analog.count == 0:
                raise MotionError(f"M66 E{wait.index}: this hardware has no analog inputs")
            try:
                self.value: float | None = analog.read(wait.index)
            except MotionError as exc:
                raise MotionError(f"M66 E{wait.index}: {exc}") from None
            return
        self.signal = f"di{wait.index}"
        level = ctl.hardware.read_input(self.signal)
        self.value = None
        if wait.mode == 0 or (wait.mode == 3 and level) or (wait.mode == 4 and not level):
            self.value = 1.0 if level else 0.0
            return
        self._deadline = ctl.time + wait.timeout
        self._want = wait.mode in (1, 3)  # the level that ends the wait
        ctl.add_edge_hook(self._on_edge, signals=(self.signal,))
        self._hooked = True

    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if self.value is None and e.axis is None and e.signal == self.signal \
                and e.level == self._want:
            self.value = 1.0 if e.level else 0.0

    def poll(self) -> InputResult | None:
        """The result when the wait is over (at a cycle end), else None."""
        if self.value is None and self._ctl.time >= self._deadline - 1e-12:
            self.value = -1.0
        return None if self.value is None else InputResult(self.value)

    def close(self) -> None:
        if getattr(self, "_hooked", False):
            self._ctl.remove_edge_hook(self._on_edge)
            self._hooked = False
