"""Programs LinuxCNC's interpreter refuses, refused here too (found by tests/lcnc_survey.py
running LinuxCNC's tests/interp as their test.sh runs them)."""

from __future__ import annotations

import pytest

from openmotion.program import GCodeError, GCodeOptions, compile_text

XYZ = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


@pytest.mark.parametrize("line", ["G38.2 F1", "G38.3 F10", "G81 R1 F100", "G73 R1 Q1 F1",
                                  "G33 K1", "G76 P1", "G5 F10"])
def test_a_motion_code_without_axis_words_is_refused(line):
    with pytest.raises(GCodeError, match="all axes missing with motion code") as e:
        compile_text(f"G21\n{line}\nM2\n", XYZ)
    assert e.value.line == 2


@pytest.mark.parametrize("line", ["G0", "G1 F100", "G2 F100", "G3"])
def test_g0_to_g3_may_stand_alone(line):
    compile_text(f"G21\n{line}\nM2\n", XYZ)


TABLE = "tests/gcode_oracle/tools.tbl"  # tools 1, 2, 3 and 5


@pytest.mark.parametrize("line, word", [("T4", "T4"), ("M61 Q4", "Q4"), ("G43 H4", "H4"),
                                        ("G43.2 H4", "H4"), ("G10 L1 P4 Z1", "P4"),
                                        ("G10 L10 P4 Z1", "P4")])
def test_a_tool_not_in_the_tool_table_is_refused(line, word):
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2}, tool_table=TABLE)
    with pytest.raises(GCodeError, match="requested tool 4 is not in the tool table") as e:
        compile_text(f"G21\n{line}\nM2\n", opts)
    assert e.value.line == 2 and word in str(e.value)


def test_tools_in_the_table_and_tool_0_are_accepted():
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2}, tool_table=TABLE)
    compile_text("G21\nT5 M6\nG43 H5\nM61 Q0\nT0 M6\nG10 L1 P2 Z1\nM2\n", opts)


def test_without_a_tool_table_every_tool_is_a_zero_tool():
    compile_text("G21\nT7 M6\nG43 H7\nG10 L1 P9 Z1\nT4\nM2\n", XYZ)


END = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2}, require_end=True)


@pytest.mark.parametrize("text", ["G0 X1\n", "%\nG0 X1\n", "O2 sub\nM2\nO2 endsub\nG0 X1\n"])
def test_require_end_refuses_a_file_without_program_end(text, tmp_path):
    from openmotion.program.stream import stream_file

    with pytest.raises(GCodeError, match="no percent sign or program end"):
        compile_text(text, END)
    f = tmp_path / "cut.ngc"
    f.write_text(text)
    with pytest.raises(GCodeError, match="no percent sign or program end"):
        list(stream_file(f, END))
    compile_text(text, XYZ)  # off by default: the text's end ends the program


@pytest.mark.parametrize("text", ["G0 X1\nM2\n", "G0 X1\nM30\nG0 X5\n", "\n%\nG0 X1\n%\n",
                                  "O2 sub\nM2\nO2 endsub\nO2 call\n", "G0 X1\nM99\n"])
def test_require_end_accepts_every_program_end(text):
    compile_text(text, END)


def test_run_refuses_a_truncated_file_unless_allowed(tmp_path, capsys):
    from openmotion.cli import main

    f = tmp_path / "cut.ngc"
    f.write_text("G21 G90\nG0 X1\n")
    assert main(["run", str(f), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "cut.ngc" in err and "no percent sign or program end" in err
    assert main(["run", str(f), "--out", str(tmp_path), "--allow-no-end"]) == 0


def test_a_subroutine_called_before_the_main_flow_reaches_it_is_refused():
    text = "O1\nG0 X1 Y2\nO2 call\nO2 sub\nG0 Z3\nO2 endsub\nM2\n"
    with pytest.raises(GCodeError, match="O2 sub found in an illegal location") as e:
        compile_text(text, XYZ)
    assert e.value.line == 4
    # defined before the call, or after the end of the main program: fine
    compile_text("O2 sub\nG0 Z3\nO2 endsub\nO2 call\nG0 X1\nM2\n", XYZ)
    compile_text("O2 call\nM2\nO2 sub\nG0 Z3\nO2 endsub\n", XYZ)


def test_ini_variables_are_read_only_and_undefined():
    with pytest.raises(GCodeError, match="read-only INI variable"):
        compile_text("#<_ini[vars]toolchange_x> = 3\nM2\n", XYZ)
    with pytest.raises(GCodeError, match="is not defined"):
        compile_text("G0 X#<_ini[vars]toolchange_x>\nM2\n", XYZ)
