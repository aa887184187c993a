"""O-word control flow (sub/call/return, if, while, do, repeat, break, continue) and
corpus-style programs written for these tests (CAM surfacing, R-form spirals, recursion,
inverse-time subroutines, program framing)."""

from __future__ import annotations

import math

import pytest

from openmotion.program import (
    ArcMove,
    End,
    Feed,
    GCodeError,
    GCodeOptions,
    Message,
    Pause,
    Rapid,
    SetBlend,
    Spindle,
    ToolChange,
    compile_file,
    compile_text,
)

XY = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


def xs(text: str, opts: GCodeOptions = XY) -> list[float]:
    return [c.end[0] for c in compile_text(text, opts) if isinstance(c, (Rapid, Feed))]


def err(text: str, opts: GCodeOptions = XY) -> GCodeError:
    with pytest.raises(GCodeError) as info:
        compile_text(text, opts)
    return info.value


def test_sub_call_arguments_locals_and_return_value():
    prog = """
o<add> sub
  #<tmp> = [#1 + #2]
  o<add> return [#<tmp>]
o<add> endsub
#1 = 100
#<tmp> = 5
o<add> call [3] [4]
G0 X#<_value> Y#1 Z#<tmp>
"""
    assert compile_text(prog, XY)[-1].end == (7.0, 100.0, 5.0)  # #1 and #<tmp> restored


def test_sub_defined_after_use_and_endsub_value():
    prog = "O10 call [2]\nG0 X#<_value>\nM2\nO10 sub\nG0 X#1\nO10 endsub [#1 * 10]\n"
    assert xs(prog) == [2.0, 20.0]


def test_if_elseif_else():
    prog = """
o1 sub
  o2 if [#1 LT 0]
    G0 X-1
  o2 elseif [#1 EQ 0]
    G0 X0
  o2 elseif [#1 LT 10]
    G0 X1
  o2 else
    G0 X2
  o2 endif
o1 endsub
o1 call [-5]
o1 call [0]
o1 call [5]
o1 call [50]
"""
    assert xs(prog) == [-1.0, 0.0, 1.0, 2.0]


def test_while_do_repeat_break_continue():
    prog = """
#1 = 0
o1 while [#1 LT 3]
  G0 X#1
  #1 = [#1 + 1]
o1 endwhile
o2 do
  G0 X[10 + #1]
  #1 = [#1 - 1]
o2 while [#1 GT 1]
o3 repeat [3]
  G0 X20
o3 endrepeat
#2 = 0
o4 while [1]
  #2 = [#2 + 1]
  o5 if [#2 EQ 2]
    o4 continue
  o5 endif
  G0 X[30 + #2]
  o6 if [#2 GE 4]
    o4 break
  o6 endif
o4 endwhile
o7 repeat [0]
  G0 X99
o7 endrepeat
"""
    assert xs(prog) == [0, 1, 2, 13, 12, 20, 20, 20, 31, 33, 34]


def test_repeat_inside_a_called_sub_restarts_each_call():
    prog = "o1 sub\no2 repeat [2]\nG0 X#1\no2 endrepeat\no1 endsub\no1 call [1]\no1 call [2]"
    assert xs(prog) == [1, 1, 2, 2]


def test_recursion_like_flowsnake():
    prog = """
o100 sub
  o101 if [#1 EQ 0]
    G1 X#2 F100
  o101 else
    o100 call [#1 - 1] [#2 + 1]
    o100 call [#1 - 1] [#2 + 2]
  o101 endif
o100 endsub
o100 call [4] [0]
"""
    assert len(xs(prog)) == 16


def test_recursion_limit():
    e = err("o1 sub\no1 call\no1 endsub\no1 call", GCodeOptions(axes={"X": 0},
                                                              max_call_depth=10))
    assert e.line == 2 and "nested deeper than 10" in str(e)


def test_endless_loop_is_an_error_not_a_hang():
    e = err("o1 while [1]\nG0 X1\no1 endwhile", GCodeOptions(axes={"X": 0}, max_blocks=5000))
    assert "endless loop" in str(e)


