"""Tool length offsets: G43 [H] (every axis offset of a tool in the table), G43.1 (offsets
given on the line), G43.2 (add a tool's or the line's offsets), G49 (none), in machine units;
the modal state re-reads them (Modal.update_offsets)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .parser import Block
from .words import Word

if TYPE_CHECKING:
    from .modal import Modal

_AXES = frozenset("XYZABCUVW")


def tool_length(m: Modal, b: Block, g: tuple[int, int], words: dict[str, Word],
                used: set[str]) -> None:
    """G43 [H] (table offsets of a tool), G43.1 (offsets given on the line), G43.2
    (add a tool's or the line's offsets), G49 (none)."""
    code, pos = g
    axes = {L: w for L, w in words.items() if L in _AXES}
    if code == 490:
        m.tool_offset = [0.0] * 9
    elif code == 431:
        if not axes:
            raise b.error("G43.1 needs axis words (the offsets)", pos, "G43.1")
        m.tool_offset = [0.0] * 9
        for L, w in axes.items():
            m.axis_index(b, L, w)
            m.tool_offset[m.letters[L][1]] = m.conv(w.value, L)
        used.update(axes)
    else:
        h = words.get("H")
        tool = m.tool
        if h is not None:
            used.add("H")
            tool = m.tool_word(b, "H", h, f"G{code / 10:g}")
        if code == 432 and h is None and axes:
            extra = [0.0] * 9
            for L, w in axes.items():
                m.axis_index(b, L, w)
                extra[m.letters[L][1]] = m.conv(w.value, L)
            used.update(axes)
        elif code == 432 and h is None:
            raise b.error("G43.2 needs H (a tool) or axis words", pos, "G43.2")
        else:
            t = m.tools.get(tool)
            extra = list(t.offsets) if t is not None else [0.0] * 9
        if code == 430:
            m.tool_offset = extra
        else:
            m.tool_offset = [a + e for a, e in zip(m.tool_offset, extra,
                                                      strict=True)]
    m.update_offsets()


def set_tool_parameters(m: Modal) -> None:
    """#5400 tool in the spindle, #5401-#5409 its offsets X..W (machine units), #5410
    diameter, #5411/#5412 front/back angle, #5413 orientation (LinuxCNC)."""
    nums = m.params
    nums.set_number(5400, float(m.tool))
    t = m.tools.get(m.tool)
    offs = t.offsets if t is not None else (0.0,) * 9
    for k in range(9):
        nums.set_number(5401 + k, offs[k])
    nums.set_number(5410, t.diameter if t is not None else 0.0)
    nums.set_number(5411, t.front_angle if t is not None else 0.0)
    nums.set_number(5412, t.back_angle if t is not None else 0.0)
    nums.set_number(5413, float(t.orientation) if t is not None else 0.0)

