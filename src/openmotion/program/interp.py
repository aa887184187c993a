"""Interpreter: O-word control flow over parsed blocks -> validated canonical commands.

`compile_text` / `compile_file` parse, check the O-word structure statically (flowtable.py:
every if/while/do/repeat/sub closed with the same label, every call names a defined
subroutine), then run the program line by line through the modal state machine
(modal.py), following sub/call/return, if/elseif/else, while, do-while, repeat, break and
continue as LinuxCNC documents them. Subroutine nesting is limited (`max_call_depth`) and so
is the number of executed lines (`max_blocks`) and of one loop's iterations
(`max_loop_iterations`); a loop whose iteration changes nothing is refused at its third
test (loopguard.py), so a runaway loop is an error within a second, not a hang.

The whole program is interpreted before anything is returned: the first problem raises
GCodeError (line, column, word) and no command list exists, so nothing can move.
"""

from __future__ import annotations

import os
import re
from collections.abc import Generator
from dataclasses import dataclass, field

from . import canon
from .fastpath import compile_plain
from .flowtable import _analyse
from .latheprofile import ProfileReader, pending_cycle
from .loopguard import LoopGuard
from .modal import Modal
from .modalstate import on_return
from .options import GCodeOptions
from .params import Parameters
from .parser import MAX_LINES, Block, Program, parse_program
from .probing import Request, Result, apply_result, preview_result
from .progunits import CompiledProgram, program_units
from .source import GCodeError, decode_program, read_program
from .splines import open_block_error

#: Programs the fast path must leave to the general one: a literal G5.2 or any computed G
#: word (G[..], G#..), which might be a G5.2 whose open block only the general path's
#: end-of-program check finds.
_GENERAL_ONLY = re.compile(r"G\s*0*5\s*\.\s*2|G\s*[\[#]", re.IGNORECASE)


@dataclass
class _Frame:
    """One active subroutine call (`fanuc`: an M98 call, repeated `repeat_left` more times
    from block `start`; `loops`: the loop guard's records)."""

    label: str
    return_to: int
    repeats: dict[int, int] = field(default_factory=dict)
    fanuc: bool = False
    repeat_left: int = 0
    start: int = 0
    loops: dict[int, list] = field(default_factory=dict)  # loop head -> LoopGuard record
    profile: ProfileReader | None = None  # a G7x cycle reading its profile (this call)


