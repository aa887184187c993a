"""Modal state machine: executes one parsed line (a `Block`) into canonical commands.

The order of execution within a line is RS-274/NGC's (LinuxCNC "G-code order of
execution"): comments/messages, feed mode G93/G94, F, S, T, M6, M3/M4/M5, M7/M8/M9, M48-M53,
M62-M65, M100-M199, G4, plane, units, cutter compensation, tool length, coordinate system,
path control, distance modes, G10/G28/G30/G92, motion (G0-G3, G53, G80), M0/M1/M2/M30.

Positions are held in machine coordinates (machine units). A program coordinate p of axis
letter L maps to machine coordinate  p * scale(L) + work(L) + g92(L) + tool(L)  where scale
converts the program unit (G20/G21) to the machine unit for linear axes (1 for A/B/C),
work is the selected G54..G59.3 origin, g92 the G92 offset and tool the G43 length (Z only).
Offsets live in LinuxCNC's parameters: G54 X..W = #5221..#5229 (+20 per system), G92 =
#5211..#5219, G28 = #5161.., G30 = #5181..; all in machine units. The group-0 commands that
rewrite them (G10, G28/G30, G92) are in coords.py; G2/G3 in arcmove.py. Axis words ->
machine targets and the soft-limit check are in modalcoords.py, the motion-mode dispatch
and feed rates in modalmotion.py (mixins of Modal).
"""

from __future__ import annotations

import math

from . import canon
from .analogout import m67_m68
from .codes import G_GROUP, G_REFUSED, M_GROUP, M_REFUSED
from .coords import offset_command
from .css import FeedMode, g96
from .cuttercomp import CutterComp, comp_off, comp_on
from .cycles import CYCLES, CycleState
from .expr import EvalError, Node
from .latheprofile import LATHE_CYCLES
from .messages import comment_commands
from .modalcoords import COORD_SYSTEMS, ModalCoordinates
from .modalmotion import ModalMotion
from .modalstate import SavedState, state_word
from .named import READ_ONLY, predefined
from .options import AXIS_LETTERS, MM_PER_INCH, GCodeOptions
from .orient import m19
from .overrides import m48_m53
from .params import Parameters
from .parser import Block, Value
from .polar import polar_words
from .probing import m66
from .splines import open_block_error
from .tooloffsets import set_tool_parameters, tool_length
from .usermcodes import m100_m199
from .words import Word, fmt

AXIS_SET = frozenset(AXIS_LETTERS)

#: Motion codes that may stand without axis words (LinuxCNC's enhance_block): G0-G3, the
#: NURBS block G5.2/G5.3 and the lathe cycles G70-G72; any other (G33, G38.x, G76, canned
#: cycles) is refused without one, "All axes missing with motion code".
AXES_OPTIONAL = frozenset({None, 0, 10, 20, 30, 52, 53, *LATHE_CYCLES})


