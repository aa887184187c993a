"""The report draws in the program's units: the G20/G21 unit in force at the first motion,
carried from the interpreter's modal state (progunits.py) to the page."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.cli import main
from openmotion.program import GCodeOptions, compile_text
from openmotion.program.progunits import CompiledProgram, ProgramUnits
from pagecheck import array, figures

OPTS = GCodeOptions(axes={"X": 0, "Y": 1})
# an O-word that does nothing: the program takes the general interpreter, not the fast path
GENERAL = "#1 = 0\no9 if [#1 GT 1]\no9 endif\n"


@pytest.mark.parametrize("text, want", [
    ("G1 X1 F100\nM2\n", ProgramUnits("mm", False)),
    ("G20\nG1 X1 F10\nM2\n", ProgramUnits("inch", False)),
    ("G20 G1 X1 F10\nM2\n", ProgramUnits("inch", False)),     # G20 runs before the move
    ("G21\nG20\nG0 X1\nM2\n", ProgramUnits("inch", False)),   # changed before any motion
    ("G20\nG0 X1\nG21\nG1 X2 F100\nM2\n", ProgramUnits("inch", True)),
    ("G20\nG0 X1\nG20\nM2\n", ProgramUnits("inch", False)),   # the same unit again
    ("G20\nM2\n", ProgramUnits("inch", False)),               # nothing moves: the last one
])
def test_units_at_the_first_motion_on_both_interpreter_paths(text, want):
    for prog in (text, GENERAL + text):
        cmds = compile_text(prog, OPTS)
        assert isinstance(cmds, CompiledProgram) and cmds.units == want, prog


def test_a_unit_change_in_a_subroutine_counts_where_it_runs():
    # the sub (defined after the first motion's line) runs before it: G20 is in force there
    text = ("o100 sub\nG20\no100 endsub\no100 call\nG0 X1\nG21\nM2\n")
    assert compile_text(text, OPTS).units == ProgramUnits("inch", True)
    # M70/M72: the saved unit restored after the first motion is a switch
    text = "G21\nM70\nG20\nG0 X1\nM72\nG0 X2\nM2\n"
    assert compile_text(text, OPTS).units == ProgramUnits("inch", True)


_LINES = st.sampled_from(["G20", "G21", "G0 X1", "G1 X2 F10", "G20 G0 X3", "G21 G1 X4 F10",
                          "(note)", "G4 P0"])


@settings(max_examples=60, deadline=None)
@given(st.lists(_LINES, max_size=8))
def test_the_fast_path_and_the_general_path_agree_with_a_scan_of_the_lines(lines):
    text = "\n".join(lines) + "\nM2\n"
    units, first, switched = "mm", None, False
    for ln in lines:   # the oracle: a program without subroutines runs its lines in order
        u = "inch" if "G20" in ln else "mm" if "G21" in ln else None
        if first is None:
            units = u or units
            if "X" in ln:
                first = units
        elif u is not None and u != first:
            switched = True
    want = ProgramUnits(first or units, switched)
    assert compile_text(text, OPTS).units == want
    assert compile_text(GENERAL + text, OPTS).units == want


@pytest.fixture(scope="module")
def inch_page(tmp_path_factory):
    out = tmp_path_factory.mktemp("inch")
    prog = out / "inch.ngc"
    prog.write_text("G20 G90\nF40\nG0 X0 Y0\nG1 X1 Y0\nG1 X1 Y0.5 F20\nG2 X0.5 Y1 I-0.5 J0\n"
                    "G1 X0 Y0\nM2\n")
    assert main(["run", str(prog), "--out", str(out)]) == 0
    return (out / "inch.html").read_text()


def _extents(page: str) -> dict[str, list[float]]:
    table = re.search(r"<table id=extents>(.*?)</table>", page).group(1)
    rows = re.findall(r"<tr><td>(\w)</td>(.*?)</tr>", table)
    return {k: [float(x) for x in re.findall(r"<td class=num>([^<]*)</td>", c)]
            for k, c in rows}


def test_an_inch_program_is_drawn_in_inches_with_feeds_in_inches_per_minute(inch_page):
    page = inch_page
    assert "Extents (program coordinates, in or deg)" in page
    ext = _extents(page)
    # the cuts span 0..1 in; the machine (mm) puts program zero at 150, 100 mm and its
    # travel is +-155 / +-105 mm about it: in inches
    assert ext["X"][:2] == pytest.approx([0.0, 1.0], abs=1e-4)
    assert ext["Y"][:2] == pytest.approx([0.0, 1.0], abs=1e-4)
    assert ext["X"][2] == pytest.approx(-150 / 25.4, abs=1e-4)
    assert ext["X"][4:] == pytest.approx([-155 / 25.4, 155 / 25.4], abs=1e-4)
    figs = figures(page)
    path = figs["om-path"]
    feed = next(t for t in path["data"] if t["name"] == "feed")
    drawn = [c for c, x in zip(array(feed["marker"]["color"]), array(feed["x"]), strict=True)
             if x == x]   # the feed trace's points (NaN x: a rapid's, not drawn)
    assert {round(c, 3) for c in drawn} == {40.0, 20.0}
    assert path["layout"]["xaxis"]["title"]["text"] == "X (in, program)"
    box = next(t for t in path["data"] if t["name"] == "soft limits (travel)")
    xs = [x for x in array(box["x"]) if x == x]
    assert min(xs) == pytest.approx(-155 / 25.4) and max(xs) == pytest.approx(155 / 25.4)
    worst = next(t for t in path["data"] if t["name"].startswith("worst contour error"))
    assert " in (line" in worst["name"]
    speed = figs["om-fig1"]
    assert speed["layout"]["yaxis"]["title"]["text"] == "speed (in/min)"
    commanded = np.array(array(speed["data"][0]["y"]))
    assert set(np.round(commanded[~np.isnan(commanded)], 3)) == {40.0, 20.0}   # in/min
    assert "units (in, G20); feeds and speeds in in/min." in page
    assert "summary above is in machine units (mm)" in page
    assert "changes units after its first motion" not in page


def test_a_program_that_switches_units_says_so(tmp_path):
    prog = tmp_path / "mixed.ngc"
    prog.write_text("G20\nG0 X0.5\nG21\nG1 X20 F600\nM2\n")
    assert main(["run", str(prog), "--out", str(tmp_path)]) == 0
    page = (tmp_path / "mixed.html").read_text()
    assert "changes units after its first motion: drawn in the units in force at its first " \
           "motion" in page
    assert _extents(page)["X"][3] == pytest.approx(20 / 25.4, abs=1e-4)   # drawn in inches
    titles = {f["layout"].get("yaxis", {}).get("title", {}).get("text")
              for f in figures(page).values()}
    assert "speed (in/min)" in titles


@pytest.mark.parametrize("machine, program, label, k", [
    ("mm", "inch", "in", 1 / 25.4), ("inch", "mm", "mm", 25.4), ("mm", "mm", "mm", 1.0),
    ("inch", "inch", "in", 1.0)])
def test_drawn_units_scale_linear_axes_to_the_program_unit_and_keep_degrees(
        machine, program, label, k):
    from types import SimpleNamespace

    from openmotion.program.report_html import drawn_units

    run = SimpleNamespace(program_units=ProgramUnits(program), machine_units=machine,
                          scales=SimpleNamespace(rotary=np.array([False, False, True])))
    got, scale = drawn_units(run)
    assert got == label and scale.tolist() == pytest.approx([k, k, 1.0])


def test_a_command_list_is_drawn_in_machine_units():
    from openmotion.control import Controller
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    run = ProgramRunner(ctl, "G20\nG0 X1\nM2\n")
    assert run.program_units == ProgramUnits("inch")
    # canonical commands carry no unit: a list given to the runner is drawn as the machine's
    assert ProgramRunner(ctl, list(run.commands)).program_units == ProgramUnits("mm")


def test_an_endless_main_program_keeps_its_unit_log_flat():
    # M99 in the main program: each pass's commands are dropped, so is its unit log
    from openmotion.program.interp import Interpreter
    from openmotion.program.parser import parse_program

    s = Interpreter(parse_program("G20\nG0 X1\nG21\nG0 X0\nM99\n", "", 1000), OPTS).session()
    s.advance()
    for _ in range(50):
        s.advance(True)
        assert len(s._interp.modal.unit_log) <= 2
    assert compile_text("G20\nG0 X1\nG21\nG0 X0\nM99\n", OPTS).units == ProgramUnits("inch", True)
