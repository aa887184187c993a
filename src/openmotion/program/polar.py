"""Polar coordinates: `@` (radius) and `^` (angle, degrees) instead of X/Y in G17.

LinuxCNC's rules: in G90 the point is at @ from the origin of the current coordinate
system, at angle ^ from +X; a missing @ keeps the current radius, a missing ^ the current
angle. In G91 @ and ^ are added to the current point's radius and angle about the origin
(undefined at the origin itself). The result replaces the line's X and Y words.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .parser import Block
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal


def polar_words(m: Modal, b: Block, words: dict[str, Word], cycle: bool = False) -> None:
    """Turn the line's @/^ words into X/Y words (program units, the distance mode's).
    For a canned cycle in G91 the increments apply before every repeat: they are left in
    `m.polar_inc` (radius, angle in rad) for cycles.py instead."""
    r_w, a_w = words.pop("@", None), words.pop("^", None)
    first = r_w or a_w
    assert first is not None
    letter = "@" if r_w is not None else "^"
    if m.plane != 170:
        raise b.error("polar coordinates (@ ^) need the XY plane (G17)", first.pos,
                      fmt(letter, first.value))
    for L in "XY":
        if L in words:
            raise b.error(f"{L} cannot be used with polar coordinates (@ ^) on one line",
                          words[L].pos, fmt(L, words[L].value))
    x, y = m.program_position(0), m.program_position(1)
    r0, a0 = math.hypot(x, y), math.atan2(y, x)
    if m.incremental and cycle:
        m.polar_inc = (r_w.value if r_w is not None else 0.0,
                       math.radians(a_w.value) if a_w is not None else 0.0)
        return
    if m.incremental:
        if x == 0.0 and y == 0.0:
            raise b.error("incremental polar motion is undefined at the origin", first.pos,
                          fmt(letter, first.value))
        r = r0 + (r_w.value if r_w is not None else 0.0)
        a = a0 + (math.radians(a_w.value) if a_w is not None else 0.0)
    else:
        r = r_w.value if r_w is not None else r0
        a = math.radians(a_w.value) if a_w is not None else a0
    nx, ny = r * math.cos(a), r * math.sin(a)
    if m.incremental:
        nx, ny = nx - x, ny - y
    words["X"] = Word(nx, first.pos)
    words["Y"] = Word(ny, first.pos)
