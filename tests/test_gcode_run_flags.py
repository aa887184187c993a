"""`openmotion run` flags of the G-code runner: --probe-input / --probe-box (a simulated
probe and its workpiece) and --spindle-axis (the machine's spindle, or a simulated one)."""

from __future__ import annotations

import math

import pytest

from openmotion.cli import main
from openmotion.config import default_machine
from openmotion.errors import MotionError
from openmotion.program.runjob import parse_probe_boxes, with_spindle


def test_probe_boxes_parse_machine_units_with_open_bounds():
    (box,) = parse_probe_boxes(["X10:50 y8:38 Z:20"], "di0")
    assert box == {"X": (10.0, 50.0), "Y": (8.0, 38.0), "Z": (-math.inf, 20.0)}
    for bad in ["X10", "X5:1", "Q1:2", "X1:2 X3:4", "", "X1:2:3", "Xa:b"]:
        with pytest.raises(MotionError, match="--probe-box"):
            parse_probe_boxes([bad], "di0")
    with pytest.raises(MotionError, match="needs --probe-input"):
        parse_probe_boxes(["X1:2"], None)


def test_spindle_axis_is_added_only_when_the_machine_lacks_it():
    cfg = default_machine()
    more = with_spindle(cfg, "spindle")
    assert [a.name for a in more.axes][-1] == "spindle" and len(more.axes) == len(cfg.axes) + 1
    assert with_spindle(more, "spindle") is more
    assert with_spindle(cfg, None) is cfg
    with pytest.raises(MotionError, match="--spindle-axis"):
        with_spindle(cfg, " ")


def test_run_probes_the_box_given_on_the_command_line(tmp_path, capsys):
    prog = tmp_path / "touch.ngc"
    prog.write_text("G21 G90 G10 L2 P1 X0 Y0 Z0\nG0 X10 Y10 Z10\nG38.2 Z0 F600\n"
                    "(debug, #5063)\nG0 Z10\nM2\n")
    out = tmp_path / "out"
    rc = main(["run", str(prog), "--out", str(out), "--probe-input", "di0",
               "--probe-box", "X0:50 Y0:50 Z:6"])
    assert rc == 0
    assert "done" in capsys.readouterr().out
    # without the box nothing is touched: G38.2 fails as in LinuxCNC
    rc = main(["run", str(prog), "--out", str(out), "--probe-input", "di0"])
    assert rc == 1
    got = capsys.readouterr()
    assert "without making contact" in got.out + got.err


def test_run_with_a_spindle_axis_threads_against_it(tmp_path, capsys):
    prog = tmp_path / "thread.ngc"
    prog.write_text("G21 G90 G10 L2 P1 X0 Y0 Z0\nG0 X10 Y10 Z0\nS1200 M3\nG4 P0.6\n"
                    "G33 Z-3 K0.5\nM5\nM2\n")
    rc = main(["run", str(prog), "--out", str(tmp_path / "out"), "--spindle-axis", "spindle"])
    assert rc == 0
    assert "done" in capsys.readouterr().out
