"""Program text: reading a file or string safely, size limits, and error locations.

Every G-code problem is a `GCodeError` that names the file, line, column and word, so the
user can find it in an editor. Columns are 1-based positions in the original line; the
parser works on a compacted copy (comments and spaces removed), so `code_columns` maps
positions in that copy back to the original text, computed only when an error is raised.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from ..errors import MotionError

#: Longest accepted line, characters (LinuxCNC's LINELEN is 255 plus the terminator).
MAX_LINE_LENGTH = 256
#: Largest accepted program, bytes (about 2 million lines of CAM output).
MAX_PROGRAM_BYTES = 64 * 1024 * 1024


class GCodeError(MotionError):
    """A program that cannot be run; the message names file, line, column and word."""

    def __init__(self, message: str, line: int = 0, column: int = 0, word: str = "",
                 file: str = "") -> None:
        where = f"{file}:" if file else ""
        loc = f"{where}line {line}" if line else (file or "program")
        if column:
            loc += f", column {column}"
        if word:
            loc += f", word {word!r}"
        super().__init__(f"{loc}: {message}")
        self.line = line
        self.column = column
        self.word = word
        self.file = file
        self.reason = message


@dataclass(frozen=True)
class SourceLine:
    """One line of program text and where it came from."""

    number: int
    text: str
    file: str = ""


def code_columns(text: str) -> list[int]:
    """1-based column in `text` of each character the parser keeps (not space, not comment).

    Mirrors the parser's compaction: parenthesised comments and everything after ';' are
    dropped, as are spaces and tabs.
    """
    cols: list[int] = []
    in_comment = False
    for k, ch in enumerate(text):
        if in_comment:
            if ch == ")":
                in_comment = False
            continue
        if ch == "(":
            in_comment = True
        elif ch == ";":
            break
        elif not ch.isspace():
            cols.append(k + 1)
    return cols


def column_of(text: str, pos: int) -> int:
    """Original 1-based column of compacted position `pos` (end of line if past the end)."""
    cols = code_columns(text)
    if 0 <= pos < len(cols):
        return cols[pos]
    return len(text.rstrip()) + 1


def decode_program(data: bytes, file: str = "", max_bytes: int = MAX_PROGRAM_BYTES) -> str:
    """Bytes of a program -> text; refuse binary data and oversize input with the line."""
    if len(data) > max_bytes:
        raise GCodeError(f"program is {len(data)} bytes, more than the limit of {max_bytes}",
                         file=file)
    nul = data.find(b"\x00")
    if nul >= 0:
        raise GCodeError("not a text file (NUL byte at offset "
                         f"{nul})", line=data.count(b"\n", 0, nul) + 1, file=file)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise GCodeError(f"not a UTF-8/ASCII text file (byte 0x{data[exc.start]:02x} at "
                         f"offset {exc.start})", line=line, file=file) from None


def read_program(path: str | os.PathLike[str], max_bytes: int = MAX_PROGRAM_BYTES) -> str:
    """Read a program file as text, checking size and that it is text before parsing."""
    name = os.fspath(path)
    try:
        size = os.path.getsize(name)
        if size > max_bytes:
            raise GCodeError(f"program is {size} bytes, more than the limit of {max_bytes}",
                             file=name)
        with open(name, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise GCodeError(f"cannot read program: {exc.strerror or exc}", file=name) from None
    return decode_program(data, name, max_bytes)
