"""Coordinate systems and offsets: G10 L1/L2/L10/L11/L20, G28/G30 and their .1 forms, G52,
G92 and G92.1/.2/.3 (RS-274/NGC group 0, LinuxCNC semantics).

They change no modal state of their own: they move through a stored position or rewrite
the parameters that hold the offsets (G54.. origins #5221.. (+20 per system), G92
#5211..#5219 with #5210 its on flag, G28 #5161.., G30 #5181..; machine units), then the
modal state re-reads them (`Modal.update_offsets`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from . import canon
from .frame import frame_position
from .parser import Block
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal


def offset_command(m: Modal, b: Block, g: tuple[int, int], axes: dict[str, Word],
                   words: dict[str, Word], used: set[str], out: list[canon.Command]) -> None:
    """Execute the group-0 word `g` = (code, column): G10, G28/G30 (.1) or G92 (.1/.2/.3)."""
    code, gpos = g
    gword = f"G{code / 10:g}"
    nums = m.params.numbers
    if code in (280, 300):
        base = 5161 if code == 280 else 5181
        if axes:
            mid = m.target_position(b, axes)
            m.check_limits(b, mid, mid, gword, gpos)
            out.append(canon.Rapid(tuple(mid), b.line, b.file))
            m.pos = mid
            letters = list(axes)
        else:
            letters = list(m.letters)
        end = m.pos[:]
        for L in letters:
            ax, k = m.letters[L]
            end[ax] = nums[base + k]
        m.check_limits(b, end, end, gword, gpos)
        out.append(canon.Rapid(tuple(end), b.line, b.file))
        m.pos = end
    elif code in (281, 301):
        base = 5161 if code == 281 else 5181
        for ax, k in m.letters.values():
            m.params.set_number(base + k, m.pos[ax])
    elif code == 920:
        if not axes:
            raise b.error("G92 needs at least one axis word", gpos, gword)
        for L, w in axes.items():
            ax = m.axis_index(b, L, w)
            k = m.letters[L][1]
            m.g92[k] = frame_position(m, k, ax) - m.conv(w.value, L)
            m.params.set_number(5211 + k, m.g92[k])
        m.params.set_number(5210, 1.0)
        m.update_offsets()
    elif code == 520:  # G52: a local offset held in the G92 registers (LinuxCNC)
        for L, w in axes.items():
            m.axis_index(b, L, w)
            k = m.letters[L][1]
            m.g92[k] = m.conv(w.value, L)
            m.params.set_number(5211 + k, m.g92[k])
        m.params.set_number(5210, 1.0 if any(m.g92) else 0.0)
        m.update_offsets()
    elif code in (921, 922):
        m.g92 = [0.0] * 9
        if code == 921:
            for k in range(9):
                m.params.set_number(5211 + k, 0.0)
        m.params.set_number(5210, 0.0)
        m.update_offsets()
    elif code == 923:
        m.g92 = [nums[5211 + k] for k in range(9)]
        m.params.set_number(5210, 1.0)
        m.update_offsets()
    elif code == 100:
        _g10(m, b, gpos, axes, words, used)

def _g10(m: Modal, b: Block, gpos: int, axes: dict[str, Word], words: dict[str, Word],
         used: set[str]) -> None:
    lw = words.get("L")
    if lw is None:
        raise b.error("G10 needs L (L1, L2, L10, L11 or L20)", gpos, "G10")
    used.add("L")
    L = m.int_word(b, "L", lw, 0)
    if L not in (1, 2, 10, 11, 20):
        raise b.error(f"G10 L{L} is not supported (L1, L2, L10, L11, L20)", lw.pos, f"L{L}")
    if L in (1, 10, 11):
        _g10_tool(m, b, L, gpos, axes, words, used)
        return
    pw = words.get("P")
    if pw is None:
        raise b.error("G10 needs P (coordinate system 1..9, 0 = current)", gpos, "G10")
    used.add("P")
    p = m.int_word(b, "P", pw, 0)
    if p > 9:
        raise b.error(f"G10 P must be in [0, 9], got {p}", pw.pos, fmt("P", pw.value))
    system = p or m.coord
    base = 5221 + 20 * (system - 1)
    rot = m.params.numbers[base + 9]
    if L == 20 and "R" in words:
        raise b.error("R is not allowed in G10 L20", words["R"].pos, "R")
    if L == 20 and rot != 0.0 and any(x in axes for x in "XY") and "X" in m.letters \
            and "Y" in m.letters:
        _l20_rotated(m, b, base, rot, axes)
        axes = {k: v for k, v in axes.items() if k not in "XY"}
    for letter, w in axes.items():
        ax = m.axis_index(b, letter, w)
        k = m.letters[letter][1]
        v = m.conv(w.value, letter)
        if L == 2:
            m.params.set_number(base + k, v)
        else:  # L20: the current position becomes v in that system
            extra = m.g92[k] + m.tool_offset[k]
            m.params.set_number(base + k, m.pos[ax] - extra - v)
    rw = words.get("R")
    if rw is not None:  # rotation of the system about its origin, degrees (#5230 + ..)
        used.add("R")
        m.params.set_number(base + 9, rw.value)
    m.update_offsets()


def _l20_rotated(m: Modal, b: Block, base: int, rot: float, axes: dict[str, Word]) -> None:
    """G10 L20 X/Y on a rotated system: the origin moves so the current point reads the
    given X/Y in that system's rotated frame (LinuxCNC convert_setup)."""
    nums = m.params.numbers
    ax, ay = m.letters["X"][0], m.letters["Y"][0]
    t = math.radians(rot)
    c, s = math.cos(t), math.sin(t)
    # current point in system `base`, rotated frame, G92 included (machine units)
    dx = m.pos[ax] - m.tool_offset[0] - nums[base]
    dy = m.pos[ay] - m.tool_offset[1] - nums[base + 1]
    cx, cy = c * dx + s * dy - m.g92[0], -s * dx + c * dy - m.g92[1]
    x = m.conv(axes["X"].value, "X") if "X" in axes else cx
    y = m.conv(axes["Y"].value, "Y") if "Y" in axes else cy
    ddx, ddy = cx - x, cy - y
    m.params.set_number(base, nums[base] + c * ddx - s * ddy)
    m.params.set_number(base + 1, nums[base + 1] + s * ddx + c * ddy)


