"""Canned cycles G73, G74, G81-G89 with G98/G99 and L repeats, expanded
into canonical motion exactly as LinuxCNC's interp_cycles.cc does.

Per repeat (CYCLE_MACRO): rapid parallel to the plane to the hole (on the first repeat
from a start above R: first at the start height, then down to R; otherwise at the
clearance height, then down to R), then the cycle's own moves along the third axis, ending
at the clearance height: R with G99, the initial level with G98 (the height before the
first of a series of consecutive cycles, never below R). In G91, X/Y (plane axes) are
increments applied before every repeat, R is relative to the initial level and Z to R.
R is sticky while the same cycle continues, Z (third-axis bottom), P (dwell) and Q (peck)
are sticky likewise; L (default 1) repeats. If the start is below R, the tool first rapids
up to R. The cycle runs in exact-path mode and restores the blend mode after.

G74/G84 are floating-chuck tapping (LinuxCNC 2.9): feed in, spindle reversed, dwell P
(optional, sticky across cycles, 0 at start), feed out to the clearance, spindle restored;
G84 needs M3, G74 M4.
G87 is back boring (LinuxCNC's convert_cycle_g87): from R, move to the offset point (hole +
I/J/K along the plane axes, always relative), stop the spindle and orient it (0 degrees, in
its turning direction), rapid down to the bottom, over to the hole, restart the spindle,
feed up to the third-axis word of the plane (K in G17, J in G18, I in G19: absolute in
G90, relative to the bottom in G91) and back down, stop and orient again, rapid to the
offset point, up to the clearance height, back over the hole, restart the spindle. I, J, K
are sticky while G87 continues. Unlike LinuxCNC (whose ORIENT_SPINDLE goes on at once),
the tool waits for each orientation (at most G87_ORIENT_TIMEOUT s) before it moves into
the hole: the oriented tool is what lets it pass.
Planes: G17 (hole at X/Y, depth along Z), G18 (Z/X, depth along Y), G19 (Y/Z, along X).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from . import canon
from .orient import Orient
from .parser import Block
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal

#: Motion codes (G * 10) of the cycles built here.
CYCLES = frozenset({730, 740, 810, 820, 830, 840, 850, 860, 870, 880, 890})
#: Plane -> (first, second, depth) axis letters.
CYCLE_AXES = {170: ("X", "Y", "Z"), 180: ("Z", "X", "Y"), 190: ("Y", "Z", "X")}
#: LinuxCNC's peck retract for G73 (chip break) and G83 (rapid back down), program units.
PECK_CLEARANCE = {"mm": 0.254, "inch": 0.010}
#: G87: the offset / back-bore word of each axis letter.
G87_WORD = {"X": "I", "Y": "J", "Z": "K"}
#: G87: the most seconds the tool waits for each spindle orientation before the run stops.
G87_ORIENT_TIMEOUT = 30.0


@dataclass
class CycleState:
    """Sticky cycle words (as written) and the initial level of a series of cycles."""

    r: float | None = None
    c: float | None = None
    p: float | None = None
    q: float | None = None
    ijk: dict[str, float] | None = None  # G87's I, J, K as written
    initial: float | None = None  # program coordinate of the depth axis before the series


class _Cycle:
    """Emits the cycle's moves in program coordinates of the plane axes (a, b, c)."""

    def __init__(self, m: Modal, b: Block, gword: str, gpos: int,
                 out: list[canon.Command]) -> None:
        self.m, self.b, self.gword, self.gpos, self.out = m, b, gword, gpos, out
        la, lb, lc = CYCLE_AXES[m.plane]
        self.idx = [m.letters[L] for L in (la, lb, lc)]  # (machine axis, param k)
        self.letters = (la, lb, lc)
        self.feed = m.per_second(m.feed_lin, b, gword, gpos)

    def prog(self, n: int) -> float:
        return self.m.program_position(self.idx[n][1])

    def _target(self, a: float, b: float, c: float) -> list[float]:
        words = {L: Word(v, self.gpos) for L, v in zip(self.letters, (a, b, c), strict=True)}
        return self.m.target_position(self.b, words, incremental=False, diameter=False)

    def traverse(self, a: float, b: float, c: float) -> None:
        t = self._target(a, b, c)
        self.m.check_limits(self.b, t, t, self.gword, self.gpos)
        self.out.append(canon.Rapid(tuple(t), self.b.line, self.b.file))
        self.m.pos = t

    def feed_to(self, a: float, b: float, c: float) -> None:
        t = self._target(a, b, c)
        self.m.check_limits(self.b, t, t, self.gword, self.gpos)
        self.out.append(canon.Feed(tuple(t), self.feed, self.b.line, self.b.file))
        self.m.pos = t


