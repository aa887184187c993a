"""G33.1 rigid tapping (LinuxCNC's dialect): `G33.1 X- Y- Z- K- [I-]`.

One `RigidTap` record: from the current point to the end point synchronised with the
spindle at K per revolution (starting at an index pulse), the spindle reversed at the end
(and sped up by I, values below 1 count as 1), synchronised back to the start, the spindle
reversed again, then an unsynchronised move to the start. The line ends where it began
(LinuxCNC: "G33.1 moves end at the original coordinate"). The runner executes it against
the spindle (rigidtap_run.py); without a spindle axis it runs at K x the commanded S.

LinuxCNC's checks: the spindle turning ("Spindle not turning in G33.1"), K given ("K word
missing with g33/g33.1"), an axis word. Deliberate refusals (rs274 accepts them): K <= 0,
rotary axis words (LinuxCNC's RIGID_TAP carries X Y Z only and drops them silently),
cutter compensation on.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from . import canon
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block


@dataclass(frozen=True, slots=True)
class RigidTap:
    """G33.1: tap from `start` to `end` (machine coordinates) at `pitch` machine units per
    revolution; the way back turns `return_scale` times faster (LinuxCNC's I)."""

    start: canon.Point
    end: canon.Point
    pitch: float
    return_scale: float
    line: int
    file: str = ""


def g33_1(m: Modal, b: Block, gpos: int, axes: dict[str, Word], words: dict[str, Word],
          used: set[str], out: list) -> None:
    """Execute G33.1 (module docstring)."""
    gw = "G33.1"
    if m.comp.side:
        raise b.error("G33.1 cannot be used with cutter compensation on", gpos, gw)
    if not m.spindle_on:
        raise b.error("Spindle not turning in G33.1", gpos, gw)
    k = words.get("K")
    if k is None:
        raise b.error("K word missing with g33/g33.1", gpos, gw)
    if k.value <= 0:
        raise b.error(f"G33.1 K must be > 0, got {k.value:g}", k.pos, fmt("K", k.value))
    rot = [L for L in axes if L not in "XYZUVW"]
    if rot:
        w = axes[rot[0]]
        raise b.error(f"G33.1 taps along X Y Z only, got {rot[0]}", w.pos, fmt(rot[0], w.value))
    used.add("K")
    scale = 1.0
    i = words.get("I")
    if i is not None:
        used.add("I")
        scale = max(1.0, i.value)
    end = m.target_position(b, axes)
    m.check_limits(b, [min(a, e) for a, e in zip(m.pos, end, strict=True)],
                   [max(a, e) for a, e in zip(m.pos, end, strict=True)], gw, gpos)
    if end == m.pos:
        return  # nothing to tap
    out.append(RigidTap(tuple(m.pos), tuple(end), m.lin(k.value), scale, b.line, b.file))
    # the line ends at its start: m.pos unchanged
