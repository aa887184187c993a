"""Interpreter: O-word control flow over parsed blocks -> validated canonical commands.

`compile_text` / `compile_file` parse, check the O-word structure statically (every
if/while/do/repeat/sub closed with the same label, every call names a defined
subroutine), then run the program line by line through the modal state machine
(modal.py), following sub/call/return, if/elseif/else, while, do-while, repeat, break and
continue as LinuxCNC documents them. Subroutine nesting is limited (`max_call_depth`) and so
is the number of executed lines (`max_blocks`), so a runaway loop is an error, not a hang.

The whole program is interpreted before anything is returned: the first problem raises
GCodeError (line, column, word) and no command list exists, so nothing can move.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

from . import canon
from .modal import Modal
from .options import GCodeOptions
from .params import Parameters
from .parser import Block, Program, parse_program
from .source import GCodeError, decode_program, read_program

_OPENERS = {"SUB": "ENDSUB", "IF": "ENDIF", "WHILE": "ENDWHILE", "DO": "WHILE",
            "REPEAT": "ENDREPEAT"}
_LOOPS = ("WHILE", "DO", "REPEAT")


@dataclass
class _Flow:
    """Static jump table of one program (indices into the block list)."""

    subs: dict[str, tuple[int, int]] = field(default_factory=dict)  # label -> (sub, endsub)
    jump: dict[int, int] = field(default_factory=dict)  # see _analyse for meanings
    head: dict[int, int] = field(default_factory=dict)  # loop end/break/continue -> head
    end: dict[int, int] = field(default_factory=dict)  # loop head/break -> loop end
    endif: dict[int, int] = field(default_factory=dict)  # if/elseif/else -> endif
    do_end: set[int] = field(default_factory=set)  # 'WHILE' lines that close a DO


def _analyse(blocks: list[Block], block_delete: bool) -> _Flow:
    """Match O-word structures; jump[i] of an if-branch line is the next branch line."""
    flow = _Flow()
    stack: list[tuple[str, str, int, list[int]]] = []  # (label, keyword, index, branches)
    for i, b in enumerate(blocks):
        o = b.oword
        if o is None or (b.delete and block_delete):
            continue
        kw, label = o.keyword, o.label
        word = f"O{label} {kw.lower()}"

        def err(msg: str, b: Block = b, word: str = word, pos: int = o.pos) -> GCodeError:
            return b.error(msg, pos, word)

        top = stack[-1] if stack else None
        if kw == "WHILE" and top is not None and top[1] == "DO" and top[0] == label:
            stack.pop()
            flow.do_end.add(i)
            flow.head[i] = top[2]
            flow.end[top[2]] = i
            for j in top[3]:
                _bind(flow, blocks, j, top[2], i)
            continue
        if kw in _OPENERS:
            if kw == "SUB":
                if stack:
                    raise err("a subroutine cannot be defined inside another block "
                              f"(O{stack[-1][0]} {stack[-1][1].lower()} is open)")
                if label in flow.subs:
                    raise err(f"subroutine O{label} is defined twice")
            stack.append((label, kw, i, []))
            continue
        if kw in ("ELSEIF", "ELSE", "ENDIF"):
            if top is None or top[1] != "IF" or top[0] != label:
                raise err(f"{kw.lower()} without a matching O{label} if")
            branches = top[3]
            prev = branches[-1] if branches else top[2]
            if kw != "ENDIF" and blocks[prev].oword.keyword == "ELSE":  # type: ignore
                raise err(f"{kw.lower()} after else")
            flow.jump[prev] = i
            if kw == "ENDIF":
                stack.pop()
                for j in [top[2], *branches]:
                    flow.endif[j] = i
            else:
                branches.append(i)
                flow.jump.setdefault(i, -1)
            continue
        if kw in ("ENDSUB", "ENDWHILE", "ENDREPEAT"):
            opener = {"ENDSUB": "SUB", "ENDWHILE": "WHILE", "ENDREPEAT": "REPEAT"}[kw]
            if top is None or top[1] != opener or top[0] != label:
                raise err(f"{kw.lower()} without a matching O{label} {opener.lower()}")
            stack.pop()
            if kw == "ENDSUB":
                flow.subs[label] = (top[2], i)
            else:
                flow.head[i] = top[2]
                flow.end[top[2]] = i
                for j in top[3]:
                    _bind(flow, blocks, j, top[2], i)
            continue
        if kw in ("BREAK", "CONTINUE"):
            for frame in reversed(stack):
                if frame[0] == label and frame[1] in _LOOPS:
                    frame[3].append(i)
                    break
            else:
                raise err(f"{kw.lower()} outside an O{label} loop")
            continue
        if kw == "RETURN":
            if not any(f[1] == "SUB" and f[0] == label for f in stack):
                raise err(f"return outside subroutine O{label}")
            continue
    if stack:
        label, kw, i, _ = stack[-1]
        b = blocks[i]
        raise b.error(f"O{label} {kw.lower()} is never closed", b.oword.pos,  # type: ignore
                      f"O{label} {kw.lower()}")
    for b in blocks:
        if b.oword is not None and b.oword.keyword == "CALL" \
                and b.oword.label not in flow.subs and not (b.delete and block_delete):
            raise b.error(f"subroutine O{b.oword.label} is not defined in this program",
                          b.oword.pos, f"O{b.oword.label} call")
    return flow


def _bind(flow: _Flow, blocks: list[Block], j: int, head: int, end: int) -> None:
    """A break/continue inside a loop: where it jumps."""
    if blocks[j].oword.keyword == "BREAK":  # type: ignore[union-attr]
        flow.end[j] = end
    else:
        flow.head[j] = head


@dataclass
class _Frame:
    """One active subroutine call."""

    label: str
    return_to: int
    repeats: dict[int, int] = field(default_factory=dict)


class Interpreter:
    """Runs a parsed program; use `run()` once. Most callers want compile_text/file."""

    def __init__(self, program: Program, options: GCodeOptions) -> None:
        if not isinstance(options, GCodeOptions):
            raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
        self.program = program
        self.opt = options
        self.params = Parameters(options.parameters)
        self.modal = Modal(options, self.params)
        self.flow = _analyse(program.blocks, options.block_delete)

    def _truth(self, b: Block) -> bool:
        o = b.oword
        assert o is not None
        return self.modal.evaluate(b, o.args[0], f"O{o.label}") != 0.0

    def run(self) -> list[canon.Command]:  # noqa: C901
        blocks = self.program.blocks
        flow = self.flow
        modal = self.modal
        skip_deleted = self.opt.block_delete
        out: list[canon.Command] = []
        frames: list[_Frame] = [_Frame("", -1)]
        steps = 0
        limit = self.opt.max_blocks
        pc = 0
        test_branch = -1  # the ELSEIF whose condition is to be tested next
        n = len(blocks)
        while pc < n:
            b = blocks[pc]
            steps += 1
            if steps > limit:
                raise b.error(f"more than {limit} lines executed (endless loop?)", 0,
                              f"O{b.oword.label}" if b.oword else "")
            if b.delete and skip_deleted:
                pc += 1
                continue
            o = b.oword
            if o is None:
                try:
                    if not modal.execute(b, out):
                        break
                except GCodeError as exc:
                    if len(frames) == 1:
                        raise
                    calls = ", ".join(
                        f"o{f.label.lower()} called at line {blocks[f.return_to - 1].line}"
                        for f in reversed(frames[1:]))
                    raise GCodeError(f"{exc.reason} (in {calls})", exc.line, exc.column,
                                     exc.word, exc.file) from None
                pc += 1
                continue
            if b.comments:
                modal.messages(b, out)
            kw = o.keyword
            if kw == "SUB":  # reached by falling through: skip the definition
                pc = flow.subs[o.label][1] + 1
            elif kw in ("ENDSUB", "RETURN"):
                if o.args:
                    v = modal.evaluate(b, o.args[0], f"O{o.label}")
                    self.params.set_named("_VALUE", v)
                    self.params.set_named("_VALUE_RETURNED", 1.0)
                frame = frames.pop()
                if len(frames) == 0:  # pragma: no cover - _analyse forbids this
                    raise b.error("return outside a subroutine", o.pos, f"O{o.label}")
                self.params.pop_call()
                pc = frame.return_to
            elif kw == "CALL":
                if len(frames) > self.opt.max_call_depth:
                    raise b.error(f"subroutine calls nested deeper than "
                                  f"{self.opt.max_call_depth}", o.pos, f"O{o.label} call")
                args = [modal.evaluate(b, a, f"O{o.label}") for a in o.args]
                self.params.set_named("_VALUE_RETURNED", 0.0)
                self.params.push_call(args)
                frames.append(_Frame(o.label, pc + 1))
                pc = flow.subs[o.label][0] + 1
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
                pc = flow.head[pc] + 1 if self._truth(b) else pc + 1
            elif kw == "WHILE":
                pc = pc + 1 if self._truth(b) else flow.end[pc] + 1
            elif kw == "ENDWHILE":
                pc = flow.head[pc]
            elif kw == "DO":
                pc += 1
            elif kw == "REPEAT":
                reps = frames[-1].repeats
                if pc not in reps:
                    count = modal.evaluate(b, o.args[0], f"O{o.label}")
                    reps[pc] = int(count) if count > 0 else 0
                if reps[pc] > 0:
                    reps[pc] -= 1
                    pc += 1
                else:
                    del reps[pc]
                    pc = flow.end[pc] + 1
            elif kw == "ENDREPEAT":
                pc = flow.head[pc]
            elif kw == "BREAK":
                end = flow.end[pc]
                head = flow.head[end]
                frames[-1].repeats.pop(head, None)
                pc = end + 1
            elif kw == "CONTINUE":
                head = flow.head[pc]
                # a do-while continues at its closing 'while' test
                pc = flow.end[head] if blocks[head].oword.keyword == "DO" else head  # type: ignore
            else:  # pragma: no cover - parser admits only the keywords above
                raise b.error(f"unknown O-word {kw}", o.pos, f"O{o.label}")
        return out


def interpret(program: Program, options: GCodeOptions) -> list[canon.Command]:
    """Run a parsed program; the command list, or GCodeError for the first problem."""
    return Interpreter(program, options).run()


def compile_text(text: str, options: GCodeOptions, file: str = "") -> list[canon.Command]:
    """Parse and interpret G-code text into canonical commands (machine coordinates)."""
    if not isinstance(options, GCodeOptions):
        raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
    if isinstance(text, bytes):
        text = decode_program(text, file, options.max_bytes)
    if not isinstance(text, str):
        raise GCodeError(f"program text must be str, got {type(text).__name__}", file=file)
    if len(text) > options.max_bytes:
        raise GCodeError(f"program is {len(text)} characters, more than the limit of "
                         f"{options.max_bytes}", file=file)
    program = parse_program(text, file, options.max_line_length)
    return interpret(program, options)


def compile_file(path: str | os.PathLike[str], options: GCodeOptions) -> list[canon.Command]:
    """Read (text check, size limit), parse and interpret a G-code file."""
    if not isinstance(options, GCodeOptions):
        raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
    text = read_program(path, options.max_bytes)
    return compile_text(text, options, os.fspath(path))
