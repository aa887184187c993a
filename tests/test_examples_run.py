"""Every shipped example program is valid on the shipped machine and runs green.

Compiling (ProgramRunner) checks every move against the soft limits with the work offsets
`openmotion run` uses, so a program that would leave the travel fails here in seconds; with
--long each one also runs to the end through `openmotion run`.
"""

from pathlib import Path

import pytest

from openmotion.cli import main
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.program.runjob import sets_work_offset, work_origin
from openmotion.program.runner import ProgramRunner, RunOptions

ROOT = Path(__file__).resolve().parent.parent / "examples"
PROGRAMS = sorted(p.relative_to(ROOT).as_posix() for p in ROOT.glob("*/*.ngc"))


def _probes(name: str) -> bool:
    """A probing program needs a probe wired to a board input (examples/gcode_probe.py
    places the workpiece and runs it)."""
    return "G38" in (ROOT / name).read_text().upper()


def test_the_examples_are_found():
    assert {"gcode/offsets_tour.ngc", "programs/cam_rose.ngc"} <= set(PROGRAMS)


@pytest.mark.parametrize("name", PROGRAMS)
def test_example_compiles_on_the_xyzu_table(name):
    ctl = Controller()
    path = ROOT / name
    params = {} if sets_work_offset(path.read_text()) else work_origin(ctl)
    options = RunOptions(probe_input="di0") if _probes(name) else None
    run = ProgramRunner(ctl, path, gcode={"parameters": params}, options=options)
    assert run.ops


@pytest.mark.parametrize("name", PROGRAMS)
def test_example_runs_green_via_openmotion_run(name, tmp_path, capsys, long_run):
    if not long_run:
        pytest.skip("full runs of every example with --long")
    if _probes(name):
        pytest.skip("a probing program runs with its workpiece: examples/gcode_probe.py")
    assert main(["run", str(ROOT / name), "--out", str(tmp_path)]) == 0
    assert "done" in capsys.readouterr().out


def test_soft_limit_error_names_letter_offset_and_calling_line():
    prog = ("G21 G90\nG10 L2 P2 X-60 Y10\no<sq> sub\n  G1 X20 F1000\no<sq> endsub\n"
            "G55\no<sq> call\nM2\n")
    with pytest.raises(MotionError) as info:
        ProgramRunner(Controller(), prog, gcode={})
    msg = str(info.value)
    assert "line 4" in msg and "X would reach machine -40" in msg
    assert "active offset G55 X-60" in msg and "o<sq> called at line 7" in msg
    assert "machine axis" not in msg
