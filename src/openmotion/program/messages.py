"""Active comments: (MSG,..), (DEBUG,..), (PRINT,..), (LOG,..) and (ABORT,..).

LinuxCNC's rules (interp_convert.cc convert_comment / convert_param_comment): the keyword is
case-insensitive after optional spaces; DEBUG, PRINT, LOG and ABORT substitute `#n` and
`#<name>` with their values ("######" when unset or out of range); a format word changes
the format of every later value in that comment: `%d` (no decimals), `%f` (4 decimals),
`%.Nf` (N = 0..9 decimals); the default is 6 decimals; anything else after `%` is copied
(`%lf` prints as written). DEBUG prints only while #5599 > 0 (1 at start). ABORT stops the
program with an error carrying the text.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import canon
from .parser import Block
from .source import GCodeError

if TYPE_CHECKING:
    from .params import Parameters

#: Values this close to 0 print as 0 (LinuxCNC's equal(), no "-0.000000").
_ZERO = 1e-6


def expand(text: str, params: Parameters) -> str:
    """A DEBUG/PRINT/LOG/ABORT text with its parameters and formats substituted."""
    out: list[str] = []
    fmt = "{:.6f}"
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        if ch == "%":
            nxt = text[i + 1:i + 2]
            if nxt == "d":
                fmt, i = "{:.0f}", i + 2
            elif nxt == "f":
                fmt, i = "{:.4f}", i + 2
            elif nxt == ".":
                if text[i + 2:i + 3].isdigit() and text[i + 3:i + 4] == "f":
                    fmt, i = "{:." + text[i + 2] + "f}", i + 4
                else:  # not a format: LinuxCNC drops the '%' and keeps the rest
                    out.append(".")
                    i += 2
            else:
                out.append("%")
                i += 1
        elif ch == "#":
            i += 1
            value: float | None = None
            if text[i:i + 1].isdigit():
                j = i
                while j < n and text[j].isdigit():
                    j += 1
                num = int(text[i:j])
                i = j
                if 1 <= num < len(params.numbers):
                    value = params.get_number(num, 0)
            elif text[i:i + 1] == "<":
                end = text.find(">", i)
                if end < 0:
                    out.append(text[i - 1:])
                    break
                name = "".join(text[i + 1:end].split()).upper()
                i = end + 1
                table = params.globals if name.startswith("_") else params.locals[-1]
                value = table.get(name, params.predefined(name))
            else:
                out.append("#")
                continue
            if value is None:
                out.append("######")
            else:
                out.append(fmt.format(0.0 if abs(value) < _ZERO else value))
        else:
            out.append(ch)
            i += 1
    return "".join(out)


def comment_commands(b: Block, params: Parameters, keep_comments: bool,
                     out: list[canon.Command]) -> None:
    """Append the Message records of a line's comments; raise on (ABORT,...)."""
    for col, text in b.comments:
        body = text.lstrip()
        head = "".join(body[:12].split()).upper()
        comma = body.find(",")
        rest = body[comma + 1:] if comma >= 0 else ""
        if head.startswith("MSG,"):
            out.append(canon.Message(rest.strip(), "msg", b.line, b.file))
        elif head.startswith("DEBUG,"):
            if params.numbers[5599] > 0.0:
                out.append(canon.Message(expand(rest, params).strip(), "debug", b.line,
                                         b.file))
        elif head.startswith("PRINT,"):
            out.append(canon.Message(expand(rest, params).strip(), "print", b.line, b.file))
        elif head.startswith("LOG,"):
            out.append(canon.Message(expand(rest, params).strip(), "log", b.line, b.file))
        elif head.startswith("ABORT,"):
            msg = expand(rest, params).strip()
            raise GCodeError(f"program aborted: {msg}", b.line, col, "(ABORT)", b.file)
        elif keep_comments:
            out.append(canon.Message(text, "comment", b.line, b.file))
