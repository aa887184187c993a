"""The O-word structure of a program, checked statically: its jump table (`_Flow`).

`_analyse` matches every sub/endsub, if/elseif/else/endif, while/endwhile, do/while and
repeat/endrepeat by label, binds each break/continue to its loop and lists the calls to
subroutines the program does not define (interp.py then loads their files and analyses
again). It runs before any line does, so a badly nested program is refused with nothing
executed. The interpreter (interp.py) follows the table; this module only builds it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .parser import Block
from .source import GCodeError

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
    fanuc: dict[str, int] = field(default_factory=dict)  # bare O<n> line (M98 target)
    missing: dict[str, int] = field(default_factory=dict)  # called, not defined: -> line


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
        if kw == "":
            flow.fanuc.setdefault(label, i)
            continue
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
        if kw == "RETURN":  # LinuxCNC: any label returns from the enclosing sub
            if not any(f[1] == "SUB" for f in stack):
                raise err(f"return outside a subroutine (O{label} return)")
            continue
    if stack:
        label, kw, i, _ = stack[-1]
        b = blocks[i]
        raise b.error(f"O{label} {kw.lower()} is never closed", b.oword.pos,  # type: ignore
                      f"O{label} {kw.lower()}")
    for i, b in enumerate(blocks):
        o = b.oword
        if o is not None and o.keyword == "CALL" and o.computed is None \
                and o.label not in flow.subs and not (b.delete and block_delete):
            if o.label in flow.fanuc:
                raise b.error(f"O{o.label} is a Fanuc-style program: call it with M98 "
                              f"P{o.label}", o.pos, f"O{o.label} call")
            flow.missing.setdefault(o.label, i)
    return flow


def _bind(flow: _Flow, blocks: list[Block], j: int, head: int, end: int) -> None:
    """A break/continue inside a loop: where it jumps."""
    if blocks[j].oword.keyword == "BREAK":  # type: ignore[union-attr]
        flow.end[j] = end
    else:
        flow.head[j] = head
