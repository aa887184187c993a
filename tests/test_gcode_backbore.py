"""G87 back boring: the spindle steps around the motion (stop, orient, restart) in
LinuxCNC's order, the words (I J K sticky, K relative to the bottom in G91), refusals.

The motion itself is compared with LinuxCNC in test_gcode_linuxcnc.py (back_boring.ngc);
the run on a simulated spindle in test_gcode_spindle.py.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from openmotion.program import (
    Feed,
    GCodeError,
    GCodeOptions,
    Rapid,
    Spindle,
    compile_file,
    compile_text,
)
from openmotion.program.cycles import G87_ORIENT_TIMEOUT
from openmotion.program.orient import Orient

XYZ = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
HERE = Path(__file__).parent
ORACLE = HERE / "gcode_oracle" / "back_boring.ngc"


def steps(cmds) -> list[str]:
    """The canon steps as rs274 names them (motion, spindle start/stop, orientation)."""
    out = []
    for c in cmds:
        if isinstance(c, Rapid):
            out.append("TRAVERSE")
        elif isinstance(c, Feed):
            out.append("FEED")
        elif isinstance(c, Spindle):
            out.append(("CW" if c.clockwise else "CCW") if c.on else "STOP")
        elif isinstance(c, Orient):
            out.append(f"ORIENT{c.mode}")
    return out


def rs274_steps(listing: str) -> list[str]:
    names = {"STRAIGHT_TRAVERSE": "TRAVERSE", "STRAIGHT_FEED": "FEED",
             "START_SPINDLE_CLOCKWISE": "CW", "START_SPINDLE_COUNTERCLOCKWISE": "CCW",
             "STOP_SPINDLE_TURNING": "STOP"}
    out = []
    for m in re.finditer(r"N\.+ (\w+)\(([^)]*)\)", listing):
        name, args = m.groups()
        if name in names:
            out.append(names[name])
        elif name == "ORIENT_SPINDLE":  # LinuxCNC passes its direction enum (2 CW, 3 CCW)
            out.append(f"ORIENT{int(args.split(',')[-1]) - 2}")
    return out


def test_spindle_steps_in_linuxcnc_order():
    lcnc = pytest.importorskip("lcnc_oracle")
    exe = lcnc.rs274_path()
    if exe is None:
        pytest.skip("LinuxCNC rs274 is not installed")
    text = ORACLE.read_text()
    theirs = lcnc.run_rs274(text, exe)
    assert theirs.error is None
    ours = steps(compile_text(text, lcnc.OPTIONS))
    theirs_steps = rs274_steps(theirs.listing)
    # the program ends M5 M2: rs274 prints a stop for each, openmotion's M2 finds it off
    assert theirs_steps[-2:] == ["STOP", "STOP"] and ours[-1] == "STOP"
    assert ours == theirs_steps[:-1]
    assert ours.count("ORIENT0") > 0 and ours.count("ORIENT1") > 0


def test_one_hole_moves_and_steps():
    cmds = compile_text("G21 S500 M3 F120\nG0 X0 Y0 Z10\n"
                        "G98 G87 X5 Y6 R2 Z-10 I1.5 J0.5 K-6\n", XYZ)
    moves = [(type(c).__name__, c.end) for c in cmds if isinstance(c, Rapid | Feed)]
    assert moves[1:] == [
        ("Rapid", (5.0, 6.0, 10.0)), ("Rapid", (5.0, 6.0, 2.0)),
        ("Rapid", (6.5, 6.5, 2.0)), ("Rapid", (6.5, 6.5, -10.0)),
        ("Rapid", (5.0, 6.0, -10.0)), ("Feed", (5.0, 6.0, -6.0)),
        ("Feed", (5.0, 6.0, -10.0)), ("Rapid", (6.5, 6.5, -10.0)),
        ("Rapid", (6.5, 6.5, 10.0)), ("Rapid", (5.0, 6.0, 10.0))]
    orients = [c for c in cmds if isinstance(c, Orient)]
    assert orients == [Orient(0.0, 0, G87_ORIENT_TIMEOUT, 3)] * 2
    assert [c.feed_per_s for c in cmds if isinstance(c, Feed)] == [2.0, 2.0]
    assert steps(cmds)[-1] == "CW"  # the spindle turns again after the cycle


def test_sticky_ijk_and_incremental_k_from_the_bottom():
    cmds = compile_text("G21 S500 M4 F120\nG0 X0 Y0 Z10\n"
                        "G87 X5 Y6 R2 Z-10 I1 J0 K-6\nG91 X3 R1 Z-5 K2\n", XYZ)
    feeds = [c.end for c in cmds if isinstance(c, Feed)]
    # second hole: R = 10 + 1, bottom = 11 - 5 = 6, back bore up to 6 + 2; I J kept
    assert feeds[2:] == [(8.0, 6.0, 8.0), (8.0, 6.0, 6.0)]
    rapids = [c.end for c in cmds if isinstance(c, Rapid)]
    assert (9.0, 6.0, 6.0) in rapids  # offset point at the bottom: hole + I1
    assert {c.mode for c in cmds if isinstance(c, Orient)} == {1}  # M4: counterclockwise


def test_g18_uses_k_i_offsets_and_j_height():
    cmds = compile_text("G21 S500 M3 F120 G18\nG0 X0 Y10 Z0\n"
                        "G87 Z5 X6 R2 Y-10 I1 J-6 K0.5\n", XYZ)
    feeds = [c.end for c in cmds if isinstance(c, Feed)]
    assert feeds == [(6.0, -6.0, 5.0), (6.0, -10.0, 5.0)]
    assert (7.0, -10.0, 5.5) in [c.end for c in cmds if isinstance(c, Rapid)]


@pytest.mark.parametrize("line, word, msg", [
    ("G87 X1 Y1 R2 Z-5 J0.5 K-3", "G87", "G87 needs I"),
    ("G87 X1 Y1 R2 Z-5 I0.5 J0.5", "G87", "G87 needs K"),
    ("G87 X1 Y1 Z-5 I0.5 J0.5 K-3", "G87", "needs R"),
    ("G87 X1 Y1 R2 I0.5 J0.5 K-3", "G87", "needs Z"),
])
def test_missing_words_name_file_line_column_word(tmp_path, line, word, msg):
    p = tmp_path / "bore.ngc"
    p.write_text(f"G21 S500 M3 F100\nG0 Z5\n  {line}\nM2\n")
    with pytest.raises(GCodeError, match=msg) as info:
        compile_file(p, XYZ)
    e = info.value
    assert (e.line, e.column, e.word) == (3, 3, word) and e.file.endswith("bore.ngc")


def test_refused_without_spindle_or_in_another_cycle_or_g93():
    with pytest.raises(GCodeError, match="G87 needs the spindle turning"):
        compile_text("G21 F100\nG0 Z5\nG87 X1 Y1 R2 Z-5 I0.5 J0 K-3\n", XYZ)
    with pytest.raises(GCodeError, match="G87 needs the spindle turning"):
        compile_text("G21 F100 S500 M3\nG0 Z5\nG87 X1 Y1 R2 Z-5 I0.5 J0 K-3\nM5\nX3\n", XYZ)
    with pytest.raises(GCodeError, match="G87 needs I"):  # I J K sticky only within G87
        compile_text("G21 F100 S500 M3\nG0 Z5\nG87 X1 Y1 R2 Z-5 I0.5 J0 K-3\n"
                     "G81 X2 Z-1 R2\nG87 X3 R2 Z-5\n", XYZ)
    with pytest.raises(GCodeError, match="inverse time"):
        compile_text("G21 G93 S500 M3\nG0 Z5\nG87 X1 Y1 R2 Z-5 I0.5 J0 K-3 F10\n", XYZ)
