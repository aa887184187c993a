"""Spindle-synchronised motion: G33 (one synchronised line) and the G76 threading cycle,
expanded into canonical motion as LinuxCNC's interpreter does (convert_threading_cycle).

A synchronised move is a `SyncedFeed`: the move advances `pitch` machine units along its
path per spindle revolution. G33 X.. Z.. K(pitch). G76 P(pitch) Z(end) I(thread peak offset
from the drive line: < 0 external, > 0 boring) J(first cut depth) K(full thread depth)
[R degression >= 1] [Q compound angle, deg] [H spring passes] [E taper length] [L taper
flags: 1 entry, 2 exit, 3 both]; the drive line is the start X (the tool's X before G76).
Cut n ends at depth I + J n^(1/R) until K, then K is cut once plus H spring passes; each
pass: rapid back to the safe X, in to depth, synchronised along Z (tapers as angled
synchronised moves at the taper pitch), rapid out, then a rapid to the end point. In G7
I, J and K are diameters. The spindle must turn (M3/M4).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from . import canon
from .parser import Block
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal


def _spindle(m: Modal, b: Block, gword: str, gpos: int) -> None:
    if not m.spindle_on:
        raise b.error(f"{gword} needs the spindle turning (M3 or M4)", gpos, gword)


def _move(m: Modal, b: Block, gword: str, gpos: int, out: list[canon.Command],
          x: float, z: float, pitch: float | None) -> None:
    """A rapid (pitch None) or synchronised move to program X/Z (program units)."""
    t = m.target_position(b, {"X": Word(x, gpos), "Z": Word(z, gpos)}, incremental=False,
                          diameter=False)
    m.check_limits(b, t, t, gword, gpos)
    if pitch is None:
        out.append(canon.Rapid(tuple(t), b.line, b.file))
    else:
        out.append(canon.SyncedFeed(tuple(t), m.lin(pitch), b.line, b.file))
    m.pos = t


def g33(m: Modal, b: Block, gpos: int, target: list[float], words: dict[str, Word],
        used: set[str], out: list[canon.Command]) -> None:
    """G33 K: one move synchronised to the spindle, K units per revolution."""
    k = words.get("K")
    if k is None:
        raise b.error("G33 needs K (distance per spindle revolution)", gpos, "G33")
    used.add("K")
    if k.value <= 0:
        raise b.error(f"G33 K must be > 0, got {k.value:g}", k.pos, fmt("K", k.value))
    _spindle(m, b, "G33", gpos)
    m.check_limits(b, target, target, "G33", gpos)
    out.append(canon.SyncedFeed(tuple(target), m.lin(k.value), b.line, b.file))
    m.pos = target


def g76(m: Modal, b: Block, gpos: int, axes: dict[str, Word], words: dict[str, Word],
        used: set[str], out: list[canon.Command]) -> None:
    """The G76 threading cycle (LinuxCNC's pass sequence)."""
    gw = "G76"
    for L in "XZ":
        if L not in m.letters:
            raise b.error(f"G76 needs a machine axis for {L}", gpos, gw)
    need = {}
    for L, what in (("P", "pitch"), ("Z", "end of the thread"), ("I", "thread peak offset"),
                    ("J", "first cut depth"), ("K", "full thread depth")):
        w = words.get(L)
        if w is None:
            raise b.error(f"G76 needs {L} ({what})", gpos, gw)
        need[L] = w.value
        used.add(L)
    if need["I"] == 0:
        raise b.error("in G76, I must not be 0", words["I"].pos, "I0")
    if need["J"] <= 0:
        raise b.error("in G76, J must be greater than 0", words["J"].pos, "J")
    if need["K"] <= need["J"]:
        raise b.error("in G76, K must be greater than J", words["K"].pos, "K")
    if need["P"] <= 0:
        raise b.error("in G76, P (pitch) must be greater than 0", words["P"].pos, "P")
    opt = {}
    for L in "RQHEL":
        if L in words:
            used.add(L)
            opt[L] = words[L].value
    _spindle(m, b, gw, gpos)
    used.update(axes)
    start_x, start_z = m.program_position(0), m.program_position(2)
    end = m.target_position(b, axes)
    m.cycle.initial = None
    i_n, j_n, k_n = need["I"], need["J"], need["K"]
    if m.diameter_mode:
        i_n, j_n, k_n = i_n / 2, j_n / 2, k_n / 2
    end_z = need["Z"] if not m.incremental else start_z + need["Z"]
    boring = i_n > 0.0
    full_dia = abs(i_n)
    start_depth = abs(i_n) + abs(j_n)
    cut = abs(j_n)
    height = abs(k_n)
    end_depth = abs(k_n) + abs(i_n)
    pitch = need["P"]
    angle = math.radians(opt.get("Q", 0.0))
    if end_z > start_z:
        angle = -angle
    springs = int(opt.get("H", 0))
    degression = opt.get("R", 1.0)
    if degression < 1.0:
        degression = 1.0
    taper = max(opt.get("E", 0.0), 0.0)
    taper_pitch = pitch * math.hypot(taper, height) / taper if taper > 0 else pitch
    if end_z > start_z:
        taper = -taper
    flags = max(int(opt.get("L", 0)), 0)
    entry, exit_ = flags & 1, flags & 2
    target_z = end_z + abs(k_n) * math.tan(angle)
    side = 1.0 if boring else -1.0

    def one_pass(depth: float) -> None:
        zoff = (depth - full_dia) * math.tan(angle)
        _move(m, b, gw, gpos, out, start_x + side * (depth - end_depth), start_z - zoff, None)
        if taper and entry:
            _move(m, b, gw, gpos, out, start_x + side * (depth - height), start_z - zoff,
                  taper_pitch)
            _move(m, b, gw, gpos, out, start_x + side * depth, start_z - zoff - taper,
                  taper_pitch)
        else:
            _move(m, b, gw, gpos, out, start_x + side * depth, start_z - zoff, None)
        if taper and exit_:
            _move(m, b, gw, gpos, out, start_x + side * depth, target_z - zoff + taper, pitch)
            _move(m, b, gw, gpos, out, start_x + side * (depth - height), target_z - zoff,
                  taper_pitch)
        else:
            _move(m, b, gw, gpos, out, start_x + side * depth, target_z - zoff, pitch)
        _move(m, b, gw, gpos, out, start_x + side * (depth - end_depth), target_z - zoff,
              None)

    depth = start_depth
    n = 1
    while depth < end_depth:
        one_pass(depth)
        n += 1
        depth = full_dia + cut * n ** (1.0 / degression)
        if n > m.opt.max_blocks:
            raise b.error("G76 makes more passes than max_blocks", gpos, gw)
    for _ in range(springs + 1):
        one_pass(end_depth)
    m.check_limits(b, end, end, gw, gpos)
    out.append(canon.Rapid(tuple(end), b.line, b.file))
    m.pos = end