def _need(m: Modal, b: Block, code: int, words: dict[str, Word], letter: str,
          sticky: float | None, used: set[str], gword: str, gpos: int,
          what: str) -> float:
    """A word the cycle needs; sticky from the previous block of the same cycle."""
    w = words.get(letter)
    if w is not None:
        used.add(letter)
        return w.value
    if m.motion_prev == code and sticky is not None:
        return sticky
    raise b.error(f"{gword} needs {letter} ({what})", gpos, gword)


def canned_cycle(m: Modal, b: Block, code: int, gpos: int, axes: dict[str, Word],
                 words: dict[str, Word], used: set[str], out: list[canon.Command]) -> None:
    """Run one canned-cycle block (code = G * 10); the tool ends at the clearance height."""
    gword = f"G{code / 10:g}"
    st = m.cycle
    if m.inverse_time:
        raise b.error("canned cycles cannot be used with inverse time feed (G93)", gpos,
                      gword)
    if m.feed_lin <= 0.0:
        raise b.error(f"feed rate is zero or not set: give F before or with {gword}", gpos,
                      gword)
    if m.plane not in CYCLE_AXES:  # pragma: no cover - planes are 170/180/190
        raise b.error("canned cycles need G17, G18 or G19", gpos, gword)
    la, lb, lc = CYCLE_AXES[m.plane]
    for L in (la, lb, lc):
        if L not in m.letters:
            raise b.error(f"{gword} in this plane needs a machine axis for {L}", gpos, gword)
    for L, w in axes.items():
        if L not in (la, lb, lc):
            raise b.error(f"axis {L} cannot move in a canned cycle in the {la}{lb} plane",
                          w.pos, fmt(L, w.value))
    same = m.motion_prev == code
    r_word = _need(m, b, code, words, "R", st.r, used, gword, gpos, "retract plane")
    if lc in axes:
        c_word = axes[lc].value
    elif same and st.c is not None:
        c_word = st.c
    else:
        raise b.error(f"{gword} needs {lc} (the bottom of the hole)", gpos, gword)
    repeats = 1
    lw = words.get("L")
    if lw is not None:
        used.add("L")
        repeats = m.int_word(b, "L", lw, 0)
        if repeats == 0:
            raise b.error("L0: a canned cycle cannot be done zero times", lw.pos, "L0")
        if repeats > m.opt.max_blocks:
            raise b.error(f"L{repeats}: more repeats than max_blocks ({m.opt.max_blocks})",
                          lw.pos, f"L{repeats}")
    dwell = peck = 0.0
    if code in (820, 860, 880, 890):
        dwell = _need(m, b, code, words, "P", st.p, used, gword, gpos, "dwell seconds")
        if dwell < 0:
            raise b.error(f"dwell time must be >= 0, got {dwell:g}", words["P"].pos, "P")
        st.p = dwell
    if code in (730, 830):
        peck = _need(m, b, code, words, "Q", st.q, used, gword, gpos, "peck depth")
        if peck <= 0:
            raise b.error(f"{gword} Q (peck depth) must be > 0, got {peck:g}",
                          words["Q"].pos if "Q" in words else gpos, "Q")
        st.q = peck
    if code in (740, 840):  # floating-chuck tapping: P optional, sticky across cycles
        pw = words.get("P")
        if pw is not None:
            used.add("P")
            st.p = pw.value
        dwell = st.p if st.p is not None else 0.0
        if not m.spindle_on:
            raise b.error(f"{gword} needs the spindle turning", gpos, gword)
        if m.spindle_cw != (code == 840):
            raise b.error(f"{gword} needs the spindle turning "
                          f"{'clockwise (M3)' if code == 840 else 'counterclockwise (M4)'}",
                          gpos, gword)
    if code in (860, 870, 880) and not m.spindle_on:
        raise b.error(f"{gword} needs the spindle turning (M3 or M4)", gpos, gword)
    back_words: tuple[float, float, float] | None = None
    if code == 870:  # I, J, K: offsets of the plane axes, back-bore height on the third
        old = st.ijk or {}
        got = {G87_WORD[L]: _need(m, b, code, words, G87_WORD[L], old.get(G87_WORD[L]),
                                  used, gword, gpos, "back boring offset or height")
               for L in (la, lb, lc)}
        st.ijk = got
        back_words = (got[G87_WORD[la]], got[G87_WORD[lb]], got[G87_WORD[lc]])
    if peck > 0 and (r_word - c_word if not m.incremental else -c_word) / peck * repeats \
            > m.opt.max_blocks:
        raise b.error(f"{gword}: Q{peck:g} makes more pecks than max_blocks "
                      f"({m.opt.max_blocks})", gpos, gword)
    cyc = _Cycle(m, b, gword, gpos, out)
    current_c = cyc.prog(2)
    if st.initial is None:
        st.initial = current_c
    old_c = st.initial
    a, bb = cyc.prog(0), cyc.prog(1)
    da = db = 0.0
    if m.incremental:
        da = axes[la].value if la in axes else 0.0
        db = axes[lb].value if lb in axes else 0.0
        r = r_word + old_c
        bottom = r + c_word
    else:
        r = r_word
        bottom = c_word
        a = axes[la].value if la in axes else a
        bb = axes[lb].value if lb in axes else bb
    if r < bottom:
        raise b.error(f"{gword}: the retract plane R ({r:g}) is below the bottom "
                      f"{lc}{bottom:g}", words["R"].pos if "R" in words else gpos, gword)
    if old_c < r:
        cyc.traverse(cyc.prog(0), cyc.prog(1), r)
        old_c = current_c = r
    clear = r if not m.retract_old_z else old_c
    restore = m.blend
    if restore is None or restore[0] != "exact_path":
        out.append(canon.SetBlend("exact_path", None, b.line, b.file))
    delta = PECK_CLEARANCE[m.units]
    polar, m.polar_inc = m.polar_inc, None
    for n in range(repeats):
        a += da
        bb += db
        if polar is not None:  # G91 @/^: radius and angle about the origin, per repeat
            if a == 0.0 and bb == 0.0:
                raise b.error("incremental polar motion is undefined at the origin", gpos,
                              gword)
            rad = math.hypot(a, bb) + polar[0]
            ang = math.atan2(bb, a) + polar[1]
            a, bb = rad * math.cos(ang), rad * math.sin(ang)
        if n == 0 and current_c > r:
            cyc.traverse(a, bb, current_c)
            cyc.traverse(a, bb, r)
        else:
            cyc.traverse(a, bb, clear)
            if clear > r:
                cyc.traverse(a, bb, r)
        if back_words is not None:
            oa, ob, mid = back_words
            _back_bore(m, cyc, a, bb, a + oa, bb + ob, r, clear,
                       bottom + mid if m.incremental else mid, bottom)
        else:
            _body(m, cyc, code, a, bb, r, clear, bottom, dwell, peck, delta)
    if restore is None or restore[0] != "exact_path":
        mode, tol, cam = restore if restore is not None else ("blend", None, None)
        out.append(canon.SetBlend(mode, tol, b.line, b.file, cam))
    st.c = c_word
    st.r = r_word
    used.update(axes)


