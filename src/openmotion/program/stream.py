"""Streaming compile: the commands of a G-code file one by one, the file never held whole.

`stream_file(path, options)` gives what `compile_file(path, options)` returns, in the same
order, as an iterator whose memory stays flat however long the file is (a few chunks of
text and the modal state; the caller decides what to keep of the commands). It reads the
file twice in chunks:

1. a check pass: the size limit, NUL bytes and UTF-8, the line count, every line's syntax
   (plain lines by the fast path's regex, the others by `parse_line`) and whether the
   program needs the interpreter's control flow (an O-word anywhere);
2. the commands, from `fastpath.plain_commands` over the decoded lines.

Whenever the check pass finds anything besides a well-formed program without O-words, the
file goes to `compile_file`, so the error raised is exactly its own (and a program with
O-word control flow is compiled whole, as before: subroutines and loops need it). A
program that fails while its commands are produced (an unknown code, a soft limit, M98
without the program) raises `compile_file`'s error at that point: the commands before it
have been handed out already, which a caller that runs them as they come must expect (the
whole-program compile refuses the program before anything moves).
"""

from __future__ import annotations

import codecs
import os
from collections.abc import Iterator

from . import canon
from .fastpath import _canonical_regex, _Defer, plain_commands
from .interp import compile_file
from .options import GCodeOptions
from .parser import MAX_LINES, parse_line
from .source import GCodeError

#: Bytes read at a time.
CHUNK = 1 << 18


class _Unusual(Exception):
    """The check pass found something compile_file must decide."""


def _text_lines(path: str, max_bytes: int) -> Iterator[str]:
    """The file's lines as `str.splitlines` gives them, decoded chunk by chunk; raises
    _Unusual for anything `read_program` would refuse (size, NUL, not UTF-8)."""
    try:
        if os.path.getsize(path) > max_bytes:
            raise _Unusual
        fh = open(path, "rb")  # noqa: SIM115 - closed below, across yields
    except OSError:
        raise _Unusual from None
    decoder = codecs.getincrementaldecoder("utf-8")("strict")
    carry = ""
    total = 0
    with fh:
        while True:
            data = fh.read(CHUNK)
            total += len(data)
            if total > max_bytes or b"\x00" in data:
                raise _Unusual
            try:
                text = carry + decoder.decode(data, final=not data)
            except UnicodeDecodeError:
                raise _Unusual from None
            if not data:
                yield from text.splitlines()
                return
            parts = text.splitlines(keepends=True)
            carry = ""
            if parts:
                last = parts[-1]
                # a last piece without its line end, or ending in a '\r' whose '\n' may
                # come next, continues in the next chunk
                if last.endswith("\r") or not _ends_line(last):
                    carry = parts.pop()
            for p in parts:
                yield p.splitlines()[0]


def _ends_line(piece: str) -> bool:
    return len(piece.splitlines()[0]) < len(piece)


def _check(path: str, options: GCodeOptions) -> None:
    """The check pass (module docstring); raises _Unusual when compile_file must decide."""
    letters = [L for L in "XYZABCUVW" if L in options.axes]
    canonical = _canonical_regex(letters).match
    max_len = options.max_line_length
    seen_code = False
    closed = False
    ended = False  # an M2 / M30 line (a plain program runs every line it has)
    n = 0
    for k, text in enumerate(_text_lines(path, options.max_bytes), 1):
        n = k
        if closed:  # parse_program ignores what follows the closing '%' (but counts it)
            continue
        if len(text) <= max_len and canonical(text) is not None:
            if text.strip():
                seen_code = True
            continue
        if text.strip() == "%":
            closed = seen_code
            seen_code = True
            continue
        try:
            b = parse_line(text, k, path, max_len)
        except GCodeError:
            raise _Unusual from None
        if b is not None:
            seen_code = True
            if b.oword is not None:
                raise _Unusual
            ended = ended or any(L == "M" and v in (2.0, 30.0) for L, v, _ in b.words)
    if n > MAX_LINES or (options.require_end and not (ended or closed)):
        raise _Unusual  # compile_file says what is wrong


def stream_file(path: str | os.PathLike[str],
                options: GCodeOptions) -> Iterator[canon.Command]:
    """The commands of the program file `path`, one at a time (module docstring)."""
    if not isinstance(options, GCodeOptions):
        raise GCodeError(f"options must be GCodeOptions, got {type(options).__name__}")
    name = os.fspath(path)
    try:
        _check(name, options)
    except _Unusual:
        return iter(compile_file(name, options))
    return _produce(name, options)


def _produce(name: str, options: GCodeOptions) -> Iterator[canon.Command]:
    done = 0
    try:
        for cmd in plain_commands(_text_lines(name, options.max_bytes), options, name):
            done += 1
            yield cmd
    except (_Defer, _Unusual):  # M98/M99, max_blocks (or the file changed): compile_file
        # raises its error; were there none, the rest of its list follows what was given
        yield from compile_file(name, options)[done:]