@pytest.mark.parametrize(
    "prog, line, fragment",
    [
        ("o1 if [1]\nG0 X1\n", 1, "never closed"),
        ("o1 if [1]\no2 endif", 2, "without a matching"),
        ("o1 endwhile", 1, "without a matching"),
        ("o1 while [1]\no2 break\no1 endwhile", 2, "outside an O2 loop"),
        ("o1 return", 1, "outside a subroutine"),
        ("o1 sub\no2 sub\no2 endsub\no1 endsub", 2, "inside another"),
        ("o1 sub\no1 endsub\no1 sub\no1 endsub", 3, "defined twice"),
        ("G0 X1\no9 call [1]", 2, "not defined"),
        ("o1 if [1]\no1 else\no1 elseif [1]\no1 endif", 3, "after else"),
        ("o1 foo", 1, "unknown O-word keyword"),
        ("o1 if", 1, "needs one"),
        ("o1 sub [1]", 1, "takes no expression"),
        ("o1 if [1] G0 X1\no1 endif", 1, "unexpected text"),
        ("G54 o1 call", 1, "alone on its line"),
    ],
)
def test_structure_errors_found_before_running(prog, line, fragment):
    e = err("G0 X5\n" + prog)  # the G0 before would be the first motion: nothing returned
    assert e.line == line + 1 and fragment in str(e)


def test_if_condition_errors_name_the_o_word():
    e = err("o1 if [#<undefined> GT 1]\no1 endif")
    assert e.line == 1 and "#<undefined>" in str(e)


# -- corpus-style programs ---------------------------------------------------------------
def test_cam_surfacing_style():
    prog = """( surfacing, scaled by parameters )
#<xscale> = 2.0
#<fscale> = 10.0
#<toolno> = 1
#<rpm> = 1600
N30 G21
N40G90
G64P.1
N50T#<toolno>M6
N60M8
N70S#<rpm>M3
N90G0Z[10.]
N100G1Z[-2.5]F[#<fscale>*60]
N120X[#<xscale>*1.5]Y-1.25
N130Y[-1.0]Z-2.4
N140M5M9
N150M30
"""
    cmds = compile_text(prog, XY)
    kinds = [type(c).__name__ for c in cmds]
    assert kinds == ["SetBlend", "ToolChange", "Coolant", "Spindle", "Rapid", "Feed", "Feed",
                     "Feed", "Spindle", "Coolant", "End"]
    assert cmds[0] == SetBlend("blend", 0.1, 8)
    assert cmds[1] == ToolChange(1, 9)
    assert cmds[3] == Spindle(True, True, 1600.0, None, 11)
    assert cmds[6].end == (3.0, -1.25, -2.5) and cmds[6].feed_per_s == 10.0
    assert cmds[-1] == End(True, 17)


def test_inch_r_form_spiral_style():
    lines = ["g20 g64", "g0 x1 y0 z.1", "g1 z-.1 f24", "g2 r1 x0 y-1"]
    r = 1.0
    ang = -90.0
    for _ in range(20):
        r -= 0.002
        ang -= 15.0
        lines.append(f"r{r:.6f} x{r * math.cos(math.radians(ang)):.6f} "
                     f"y{r * math.sin(math.radians(ang)):.6f}")
    lines.append("m2")
    cmds = compile_text("\n".join(lines), XY)
    arcs = [c for c in cmds if isinstance(c, ArcMove)]
    assert len(arcs) == 21
    assert all(a.feed_per_s == pytest.approx(24 * 25.4 / 60) for a in arcs)
    assert arcs[0].end == pytest.approx((0.0, -25.4, -2.54))


