"""The program coordinate frame: machine = R(program + G92) + origin + tool, in XY.

R is the rotation of the active coordinate system about its origin (G10 L2 R, stored in
#5230 + 20 (n - 1)), applied to X/Y only, as LinuxCNC's canon does: the G92 offset is
rotated with the program point, the G5x origin and the tool offset are not. With no
rotation each axis is a plain sum (Modal.off). Values here are in machine units (program
values already scaled by G20/G21).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .modal import Modal


def update(m: Modal) -> None:
    """Re-read origin, rotation, G92 and tool offsets after any of them changed."""
    base = 5221 + 20 * (m.coord - 1)
    nums = m.params.numbers
    for k in range(9):
        m.work[k] = nums[base + k]
        m.off[k] = m.work[k] + m.g92[k] + m.tool_offset[k]
    m.rot = nums[base + 9]
    m.rotated = m.rot != 0.0 and "X" in m.letters and "Y" in m.letters


def xy_to_machine(m: Modal, px: float, py: float) -> tuple[float, float]:
    """Program X/Y (machine units, G92 not yet added) -> machine X/Y."""
    t = math.radians(m.rot)
    c, s = math.cos(t), math.sin(t)
    x, y = px + m.g92[0], py + m.g92[1]
    return (c * x - s * y + m.work[0] + m.tool_offset[0],
            s * x + c * y + m.work[1] + m.tool_offset[1])


def machine_to_xy(m: Modal, mx: float, my: float, with_g92: bool = False
                  ) -> tuple[float, float]:
    """Machine X/Y -> program X/Y (machine units); with_g92 keeps the G92 offset in."""
    t = math.radians(m.rot)
    c, s = math.cos(t), math.sin(t)
    x, y = mx - m.work[0] - m.tool_offset[0], my - m.work[1] - m.tool_offset[1]
    px, py = c * x + s * y, -s * x + c * y
    if with_g92:
        return px, py
    return px - m.g92[0], py - m.g92[1]


def frame_position(m: Modal, k: int, ax: int) -> float:
    """Position of letter number k (machine axis ax) in the frame before G92 (machine
    units): what G92 and G10 L20 measure from."""
    if m.rotated and k in (0, 1):
        xm, ym = m.pos[m.letters["X"][0]], m.pos[m.letters["Y"][0]]
        return machine_to_xy(m, xm, ym, with_g92=True)[k]
    return m.pos[ax] - m.work[k] - m.tool_offset[k]


def rotate_vector(m: Modal, dx: float, dy: float) -> tuple[float, float]:
    """A program-frame XY vector (an arc centre offset) in machine axes."""
    t = math.radians(m.rot)
    c, s = math.cos(t), math.sin(t)
    return c * dx - s * dy, s * dx + c * dy