class Modal(ModalCoordinates, ModalMotion):
    """Modal state + positions; `execute(block, out)` appends the line's commands to out.

    Returns False when the line ended the program (M2/M30).
    """

    def __init__(self, options: GCodeOptions, params: Parameters) -> None:
        self.opt = options
        self.params = params
        self.pos: list[float] = list(options.start or ())
        self.machine_mm = options.machine_units == "mm"
        self.units = options.machine_units  # program units, "mm" or "inch"
        # every G20/G21 (or restore) run: (commands output before its block, line, unit)
        self.unit_log: list[tuple[int, int, str]] = []
        self.out_at = 0
        self.lscale = 1.0  # program length unit -> machine unit: v * lscale / ldiv
        self.ldiv = 1.0
        self.incremental = False
        self.arc_incremental = True
        self.plane = 170
        self.inverse_time = False
        self.feed = 0.0  # the F number: program units per minute (G94) or inverse time (G93)
        # G94 feed in machine units per minute, fixed when F is set (LinuxCNC's canon
        # converts F with the units active then); angular feeds are never converted.
        self.feed_lin = 0.0
        self.feed_ang = 0.0
        self.motion: int | None = None  # G80: no motion mode until G0..G3
        self.motion_prev: int | None = None  # the motion mode before this line's G-code
        self.cycle = CycleState()
        self.polar_inc: tuple[float, float] | None = None  # G91 polar cycle increments
        self.comp = CutterComp()
        self.saved_states: dict[int, SavedState] = {}  # call level -> M70/M73 snapshot
        self.blend: tuple[str, float | None, float | None] | None = None  # last G61/G64
        self.coord = 1
        self.tools = dict(options.tool_table)  # type: ignore[arg-type]  # G10 L1 edits
        # with a tool table, a tool not in it is refused (LinuxCNC); without one, every
        # tool is a tool with zero offsets and diameter
        self.has_tool_table = bool(self.tools)
        self.selected_tool = 0
        self.tool = 0
        self.spindle_on = False
        self.spindle_cw = True
        self.speed = 0.0
        self.mist = False
        self.flood = False
        self.feed_override_on = self.speed_override_on = True  # M48-M51 (overrides.py)
        self.feed_hold_on = True  # M53
        self.adaptive_feed_on = False  # M52
        self.ended = False
        #: M98 (call: P number, L count) or M99 for the interpreter, after the line ran:
        #: (kind, P, L, column)
        self.flow_request: tuple[str, float, int, int] | None = None
        #: a G38.x probe or M66 wait on this line: the interpreter stops after the line
        #: until the machine's answer is in (probing.py)
        self.wait_request: object | None = None
        # letter -> (machine axis, parameter offset k)
        self.letters = {L: (options.axes[L], AXIS_LETTERS.index(L)) for L in options.axes}
        self.g92 = [params.numbers[5211 + k] for k in range(9)]
        if any(self.g92):
            params.set_number(5210, 1.0)
        params.set_number(5220, 1.0)
        if 5599 not in options.parameters:
            params.set_number(5599, 1.0)  # (DEBUG,...) output on, as LinuxCNC starts
        self.off = [0.0] * 9
        self.work = [0.0] * 9  # G5x origin per axis letter
        self.rot = 0.0  # rotation of the active system about its origin, degrees
        self.rotated = False
        self.tool_offset = [0.0] * 9  # active G43 offset per axis letter (machine units)
        self.update_offsets()
        params.position_hook = self.program_position
        params.predefined_hook = lambda name: predefined(self, name)
        self.line = 0  # the line being executed (#<_line>)
        self.per_rev = False  # G95
        self.css = False  # G96
        self.retract_old_z = False  # G98 (True) / G99; LinuxCNC's rs274 starts in G99
        self.diameter_mode = False  # G7

    # -- state read by predefined parameters (named.py); coordinates: modalcoords.py --
    def ccomp_code(self) -> int:
        """Active cutter compensation as G-code * 10 (400 = off)."""
        return self.comp.code()

    def feed_program_units(self) -> float:
        """The active feed (#<_feed>): units per minute in the program's units (G94)."""
        if self.inverse_time:
            return self.feed
        return self.feed_lin * self.ldiv / self.lscale

    def pocket_of(self, tool: int) -> int:
        """Pocket of a tool (a tool table without pockets: the tool number, 0 -> -1)."""
        return tool if tool > 0 else -1

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

    # -- one line --------------------------------------------------------------------
    def execute(self, b: Block, out: list[canon.Command]) -> bool:  # noqa: C901
        line, file = b.line, b.file
        self.line = line
        self.out_at = len(out)  # where this block's commands start (unit_log)
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
                if grp == 1 and grp in gs and 800 in (code, gs[1][0]):
                    # LinuxCNC: G80 with another motion code on the line gives way to it
                    if code != 800:
                        gs[1] = (code, pos)
                    continue
                if grp in gs:
                    raise b.error(f"two G-codes of the same modal group on one line "
                                  f"(G{gs[grp][0] / 10:g} and G{x:g})", pos, fmt("G", x))
                gs[grp] = (code, pos)
            elif letter == "M":
                code = round(x)
                if abs(x - code) > 1e-6 or code not in M_GROUP:
                    msg = M_REFUSED.get(code, f"unsupported M-code M{x:g}")
                    raise b.error(msg, pos, fmt("M", x))
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
        if 5 in gs:  # LinuxCNC: G94 and G95 always clear F; G93 needs F on each line
            code = gs[5][0]
            self.inverse_time = code == 930
            if self.per_rev != (code == 950):
                out.append(FeedMode(code == 950, line, file))
            self.per_rev = code == 950
            if code != 930:
                self.feed = self.feed_lin = self.feed_ang = 0.0
        f = words.get("F")
        if f is not None:
            used.add("F")
            if f.value < 0:
                raise b.error(f"feed rate must be >= 0, got {f.value:g}", f.pos,
                              fmt("F", f.value))
            # F comes before G20/G21 in the order of execution: a unit change on the
            # same line does not rescale it (LinuxCNC).
            self.feed = f.value
            self.feed_lin = self.lin(f.value)
            self.feed_ang = f.value
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
        if 14 in gs:  # G96/G97 after S (S is the surface speed of G96)
            g96(self, b, gs[14][0], gs[14][1], words, used, out)
        t = words.get("T")
        if t is not None:
            used.add("T")
            self.selected_tool = self.tool_word(b, "T", t, "T")
        if 6 in ms and ms[6][0] == 61:  # M61 Q: the tool in the spindle, no change
            q = words.get("Q")
            if q is None:
                raise b.error("M61 needs Q (the tool now in the spindle)", ms[6][1], "M61")
            used.add("Q")
            self.tool = self.tool_word(b, "Q", q, "M61")
            self.set_tool_parameters()
        elif 6 in ms:
            if self.comp.side:
                raise b.error("cannot change tools with cutter compensation on (G40 first)",
                              ms[6][1], "M6")
            self.tool = self.selected_tool
            self.set_tool_parameters()
            out.append(canon.ToolChange(self.tool, line, file))
        if 7 in ms and ms[7][0] == 19:
            m19(self, b, ms[7][1], words, used, out)
        elif 7 in ms:
            code = ms[7][0]
            self.spindle_on = code != 5
            if code != 5:
                self.spindle_cw = code == 3
            out.append(canon.Spindle(self.spindle_on, self.spindle_cw, self.speed,
                                     self.opt.spindle_output, line, file))
        if 12 in ms:
            state_word(self, b, ms[12][0], ms[12][1], out)
        if coolant:
            if 9 in coolant:
                self.mist = self.flood = False
            self.mist = self.mist or 7 in coolant
            self.flood = self.flood or 8 in coolant
            out.append(canon.Coolant(self.mist, self.flood, self.opt.mist_output,
                                     self.opt.flood_output, line, file))
        if 9 in ms:
            m48_m53(self, b, ms[9][0], ms[9][1], words, used, out)
        if 5 in ms and ms[5][0] == 66:
            m66(self, b, ms[5][1], words, used, out)
        elif 5 in ms and ms[5][0] in (67, 68):
            m67_m68(self, b, ms[5][0], ms[5][1], words, used, out)
        elif 5 in ms:
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
        if 10 in ms:  # M100-M199: after the overrides and M62-M68, before G4 (LinuxCNC)
            m100_m199(self, b, ms[10][0], ms[10][1], words, used, out)
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
            if self.comp.side and gs[2][0] != self.plane:
                raise b.error("cannot change planes with cutter compensation on", gs[2][1],
                              f"G{gs[2][0] / 10:g}")
            self.plane = gs[2][0]
        if 6 in gs:
            self._set_units("inch" if gs[6][0] == 200 else "mm")
        if 7 in gs:
            if gs[7][0] == 400:
                comp_off(self)
            else:
                comp_on(self, b, gs[7][0], gs[7][1], words, used)
        if 8 in gs:
            tool_length(self, b, gs[8], words, used)
            if gs[8][0] in (431, 432):  # their axis words are offsets, not a move
                for L in [L for L in words if L in AXIS_SET and L in used]:
                    del words[L]
        if 12 in gs:
            self.coord = COORD_SYSTEMS[gs[12][0]]
            self.params.set_number(5220, float(self.coord))
            self.update_offsets()
        if 13 in gs:
            self._path_control(b, gs[13][0], words, used, out)
        if 15 in gs:
            self.diameter_mode = gs[15][0] == 70
        if 10 in gs:
            self.retract_old_z = gs[10][0] == 980
        if 3 in gs:
            self.incremental = gs[3][0] == 910
        if 4 in gs:
            self.arc_incremental = gs[4][0] == 911
        if "@" in words or "^" in words:
            mode = (None if gs[1][0] == 800 else gs[1][0]) if 1 in gs else self.motion
            polar_words(self, b, words, cycle=mode in CYCLES)
        axes = {L: w for L, w in words.items() if L in AXIS_SET}
        if g0 is not None and g0[0] in (100, 520, 280, 281, 300, 301, 920, 921, 922, 923):
            if axes and 1 in gs and gs[1][0] != 800:
                raise b.error("axis words are used by two commands on this line "
                              f"(G{g0[0] / 10:g} and G{gs[1][0] / 10:g})", gs[1][1],
                              f"G{gs[1][0] / 10:g}")
            if self.comp.side and g0[0] in (280, 300):
                raise b.error("G28/G30 cannot be used with cutter compensation on", g0[1],
                              f"G{g0[0] / 10:g}")
            offset_command(self, b, g0, axes, words, used, out)
            used.update(axes)
        elif 1 in gs or axes or (g0 is not None and g0[0] == 530):
            self.motion_prev = self.motion
            if 1 in gs:
                self.motion = None if gs[1][0] == 800 else gs[1][0]
            if self.motion not in CYCLES and (1 in gs or axes):
                self.cycle.initial = None  # a series of cycles ends at any other motion
            if 1 in gs and not axes and self.motion not in AXES_OPTIONAL and not (
                    self.polar_inc is not None and self.motion in CYCLES):
                gword = f"G{gs[1][0] / 10:g}"
                raise b.error(f"all axes missing with motion code {gword} (it needs at least "
                              "one axis word)", gs[1][1], gword)
            if axes or (self.motion in (20, 30) and any(k in words for k in "IJK")) or (
                    (1 in gs or self.polar_inc is not None) and self.motion in CYCLES) or (
                    1 in gs and self.motion in (52, 53)) or self.motion in LATHE_CYCLES:
                self._motion(b, gs, axes, words, used, out, machine=g0 is not None)
                used.update(axes)
        if 11 in ms and ms[11][0] == 98:
            used.update(L for L in "PL" if L in words)
        for letter, w in words.items():
            if letter not in used:
                raise b.error(f"word {letter} is not used by any command on this line",
                              w.pos, fmt(letter, w.value))
        if 4 in ms and 11 in ms:
            raise b.error("M98/M99 cannot share a line with M0/M1/M2/M30", ms[11][1],
                          f"M{ms[11][0]}")
        if 11 in ms:
            self._flow_word(b, ms[11], words)
        if 4 in ms:
            code = ms[4][0]
            if code in (0, 1):
                out.append(canon.Pause(code == 1, line, file))
            else:
                open_block_error(self, b, ms[4][1], f"M{code}")
                comp_off(self)
                out.append(canon.End(code == 30, line, file))
                self.ended = True
                return False
        return True

    # -- pieces ----------------------------------------------------------------------
    def tool_word(self, b: Block, letter: str, w: Word, what: str) -> int:
        """A tool number word (T, M61 Q, G43 H, G10 L1 P): an integer >= 0 that, on a
        machine with a tool table, must be in it (tool 0, no tool, always is)."""
        n = self.int_word(b, letter, w, 0)
        if n and self.has_tool_table and n not in self.tools:
            raise b.error(f"{what}: requested tool {n} is not in the tool table", w.pos,
                          fmt(letter, w.value))
        return n

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
        for target, _value in pending:
            if isinstance(target, str) and target in READ_ONLY:
                raise b.error(f"#<{target.lower()}> is a predefined parameter and cannot be "
                              "assigned", -1, f"#<{target.lower()}>")
            if isinstance(target, str) and target.startswith("_INI["):
                raise b.error(f"#<{target.lower()}> is a read-only INI variable (LinuxCNC's "
                              "INI_VARS; openmotion reads no INI file)", -1,
                              f"#<{target.lower()}>")
        for target, value in pending:
            if isinstance(target, int):
                self.params.set_number(target, value)
            else:
                self.params.set_named(target, value)
        # Offsets are read from parameters: a program may set #5221.. directly.
        self.update_offsets()

    def messages(self, b: Block, out: list[canon.Command]) -> None:
        comment_commands(b, self.params, self.opt.keep_comments, out)

    def _set_units(self, units: str) -> None:
        self.unit_log.append((self.out_at, self.line, units))  # progunits.py
        self.units = units
        self.lscale = self.ldiv = 1.0
        if units != self.opt.machine_units:
            if units == "inch":
                self.lscale = MM_PER_INCH
            else:
                self.ldiv = MM_PER_INCH

    def _path_control(self, b: Block, code: int, words: dict[str, Word], used: set[str],
                      out: list[canon.Command]) -> None:
        if code != 640:
            mode = "exact_path" if code == 610 else "exact_stop"
            out.append(canon.SetBlend(mode, None, b.line, b.file))
            self.blend = (mode, None, None)
            return
        tol = cam = None
        p = words.get("P")
        if p is not None:
            used.add("P")
            if p.value < 0:
                raise b.error(f"G64 P must be >= 0, got {p.value:g}", p.pos, fmt("P", p.value))
            # P0 is plain G64 (best speed), as LinuxCNC reads a zero tolerance
            tol = self.lin(p.value) if p.value > 0 else None
        q = words.get("Q")
        if q is not None:
            used.add("Q")
            if q.value < 0:
                raise b.error(f"G64 Q must be >= 0, got {q.value:g}", q.pos, fmt("Q", q.value))
            cam = self.lin(q.value)
        out.append(canon.SetBlend("blend", tol, b.line, b.file, cam))
        self.blend = ("blend", tol, cam)

    def _flow_word(self, b: Block, m: tuple[int, int], words: dict[str, Word]) -> None:
        code, pos = m
        if code == 99:
            self.flow_request = ("M99", 0.0, 0, pos)
            return
        p = words.get("P")
        if p is None:
            raise b.error("M98 needs P (the program number to call)", pos, "M98")
        count = 1
        lw = words.get("L")
        if lw is not None:
            count = self.int_word(b, "L", lw, 0)
        self.flow_request = ("M98", p.value, count, pos)

    def set_tool_parameters(self) -> None:
        """#5400-#5413 from the tool in the spindle (tooloffsets.py)."""
        set_tool_parameters(self)

    def spindle_record(self, on: bool, b: Block) -> canon.Spindle:
        """A Spindle record in the current direction and speed (cycles stop/restart)."""
        return canon.Spindle(on, self.spindle_cw, self.speed, self.opt.spindle_output,
                             b.line, b.file)