class Interpreter:
    """Runs a parsed program; use `run()` once. Most callers want compile_text/file."""

    def __init__(self, program: Program, options: GCodeOptions) -> None:
        if not isinstance(options, GCodeOptions):
            raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
        self.program = program
        self.opt = options
        self.params = Parameters(options.parameters)
        self.modal = Modal(options, self.params)
        self.blocks = list(program.blocks)
        self.main_end = len(self.blocks)  # blocks after this come from subroutine files
        self.search = subroutine_dirs(options, program.file)
        self.flow = _analyse(self.blocks, options.block_delete)
        while self.flow.missing:
            label, i = next(iter(self.flow.missing.items()))
            self._load(label, self.blocks[i])

    def _load(self, label: str, b: Block, at: tuple[int, str] | None = None) -> None:
        """Append subroutine file <label>.ngc (found on the search path) and re-analyse;
        `at`: the caller's (position, word) when it is not an O-word or M98 (G70-G72)."""
        o = b.oword
        pos, word = (o.pos, f"O{label} call") if o is not None else (0, f"M98 P{label}")
        if at is not None:
            pos, word = at
        path = find_subroutine(label, self.search)
        if path is None:
            where = ", ".join(self.search) or "(no search path)"
            raise b.error(f"subroutine O{label} is not defined in this program and no file "
                          f"{sub_file_name(label)} is in {where}", pos, word)
        sub = parse_program(read_program(path, self.opt.max_bytes), path,
                            self.opt.max_line_length)
        own = _analyse(sub.blocks, self.opt.block_delete)
        if label not in own.subs:
            raise b.error(f"{path} does not define O{label} sub ... O{label} endsub", pos,
                          word)
        # code outside the sub (a test harness, M2 ...) is never run, as in LinuxCNC
        self.blocks.extend(sub.blocks)
        self.flow = _analyse(self.blocks, self.opt.block_delete)


    def _truth(self, b: Block) -> bool:
        o = b.oword
        assert o is not None
        return self.modal.evaluate(b, o.args[0], f"O{o.label}") != 0.0

    def run(self) -> list[canon.Command]:
        """Interpret the whole program; probes and input waits get LinuxCNC rs274's
        answers without a machine (probing.preview_result)."""
        steps = self._steps()
        try:
            req = next(steps)
            while True:  # M99 in the main program: one pass, as rs274 (False)
                req = steps.send(False if isinstance(req, canon.End)
                                 else preview_result(self.modal, req))
        except StopIteration as stop:
            return stop.value

    def session(self) -> Session:
        """Interpret step by step, stopping at each probe / input wait until its result
        is given (the runner's live interpretation; see `Session`)."""
        return Session(self)

    def _steps(self) -> Generator[Request | canon.End, Result | bool, list]:  # noqa: C901
        """The interpreter loop: yields every probe / M66 request (after its line ran) and
        continues with the result sent in, and the End(restart=True) of an M99 in the main
        program (True: run it again from the top, False: it ends there); returns the
        command list."""
        blocks = self.blocks
        flow = self.flow
        modal = self.modal
        skip_deleted = self.opt.block_delete
        out: list[canon.Command] = []
        self._out = out
        frames: list[_Frame] = [_Frame("", -1)]
        self._profile: ProfileReader | None = None
        steps = 0
        limit = self.opt.max_blocks
        guard = LoopGuard(modal, self.opt.max_loop_iterations)
        pc = 0
        test_branch = -1  # the ELSEIF whose condition is to be tested next
        called: set[str] = set()  # subroutines called in this pass (an O-sub reached after)
        n = len(blocks)
        while pc < n:
            if pc == self.main_end and len(frames) == 1:
                break  # the main program ran off its end: loaded files are not run
            b = blocks[pc]
            steps += 1
            if steps > limit:
                loops = frames[-1].loops
                where = ""
                if loops:  # the innermost active loop
                    h = blocks[next(reversed(loops))]
                    where = f" in loop O{h.oword.label} at line {h.line}"  # type: ignore
                raise b.error(f"more than {limit} lines executed{where} (max_blocks; "
                              "endless loop?)", 0, f"O{b.oword.label}" if b.oword else "")
            if b.delete and skip_deleted:
                pc += 1
                continue
            o = b.oword
            modal.line = b.line
            if o is None and self._profile is not None:  # a G70-G72 profile line
                self._profile.line(modal, b)
                pc += 1
                continue
            if o is None:
                try:
                    more = modal.execute(b, out)
                    req = modal.wait_request
                    if req is not None:
                        modal.wait_request = None
                        result = yield req
                        apply_result(modal, req, result)
                    if not more:
                        break
                except GCodeError as exc:
                    if len(frames) == 1:
                        raise
                    calls = ", ".join(
                        f"o{f.label.lower()} called at line {blocks[f.return_to - 1].line}"
                        for f in reversed(frames[1:]))
                    raise GCodeError(f"{exc.reason} (in {calls})", exc.line, exc.column,
                                     exc.word, exc.file) from None
                req = modal.flow_request
                if req is None:
                    pc += 1
                    continue
                modal.flow_request = None
                if req[0] == "G7x":
                    pc = self._lathe_call(b, pc, frames)
                    flow = self.flow  # a profile from a file extends the program
                    n = len(blocks)
                    continue
                if req[0] == "M99" and len(frames) == 1:  # the main program's M99
                    again = yield self._main_m99(b, req[3], out)
                    if not again:  # ends as M2 (LinuxCNC's rs274 and preview)
                        modal.ended = True
                        break
                    # LinuxCNC's task: back to the top, every state kept
                    pc = steps = 0
                    test_branch = -1
                    called.clear()
                    frames[0].repeats.clear()
                    frames[0].loops.clear()
                    continue
                pc = self._fanuc(b, pc, req, frames)
                flow = self.flow
                n = len(blocks)
                continue
            if b.comments:
                modal.messages(b, out)
            kw = o.keyword
            if kw == "":  # a Fanuc-style program number: a label, nothing to do
                pc += 1
            elif kw == "SUB":  # reached by falling through: skip the definition
                if o.label in called:  # LinuxCNC found it seeking forward for that call
                    raise b.error(f"O{o.label} sub found in an illegal location: the program "
                                  "runs into the definition of a subroutine it has already "
                                  "called (end the main program with M2 or M30 before its "
                                  "subroutines)", o.pos, f"O{o.label} sub")
                pc = flow.subs[o.label][1] + 1
            elif kw in ("ENDSUB", "RETURN"):
                if frames[-1].fanuc:
                    raise b.error(f"O{frames[-1].label} was called with M98: it must end "
                                  "with M99", o.pos, f"O{o.label} {kw.lower()}")
                if o.args:
                    v = modal.evaluate(b, o.args[0], f"O{o.label}")
                    self.params.set_named("_VALUE", v)
                    self.params.set_named("_VALUE_RETURNED", 1.0)
                frame = frames.pop()
                if len(frames) == 0:  # pragma: no cover - _analyse forbids this
                    raise b.error("return outside a subroutine", o.pos, f"O{o.label}")
                on_return(modal, self.params.depth, b, out)
                self.params.pop_call()
                pc = frame.return_to
                if frame.profile is not None:  # the profile is read: cut it
                    self._profile = None
                    frame.profile.finish(modal, out)
            elif kw == "CALL":
                if len(frames) > self.opt.max_call_depth:
                    raise b.error(f"subroutine calls nested deeper than "
                                  f"{self.opt.max_call_depth}", o.pos, f"O{o.label} call")
                label = o.label
                if o.computed is not None:
                    label = self._label(b, modal.evaluate(b, o.computed, "O[...]"), o.pos)
                    if label not in self.flow.subs:
                        if label in self.flow.fanuc:
                            raise b.error(f"O{label} is a Fanuc-style program: call it "
                                          f"with M98 P{label}", o.pos, f"O{label} call")
                        self._load(label, b)
                        flow = self.flow
                        n = len(blocks)
                args = [modal.evaluate(b, a, f"O{label}") for a in o.args]
                self.params.set_named("_VALUE_RETURNED", 0.0)
                self.params.push_call(args)
                frames.append(_Frame(label, pc + 1))
                called.add(label)
                pc = flow.subs[label][0] + 1
            elif kw == "ELSEIF" and pc != test_branch:  # reached from a taken branch
                pc = flow.endif[pc] + 1
            elif kw in ("IF", "ELSEIF"):
                if self._truth(b):
                    pc += 1
                else:
                    nxt = flow.jump[pc]
                    # the next branch: test an ELSEIF, enter an ELSE, pass an ENDIF
                    if blocks[nxt].oword.keyword == "ELSEIF":  # type: ignore[union-attr]
                        test_branch = pc = nxt
                    else:
                        pc = nxt + 1
            elif kw == "ELSE":  # reached from a taken branch
                pc = flow.endif[pc] + 1
            elif kw == "ENDIF":
                pc += 1
            elif kw == "WHILE" and pc in flow.do_end:
                head = flow.head[pc]
                if self._truth(b):
                    guard.iterate(frames[-1].loops, frames[-1].repeats, head, blocks[head])
                    pc = head + 1
                else:
                    guard.leave(frames[-1].loops, head)
                    pc += 1
            elif kw == "WHILE":
                if self._truth(b):
                    guard.iterate(frames[-1].loops, frames[-1].repeats, pc, b)
                    pc += 1
                else:
                    guard.leave(frames[-1].loops, pc)
                    pc = flow.end[pc] + 1
            elif kw == "ENDWHILE":
                pc = flow.head[pc]
            elif kw == "DO":
                guard.leave(frames[-1].loops, pc)  # a fresh entry into the loop
                pc += 1
            elif kw == "REPEAT":
                reps = frames[-1].repeats
                if pc not in reps:
                    count = modal.evaluate(b, o.args[0], f"O{o.label}")
                    reps[pc] = int(count) if count > 0 else 0
                if reps[pc] > 0:
                    reps[pc] -= 1
                    guard.iterate(frames[-1].loops, reps, pc, b)
                    pc += 1
                else:
                    del reps[pc]
                    guard.leave(frames[-1].loops, pc)
                    pc = flow.end[pc] + 1
            elif kw == "ENDREPEAT":
                pc = flow.head[pc]
            elif kw == "BREAK":
                end = flow.end[pc]
                head = flow.head[end]
                frames[-1].repeats.pop(head, None)
                guard.leave(frames[-1].loops, head)
                pc = end + 1
            elif kw == "CONTINUE":
                head = flow.head[pc]
                # a do-while continues at its closing 'while' test
                pc = flow.end[head] if blocks[head].oword.keyword == "DO" else head  # type: ignore
            else:  # pragma: no cover - parser admits only the keywords above
                raise b.error(f"unknown O-word {kw}", o.pos, f"O{o.label}")
        if blocks and not modal.ended:  # the program's end without M2/M30
            open_block_error(modal, blocks[min(pc, n) - 1], 0, "the end of the program")
        return out


    def _lathe_call(self, b: Block, pc: int, frames: list[_Frame]) -> int:
        """G70-G72: call the profile subroutine, its lines read by a ProfileReader."""
        cycle = pending_cycle(self.modal)
        label = cycle.label
        if label not in self.flow.subs:
            if label in self.flow.fanuc:
                raise b.error(f"{cycle.word} Q{label}: O{label} is a Fanuc-style program "
                              f"(M99); the profile must be O{label} sub ... endsub",
                              cycle.gpos, cycle.word)
            self._load(label, b, (cycle.gpos, f"{cycle.word} Q{label}"))
        if len(frames) > self.opt.max_call_depth:
            raise b.error(f"subroutine calls nested deeper than {self.opt.max_call_depth}",
                          cycle.gpos, cycle.word)
        reader = ProfileReader(self.modal, cycle)
        self.params.set_named("_VALUE_RETURNED", 0.0)
        self.params.push_call([])
        frames.append(_Frame(label, pc + 1, profile=reader))
        self._profile = reader
        return self.flow.subs[label][0] + 1

    def _main_m99(self, b: Block, pos: int, out: list[canon.Command]) -> canon.End:
        """M99 in the main program: the `End(restart=True)` record, appended and returned
        as the request (the answer: True = start again from the top)."""
        m = self.modal
        if m.comp.side:  # LinuxCNC would carry a half-finished compensated path over
            raise b.error("M99 in the main program with cutter compensation on: turn it "
                          "off (G40) before the program restarts", pos, "M99")
        open_block_error(m, b, pos, "M99")
        end = canon.End(False, b.line, b.file, restart=True)
        out.append(end)
        return end

    @staticmethod
    def _label(b: Block, v: float, pos: int) -> str:
        n = round(v)
        if abs(v - n) > 1e-6 or n < 0:
            raise b.error(f"an O-word number must be an integer >= 0, got {v:g}", pos,
                          f"O{v:g}")
        return str(int(n))

    def _fanuc(self, b: Block, pc: int, req: tuple[str, float, int, int],
               frames: list[_Frame]) -> int:
        """M98 P.. L.. (call a Fanuc-style program) or M99 (return); the next pc."""
        kind, p, count, pos = req
        if kind == "M99":
            top = frames[-1]
            if not top.fanuc:
                raise b.error(f"O{top.label} sub must end with O{top.label} endsub or "
                              "return, not M99", pos, "M99")
            if top.repeat_left > 0:
                top.repeat_left -= 1
                top.repeats.clear()
                top.loops.clear()
                return top.start
            frames.pop()
            on_return(self.modal, self.params.depth, b, self._out)
            self.params.pop_call(keep_numbered=True)
            return top.return_to
        label = self._label(b, p, pos)
        word = f"M98 P{label}"
        if label not in self.flow.fanuc:
            if label in self.flow.subs:
                raise b.error(f"O{label} sub must be called with O{label} call, not M98",
                              pos, word)
            raise b.error(f"M98: program O{label} is not defined in this program", pos,
                          word)
        if count == 0:
            return pc + 1
        if len(frames) > self.opt.max_call_depth:
            raise b.error(f"subroutine calls nested deeper than {self.opt.max_call_depth}",
                          pos, word)
        start = self.flow.fanuc[label] + 1
        self.params.push_call(None)
        frames.append(_Frame(label, pc + 1, fanuc=True, repeat_left=count - 1,
                             start=start))
        return start


