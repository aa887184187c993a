"""M19: spindle orientation (LinuxCNC convert_m): stop the spindle at an angle from its
index pulse.

`M19 R<angle> [P<mode>] [Q<timeout>]`: R degrees from the index (0 default), P the way
to turn (0 clockwise, the M3 direction; 1 counter-clockwise; 2 the shorter way), Q: wait at
most that many seconds for the orientation to complete (without Q the program goes on).
M19 marks the spindle stopped (#<_spindle_on> 0), and without R or P it only does that.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block

#: M19 P: the way the spindle turns to its orientation.
ORIENT_MODES = {0: "clockwise", 1: "counterclockwise", 2: "shortest"}


@dataclass(frozen=True, slots=True)
class Orient:
    """M19: turn the spindle to `angle` degrees from its index, the `mode` way (0 CW, 1 CCW,
    2 shortest); `timeout` (s) or None: whether, and how long, to wait for it."""

    angle: float
    mode: int
    timeout: float | None
    line: int
    file: str = ""


def m19(m: Modal, b: Block, pos: int, words: dict[str, Word], used: set[str],
        out: list) -> None:
    """An M19 line (see the module doc)."""
    m.spindle_on = False
    r, p, q = (words.get(k) for k in "RPQ")
    used.update(k for k in "RPQ" if k in words)
    mode = 0
    if p is not None:
        mode = round(p.value)
        if abs(p.value - mode) > 1e-4 or mode not in ORIENT_MODES:
            raise b.error(f"M19 P must be 0 (clockwise), 1 (counterclockwise) or 2 "
                          f"(shortest), got {p.value:g}", p.pos, fmt("P", p.value))
    timeout = None
    if q is not None:
        if q.value <= 0.0:
            raise b.error("Q word with M19 requires a value > 0", q.pos, fmt("Q", q.value))
        timeout = q.value
    if r is None and p is None:
        return
    angle = 0.0 if r is None else r.value % 360.0
    out.append(Orient(angle, int(mode), timeout, b.line, b.file))