def _body(m: Modal, cyc: _Cycle, code: int, a: float, b: float, r: float, clear: float,
          bottom: float, dwell: float, peck: float, delta: float) -> None:
    """The moves of one hole after positioning at R (interp_cycles.cc convert_cycle_gNN)."""
    out, blk = cyc.out, cyc.b
    if code in (730, 830):
        depth = r - peck
        while depth > bottom:
            cyc.feed_to(a, b, depth)
            if code == 830:
                cyc.traverse(a, b, r)
            cyc.traverse(a, b, depth + delta)
            depth -= peck
        cyc.feed_to(a, b, bottom)
        cyc.traverse(a, b, clear)
    elif code == 810:
        cyc.feed_to(a, b, bottom)
        cyc.traverse(a, b, clear)
    elif code == 820:
        cyc.feed_to(a, b, bottom)
        out.append(canon.Dwell(dwell, blk.line, blk.file))
        cyc.traverse(a, b, clear)
    elif code in (740, 840):  # feed in, reverse the spindle, dwell, feed out, restore
        cyc.feed_to(a, b, bottom)
        cw = m.spindle_cw
        out.append(m.spindle_record(False, blk))
        out.append(canon.Spindle(True, not cw, m.speed, m.opt.spindle_output, blk.line,
                                 blk.file))
        out.append(canon.Dwell(dwell, blk.line, blk.file))
        cyc.feed_to(a, b, clear)
        out.append(canon.Spindle(False, not cw, m.speed, m.opt.spindle_output, blk.line,
                                 blk.file))
        out.append(m.spindle_record(True, blk))
    elif code == 850:
        cyc.feed_to(a, b, bottom)
        cyc.feed_to(a, b, r)
        cyc.traverse(a, b, clear)
    elif code == 860:
        cyc.feed_to(a, b, bottom)
        out.append(canon.Dwell(dwell, blk.line, blk.file))
        out.append(m.spindle_record(False, blk))
        cyc.traverse(a, b, clear)
        out.append(m.spindle_record(True, blk))
    elif code == 880:
        cyc.feed_to(a, b, bottom)
        out.append(canon.Dwell(dwell, blk.line, blk.file))
        out.append(m.spindle_record(False, blk))
        out.append(canon.Pause(False, blk.line, blk.file))
        # LinuxCNC leaves the retraction to the operator and then assumes the tool at the
        # clearance height; a motion controller moves there itself on resume
        cyc.traverse(a, b, clear)
        out.append(m.spindle_record(True, blk))
    else:  # 890
        cyc.feed_to(a, b, bottom)
        out.append(canon.Dwell(dwell, blk.line, blk.file))
        cyc.feed_to(a, b, clear)


def _back_bore(m: Modal, cyc: _Cycle, a: float, b: float, oa: float, ob: float, r: float,
               clear: float, middle: float, bottom: float) -> None:
    """G87's moves of one hole after positioning at R (module doc)."""
    out, blk = cyc.out, cyc.b
    orient = Orient(0.0, 0 if m.spindle_cw else 1, G87_ORIENT_TIMEOUT, blk.line, blk.file)
    cyc.traverse(oa, ob, r)
    out.append(m.spindle_record(False, blk))
    out.append(orient)
    cyc.traverse(oa, ob, bottom)
    cyc.traverse(a, b, bottom)
    out.append(m.spindle_record(True, blk))
    cyc.feed_to(a, b, middle)
    cyc.feed_to(a, b, bottom)
    out.append(m.spindle_record(False, blk))
    out.append(orient)
    cyc.traverse(oa, ob, bottom)
    cyc.traverse(oa, ob, clear)
    cyc.traverse(a, b, clear)
    out.append(m.spindle_record(True, blk))
