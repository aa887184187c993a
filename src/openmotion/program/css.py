"""G96 / G97 (constant surface speed / rpm) and the feed-mode record G95 needs.

`G96 S- [D-]`: S is the surface speed (m/min in G21, ft/min in G20), D the highest spindle
rpm (LinuxCNC: |D|; without D no limit but the machine's). The spindle turns at
S / (2 pi |x|) where x is the tool's X from X0 of the coordinate system in force at the
G96 (offsets and tool length included, as LinuxCNC's documentation asks). `G97` returns
to rpm mode. Both emit a `SpindleMode` record (the runner's spindle follows X with it);
without a spindle axis the converter and the G95 feed use the rpm at each move's start.

`FeedMode` marks the G93/G94/G95 changes in the command list: the runner scales the moves
of a G95 stretch by measured / planned spindle speed (G95 follows the measured speed, as
LinuxCNC's spindle.N.speed-in).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .words import Word

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block


@dataclass(frozen=True, slots=True)
class SpindleMode:
    """G96 (`per_s_unit` > 0: machine units of surface per minute per S unit, `max_rpm`,
    `x_axis` the machine axis of X, `x_origin` its machine coordinate of X0) or G97
    (`per_s_unit` 0)."""

    per_s_unit: float
    max_rpm: float
    x_axis: int
    x_origin: float
    line: int
    file: str = ""

    def rpm(self, s: float, x: float) -> float:
        """Spindle rpm for S = `s` with the tool at machine X `x` (limited by max_rpm)."""
        r = abs(x - self.x_origin)
        if r <= 0.0:
            return self.max_rpm
        return min(self.max_rpm, self.per_s_unit * s / (2.0 * math.pi * r))


@dataclass(frozen=True, slots=True)
class FeedMode:
    """G93/G94 (per_rev False) or G95 (True) from this line on."""

    per_rev: bool
    line: int
    file: str = ""


def g96(m: Modal, b: Block, code: int, pos: int, words: dict[str, Word], used: set[str],
        out: list) -> None:
    """G96 S [D] / G97 (module docstring); S itself is set by the caller (order of
    execution: S before G96)."""
    x = m.letters.get("X")
    if code == 970:
        if m.css:
            out.append(SpindleMode(0.0, 0.0, x[0] if x else 0, 0.0, b.line, b.file))
        m.css = False
        return
    if "S" not in words:
        raise b.error("S word missing with G96", pos, "G96")
    if x is None:
        raise b.error("G96 needs a machine axis for X (the radius)", pos, "G96")
    d = words.get("D")
    max_rpm = math.inf
    if d is not None:
        used.add("D")
        if d.value != 0.0:
            max_rpm = abs(d.value)
    k = m.lin(1000.0 if m.units == "mm" else 12.0)  # m/min or ft/min -> machine units
    rec = SpindleMode(k, max_rpm, x[0], m.off[x[1]], b.line, b.file)
    m.css = rec  # type: ignore[assignment]  # truthy: #<_spindle_css_mode> reads it
    out.append(rec)


def nominal_rpm(m: Modal) -> float:
    """The commanded spindle rpm now: S, or in G96 the rpm at the current X."""
    mode = m.css
    if isinstance(mode, SpindleMode):
        return mode.rpm(m.speed, m.pos[mode.x_axis])
    return m.speed
