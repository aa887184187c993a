"""Canned cycles: the records around the motion (dwells, spindle, blend) and errors.

The motion itself is compared with LinuxCNC in test_gcode_linuxcnc.py (canned_cycles.ngc).
"""

from __future__ import annotations

import pytest

from openmotion.program import (
    Dwell,
    Feed,
    GCodeError,
    GCodeOptions,
    Pause,
    Rapid,
    SetBlend,
    Spindle,
    compile_text,
)

XYZ = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


def run(text: str):
    return compile_text(text, XYZ)


def test_g81_moves_and_exact_path_around_the_cycle():
    cmds = run("G64 P0.1\nG0 Z10\nG99 G81 X1 Y2 Z-1 R2 F60\n")
    kinds = [type(c).__name__ for c in cmds]
    assert kinds == ["SetBlend", "Rapid", "SetBlend", "Rapid", "Rapid", "Feed", "Rapid",
                     "SetBlend"]
    assert cmds[2] == SetBlend("exact_path", None, 3)
    assert cmds[-1].mode == "blend" and cmds[-1].tolerance == pytest.approx(0.1)
    assert [c.end for c in cmds if isinstance(c, (Rapid, Feed))][1:] == [
        (1.0, 2.0, 10.0), (1.0, 2.0, 2.0), (1.0, 2.0, -1.0), (1.0, 2.0, 2.0)]
    assert cmds[5].feed_per_s == pytest.approx(1.0)


def test_g98_returns_to_the_initial_level_of_the_series():
    cmds = run("G0 Z10\nG98 G81 X1 Z-1 R2 F60\nX2\nG80\nG0 Z5\nG81 X3 Z-1 R2\n")
    z = [c.end[2] for c in cmds if isinstance(c, Rapid)]
    assert z == [10.0, 10.0, 2.0, 10.0, 10.0, 2.0, 10.0, 5.0, 5.0, 2.0, 5.0]


def test_dwell_spindle_and_g88_pause():
    cmds = run("S500 M3\nG0 Z5\nG86 X1 Z-1 R1 P0.5 F60\n")
    recs = [c for c in cmds if isinstance(c, (Dwell, Spindle))][1:]
    assert recs[0] == Dwell(0.5, 3)
    assert [r.on for r in recs[1:]] == [False, True]
    cmds = run("S500 M3\nG0 Z5\nG99 G88 X1 Z-1 R1 P0.5 F60\n")
    names = [type(c).__name__ for c in cmds[3:]]
    # to the hole, down to R, feed down, dwell, spindle off, pause (the operator),
    # rapid out (ours, see docs), spindle on
    assert names == ["Rapid", "Rapid", "Feed", "Dwell", "Spindle", "Pause", "Rapid",
                     "Spindle", "SetBlend"]
    assert isinstance(cmds[-4], Pause) and cmds[-3].end[2] == 1.0


def test_cycle_errors_name_the_word_and_nothing_runs():
    with pytest.raises(GCodeError) as info:
        run("G0 Z5\nG81 X1 Z-1 F60\n")
    assert info.value.line == 2 and "needs R" in str(info.value)
    with pytest.raises(GCodeError, match="L0"):
        run("G81 X1 Z-1 R1 L0 F60\n")
    with pytest.raises(GCodeError, match="Q"):
        run("G83 X1 Z-1 R1 F60\n")
    with pytest.raises(GCodeError, match="below the bottom"):
        run("G81 X1 Z2 R1 F60\n")
    with pytest.raises(GCodeError, match="G84 needs the spindle turning"):
        run("G84 X1 Z-1 R1 F60\n")
    # sticky R and Z only within the same cycle
    with pytest.raises(GCodeError, match="needs R"):
        run("G81 X1 Z-1 R1 F60\nG82 X2 P1\n")