class Session:
    """A program interpreted piece by piece against a machine.

        s = Interpreter(program, options).session()
        cmds = s.advance()            # commands up to and including the first request
        while s.request is not None:  # a probing.Probe or probing.WaitInput, or the
            ... run cmds, then the request, on the machine ...   # End(restart=True)
            cmds = s.advance(result)  # ProbeResult / InputResult / bool -> the next piece

    Each piece ends with its request (or the program's end, `done`). An error in the
    rest of the program raises GCodeError from `advance` (the machine has not run it).
    An M99 in the main program ends its piece with `canon.End(restart=True)`: advance(True)
    runs the program again from its top with every state kept (parameters, modal state,
    offsets, as LinuxCNC's task does), advance(False) ends it there.
    """

    def __init__(self, interp: Interpreter) -> None:
        self._interp = interp
        self._steps = interp._steps()
        self._taken = 0
        self._started = False
        self.request: Request | canon.End | None = None
        self.done = False

    def advance(self, result: Result | bool | None = None) -> list[canon.Command]:
        """Run to the next request (the first call: from the start); the new commands."""
        if self.done:
            raise GCodeError("the program has ended: nothing to advance")
        restart = isinstance(self.request, canon.End)
        if self._started and result is None and not restart:
            raise GCodeError("advance needs the result of the pending request "
                             f"({type(self.request).__name__})")
        if self._started and restart != isinstance(result, bool):
            want = "True or False (run it again?)" if restart else "a request's result"
            raise GCodeError(f"advance: the pending {type(self.request).__name__} needs "
                             f"{want}, got {result!r}")
        try:
            if self._started:
                self.request = self._steps.send(result)  # type: ignore[arg-type]
            else:
                self._started = True
                self.request = next(self._steps)
        except StopIteration:
            self.request = None
            self.done = True
        except GCodeError:
            self.request = None
            self.done = True
            raise
        out = self._interp._out
        chunk = out[self._taken:]
        self._taken = len(out)
        if isinstance(self.request, canon.End):  # a pass is over: forget its commands
            out.clear()  # (no compensated move is pending at an M99: memory stays flat)
            self._interp.modal.unit_log.clear()  # (its positions are in the pass's commands)
            self._taken = 0
        return chunk


