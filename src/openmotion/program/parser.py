"""Lexer and parser: program text -> a list of `Block`s, one per non-empty line.

A line is compacted before parsing: comments are cut out (kept separately, with their
column), spaces and tabs are removed and letters are upper-cased, as RS-274/NGC does
(`G1 X 1.5` == `g1x1.5`, `#<_foo bar>` == `#<_FOOBAR>`). Plain lines of words with literal
numbers take a regex fast path; anything with parameters, expressions or O-words goes
through a small recursive-descent parser. Constant expressions are folded to floats here.

Syntax errors raise GCodeError naming line, column and word. Nothing is executed here.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from .expr import (
    FUNCTIONS,
    PRECEDENCE,
    Atan,
    Binary,
    Exists,
    ExistsNumber,
    Func,
    NamedParam,
    Neg,
    Node,
    Num,
    NumParam,
    fold,
)
from .source import MAX_LINE_LENGTH, GCodeError, column_of

#: Letters that may start a word; @ and ^ are the polar radius and angle, E the G76 taper
#: (LinuxCNC).
WORD_LETTERS = frozenset("ABCDEFGHIJKLMNPQRSTUVWXYZ@^")
#: O-word keywords and whether they take expressions: 0 none, 1 optional one, 2 one, 9 any.
O_KEYWORDS = {
    "SUB": 0, "ENDSUB": 1, "RETURN": 1, "CALL": 9, "DO": 0, "WHILE": 2, "ENDWHILE": 0,
    "IF": 2, "ELSEIF": 2, "ELSE": 0, "ENDIF": 0, "REPEAT": 2, "ENDREPEAT": 0,
    "BREAK": 0, "CONTINUE": 0,
    "": 0,  # a bare O<n> line: a Fanuc-style program number (called with M98, ends at M99)
}
_WORD_OPS = ("MOD", "AND", "XOR", "OR", "EQ", "NE", "GT", "GE", "LT", "LE")

#: One unsigned literal; the alternatives cannot both match a digit run (no backtracking).
_NUMBER = re.compile(r"\d+(?:\.\d*)?|\.\d+")
_SIMPLE_LETTERS = frozenset("ABCDFGHIJKLMNPQRSTUVWXYZ")
_DIGITS = frozenset("0123456789")
_LINE_NUMBER = re.compile(r"N\d+(?:\.\d+)?")

#: A word value: a literal (float) or an expression evaluated when the line runs.
Value = float | Node


@dataclass(slots=True)
class OWord:
    """An O-word control line: `O<label> <keyword> [args]`; `computed` is the expression
    of an `O[expr] call` label (then `label` is its text)."""

    label: str
    keyword: str
    args: list[Value]
    pos: int
    computed: Node | None = None


@dataclass(slots=True)
class Block:
    """One program line after parsing.

    `words` are (letter, value, pos) in line order; `assigns` are (target, value, pos) where
    target is an int (numbered) or str (named) or a Node (computed index); `comments` are
    (column, text) with the original case.
    """

    line: int
    text: str
    file: str = ""
    delete: bool = False
    number: float | None = None
    words: list[tuple[str, Value, int]] = field(default_factory=list)
    assigns: list[tuple[int | str | Node, Value, int]] = field(default_factory=list)
    comments: list[tuple[int, str]] = field(default_factory=list)
    oword: OWord | None = None

    def error(self, message: str, pos: int = -1, word: str = "") -> GCodeError:
        """A GCodeError located at compacted position `pos` of this line."""
        col = column_of(self.text, pos) if pos >= 0 else 0
        return GCodeError(message, self.line, col, word, self.file)


def split_comments(text: str, line: int, file: str) -> tuple[str, list[tuple[int, str]]]:
    """Cut comments out of a line: (code without comments, [(column, comment text)])."""
    code: list[str] = []
    comments: list[tuple[int, str]] = []
    k = 0
    n = len(text)
    while k < n:
        ch = text[k]
        if ch == "(":
            end = text.find(")", k + 1)
            if end < 0:
                raise GCodeError("comment is not closed with ')'", line, k + 1, "(", file)
            inner = text.find("(", k + 1, end)
            if inner >= 0:
                raise GCodeError("nested comment: '(' inside a comment", line, inner + 1,
                                 "(", file)
            comments.append((k + 1, text[k + 1:end]))
            k = end + 1
            continue
        if ch == ";":
            comments.append((k + 1, text[k + 1:]))
            break
        if ch == ")":
            raise GCodeError("')' without an opening '('", line, k + 1, ")", file)
        code.append(ch)
        k += 1
    return "".join(code), comments


class _LineParser:
    """Recursive descent over one compacted, upper-cased line."""

    def __init__(self, s: str, block: Block) -> None:
        self.s = s
        self.i = 0
        self.block = block

    # -- helpers ---------------------------------------------------------------------
    def fail(self, message: str, pos: int | None = None, word: str | None = None) -> None:
        p = self.i if pos is None else pos
        if word is None:
            word = self.s[p:p + 8] if p < len(self.s) else ""
        raise self.block.error(message, p, word)

    def peek(self) -> str:
        return self.s[self.i] if self.i < len(self.s) else ""

    def expect(self, ch: str) -> None:
        if self.peek() != ch:
            got = self.peek() or "end of line"
            self.fail(f"expected '{ch}', got {got!r}")
        self.i += 1

    # -- values ----------------------------------------------------------------------
    def number(self) -> float:
        m = _NUMBER.match(self.s, self.i)
        if m is None:
            self.fail("expected a number")
        assert m is not None
        self.i = m.end()
        if self.peek() == ".":
            self.fail("malformed number (two decimal points)", m.start(),
                      self.s[m.start():self.i + 1])
        return float(m.group())

    def name(self) -> str:
        """<name> after '#'; returns the upper-cased name without brackets."""
        start = self.i
        self.expect("<")
        end = self.s.find(">", self.i)
        if end < 0:
            self.fail("named parameter is not closed with '>'", start)
        name = self.s[self.i:end]
        if not name:  # LinuxCNC takes any character but '>' (e.g. <_move:x>, <tap-d>)
            self.fail("parameter name must not be empty", start, self.s[start:end + 1])
        self.i = end + 1
        return name

    def param(self) -> Node:
        """A parameter reference starting at '#'."""
        pos = self.i
        self.expect("#")
        if self.peek() == "<":
            return NamedParam(self.name(), pos)
        return NumParam(self.primary(), pos)

    def primary(self) -> Node:
        pos = self.i
        ch = self.peek()
        if ch == "[":
            self.i += 1
            node = self.expression()
            self.expect("]")
            return node
        if ch == "#":
            return self.param()
        if ch in "+-" and ch:
            self.i += 1
            arg = self.primary()
            return Neg(arg, pos) if ch == "-" else arg
        if ch.isdigit() or ch == ".":
            return Num(self.number(), pos)
        if ch.isalpha():
            return self.function()
        self.fail("expected a value (number, #parameter, [expression] or function)",
                  word=ch or "end of line")
        raise AssertionError  # unreachable

    def function(self) -> Node:
        pos = self.i
        j = pos
        while j < len(self.s) and self.s[j].isalpha():
            j += 1
        name = self.s[pos:j]
        if name == "ATAN":
            self.i = j
            self.expect("[")
            y = self.expression()
            self.expect("]")
            self.expect("/")
            self.expect("[")
            x = self.expression()
            self.expect("]")
            return Atan(y, x, pos)
        if name == "EXISTS":
            self.i = j
            self.expect("[")
            self.expect("#")
            if self.peek() != "<":  # EXISTS[#n], EXISTS[##n]: is the number in range
                idx = self.primary()
                self.expect("]")
                return ExistsNumber(idx, pos)
            nm = self.name()
            self.expect("]")
            return Exists(nm, pos)
        if name not in FUNCTIONS:
            self.fail(f"unknown function {name!r}", pos, name)
        self.i = j
        self.expect("[")
        arg = self.expression()
        self.expect("]")
        return Func(name, arg, pos)

    def operator(self) -> str | None:
        s, i = self.s, self.i
        if s.startswith("**", i):
            return "**"
        ch = s[i:i + 1]
        if ch and ch in "*/+-":
            return ch
        for op in _WORD_OPS:
            if s.startswith(op, i):
                return op
        return None

    def expression(self, min_prec: int = 1) -> Node:
        """Precedence climbing; every level is left-associative."""
        left = self.primary()
        while True:
            op = self.operator()
            if op is None or PRECEDENCE[op] < min_prec:
                return left
            pos = self.i
            self.i += len(op)
            right = self.expression(PRECEDENCE[op] + 1)
            left = Binary(op, left, right, pos)

    def value(self) -> Value:
        return fold(self.primary())

    # -- line items ------------------------------------------------------------------
    def oword(self) -> OWord:
        pos = self.i
        self.i += 1  # 'O'
        computed: Value | None = None
        if self.peek() == "<":
            label = "<" + self.name() + ">"
        elif self.peek() and self.peek() in "[#":  # O[expr] / O#<name> call: computed label
            start = self.i
            computed = self.value()
            label = self.s[start:self.i]
            if not isinstance(computed, Node):
                label = str(int(computed)) if computed == int(computed) else label
        else:
            m = _NUMBER.match(self.s, self.i)
            if m is None or "." in m.group():
                self.fail("O-word needs a number or <name>", pos, "O")
            assert m is not None
            label = str(int(m.group()))
            self.i = m.end()
        kstart = self.i
        while self.i < len(self.s) and self.s[self.i].isalpha():
            self.i += 1
        keyword = self.s[kstart:self.i]
        if keyword not in O_KEYWORDS:
            self.fail(f"unknown O-word keyword {keyword or '(none)'!r}", kstart,
                      f"O{label} {keyword}".strip())
        args: list[Value] = []
        while self.peek() == "[":
            self.i += 1
            args.append(fold(self.expression()))
            self.expect("]")
        rule = O_KEYWORDS[keyword]
        word = f"O{label} {keyword}"
        if rule == 0 and args:
            self.fail(f"{keyword} takes no expression", kstart, word)
        if rule == 1 and len(args) > 1:
            self.fail(f"{keyword} takes at most one expression", kstart, word)
        if rule == 2 and len(args) != 1:
            self.fail(f"{keyword} needs one [expression]", kstart, word)
        if rule == 9 and len(args) > 30:
            self.fail("CALL takes at most 30 arguments", kstart, word)
        if self.i < len(self.s):
            self.fail("unexpected text after the O-word", word=self.s[self.i:self.i + 8])
        if computed is not None and keyword != "CALL" and isinstance(computed, Node):
            self.fail("a computed O-word label is only allowed with call", pos, word)
        return OWord(label, keyword, args, pos,
                     computed if isinstance(computed, Node) else None)

    def items(self) -> None:
        b = self.block
        s = self.s
        while self.i < len(s):
            ch = s[self.i]
            pos = self.i
            if ch == "#":
                self.i += 1
                if self.peek() == "<":
                    target: int | str | Node = self.name()
                else:
                    idx = fold(self.primary())
                    target = idx if isinstance(idx, Node) else _param_index(self, idx, pos)
                if self.peek() != "=":
                    self.fail("a parameter at the start of an item must be assigned "
                              "with '='", pos, s[pos:self.i])
                self.i += 1
                b.assigns.append((target, self.value(), pos))
            elif ch == "O":
                self.fail("an O-word must be alone on its line (after an optional N)", pos,
                          "O")
            elif ch in WORD_LETTERS:
                if ch == "N":
                    self.fail("line number N must come first on the line", pos, "N")
                self.i += 1
                if self.i >= len(s):
                    self.fail(f"word {ch} has no value", pos, ch)
                b.words.append((ch, self.value(), pos))
            elif ch.isalpha():
                self.fail(f"unknown word letter {ch!r}", pos, ch)
            else:
                self.fail(f"unexpected character {ch!r}", pos, ch)


def _param_index(p: _LineParser, value: float, pos: int) -> int:
    n = round(value)
    if abs(value - n) > 1e-4 or not 1 <= n <= MAX_PARAMETER:
        p.fail(f"parameter number must be an integer in [1, {MAX_PARAMETER}], got {value:g}",
               pos, f"#{value:g}")
    return int(n)


#: Highest numbered parameter (LinuxCNC RS274NGC_MAX_PARAMETERS - 1).
MAX_PARAMETER = 5601


def _simple_words(code: str, i: int) -> list[tuple[str, Value, int]] | None:
    """Words of a plain line (letters and literal numbers only) from `i`, else None.

    A hand-written scan, one pass over the characters: a regex with a repeated group of
    optional parts backtracked exponentially on a long plain prefix followed by a '['.
    """
    words: list[tuple[str, Value, int]] = []
    n = len(code)
    digits = _DIGITS
    while i < n:
        letter = code[i]
        if letter not in _SIMPLE_LETTERS:
            return None
        start = i
        i += 1
        if i < n and code[i] in "+-":
            i += 1
        lead = i
        while i < n and code[i] in digits:
            i += 1
        whole = i > lead
        if i < n and code[i] == ".":
            i += 1
            frac = i
            while i < n and code[i] in digits:
                i += 1
            if not whole and i == frac:
                return None
        elif not whole:
            return None
        words.append((letter, float(code[start + 1:i]), start))
    return words


def parse_line(text: str, line: int, file: str = "",
               max_line_length: int = MAX_LINE_LENGTH) -> Block | None:
    """Parse one line; None for a line with nothing on it. '%' lines return a marker block."""
    if len(text) > max_line_length:
        raise GCodeError(f"line is {len(text)} characters, more than the limit of "
                         f"{max_line_length}", line, max_line_length + 1, "", file)
    comments: list[tuple[int, str]] = []
    if "(" in text or ";" in text or ")" in text:
        raw, comments = split_comments(text, line, file)
    else:
        raw = text
    code = "".join(raw.split()).upper()
    if not code and not comments:
        return None
    block = Block(line, text, file, comments=comments)
    i = 0
    if code.startswith("/"):
        block.delete = True
        i = 1
    if code.startswith("N", i):
        m = _LINE_NUMBER.match(code, i)
        if m is None:
            raise block.error("line number N needs digits", i, "N")
        block.number = float(m.group()[1:])
        i = m.end()
    simple = _simple_words(code, i)
    if simple is not None:
        block.words = simple
        return block
    p = _LineParser(code, block)
    p.i = i
    if p.peek() == "O":
        block.oword = p.oword()
    else:
        p.items()
    return block


@dataclass(frozen=True)
class Program:
    """A parsed program: its blocks (empty lines dropped) and source file name."""

    blocks: list[Block]
    file: str = ""


#: Most lines parse_program accepts by default.
MAX_LINES = 5_000_000


def parse_program(text: str, file: str = "", max_line_length: int = MAX_LINE_LENGTH,
                  max_lines: int = MAX_LINES) -> Program:
    """Parse a whole program. A first line '%' opens it; the next '%' line ends it."""
    lines = text.splitlines()
    if len(lines) > max_lines:
        raise GCodeError(f"program has {len(lines)} lines, more than the limit of "
                         f"{max_lines}", file=file)
    blocks: list[Block] = []
    seen_code = False
    for k, t in enumerate(lines, 1):
        if t.strip() == "%":
            if seen_code:
                break
            seen_code = True
            continue
        b = parse_line(t, k, file, max_line_length)
        if b is not None:
            blocks.append(b)
            seen_code = True
    return Program(blocks, file)
