"""Modal state machine: executes one parsed line (a `Block`) into canonical commands.

The order of execution within a line is RS-274/NGC's (LinuxCNC "G-code order of
execution"): comments/messages, feed mode G93/G94, F, S, T, M6, M3/M4/M5, M7/M8/M9, M62-M65,
G4, plane, units, cutter compensation, tool length, coordinate system, path control,
distance modes, G10/G28/G30/G92, motion (G0-G3, G53, G80), M0/M1/M2/M30.

Positions are held in machine coordinates (machine units). A program coordinate p of axis
letter L maps to machine coordinate  p * scale(L) + work(L) + g92(L) + tool(L)  where scale
converts the program unit (G20/G21) to the machine unit for linear axes (1 for A/B/C),
work is the selected G54..G59.3 origin, g92 the G92 offset and tool the G43 length (Z only).
Offsets live in LinuxCNC's parameters: G54 X..W = #5221..#5229 (+20 per system), G92 =
#5211..#5219, G28 = #5161.., G30 = #5181..; all in machine units. The group-0 commands that
rewrite them (G10, G28/G30, G92) are in coords.py; G2/G3 in arcmove.py.
"""

from __future__ import annotations

import math
import re

from . import canon
from .arcmove import arc_move
from .coords import offset_command
from .expr import EvalError, Node
from .options import AXIS_LETTERS, MM_PER_INCH, ROTARY_LETTERS, GCodeOptions
from .params import Parameters
from .parser import Block, Value
from .words import Word, feed_length, fmt

# G codes are held as int(round(10 * value)): G1 -> 10, G90.1 -> 901.
G_GROUP = {
    40: 0, 100: 0, 280: 0, 281: 0, 300: 0, 301: 0, 530: 0, 920: 0, 921: 0, 922: 0, 923: 0,
    0: 1, 10: 1, 20: 1, 30: 1, 800: 1,
    170: 2, 180: 2, 190: 2,
    900: 3, 910: 3,
    901: 4, 911: 4,
    930: 5, 940: 5,
    200: 6, 210: 6,
    400: 7,
    430: 8, 490: 8,
    540: 12, 550: 12, 560: 12, 570: 12, 580: 12, 590: 12, 591: 12, 592: 12, 593: 12,
    610: 13, 611: 13, 640: 13,
}
#: Why some well-known codes are refused (others get a generic "unsupported").
G_REFUSED = {
    410: "cutter radius compensation (G41) is not supported",
    420: "cutter radius compensation (G42) is not supported",
    330: "spindle-synchronized motion (G33) is not supported",
    382: "probing (G38.x) is not supported",
    950: "feed per revolution (G95) is not supported",
    810: "canned cycles (G81) are not supported",
}
M_GROUP = {0: 4, 1: 4, 2: 4, 30: 4, 6: 6, 3: 7, 4: 7, 5: 7, 7: 8, 8: 8, 9: 8,
           62: 5, 63: 5, 64: 5, 65: 5}
COORD_SYSTEMS = {540: 1, 550: 2, 560: 3, 570: 4, 580: 5, 590: 6, 591: 7, 592: 8, 593: 9}
AXIS_SET = frozenset(AXIS_LETTERS)
_DEBUG_PARAM = re.compile(r"#<([^>]*)>|#(\d+)")


