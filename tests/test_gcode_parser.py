"""Parser, expressions and source checks of openmotion.program (no motion semantics)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.program import GCodeError, GCodeOptions, compile_file, compile_text
from openmotion.program.parser import parse_line, parse_program
from openmotion.program.source import decode_program

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


def value_of(expr: str) -> float:
    """Evaluate an expression through the whole interpreter: #1 = expr, then X#1."""
    cmds = compile_text(f"#1 = {expr}\nG0 X#1", OPTS)
    return cmds[-1].end[0]


def err(text: str, opts: GCodeOptions = OPTS) -> GCodeError:
    with pytest.raises(GCodeError) as info:
        compile_text(text, opts)
    return info.value


# -- lexing ------------------------------------------------------------------------------
def test_spaces_case_comments_and_line_numbers():
    b = parse_line("n0040 g 1 x 1 . 5 (move) y-2;rest", 7)
    assert b is not None
    assert b.number == 40
    assert [(w[0], w[1]) for w in b.words] == [("G", 1.0), ("X", 1.5), ("Y", -2.0)]
    assert [c[1] for c in b.comments] == ["move", "rest"]


def test_numbers_forms():
    b = parse_line("X1. Y.5 Z-0.25 A+3", 1)
    assert [w[1] for w in b.words] == [1.0, 0.5, -0.25, 3.0]


def test_block_delete_flag_and_switch():
    prog = "G0 X1\n/G0 X5\n"
    assert compile_text(prog, OPTS)[-1].end[0] == 1.0
    off = GCodeOptions(axes={"X": 0}, block_delete=False)
    assert compile_text(prog, off)[-1].end[0] == 5.0


def test_percent_delimits_program():
    cmds = compile_text("%\nG0 X1\n%\nthis is ignored ###\n", OPTS)
    assert [c.end[0] for c in cmds] == [1.0]


def test_empty_and_comment_only_lines_make_no_blocks():
    prog = parse_program("\n   \n(just a comment)\nG0 X1\n")
    assert [b.line for b in prog.blocks] == [3, 4]


@pytest.mark.parametrize(
    "text, line, column, word",
    [
        ("G0 X1\nG1 X1.2.3 F5", 2, 5, "1.2."),   # malformed number
        ("G0 X1\nG0 E5", 2, 4, "E"),            # unknown letter
        ("G0 X", 1, 4, "X"),                      # word without value
        ("G0 X1 (open", 1, 7, "("),               # unclosed comment
        ("G0 (a (b) c) X1", 1, 7, "("),           # nested comment
        ("G0 X[1+2", 1, 0, ""),                   # missing ']' (column at end)
        ("G0 X1 N5", 1, 7, "N"),                  # line number not first
    ],
)
def test_syntax_errors_name_line_column_word(text, line, column, word):
    e = err(text)
    assert e.line == line
    if column:
        assert e.column == column
    if word:
        assert e.word.startswith(word)
    assert f"line {line}" in str(e)


def test_unknown_function_and_bad_character():
    e = err("G0 X[FOO[1]]")
    assert e.word == "FOO" and e.column == 6
    e = err("G0 X1 $")
    assert e.column == 7 and "unexpected character" in str(e)


def test_long_line_refused():
    e = err("G0 X1\n" + "G1" + " " * 300 + "X1\n")
    assert e.line == 2 and "characters" in str(e)


def test_not_text_refused(tmp_path):
    with pytest.raises(GCodeError, match="not a text file"):
        decode_program(b"G0 X1\n\x00\x01\x02")
    p = tmp_path / "bin.ngc"
    p.write_bytes(b"G0 X1\nG0 \xff\xfe X2\n")
    with pytest.raises(GCodeError, match="line 2.*UTF-8") as info:
        compile_file(p, OPTS)
    assert info.value.line == 2
    with pytest.raises(GCodeError, match="cannot read"):
        compile_file(tmp_path / "missing.ngc", OPTS)


def test_huge_program_refused_before_parsing():
    small = GCodeOptions(axes={"X": 0}, max_bytes=100)
    with pytest.raises(GCodeError, match="more than the limit"):
        compile_text("G0 X1\n" * 50, small)


def test_gcode_error_is_a_motion_error():
    assert issubclass(GCodeError, MotionError) and issubclass(GCodeError, ValueError)