def test_inverse_time_subroutine_style():
    prog = """G20
O100 sub ([scale])
  #61=#1
  G0 X0Y0Z0A0
  G93
O100 endsub
O200 sub ([t] [x])
  #41=[#2*#1/#61]
  G1 X#41 A#41 F[60/#1]
O200 endsub
O100 call [2]
G4P2
O200 call [0.5] [4]
O200 call [2] [1]
M2
%
"""
    cmds = compile_text(prog, GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}))
    feeds = [c for c in cmds if isinstance(c, Feed)]
    assert [f.duration for f in feeds] == [0.5, 2.0]
    assert feeds[0].end == (1.0 * 25.4, 0.0, 0.0, 1.0)  # A in degrees, X in inches
    assert feeds[1].end == (1.0 * 25.4, 0.0, 0.0, 1.0)


def test_program_skeleton_style():
    prog = """(program skeleton)
N0010 G17 G20 G40 G49
N0020 G54 G80 G90 G94
N0030 G53 G0 Z0
N0040 X0 Y0
N0050 M05 M09
N0060 (MSG,Load tool #1)
N0070 M00
N0080 T1 M06 G43 H1
N0090 G04 P.001 G0 X1.0 Y1.0 S1000 M3 M8
N0100 M01
N0110 M2
"""
    cmds = compile_text(prog, XY)
    assert Message("Load tool #1", "msg", 7) in cmds
    assert Pause(False, 8) in cmds and Pause(True, 11) in cmds
    assert [c.end for c in cmds if isinstance(c, Rapid)][-1] == (25.4, 25.4, 0.0)


@pytest.mark.parametrize("name", ["laser_square", "flowsnake_lite", "bolt_circle", "helix_drill",
                                  "offsets_tour"])
def test_shipped_examples_compile(name):
    import pathlib

    path = pathlib.Path(__file__).resolve().parents[1] / "examples" / "gcode" / f"{name}.ngc"
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2}, soft_limits=[(-200, 200)] * 3)
    cmds = compile_file(path, opts)
    assert isinstance(cmds[-1], End)
    assert all(c.file == str(path) for c in cmds)


# -- Fanuc-style programs, computed labels, subroutine files ---------------------------------
def test_m98_repeats_shares_numbered_parameters_and_m99_returns():
    prog = "#1=0\nM98 P7 L3\nG0 X#1\nM98 P7 L0\nM30\nO7\n#1=[#1+1]\nG0 X[#1*10]\nM99\n"
    assert xs(prog) == [10.0, 20.0, 30.0, 3.0]
    assert "cutter compensation" in str(err("G41.1 D1\nG1 X1 F9\nM99\n"))  # main M99
    e = err("M98 P[2.5]\nM30\n")
    assert "integer" in str(e) and e.line == 1


def test_bare_o_line_is_a_label_when_reached():
    assert xs("O42 (program title)\nG0 X1\nM30\n") == [1.0]


def test_computed_call_labels():
    prog = "o10 sub\nG0 X#1\no10 endsub\n#2=5\no[#2*2] call [4]\nM2\n"
    assert xs(prog) == [4.0]
    e = err("o[#2+1] sub\no1 endsub\n")
    assert "only allowed with call" in str(e)
    e = err("o[7] call\nM2\n")
    assert "O7" in str(e) and "7.ngc" in str(e)


def test_subroutine_files_on_the_path(tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "Square.ngc").write_text("o<square> sub\nG1 X#1 F100\nG1 X0\no<square> endsub\n")
    (lib / "junk.ngc").write_text("G0 X9\no<junk> sub\no<junk> endsub\n")
    (lib / "other.ngc").write_text("o<something> sub\no<something> endsub\n")
    opts = GCodeOptions(axes={"X": 0}, subroutine_path=[lib])
    assert xs("o<square> call [5]\nM2\n", opts) == [5.0, 0.0]
    e = err("o<nosuch> call\nM2\n", opts)
    assert "nosuch.ngc" in str(e) and str(lib) in str(e)
    e = err("o<other> call\nM2\n", opts)
    assert "does not define" in str(e)
    # code outside the sub in its file is never run (LinuxCNC), even when the main
    # program has no M2
    assert xs("o<junk> call\n", opts) == []
    from openmotion.errors import MotionError

    with pytest.raises(MotionError, match="subroutine_path"):
        GCodeOptions(axes={"X": 0}, subroutine_path=str(lib))