class Modal:
    """Modal state + positions; `execute(block, out)` appends the line's commands to out.

    Returns False when the line ended the program (M2/M30).
    """

    def __init__(self, options: GCodeOptions, params: Parameters) -> None:
        self.opt = options
        self.params = params
        self.pos: list[float] = list(options.start or ())
        self.machine_mm = options.machine_units == "mm"
        self.units = options.machine_units  # program units, "mm" or "inch"
        self.lscale = 1.0  # program length unit -> machine unit: v * lscale / ldiv
        self.ldiv = 1.0
        self.incremental = False
        self.arc_incremental = True
        self.plane = 170
        self.inverse_time = False
        self.feed = 0.0  # the F number: program units per minute (G94) or inverse time (G93)
        self.motion: int | None = None  # G80: no motion mode until G0..G3
        self.coord = 1
        self.tool_z = 0.0
        self.selected_tool = 0
        self.tool = 0
        self.spindle_on = False
        self.spindle_cw = True
        self.speed = 0.0
        self.mist = False
        self.flood = False
        self.ended = False
        # letter -> (machine axis, parameter offset k)
        self.letters = {L: (options.axes[L], AXIS_LETTERS.index(L)) for L in options.axes}
        self.g92 = [params.numbers[5211 + k] for k in range(9)]
        if any(self.g92):
            params.set_number(5210, 1.0)
        params.set_number(5220, 1.0)
        self.off = [0.0] * 9
        self.update_offsets()
        params.position_hook = self.program_position

    # -- coordinates -----------------------------------------------------------------
    def update_offsets(self) -> None:
        base = 5221 + 20 * (self.coord - 1)
        nums = self.params.numbers
        for k in range(9):
            self.off[k] = nums[base + k] + self.g92[k]
        self.off[2] += self.tool_z

    def lin(self, v: float) -> float:
        """A program length in machine units (exact when the units agree or 1 in = 25.4 mm)."""
        return v * self.lscale / self.ldiv

    def conv(self, v: float, letter: str) -> float:
        """Program value of axis `letter` in machine units (rotary axes are degrees)."""
        return v if letter in ROTARY_LETTERS else v * self.lscale / self.ldiv

    def program_position(self, k: int) -> float:
        """Current position of axis letter number k (X=0..W=8) in program coordinates."""
        letter = AXIS_LETTERS[k]
        info = self.letters.get(letter)
        if info is None:
            return 0.0
        d = self.pos[info[0]] - self.off[k]
        return d if letter in ROTARY_LETTERS else d * self.ldiv / self.lscale

    def axis_index(self, b: Block, letter: str, w: Word) -> int:
        info = self.letters.get(letter)
        if info is None:
            raise b.error(f"axis letter {letter} has no machine axis (axes: "
                          f"{', '.join(sorted(self.letters))})", w.pos, fmt(letter, w.value))
        return info[0]

    def target_position(self, b: Block, axes: dict[str, Word], machine: bool = False,
                incremental: bool | None = None) -> list[float]:
        inc = self.incremental if incremental is None else incremental
        target = self.pos[:]
        for letter, w in axes.items():
            ax = self.axis_index(b, letter, w)
            v = self.conv(w.value, letter)
            if machine:
                target[ax] = v
            elif inc:
                target[ax] = self.pos[ax] + v
            else:
                target[ax] = v + self.off[self.letters[letter][1]]
        return target

    def check_limits(self, b: Block, lo: list[float], hi: list[float], word: str,
                      pos: int) -> None:
        limits = self.opt.soft_limits
        if limits is None:
            return
        for ax, lim in enumerate(limits):
            if lim is None:
                continue
            if lo[ax] < lim[0] - 1e-9 * max(1.0, abs(lim[0])):
                raise b.error(f"move beyond soft limit: {self._limit_axis(ax)} would reach "
                              f"machine {lo[ax]:.6g} < min {lim[0]:g}"
                              f"{self._offset_note(ax)}", pos, word)
            if hi[ax] > lim[1] + 1e-9 * max(1.0, abs(lim[1])):
                raise b.error(f"move beyond soft limit: {self._limit_axis(ax)} would reach "
                              f"machine {hi[ax]:.6g} > max {lim[1]:g}"
                              f"{self._offset_note(ax)}", pos, word)

    def _limit_axis(self, ax: int) -> str:
        """The program's letter for machine axis `ax` (soft-limit messages)."""
        names = [L for L, (a, _) in self.letters.items() if a == ax]
        return names[0] if names else f"machine axis {ax}"

    def _offset_note(self, ax: int) -> str:
        """' (active offset G55 X-60, G92 X5)': where the program origin of axis `ax` is."""
        names = [(L, k) for L, (a, k) in self.letters.items() if a == ax]
        if not names:
            return ""
        letter, k = names[0]
        system = {v: f"G{c // 10}" + (f".{c % 10}" if c % 10 else "")
                  for c, v in COORD_SYSTEMS.items()}[self.coord]
        work = self.params.numbers[5221 + 20 * (self.coord - 1) + k]
        note = f" (active offset {system} {letter}{work:g}"
        if self.g92[k]:
            note += f", G92 {letter}{self.g92[k]:g}"
        return note + ")"

    # -- evaluation ------------------------------------------------------------------
    def evaluate(self, b: Block, v: Value, word: str = "") -> float:
        if type(v) is float:
            return v
        assert isinstance(v, Node)
        try:
            x = v.ev(self.params)
        except EvalError as exc:
            raise b.error(exc.message, exc.pos, exc.word or word) from None
        if not math.isfinite(x):
            raise b.error(f"value is not finite ({x})", v.pos, word)
        return x

    def debug_text(self, text: str) -> str:
        """(DEBUG,...) text with #n and #<name> replaced by their values."""

        def sub(m: re.Match[str]) -> str:
            if m.group(1) is not None:
                name = "".join(m.group(1).split()).upper()
                table = self.params.globals if name.startswith("_") else \
                    self.params.locals[-1]
                return f"{table[name]:.6f}" if name in table else "######"
            n = int(m.group(2))
            if 1 <= n < len(self.params.numbers):
                return f"{self.params.get_number(n, 0):.6f}"
            return "######"

        return _DEBUG_PARAM.sub(sub, text)

    # -- one line --------------------------------------------------------------------
    def execute(self, b: Block, out: list[canon.Command]) -> bool:  # noqa: C901
        line, file = b.line, b.file
        gs: dict[int, tuple[int, int]] = {}  # group -> (code, pos)
        ms: dict[int, tuple[int, int]] = {}
        words: dict[str, Word] = {}
        coolant: set[int] = set()
        for letter, v, pos in b.words:
            x = v if type(v) is float else self.evaluate(b, v, letter)
            if letter == "G":
                code = round(x * 10)
                if abs(x * 10 - code) > 1e-6 or code not in G_GROUP:
                    msg = G_REFUSED.get(code, f"unsupported G-code G{x:g}")
                    raise b.error(msg, pos, fmt("G", x))
                grp = G_GROUP[code]
                if grp in gs:
                    raise b.error(f"two G-codes of the same modal group on one line "
                                  f"(G{gs[grp][0] / 10:g} and G{x:g})", pos, fmt("G", x))
                gs[grp] = (code, pos)
            elif letter == "M":
                code = round(x)
                if abs(x - code) > 1e-6 or code not in M_GROUP:
                    raise b.error(f"unsupported M-code M{x:g}", pos, fmt("M", x))
                grp = M_GROUP[code]
                if grp == 8 and code != 9 and grp in ms and ms[grp][0] != 9:
                    coolant.add(code)  # M7 and M8 may share a line
                    continue
                if grp in ms:
                    raise b.error(f"two M-codes of the same modal group on one line "
                                  f"(M{ms[grp][0]} and M{code})", pos, fmt("M", x))
                ms[grp] = (code, pos)
                if grp == 8:
                    coolant.add(code)
            else:
                if letter in words:
                    raise b.error(f"word {letter} appears twice on one line", pos,
                                  fmt(letter, x))
                words[letter] = Word(x, pos)
        if b.assigns:
            self._assign(b)
        used: set[str] = set()
        if b.comments:
            self.messages(b, out)
        # feed mode, F, S, T
        if 5 in gs:
            inv = gs[5][0] == 930
            if inv != self.inverse_time:
                self.inverse_time = inv
                self.feed = 0.0
        f = words.get("F")
        if f is not None:
            used.add("F")
            if f.value < 0:
                raise b.error(f"feed rate must be >= 0, got {f.value:g}", f.pos,
                              fmt("F", f.value))
            self.feed = f.value  # program units per minute: converted when used
        s = words.get("S")
        if s is not None:
            used.add("S")
            if s.value < 0:
                raise b.error(f"spindle speed must be >= 0, got {s.value:g}", s.pos,
                              fmt("S", s.value))
            self.speed = s.value
            if self.spindle_on and 7 not in ms:
                out.append(canon.Spindle(True, self.spindle_cw, self.speed,
                                         self.opt.spindle_output, line, file))
        t = words.get("T")
        if t is not None:
            used.add("T")
            self.selected_tool = self.int_word(b, "T", t, 0)
        if 6 in ms:
            self.tool = self.selected_tool
            out.append(canon.ToolChange(self.tool, line, file))
        if 7 in ms:
            code = ms[7][0]
            self.spindle_on = code != 5
            if code != 5:
                self.spindle_cw = code == 3
            out.append(canon.Spindle(self.spindle_on, self.spindle_cw, self.speed,
                                     self.opt.spindle_output, line, file))
        if coolant:
            if 9 in coolant:
                self.mist = self.flood = False
            self.mist = self.mist or 7 in coolant
            self.flood = self.flood or 8 in coolant
            out.append(canon.Coolant(self.mist, self.flood, self.opt.mist_output,
                                     self.opt.flood_output, line, file))
        if 5 in ms:
            code, pos = ms[5]
            p = words.get("P")
            if p is None:
                raise b.error(f"M{code} needs P (the output number)", pos, f"M{code}")
            used.add("P")
            idx = self.int_word(b, "P", p, 0)
            if idx >= self.opt.n_outputs:
                raise b.error(f"output number must be < {self.opt.n_outputs}, got {idx}",
                              p.pos, fmt("P", p.value))
            out.append(canon.SetOutput(idx, code in (62, 64), code in (62, 63), line, file))
        g0 = gs.get(0)
        if g0 is not None and g0[0] == 40:
            p = words.get("P")
            if p is None:
                raise b.error("G4 needs P (dwell time in seconds)", g0[1], "G4")
            used.add("P")
            if p.value < 0:
                raise b.error(f"dwell time must be >= 0, got {p.value:g}", p.pos,
                              fmt("P", p.value))
            out.append(canon.Dwell(p.value, line, file))
        if 2 in gs:
            self.plane = gs[2][0]
        if 6 in gs:
            self._set_units("inch" if gs[6][0] == 200 else "mm")
        if 8 in gs:
            self._tool_length(b, gs[8], words, used)
        if 12 in gs:
            self.coord = COORD_SYSTEMS[gs[12][0]]
            self.params.set_number(5220, float(self.coord))
            self.update_offsets()
        if 13 in gs:
            self._path_control(b, gs[13][0], words, used, out)
        if 3 in gs:
            self.incremental = gs[3][0] == 910
        if 4 in gs:
            self.arc_incremental = gs[4][0] == 911
        axes = {L: w for L, w in words.items() if L in AXIS_SET}
        if g0 is not None and g0[0] in (100, 280, 281, 300, 301, 920, 921, 922, 923):
            if axes and 1 in gs and gs[1][0] != 800:
                raise b.error("axis words are used by two commands on this line "
                              f"(G{g0[0] / 10:g} and G{gs[1][0] / 10:g})", gs[1][1],
                              f"G{gs[1][0] / 10:g}")
            offset_command(self, b, g0, axes, words, used, out)
            used.update(axes)
        elif 1 in gs or axes or (g0 is not None and g0[0] == 530):
            if 1 in gs:
                self.motion = None if gs[1][0] == 800 else gs[1][0]
            if axes or (self.motion in (20, 30) and any(k in words for k in "IJK")):
                self._motion(b, gs, axes, words, used, out, machine=g0 is not None)
                used.update(axes)
        for letter, w in words.items():
            if letter not in used:
                raise b.error(f"word {letter} is not used by any command on this line",
                              w.pos, fmt(letter, w.value))
        if 4 in ms:
            code = ms[4][0]
            if code in (0, 1):
                out.append(canon.Pause(code == 1, line, file))
            else:
                out.append(canon.End(code == 30, line, file))
                self.ended = True
                return False
        return True

    # -- pieces ----------------------------------------------------------------------
    def int_word(self, b: Block, letter: str, w: Word, lo: int) -> int:
        n = round(w.value)
        if abs(w.value - n) > 1e-4 or n < lo:
            raise b.error(f"{letter} must be an integer >= {lo}, got {w.value:g}", w.pos,
                          fmt(letter, w.value))
        return int(n)

    def _assign(self, b: Block) -> None:
        # All values on the line are read before any parameter is set (RS-274/NGC).
        pending = []
        for target, v, pos in b.assigns:
            value = self.evaluate(b, v, "#")
            if isinstance(target, Node):
                idx = self.evaluate(b, target, "#")
                n = round(idx)
                if abs(idx - n) > 1e-4 or not 1 <= n < len(self.params.numbers):
                    raise b.error(f"parameter number must be an integer in [1, "
                                  f"{len(self.params.numbers) - 1}], got {idx:g}", pos,
                                  f"#{idx:g}")
                target = int(n)
            pending.append((target, value))
        for target, value in pending:
            if isinstance(target, int):
                self.params.set_number(target, value)
            else:
                self.params.set_named(target, value)
        # Offsets are read from parameters: a program may set #5221.. directly.
        self.update_offsets()

    def messages(self, b: Block, out: list[canon.Command]) -> None:
        for _col, text in b.comments:
            body = text.lstrip()
            head = body[:6].upper()
            if head.startswith("MSG,"):
                out.append(canon.Message(body[4:].strip(), "msg", b.line, b.file))
            elif head.startswith("DEBUG,"):
                out.append(canon.Message(self.debug_text(body[6:].strip()), "debug", b.line,
                                         b.file))
            elif head.startswith("PRINT,"):
                out.append(canon.Message(self.debug_text(body[6:].strip()), "print", b.line,
                                         b.file))
            elif self.opt.keep_comments:
                out.append(canon.Message(text, "comment", b.line, b.file))

    def _set_units(self, units: str) -> None:
        self.units = units
        self.lscale = self.ldiv = 1.0
        if units != self.opt.machine_units:
            if units == "inch":
                self.lscale = MM_PER_INCH
            else:
                self.ldiv = MM_PER_INCH

    def _tool_length(self, b: Block, g: tuple[int, int], words: dict[str, Word],
                     used: set[str]) -> None:
        if g[0] == 490:
            self.tool_z = 0.0
        else:
            h = words.get("H")
            tool = self.tool
            if h is not None:
                used.add("H")
                tool = self.int_word(b, "H", h, 0)
            self.tool_z = float(self.opt.tool_lengths.get(tool, 0.0))
        self.update_offsets()

    def _path_control(self, b: Block, code: int, words: dict[str, Word], used: set[str],
                      out: list[canon.Command]) -> None:
        if code != 640:
            mode = "exact_path" if code == 610 else "exact_stop"
            out.append(canon.SetBlend(mode, None, b.line, b.file))
            return
        tol = cam = None
        p = words.get("P")
        if p is not None:
            used.add("P")
            if p.value < 0:
                raise b.error(f"G64 P must be >= 0, got {p.value:g}", p.pos, fmt("P", p.value))
            tol = self.lin(p.value)
        q = words.get("Q")
        if q is not None:
            used.add("Q")
            if q.value < 0:
                raise b.error(f"G64 Q must be >= 0, got {q.value:g}", q.pos, fmt("Q", q.value))
            cam = self.lin(q.value)
        out.append(canon.SetBlend("blend", tol, b.line, b.file, cam))

    def feed_rate(self, b: Block, words: dict[str, Word], gword: str, gpos: int
                   ) -> tuple[float, float | None]:
        """(feed_per_s, duration) for a feed move; errors when F is missing."""
        if self.inverse_time:
            f = words.get("F")
            if f is None or f.value <= 0:
                raise b.error("inverse time feed (G93) needs F > 0 on every G1/G2/G3 line",
                              gpos, gword)
            return 0.0, 60.0 / f.value
        if self.feed <= 0.0:
            raise b.error("feed rate is zero or not set: give F before or with "
                          f"{gword}", gpos, gword)
        return self.lin(self.feed) / 60.0, None

    def _motion(self, b: Block, gs: dict[int, tuple[int, int]], axes: dict[str, Word],
                words: dict[str, Word], used: set[str], out: list[canon.Command],
                machine: bool) -> None:
        mode = self.motion
        gpos = gs[1][1] if 1 in gs else (axes[next(iter(axes))].pos if axes else 0)
        if mode is None:
            if 1 in gs:
                raise b.error("axis words cannot be used with G80", gs[1][1], "G80")
            w = next(iter(axes.values()))
            raise b.error("axis words without a motion mode (G0, G1, G2 or G3)", w.pos,
                          fmt(next(iter(axes)), w.value))
        gword = f"G{mode // 10}"
        if machine:
            if mode not in (0, 10):
                raise b.error("G53 needs G0 or G1", gs[0][1], "G53")
            if self.incremental:
                raise b.error("G53 cannot be used in incremental mode (G91)", gs[0][1], "G53")
        target = self.target_position(b, axes, machine=machine)
        if mode == 0:
            self.check_limits(b, target, target, gword, gpos)
            out.append(canon.Rapid(tuple(target), b.line, b.file))
        elif mode == 10:
            feed, duration = self.feed_rate(b, words, gword, gpos)
            if duration is not None:
                feed = feed_length(self.pos, target, self.letters) / duration
            self.check_limits(b, target, target, gword, gpos)
            out.append(canon.Feed(tuple(target), feed, b.line, b.file, duration))
        else:
            out.append(arc_move(self, b, mode, gpos, target, words, used))
        self.pos = target
