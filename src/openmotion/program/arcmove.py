"""G2/G3 for the modal state machine: words -> a checked `ArcMove` in machine coordinates.

Plane letters, centre (I/J/K relative by default, absolute with G90.1, or R), the LinuxCNC
radius tolerances (arcgeom.py), P turns, soft limits over the arc's bounding box, and the
feed (G94 rate or G93 time over the helical length).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..path import Direction
from . import canon
from .arcgeom import (
    CENTRE_TOL,
    RADIUS_TOL,
    ArcGeometryError,
    arc_extent,
    centre_from_radius,
    check_radii,
    sweep_angle,
)
from .frame import rotate_vector, xy_to_machine
from .parser import Block
from .words import Word, feed_length, fmt

if TYPE_CHECKING:
    from .modal import Modal

#: Plane -> (first, second, helix) axis letters and the centre-offset letters.
PLANES = {170: ("X", "Y", "Z", "I", "J", "K"), 180: ("Z", "X", "Y", "K", "I", "J"),
          190: ("Y", "Z", "X", "J", "K", "I")}


def arc_move(m: Modal, b: Block, mode: int, gpos: int, target: list[float],
             words: dict[str, Word], used: set[str]) -> canon.ArcMove:
    """The ArcMove of a G2 (mode 20) / G3 (30) line from m.pos to `target`; marks the words
    it consumes in `used`. Raises GCodeError naming the word at fault."""
    gword = f"G{mode // 10}"
    la, lb, _lh, oa, ob, oh = PLANES[m.plane]
    for L in (la, lb):
        if L not in m.letters:
            raise b.error(f"arc in the {la}{lb} plane needs a machine axis for {L}", gpos,
                          gword)
    if oh in words:
        w = words[oh]
        raise b.error(f"{oh} is not allowed for an arc in the {la}{lb} plane", w.pos,
                      fmt(oh, w.value))
    if m.rotated and m.plane != 170:
        raise b.error(f"{gword} in G18/G19 on a rotated coordinate system (G10 R) is not "
                      "supported", gpos, gword)
    feed, duration = m.feed_rate(b, words, gword, gpos)
    ax_a, ka = m.letters[la]
    ax_b, kb = m.letters[lb]
    s = m.lin
    sa, sb = m.pos[ax_a], m.pos[ax_b]
    ea, eb = target[ax_a], target[ax_b]
    ccw = mode == 30
    rtol = s(RADIUS_TOL[m.units])
    turns = 0
    pw = words.get("P")
    if pw is not None:
        used.add("P")
        turns = m.int_word(b, "P", pw, 1) - 1
    try:
        if "R" in words:
            rw = words["R"]
            used.add("R")
            for L in (oa, ob):
                if L in words:
                    raise b.error("an arc takes either R or I/J/K, not both",
                                  words[L].pos, fmt(L, words[L].value))
            if rw.value == 0:
                raise b.error("arc radius R must not be 0", rw.pos, "R0")
            ca, cb = centre_from_radius(sa, sb, ea, eb, s(rw.value), ccw, rtol)
            r1 = r2 = math.hypot(sa - ca, sb - cb)
        else:
            wa, wb = words.get(oa), words.get(ob)
            if wa is None and wb is None:
                raise b.error(f"{gword} needs R or a centre ({oa}/{ob})", gpos, gword)
            used.update(L for L in (oa, ob) if L in words)
            if m.rotated and m.plane == 170:  # centre given in the rotated frame
                da = s(wa.value) if wa is not None else 0.0
                db = s(wb.value) if wb is not None else 0.0
                if m.arc_incremental:
                    ra, rb = rotate_vector(m, da, db)
                    ca, cb = sa + ra, sb + rb
                elif wa is None or wb is None:
                    raise b.error(f"absolute arc centre (G90.1) needs both {oa} and {ob}",
                                  gpos, oa if wa is None else ob)
                else:
                    ca, cb = xy_to_machine(m, da, db)
            elif m.arc_incremental:
                ca = sa + (s(wa.value) if wa is not None else 0.0)
                cb = sb + (s(wb.value) if wb is not None else 0.0)
            else:
                if wa is None or wb is None:
                    missing = oa if wa is None else ob
                    raise b.error(f"absolute arc centre (G90.1) needs both {oa} and {ob}",
                                  gpos, missing)
                ca = s(wa.value) + m.off[ka]
                cb = s(wb.value) + m.off[kb]
            r1, r2 = check_radii(sa, sb, ea, eb, ca, cb, s(CENTRE_TOL[m.units]), rtol)
    except ArcGeometryError as exc:
        w = words.get("R") or words.get(oa) or words.get(ob)
        pos = w.pos if w is not None else gpos
        raise b.error(f"{gword}: {exc.message}", pos, exc.word) from None
    sweep = sweep_angle(sa, sb, ea, eb, ca, cb, ccw, turns)
    if m.opt.soft_limits is not None:
        a0 = math.atan2(sb - cb, sa - ca)
        amin, amax, bmin, bmax = arc_extent(ca, cb, max(r1, r2), a0, sweep, ccw,
                                            sa, sb, ea, eb)
        lo = [min(p, q) for p, q in zip(m.pos, target, strict=True)]
        hi = [max(p, q) for p, q in zip(m.pos, target, strict=True)]
        lo[ax_a], hi[ax_a], lo[ax_b], hi[ax_b] = amin, amax, bmin, bmax
        m.check_limits(b, lo, hi, gword, gpos)
    centre = m.pos[:]
    centre[ax_a], centre[ax_b] = ca, cb
    if duration is not None:
        r = 0.5 * (r1 + r2)
        helix = feed_length(m.pos, target, m.letters, skip=(ax_a, ax_b))
        feed = math.hypot(r * sweep, helix) / duration
    return canon.ArcMove(tuple(m.pos), tuple(target), tuple(centre), (ax_a, ax_b),
                         Direction.CCW if ccw else Direction.CW, turns, sweep, r1, r2,
                         feed, b.line, b.file, duration)