# -- expressions -------------------------------------------------------------------------
@pytest.mark.parametrize(
    "expr, expected",
    [
        ("[1 + 2 * 3]", 7.0),
        ("[[1 + 2] * 3]", 9.0),
        ("[2 ** 3 * 2]", 16.0),
        ("[2 * 3 ** 2]", 18.0),
        ("[2 ** 3 ** 2]", 64.0),          # left to right
        ("[10 - 4 - 3]", 3.0),
        ("[12 / 3 / 2]", 2.0),
        ("[7 MOD 3]", 1.0),
        ("[-7 MOD 3]", 2.0),              # result in [0, |b|)
        ("[1 + 2 EQ 3]", 1.0),            # comparison below + -
        ("[1 LT 2 AND 3 GT 4]", 0.0),     # logic below comparison
        ("[1 LT 2 OR 3 GT 4]", 1.0),
        ("[1 XOR 1]", 0.0),
        ("[2 NE 2.0000001]", 0.0),        # EQ tolerance
        ("[3 GE 3]", 1.0),
        ("[3 LE 2]", 0.0),
        ("-[2]", -2.0),
        ("[-2 ** 2]", 4.0),               # unary binds tighter than **
        ("SQRT[16]", 4.0),
        ("ABS[-3.5]", 3.5),
        ("COS[60]", 0.5),
        ("SIN[90]", 1.0),
        ("TAN[45]", 1.0),
        ("ATAN[1]/[1]", 45.0),
        ("ATAN[1]/[-1]", 135.0),
        ("ACOS[0]", 90.0),
        ("ASIN[1]", 90.0),
        ("EXP[0]", 1.0),
        ("LN[1]", 0.0),
        ("FIX[-2.5]", -3.0),
        ("FUP[2.1]", 3.0),
        ("ROUND[2.5]", 3.0),
        ("ROUND[-2.5]", -3.0),
        ("[SQRT[12.0] * SQRT[3]]", 6.0),
    ],
)
def test_expression_values(expr, expected):
    assert value_of(expr) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize(
    "expr, word",
    [("[1/0]", "/"), ("SQRT[-1]", "SQRT"), ("LN[0]", "LN"), ("ACOS[2]", "ACOS"),
     ("[1 MOD 0]", "MOD"), ("[-8 ** 0.5]", "**")],
)
def test_expression_errors_name_the_operator(expr, word):
    e = err(f"G0 X1\n#1 = {expr}")
    assert e.line == 2 and e.word == word


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-50, 50), min_size=2, max_size=6),
       st.lists(st.sampled_from(["+", "-", "*"]), min_size=5, max_size=5))
def test_arithmetic_matches_python_precedence(nums, ops):
    expr = str(nums[0])
    for n, op in zip(nums[1:], ops, strict=False):
        expr += f" {op} {n}"
    assert value_of(f"[{expr}]") == eval(expr)  # noqa: S307 - integers and + - * only


@settings(max_examples=40, deadline=None)
@given(st.floats(-1e3, 1e3, allow_nan=False), st.floats(-1e3, 1e3, allow_nan=False))
def test_atan_matches_atan2_in_degrees(y, x):
    ys, xs = f"{y:.6f}", f"{x:.6f}"  # G-code has no exponent notation
    got = value_of(f"ATAN[{ys}]/[{xs}]")
    assert got == pytest.approx(math.degrees(math.atan2(float(ys), float(xs))), abs=1e-9)


# -- parameters --------------------------------------------------------------------------
def test_numbered_named_and_indirect_parameters():
    cmds = compile_text(
        "#1 = 5\n#2 = 1\n#<my var> = [#1 * 2]\n#<_g> = 3\n"
        "G0 X#<MYVAR> Y##2 Z#<_g>", OPTS)
    assert cmds[-1].end == (10.0, 5.0, 3.0)


def test_parameters_on_one_line_read_before_set():
    cmds = compile_text("#1 = 1\n#1 = 2 #2 = #1\nG0 X#1 Y#2", OPTS)
    assert cmds[-1].end[:2] == (2.0, 1.0)


def test_unset_numbered_is_zero_unset_named_is_error():
    assert compile_text("G0 X#77", OPTS)[-1].end[0] == 0.0
    e = err("G0 X1\nG0 X#<nope>")
    assert e.line == 2 and "#<nope>" in str(e) and e.column == 5


def test_parameter_number_out_of_range():
    e = err("#6000 = 1")
    assert "parameter number" in str(e)
    e = err("G0 X#[1.5]")
    assert "integer" in str(e)


def test_exists_and_initial_parameters():
    opts = GCodeOptions(axes={"X": 0}, parameters={100: 2.5})
    cmds = compile_text("#<a> = 1\nG0 X[EXISTS[#<a>] + EXISTS[#<b>] + #100]", opts)
    assert cmds[-1].end[0] == 3.5


def test_debug_and_print_substitute_parameters():
    cmds = compile_text("#<_vv> = 7\n#3 = 2\n(DEBUG, v=#<_ v v> p=#3 u=#<_zz>)\n(print,x)\n"
                        "(MSG, Hello World)", OPTS)
    assert [c.text for c in cmds] == ["v=7.000000 p=2.000000 u=######", "x", "Hello World"]
    assert [c.kind for c in cmds] == ["debug", "print", "msg"]


def test_plain_comments_kept_on_request():
    keep = GCodeOptions(axes={"X": 0}, keep_comments=True)
    cmds = compile_text("(hello)\nG0 X1 ; tail", keep)
    assert [c.text for c in cmds if hasattr(c, "kind")] == ["hello", " tail"]
    assert len(compile_text("(hello)\nG0 X1", OPTS)) == 1
