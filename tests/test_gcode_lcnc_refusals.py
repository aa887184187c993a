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
