"""A G0-G3 under cutter compensation: the words are read against the programmed point
(not where the tool centre is), then cuttercomp.py offsets the move."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..path import Direction
from . import canon
from .arcmove import arc_move
from .cuttercomp import comp_arc, comp_straight, plane_axes
from .parser import Block
from .words import Word, feed_length

if TYPE_CHECKING:
    from .modal import Modal


def comp_motion(m: Modal, b: Block, mode: int, gpos: int, gword: str,
                axes: dict[str, Word], words: dict[str, Word], used: set[str],
                out: list[canon.Command], machine: bool) -> None:
    """A move under cutter compensation: words read against the programmed point."""
    if machine:
        raise b.error("G53 cannot be used with cutter compensation on", gpos, "G53")
    ax, ay = plane_axes(m)
    tool_pos = m.pos
    prog = tool_pos[:]
    if not m.comp.first_move:
        prog[ax], prog[ay] = m.comp.prog
    m.pos = prog
    try:
        target = m.target_position(b, axes)
        if mode in (20, 30):
            arc = arc_move(m, b, mode, gpos, target, words, used)
    finally:
        m.pos = tool_pos
    if mode == 0:
        feed = 0.0
    elif mode == 10:
        feed, duration = m.feed_rate(b, words, gword, gpos)
        if duration is not None:  # G93: the programmed length in that time (LinuxCNC)
            feed = feed_length(prog, target, m.letters) / duration
    else:
        feed = arc.feed_per_s
    if mode in (0, 10):
        comp_straight(m, b, mode, target, feed, out, gword, gpos)
    else:
        sign = 1 if arc.direction == Direction.CCW else -1
        comp_arc(m, b, mode, target, arc.centre[ax], arc.centre[ay],
                 sign * (arc.turns + 1), feed, out, gword, gpos)

