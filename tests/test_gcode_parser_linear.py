"""The G-code tokenizer works in linear steps (issue #12 defect 6).

A backtracking regex took 76 s on `"X11111"*12 + "["`. Two checks that count work, not
time: no module regex of the parser has a repeat nested in a repeat (the C regex engine's
exponential case), and the Python-level steps of parsing a line grow at most linearly with
its length (counted with a line tracer).
"""

from __future__ import annotations

import re
import sys
from re import _parser as sre_parse  # type: ignore[attr-defined]

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.program import parser
from openmotion.program.source import GCodeError

_REPEATS = {sre_parse.MAX_REPEAT, sre_parse.MIN_REPEAT, sre_parse.POSSESSIVE_REPEAT}


def _nested_repeat(items, inside: bool = False) -> bool:
    """A repeat inside an unbounded (or >1) repeat: the exponential backtracking shape."""
    for op, av in items:
        if op in _REPEATS:
            if inside:
                return True
            if _nested_repeat(av[2], av[1] > 1):
                return True
        elif op is sre_parse.SUBPATTERN:
            if _nested_repeat(av[3], inside):
                return True
        elif op is sre_parse.BRANCH and any(_nested_repeat(b, inside) for b in av[1]):
            return True
    return False


def test_parser_regexes_have_no_nested_repeats() -> None:
    patterns = [v for v in vars(parser).values() if isinstance(v, re.Pattern)]
    assert patterns
    for pat in patterns:
        assert not _nested_repeat(sre_parse.parse(pat.pattern)), pat.pattern


def _steps(text: str) -> int:
    """Python line events spent inside the parser package on `text`."""
    count = 0
    prefix = parser.__file__.rsplit("/", 1)[0]

    def tracer(frame, event, arg):  # noqa: ANN001, ANN202
        nonlocal count
        if frame.f_code.co_filename.startswith(prefix):
            count += 1
            return tracer
        return None

    old = sys.gettrace()
    sys.settrace(tracer)
    try:
        parser.parse_line(text, 1)
    except GCodeError:
        pass
    finally:
        sys.settrace(old)
    return count


def test_defect6_reproducer_is_refused() -> None:
    with pytest.raises(GCodeError):
        parser.parse_line("X11111" * 12 + "[", 1)
    assert _steps("X11111" * 12 + "[") < 40 * 80


_ALPHABET = "XYZGMFIJKN0123456789.+-[]#<>=*/ O"


@settings(max_examples=300, derandomize=True, deadline=None)
@given(st.text(alphabet=_ALPHABET, max_size=200))
def test_parse_steps_grow_linearly(text: str) -> None:
    assert _steps(text) <= 60 * (len(text) + 4)


def test_fast_path_matches_slow_path_words() -> None:
    line = "G1X-1.5Y.25Z3.F1200"
    fast = parser.parse_line(line, 1)
    assert fast is not None
    slow = parser.parse_line(line + "#1=2", 1)  # an assignment forces the slow path
    assert slow is not None
    assert [(w[0], w[1], w[2]) for w in fast.words] == [(w[0], float(w[1]), w[2])
                                                         for w in slow.words]
