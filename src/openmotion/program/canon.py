"""Canonical commands: the interpreter's output, in MACHINE coordinates, machine units, s.

A G-code program becomes a flat list of these frozen records; the group runtime (not part of
this package) executes them. Positions are full tuples over the machine's axes (index = the
machine axis number given in the axis map); linear axes are in the machine's length unit
(mm by default), rotary axes A/B/C in degrees. Feeds are machine units per second. Every
record carries the source `line` (1-based) and `file` so a runtime error can point back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..path import ARC_TOL, Arc, Direction

Point = tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Rapid:
    """G0 (also G28/G30 legs): straight move at the machine's rapid speed."""

    end: Point
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class Feed:
    """G1: straight move at `feed_per_s`; with G93 `duration` (s) is the commanded time.

    `feed_per_s` follows LinuxCNC: the speed along the linear axes (XYZUVW) if any of them
    moves, else along the rotary axes (deg/s). With G93 it is that length / duration.
    """

    end: Point
    feed_per_s: float
    line: int
    file: str = ""
    duration: float | None = None


@dataclass(frozen=True, slots=True)
class SyncedFeed:
    """G33 / G76 passes: a straight move synchronised to the spindle, advancing `pitch`
    machine units along the move per spindle revolution."""

    end: Point
    pitch: float
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class ArcMove:
    """G2/G3: circular arc in the plane of axes `plane` = (i, j); other axes move linearly.

    `centre` is a full point (plane coordinates of the centre, other axes as at the start).
    `direction` is CCW from axis i towards axis j (G17: X->Y, G18: Z->X, G19: Y->Z, as
    RS-274/NGC defines the planes). `sweep` (rad, > 0) includes `turns` extra whole turns
    (G-code P = turns + 1). `end_radius` differs from `radius` when the program's end point
    was on the circle only within the LinuxCNC tolerance (a slight spiral).
    """

    start: Point
    end: Point
    centre: Point
    plane: tuple[int, int]
    direction: Direction
    turns: int
    sweep: float
    radius: float
    end_radius: float
    feed_per_s: float
    line: int
    file: str = ""
    duration: float | None = None

    def to_path(self) -> Arc:
        """The same arc as an `openmotion.path.Arc` (its end tolerance covers the spiral)."""
        miss = abs(self.end_radius - self.radius) / self.radius
        tol = max(ARC_TOL, miss * (1.0 + 1e-6) + 1e-12)
        return Arc(self.start, self.centre, self.end, plane=self.plane,
                   direction=self.direction, turns=self.turns, tol=tol)

    @property
    def length(self) -> float:
        """Path length of the (helical) arc, machine units."""
        i, j = self.plane
        lin2 = sum((e - s) ** 2 for k, (s, e) in enumerate(zip(self.start, self.end, strict=True))
                   if k not in (i, j))
        r = 0.5 * (self.radius + self.end_radius)
        return math.hypot(r * self.sweep, math.sqrt(lin2))


@dataclass(frozen=True, slots=True)
class Dwell:
    """G4 P: wait `seconds` with the axes stopped."""

    seconds: float
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class SetBlend:
    """Path control: G61 "exact_path", G61.1 "exact_stop", G64 "blend".

    `tolerance` (G64 P, machine units) bounds the corner deviation; None = best speed.
    `naive_cam` is G64 Q (collinear-merge tolerance), recorded for the runtime.
    """

    mode: str
    tolerance: float | None
    line: int
    file: str = ""
    naive_cam: float | None = None


@dataclass(frozen=True, slots=True)
class Pause:
    """M0 (optional=False) or M1 (optional=True: only when the optional-stop switch is on)."""

    optional: bool
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class End:
    """M2 (rewind=False) or M30 (rewind=True): program end. `restart`: M99 in the main
    program, where LinuxCNC's task starts the program again from its top with its state
    kept (interp.py: a compiled list ends here, a runner's session goes on)."""

    rewind: bool
    line: int
    file: str = ""
    restart: bool = False


@dataclass(frozen=True, slots=True)
class SetOutput:
    """M62-M65 P: digital output `index` to `level`; `synced` = at the start of the next
    motion (M62/M63, the hook for a PSO job), else immediately (M64/M65)."""

    index: int
    level: bool
    synced: bool
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class Spindle:
    """M3/M4/M5 and S: spindle (or laser/dispenser) on/off, rpm; `output` from the options."""

    on: bool
    clockwise: bool
    speed: float
    output: int | None
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class Coolant:
    """M7 mist / M8 flood / M9 off, with the outputs the options map them to."""

    mist: bool
    flood: bool
    mist_output: int | None
    flood_output: int | None
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class ToolChange:
    """M6 with the tool selected by T. A motion controller has no changer: the runtime
    pauses with a message (or ignores it); length offsets are G43's business."""

    tool: int
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class Message:
    """(MSG,...) kind "msg"; (DEBUG,...)/(PRINT,...) with parameters substituted; plain
    comments kind "comment" only when the options ask to keep them."""

    text: str
    kind: str
    line: int
    file: str = ""


Command = (Rapid | Feed | SyncedFeed | ArcMove | Dwell | SetBlend | Pause | End | SetOutput
           | Spindle | Coolant | ToolChange | Message)
MOTIONS = (Rapid, Feed, SyncedFeed, ArcMove)