def sub_file_name(label: str) -> str:
    """The file a subroutine is searched in: its name in lower case + '.ngc'."""
    return label.strip("<>").lower() + ".ngc"


def subroutine_dirs(options: GCodeOptions, program_file: str) -> list[str]:
    """Where external subroutines are searched: options.subroutine_path, then the
    program's own folder (LinuxCNC: SUBROUTINE_PATH, then the program's directory)."""
    dirs = [os.fspath(d) for d in options.subroutine_path]
    if program_file:
        here = os.path.dirname(os.path.abspath(program_file))
        if here not in dirs:
            dirs.append(here)
    return dirs


def find_subroutine(label: str, dirs: list[str]) -> str | None:
    """Path of <label>.ngc in the first folder holding it (case-insensitive name)."""
    want = sub_file_name(label)
    for d in dirs:
        try:
            names = os.listdir(d)
        except OSError:
            continue
        for name in names:
            if name.lower() == want and os.path.isfile(os.path.join(d, name)):
                return os.path.join(d, name)
    return None


def interpret(program: Program, options: GCodeOptions) -> list[canon.Command]:
    """Run a parsed program; the command list, or GCodeError for the first problem."""
    return Interpreter(program, options).run()


def compile_text(text: str, options: GCodeOptions, file: str = "") -> list[canon.Command]:
    """Parse and interpret G-code text into canonical commands (machine coordinates); a
    `CompiledProgram` list, whose `units` are the program's G20/G21 unit (progunits.py)."""
    if not isinstance(options, GCodeOptions):
        raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
    if isinstance(text, bytes):
        text = decode_program(text, file, options.max_bytes)
    if not isinstance(text, str):
        raise GCodeError(f"program text must be str, got {type(text).__name__}", file=file)
    if len(text) > options.max_bytes:
        raise GCodeError(f"program is {len(text)} characters, more than the limit of "
                         f"{options.max_bytes}", file=file)
    lines = text.splitlines()
    # a G5.2 block must be closed: only the general path checks the program's end
    if len(lines) <= MAX_LINES and not _GENERAL_ONLY.search(text):  # fastpath.py
        out = compile_plain(lines, options, file, lambda: _compile_full(text, options, file))
    else:
        out = _compile_full(text, options, file)
    if options.require_end and not (out and isinstance(out[-1], canon.End)) and not (
            percent_closed(lines)):
        raise GCodeError("the file ended with no percent sign or program end (M2 or M30): "
                         "is it complete?", len(lines), 0, "", file)
    return out


def percent_closed(lines: list[str]) -> bool:
    """True when the program opens with a '%' line and a second '%' line closes it."""
    marks = [k for k, ln in enumerate(lines) if ln.strip() == "%"][:2]
    return len(marks) == 2 and not any(ln.strip() for ln in lines[:marks[0]])


def _compile_full(text: str, options: GCodeOptions, file: str) -> list[canon.Command]:
    """The general path: parse the whole program, then interpret it."""
    program = parse_program(text, file, options.max_line_length)
    interp = Interpreter(program, options)
    out = interp.run()
    return CompiledProgram(out, program_units(out, interp.modal.unit_log,
                                              options.machine_units))


def compile_file(path: str | os.PathLike[str], options: GCodeOptions) -> list[canon.Command]:
    """Read (text check, size limit), parse and interpret a G-code file."""
    if not isinstance(options, GCodeOptions):
        raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
    text = read_program(path, options.max_bytes)
    return compile_text(text, options, os.fspath(path))
