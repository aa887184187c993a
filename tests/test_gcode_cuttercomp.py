"""Cutter compensation: geometry of a compensated square and the refusals.

Agreement with LinuxCNC on many shapes is in test_gcode_linuxcnc.py (cutter_comp_*.ngc)."""

from __future__ import annotations

import math

import pytest

from openmotion.program import ArcMove, Feed, GCodeError, GCodeOptions, compile_text
from openmotion.program.tooltable import Tool

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2},
                    tool_table={3: Tool(3, 3, diameter=2.0)})


def moves(text: str):
    return [c for c in compile_text(text, OPTS) if isinstance(c, (Feed, ArcMove))]


def test_outside_square_left_of_a_ccw_path_is_inside():
    # G42 (right of the path) around a CCW square puts the tool outside
    ms = moves("G0 X-5 Y-5\nT3 M6\nG42 D3\nG1 X0 Y0 F60\nX10\nY10\nX0\nY0\nG40 X-5 Y-5\n")
    ends = [tuple(round(v, 9) for v in m.end[:2]) for m in ms]
    # the entry ends 1 below the first side: the corner between the 45 deg entry and the
    # first side is concave for the tool, so the entry is cut back to tan(22.5 deg)
    assert ends[0] == pytest.approx((math.tan(math.pi / 8), -1.0))
    assert ends[1] == (10.0, -1.0)  # along the bottom, 1 below
    arc = ms[2]
    assert isinstance(arc, ArcMove) and arc.centre[:2] == (10.0, 0.0)
    assert arc.radius == pytest.approx(1.0) and arc.end[:2] == pytest.approx((11.0, 0.0))
    # each side 1 outside the square, an arc round every convex corner
    assert ends[3:8] == [(11.0, 10.0), (10.0, 11.0), (0.0, 11.0), (-1.0, 10.0), (-1.0, 0.0)]
    assert [type(m).__name__ for m in ms[2:8]] == ["ArcMove", "Feed"] * 3
    assert ms[-1].end[:2] == (-5.0, -5.0)  # exit move to the programmed point


def test_inside_square_concave_corners_meet():
    ms = moves("G0 X5 Y5\nG41.1 D2\nG1 X10 Y0 F60\nX10 Y10\nX0\nY0\nX10\nG40 G0 X5 Y5\n")
    ends = [m.end[:2] for m in ms]
    assert ends[1] == pytest.approx((9.0, 9.0))  # the corner pulled back to the bisector
    assert not any(isinstance(m, ArcMove) for m in ms)
    assert all(math.isfinite(v) for e in ends for v in e)


def test_refusals():
    with pytest.raises(GCodeError, match="tool 9 is not in the tool table"):
        compile_text("G41 D9\n", OPTS)
    with pytest.raises(GCodeError, match="already on"):
        compile_text("G41 D3\nG42 D3\n", OPTS)
    with pytest.raises(GCodeError, match="change tools"):
        compile_text("G41 D3\nT3 M6\n", OPTS)
    with pytest.raises(GCodeError, match="G28/G30"):
        compile_text("G41 D3\nG1 X5 F60\nG28\n", OPTS)
    with pytest.raises(GCodeError, match="canned cycles"):
        compile_text("G41 D3\nG1 X5 F60\nG81 X1 Z-1 R1\n", OPTS)
    with pytest.raises(GCodeError, match="entry arc"):
        compile_text("G41 D3\nG2 X0.5 I0.25 F60\n", OPTS)
    with pytest.raises(GCodeError, match="change planes"):
        compile_text("G41 D3\nG18\n", OPTS)
