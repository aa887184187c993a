"""G70/G71/G72 in the interpreter: the cycle line, its profile subroutine, its moves.

`G71 Q<n> [X Z] [D I R]` (G72 the same, G70 `Q [X Z] [D E P]`; G71.1/.2, G72.1/.2): the
cycle line rapids to X Z (`lathe_cycle`, called by Modal) and asks the interpreter to read
subroutine O<n> as the profile (Modal.flow_request "G7x"). While it is read, each line goes
to `ProfileReader.line` instead of Modal.execute, as LinuxCNC's convert_g7x reads it:
parameter assignments and O-word flow run, G0/G1 make lines and G2/G3 arcs (I K or R), A
and C put a fillet or chamfer at a move's end, U/W are increments of X/Z; every other word
and code is ignored (LinuxCNC's documentation). X words are diameters in G7. At the
sub's return `finish` computes the passes (lathecycles.py) and runs each one through
Modal.execute as a G0/G1/G2/G3 line at the cycle line, so feed, units, offsets, cutter
compensation (G70) and soft limits apply as to any move.

Refused (file, line, column, word): Fanuc's `G71 P.. Q..` line-range form and U/W on the
cycle line (rs274 2.9 takes neither), any motion but G0-G3 in the profile, a rotated
coordinate system (G10 L2 R), a plane other than G18, G71/G72 under cutter compensation.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from . import canon
from .lathecycles import Profile, corner
from .lathegeom import Arc, Element, Emit, Line, ProfileError, radius_centre
from .parser import Block
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal

LATHE_CYCLES = (700, 710, 711, 712, 720, 721, 722)
_WORDS = {700: "QDEP", 710: "QDIR", 720: "QDIR"}

#: The cycle a Modal asked the interpreter to read a profile for (kept beside the Modal,
#: as splines.py does, so the fast path's list of modal state stays as it is).
_PENDING: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass
class LatheCycle:
    """One G7x line: what the passes need once its profile is read."""

    code: int  # 700, 710, 711, 712, 720, 721, 722
    block: Block
    gpos: int
    label: str
    start: complex  # z + i x, program units, X a radius
    params: dict[str, float] = field(default_factory=dict)

    @property
    def word(self) -> str:
        return fmt("G", self.code / 10)


def lathe_cycle(m: Modal, b: Block, code: int, gpos: int, axes: dict[str, Word],
                words: dict[str, Word], used: set[str], out: list[canon.Command]) -> None:
    """The G7x line itself: checks, the rapid to X Z, the request for the profile."""
    gword = fmt("G", code / 10)
    family = code // 10 * 10
    if "P" in words and family != 700:
        raise b.error(f"{gword} P.. Q.. (a profile between two line numbers, the Fanuc "
                      f"form) is not supported: give the profile as a subroutine, {gword} "
                      "Q<sub number>", words["P"].pos, fmt("P", words["P"].value))
    for letter in "UW":
        if letter in words:
            w = words[letter]
            raise b.error(f"{letter} on a {gword} line (a displacement of the profile) is "
                          "not supported", w.pos, fmt(letter, w.value))
    q = words.get("Q")
    if q is None:
        raise b.error(f"{gword} requires a Q word (the profile subroutine's number)", gpos,
                      gword)
    if m.comp.side and family != 700:
        raise b.error(f"{gword} cannot be used with cutter compensation enabled", gpos,
                      gword)
    if m.comp.side:
        raise b.error("G70 under cutter compensation is not supported (rs274 2.9.0~pre1 "
                      "moves back to the profile's end there; G40 first)", gpos, gword)
    if m.plane != 180:
        raise b.error(f"{gword} can only be used in XZ plane (G18)", gpos, gword)
    if m.rotated:
        raise b.error(f"{gword} in a rotated coordinate system (G10 L2 R) is not "
                      "supported", gpos, gword)
    for letter in "XZ":
        if letter not in m.letters:
            raise b.error(f"{gword} needs X and Z axes", gpos, gword)
    n = round(q.value)
    if abs(q.value - n) > 1e-6 or n < 0:
        raise b.error(f"{gword} Q must be a subroutine number, got {q.value:g}", q.pos,
                      fmt("Q", q.value))
    params = {}
    for letter in _WORDS[family]:
        if letter in words:
            used.add(letter)
            params[letter] = words[letter].value
    if params.get("I", 1.0) <= 0:
        w = words["I"]
        raise b.error("G7X error: I must be greater than zero.", w.pos, fmt("I", w.value))
    if params.get("P", 1.0) < 1:
        w = words["P"]
        raise b.error(f"{gword} P (passes) must be at least 1, got {w.value:g}", w.pos,
                      fmt("P", w.value))
    target = m.target_position(b, axes)
    m.check_limits(b, target, target, gword, gpos)
    out.append(canon.Rapid(tuple(target), b.line, b.file))
    m.pos = target
    m.motion = 0  # LinuxCNC: the cycle's rapid leaves G0 in force (the profile starts in it)
    start = complex(m.program_position(2), m.program_position(0))
    _PENDING[m] = LatheCycle(code, b, gpos, str(n), start, params)
    m.flow_request = ("G7x", float(n), 0, q.pos)


def pending_cycle(m: Modal) -> LatheCycle:
    return _PENDING.pop(m)


class ProfileReader:
    """Collects the profile while its subroutine runs (LinuxCNC's convert_g7x loop)."""

    def __init__(self, m: Modal, cycle: LatheCycle) -> None:
        self.cycle = cycle
        self.at = cycle.start
        self.mode = 0
        self.incremental = m.incremental
        self.arc_incremental = m.arc_incremental
        self.elements: list[Element] = []
        self.saved_pos = m.pos[:]

    def _place(self, m: Modal, p: complex) -> None:
        """The profile point as the current position (#<_x>, #<_z> in the profile)."""
        for letter, k, v in (("X", 0, p.imag), ("Z", 2, p.real)):
            ax = m.letters[letter][0]
            m.pos[ax] = m.lin(v) + m.off[k]

    def line(self, m: Modal, b: Block) -> None:  # noqa: C901 - one profile line
        vals: dict[str, Word] = {}
        mode = None
        for letter, v, pos in b.words:
            x = v if type(v) is float else m.evaluate(b, v, letter)
            if letter == "G":
                code = round(x * 10)
                if code in (0, 10, 20, 30):
                    mode = code
                elif code in (330, 331, 760, 800, 50, 51, 52, 53, 382, 383, 384, 385) \
                        or 730 <= code <= 890 or code in LATHE_CYCLES:
                    raise b.error(f"G{x:g} in the profile of {self.cycle.word} is not "
                                  "supported (only G0, G1, G2 and G3)", pos, fmt("G", x))
            elif letter != "M":
                vals[letter] = Word(x, pos)
        if b.assigns:
            m._assign(b)
        if mode is not None:
            self.mode = mode
        start = self.at
        end = 0j if self.incremental else start
        diam = m.diameter_mode
        for axis, inc, imag in (("X", "U", True), ("Z", "W", False)):
            w, u = vals.get(axis), vals.get(inc)
            if u is not None:
                if self.incremental:
                    raise b.error(f"G7x error: Cannot use {inc} in incremental mode (G91)",
                                  u.pos, fmt(inc, u.value))
                if w is not None:
                    raise b.error(f"G7x error: Cannot use {inc} and {axis} in the same "
                                  "block", u.pos, fmt(inc, u.value))
                d = u.value / 2 if imag and diam else u.value
                end += 1j * d if imag else d
            elif w is not None:
                v = w.value / 2 if imag and diam else w.value
                end = complex(end.real, v) if imag else complex(v, end.imag)
        if self.incremental:
            end += start
        if start == end:
            return
        if self.mode in (0, 10):
            self.elements.append(Line(start, end))
        else:
            self.elements.append(self._arc(b, start, end, vals))
        a, c = vals.get("A"), vals.get("C")
        if a is not None and c is not None:
            raise b.error("G7X error: Both A and C parameters on a corner", c.pos,
                          fmt("C", c.value))
        if a is not None:
            self.elements.append(corner("A", a.value, end))
        if c is not None:
            self.elements.append(corner("C", c.value, end))
        self.at = end
        self._place(m, end)

    def _arc(self, b: Block, start: complex, end: complex, vals: dict[str, Word]) -> Arc:
        ccw = self.mode == 30
        r = vals.get("R")
        i, k = vals.get("I"), vals.get("K")
        if r is not None:
            if i is not None or k is not None:
                raise b.error("G7X error: both R and I or K flag used for arc", r.pos,
                              fmt("R", r.value))
            try:
                centre = radius_centre(start, end, r.value, ccw)
            except ProfileError as exc:
                raise b.error(f"G7X error: {exc}", r.pos, fmt("R", r.value)) from None
        else:
            if i is None and k is None:
                raise b.error("G7X error: either I or K must be present for arc", -1,
                              f"G{self.mode // 10}")
            centre = complex(k.value if k else 0.0, i.value if i else 0.0)
            if self.arc_incremental:
                centre += start
        return Arc(ccw, start, centre, end)

    def finish(self, m: Modal, out: list[canon.Command]) -> None:
        """The profile is read: compute and run the cycle's passes."""
        cyc = self.cycle
        m.pos = self.saved_pos
        if len(self.elements) <= 1:
            return  # LinuxCNC: nothing to cut
        el = self.elements
        el[0].start = cyc.start
        prof = Profile(el)
        p = cyc.params
        emit = _Emitter(m, cyc, out)
        try:
            if cyc.code == 700:
                prof.g70(emit.sink, p.get("D", 0.0), p.get("E", 0.0), p.get("P", 1.0))
            else:
                prof.g71(emit.sink, cyc.code % 10, p.get("D", 0.0), p.get("I", 1.0),
                         p.get("R", 0.5), rotate=cyc.code >= 720)
        except ProfileError as exc:
            raise cyc.block.error(f"G7X error: {exc} (profile O{cyc.label})", cyc.gpos,
                                  cyc.word) from None


class _Emitter:
    """Runs each pass move through Modal.execute as an absolute G0/G1/G2/G3 line."""

    def __init__(self, m: Modal, cyc: LatheCycle, out: list[canon.Command]) -> None:
        self.m, self.cyc, self.out = m, cyc, out
        self.sink = Emit(self.rapid, self.feed, self.arc)
        self.at: complex | None = None

    def _run(self, g: float, end: complex, centre: complex | None = None) -> None:
        m, b, pos = self.m, self.cyc.block, self.cyc.gpos
        x = end.imag * 2 if m.diameter_mode else end.imag
        words: list[tuple[str, float, int]] = [("G", g, pos), ("X", x, pos),
                                                ("Z", end.real, pos)]
        if centre is not None:
            words += [("I", centre.imag, pos), ("K", centre.real, pos)]
        line = Block(b.line, b.text, b.file, words=words)  # type: ignore[arg-type]
        inc, arc_inc = m.incremental, m.arc_incremental
        m.incremental = m.arc_incremental = False
        try:
            m.execute(line, self.out)
        finally:
            m.incremental, m.arc_incremental = inc, arc_inc
        self.at = end

    def rapid(self, end: complex) -> None:
        self._run(0.0, end)

    def feed(self, end: complex) -> None:
        self._run(1.0, end)

    def arc(self, ccw: bool, centre: complex, end: complex) -> None:
        at = self.at
        if at is not None and abs(at.real - end.real) < 1e-4 and abs(at.imag - end.imag) < 1e-4:
            return  # LinuxCNC skips an arc to where it is (it would be a full circle)
        self._run(3.0 if ccw else 2.0, end, centre)
