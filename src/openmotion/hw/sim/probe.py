"""A simulated touch probe: a board input (di<n>) that is in contact while the tool is
inside the workpiece.

The workpiece is one or more boxes in load positions (command pulses, the positions the
switches see): per axis an interval [lo, hi), an axis left out is unbounded. The probe is
in contact while every axis of some box lies inside its interval. Each interval bound is a
hidden switch on its axis, so the simulator finds the crossing at its exact time as it
does for a limit switch; the probe turns those crossings into edges of its board input,
with every axis's encoder count at that instant (what a board latches). The control layer
sees an ordinary `di<n>` edge: it cannot tell the probe is simulated.

    probe = SimProbe.attach(machine, "di0")
    probe.place([{2: (-1e9, -5000.0)}])           # a floor at Z = -5000 pulses
    probe.place([{0: (0, 8000), 1: (0, 6000), 2: (-1e9, -5000)}], at=1.0)  # a block
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from openmotion.errors import MotionError, check_finite

from .switches import Switch

if TYPE_CHECKING:
    from .machine import SimMachine

#: An unbounded side of an interval (finite, so the switch arithmetic stays exact).
_FAR = 1e300
Box = Mapping[int, tuple[float, float]]


class SimProbe:
    """A touch probe wired to board input `signal` of a SimMachine (use `attach`)."""

    def __init__(self, machine: SimMachine, signal: str, normally_closed: bool) -> None:
        self._m = machine
        self.signal = signal
        self._index = machine._board_index(signal, "di", len(machine._di))
        self.normally_closed = normally_closed
        self._boxes: list[dict[int, str]] = []   # box -> axis -> hidden switch name
        self._state: dict[str, bool] = {}        # hidden switch -> inside its interval
        self._serial = 0

    @classmethod
    def attach(cls, machine: SimMachine, signal: str = "di0", *,
               normally_closed: bool = False) -> SimProbe:
        """Wire a probe to `signal` (di<n>); `normally_closed`: the contact opens on touch
        (the input reads False in contact). The probe owns that input from now on."""
        from .machine import SimMachine

        if not isinstance(machine, SimMachine):
            raise MotionError(f"machine must be a SimMachine, got {type(machine).__name__}")
        if not isinstance(normally_closed, bool):
            raise MotionError(f"normally_closed must be a bool, got {normally_closed!r}")
        if any(isinstance(f, _Filter) and f.probe.signal == signal
               for f in machine._edge_filters):
            raise MotionError(f"a probe is already wired to {signal}")
        probe = cls(machine, signal, normally_closed)
        machine._edge_filters.append(_Filter(probe))
        machine._di[probe._index] = probe._level()
        return probe

    # -- scenario ---------------------------------------------------------------------
    def place(self, boxes: Sequence[Box], at: float | None = None) -> None:
        """Put the workpiece (a list of boxes, see the module doc) in place at time `at`
        (default now); an empty list takes it away. If the tool is inside it then, the
        input changes at that instant."""
        checked = [self._check_box(k, b) for k, b in enumerate(self._seq(boxes))]
        t = self._m.scenario._at(at)
        self._m.scenario._push(t, lambda raw: self._apply(checked, raw))

    def remove(self, at: float | None = None) -> None:
        """Take the workpiece away (no contact)."""
        self.place([], at)

    @property
    def in_contact(self) -> bool:
        """Whether the tool touches the workpiece now."""
        return any(all(self._state[n] for n in box.values()) for box in self._boxes)

    # -- internals ----------------------------------------------------------------------
    @staticmethod
    def _seq(boxes: Sequence[Box]) -> list[Box]:
        if isinstance(boxes, Mapping) or not isinstance(boxes, Sequence):
            raise MotionError(f"boxes must be a list of {{axis: (lo, hi)}} mappings, got "
                              f"{boxes!r}")
        return list(boxes)

    def _check_box(self, k: int, box: Box) -> dict[int, tuple[float, float]]:
        if not isinstance(box, Mapping) or not box:
            raise MotionError(f"boxes[{k}] must be a non-empty mapping axis -> (lo, hi), "
                              f"got {box!r}")
        out = {}
        for axis, span in box.items():
            self._m._axis(axis)
            if not isinstance(span, (tuple, list)) or len(span) != 2:
                raise MotionError(f"boxes[{k}][{axis}] must be (lo, hi), got {span!r}")
            lo, hi = (v if isinstance(v, (int, float)) and not isinstance(v, bool)
                      and math.isinf(v) else check_finite(f"boxes[{k}][{axis}]", v)
                      for v in span)
            if not lo < hi:
                raise MotionError(f"boxes[{k}][{axis}] must have lo < hi, got {span!r}")
            out[axis] = (max(float(lo), -_FAR), min(float(hi), _FAR))
        return out

    def _level(self) -> bool:
        return self.in_contact != self.normally_closed

    def _apply(self, boxes: list[dict[int, tuple[float, float]]], raw: list) -> None:
        """Scenario action: replace the hidden switches, then report a changed input."""
        m = self._m
        raw.sort(key=lambda e: e[0])
        raw[:] = self.translate(raw)  # the old workpiece's edges up to now
        before = self._level()
        for box in self._boxes:
            for axis, name in box.items():
                del m._axes[axis].switches[name]
                del m._axes[axis].nc[name]
        self._boxes, self._state = [], {}
        for box in boxes:
            names = {}
            for axis, (lo, hi) in box.items():
                self._serial += 1
                name = f"probe:{self.signal}:{self._serial}"
                ax = m._axes[axis]
                sw = Switch(lo, 1.0, 0.0)
                sw.lo, sw.hi = lo, hi  # exact bounds (hi - lo may not be representable)
                sw.reset(ax.y)
                ax.switches[name] = sw
                ax.nc[name] = False
                self._state[name] = ax.switches[name].active
                names[axis] = name
            self._boxes.append(names)
        level = self._level()
        m._di[self._index] = level
        if level != before:
            raw.append((m.time, None, self.signal, level, None))

    def translate(self, raw: list) -> list:
        """Hidden switch edges (time-ordered) -> edges of the probe's input."""
        out = []
        level = self._level()
        for e in raw:
            name = e[2]
            if name not in self._state:
                out.append(e)
                continue
            self._state[name] = e[3]
            now = self._level()
            if now != level:
                level = now
                out.append((e[0], None, self.signal, level, None))
        self._m._di[self._index] = level
        return out


class _Filter:
    """The machine's edge filter for one probe (SimMachine._edge_filters)."""

    def __init__(self, probe: SimProbe) -> None:
        self.probe = probe

    def __call__(self, raw: list) -> list:
        return self.probe.translate(raw)