def _rotation(m: Modal, L: int) -> float:
    """Rotation of the system G10 L10 (the current one) or L11 (G59.3) measures in."""
    system = 9 if L == 11 else m.coord
    return m.params.numbers[5221 + 20 * (system - 1) + 9]


def _tool_xy_rotated(m: Modal, L: int, axes: dict[str, Word], offsets: list[float]) -> None:
    """G10 L10/L11 X/Y in a rotated system (LinuxCNC convert_setup_tool): the tool's X/Y
    offset so the current point reads the values in the rotated frame; with only one of
    X/Y the offset's component along the other rotated axis is kept."""
    nums = m.params.numbers
    system = 9 if L == 11 else m.coord
    base = 5221 + 20 * (system - 1)
    t = math.radians(nums[base + 9])
    c, s = math.cos(t), math.sin(t)
    ax, ay = m.letters["X"][0], m.letters["Y"][0]
    dx, dy = m.pos[ax] - nums[base], m.pos[ay] - nums[base + 1]
    tx, ty = c * dx + s * dy, -s * dx + c * dy  # current point in the rotated frame
    if L == 10:
        tx, ty = tx - m.g92[0], ty - m.g92[1]
    ox, oy = c * offsets[0] + s * offsets[1], -s * offsets[0] + c * offsets[1]
    if "X" in axes:
        ox = tx - m.conv(axes["X"].value, "X")
    if "Y" in axes:
        oy = ty - m.conv(axes["Y"].value, "Y")
    offsets[0], offsets[1] = c * ox - s * oy, s * ox + c * oy


def _g10_tool(m: Modal, b: Block, L: int, gpos: int, axes: dict[str, Word],
              words: dict[str, Word], used: set[str]) -> None:
    """G10 L1 (set a tool table entry), L10 / L11 (set a tool's offsets so the current
    position reads the given values with the current work offsets, or with G59.3's)."""
    from dataclasses import replace

    from .tooltable import Tool

    word = f"G10 L{L}"
    pw = words.get("P")
    if pw is None:
        raise b.error(f"{word} needs P (the tool number)", gpos, word)
    used.add("P")
    n = m.int_word(b, "P", pw, 1)
    if m.has_tool_table and n not in m.tools:
        raise b.error(f"{word}: requested tool {n} is not in the tool table", pw.pos,
                      fmt("P", pw.value))
    tool = m.tools.get(n) or Tool(n, n)
    offsets = list(tool.offsets)
    base9 = 5221 + 20 * 8
    for letter, w in axes.items():
        ax = m.axis_index(b, letter, w)
        k = m.letters[letter][1]
        v = m.conv(w.value, letter)
        if L == 1:
            offsets[k] = v
        elif k < 2 and _rotation(m, L) != 0.0 and "X" in m.letters and "Y" in m.letters:
            continue  # X/Y of a rotated system: below, together
        elif L == 10:
            work = m.off[k] - m.tool_offset[k]  # origin + G92
            offsets[k] = m.pos[ax] - work - v
        else:
            offsets[k] = m.pos[ax] - m.params.numbers[base9 + k] - v
    if L in (10, 11) and _rotation(m, L) != 0.0 and any(x in axes for x in "XY") \
            and "X" in m.letters and "Y" in m.letters:
        _tool_xy_rotated(m, L, axes, offsets)
    changes: dict[str, object] = {"offsets": tuple(offsets)}
    rw = words.get("R")
    if rw is not None:
        used.add("R")
        if rw.value < 0:
            raise b.error(f"{word} R (tool radius) must be >= 0, got {rw.value:g}", rw.pos,
                          fmt("R", rw.value))
        changes["diameter"] = 2.0 * m.lin(rw.value)
    for letter, name in (("I", "front_angle"), ("J", "back_angle")):
        if letter in words:
            used.add(letter)
            changes[name] = words[letter].value
    if "Q" in words:
        used.add("Q")
        q = m.int_word(b, "Q", words["Q"], 0)
        if q > 9:
            raise b.error(f"{word} Q (orientation) must be 0..9, got {q}", words["Q"].pos,
                          fmt("Q", q))
        changes["orientation"] = q
    m.tools[n] = replace(tool, **changes)  # type: ignore[arg-type]
    if n == m.tool:
        m.set_tool_parameters()
