"""Tool table in LinuxCNC's format: tool numbers, pockets, offsets per axis, diameters.

One tool per line, words in any order, a `;` starts the comment:

    T1 P1 Z12.5 D6.0 ;6 mm end mill
    T7 P7 X0.5 Z-2 D0.8 I95 J155 Q2 ;lathe tool, orientation 2

T = tool number (>= 1), P = pocket, X Y Z A B C U V W = offsets (machine units; G43 applies
them), D = diameter (cutter compensation uses D/2), I/J = front/back angle and Q = lathe
orientation (0..9). Blank lines and comment-only lines are skipped. Every other problem
raises GCodeError naming the file, line and column.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from .options import AXIS_LETTERS
from .source import GCodeError, read_program

_WORD = re.compile(r"\s*([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


@dataclass(frozen=True)
class Tool:
    """One tool: offsets are per axis letter X..W (machine units), 0 when absent."""

    number: int
    pocket: int = 0
    offsets: tuple[float, ...] = field(default=(0.0,) * 9)
    diameter: float = 0.0
    front_angle: float = 0.0
    back_angle: float = 0.0
    orientation: int = 0
    comment: str = ""

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter


def parse_tool_table(text: str, file: str = "") -> dict[int, Tool]:
    """Tool table text -> {tool number: Tool}."""
    tools: dict[int, Tool] = {}
    for n, raw in enumerate(text.splitlines(), 1):
        body, _sep, comment = raw.partition(";")
        if not body.strip():
            continue
        vals: dict[str, float] = {}
        k = 0
        while k < len(body):
            if body[k].isspace():
                k += 1
                continue
            m = _WORD.match(body, k)
            if m is None:
                raise GCodeError("expected a word such as T1, P1, Z1.5 or D6", n, k + 1,
                                 body[k:k + 8].strip(), file)
            letter = m.group(1).upper()
            if letter not in "TPDIJQ" + AXIS_LETTERS:
                raise GCodeError(f"unknown tool table word {letter}", n, m.start(1) + 1,
                                 letter, file)
            if letter in vals:
                raise GCodeError(f"word {letter} appears twice", n, m.start(1) + 1, letter,
                                 file)
            v = float(m.group(2))
            if not math.isfinite(v):
                raise GCodeError(f"{letter} must be finite", n, m.start(1) + 1, letter, file)
            vals[letter] = v
            k = m.end()
        if "T" not in vals:
            raise GCodeError("a tool table line needs T (the tool number)", n, 1, "", file)
        number = vals["T"]
        if number != int(number) or number < 1:
            raise GCodeError(f"T must be an integer >= 1, got {number:g}", n, 1, "T", file)
        if int(number) in tools:
            raise GCodeError(f"tool {int(number)} is listed twice", n, 1, "T", file)
        if vals.get("D", 0.0) < 0:
            raise GCodeError(f"D (diameter) must be >= 0, got {vals['D']:g}", n, 1, "D", file)
        q = vals.get("Q", 0.0)
        if q != int(q) or not 0 <= q <= 9:
            raise GCodeError(f"Q (orientation) must be an integer 0..9, got {q:g}", n, 1,
                             "Q", file)
        pocket = vals.get("P", number)
        if pocket != int(pocket) or pocket < 0:
            raise GCodeError(f"P (pocket) must be an integer >= 0, got {pocket:g}", n, 1,
                             "P", file)
        tools[int(number)] = Tool(int(number), int(pocket),
                                  tuple(vals.get(L, 0.0) for L in AXIS_LETTERS),
                                  vals.get("D", 0.0), vals.get("I", 0.0), vals.get("J", 0.0),
                                  int(q), comment.strip())
    return tools


def read_tool_table(path: str | os.PathLike[str]) -> dict[int, Tool]:
    """Read and parse a LinuxCNC .tbl file."""
    return parse_tool_table(read_program(path, 16 * 1024 * 1024), os.fspath(path))


def format_tool_table(tools: Mapping[int, Tool]) -> str:
    """The table as LinuxCNC writes it (for saving G10 L1/L10/L11 results)."""
    lines = []
    for t in sorted(tools.values(), key=lambda t: t.number):
        words = [f"T{t.number}", f"P{t.pocket}"]
        words += [f"{L}{v:+.6f}" for L, v in zip(AXIS_LETTERS, t.offsets, strict=True) if v]
        if t.diameter:
            words.append(f"D{t.diameter:.6f}")
        for L, v in (("I", t.front_angle), ("J", t.back_angle)):
            if v:
                words.append(f"{L}{v:+.6f}")
        if t.orientation:
            words.append(f"Q{t.orientation}")
        lines.append(" ".join(words) + f" ;{t.comment}")
    return "\n".join(lines) + "\n"
