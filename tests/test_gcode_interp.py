"""Modal semantics of openmotion.program: motion words, arcs, offsets, units, I/O, errors."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.path import Direction
from openmotion.program import (
    ArcMove,
    Coolant,
    Dwell,
    End,
    Feed,
    GCodeError,
    GCodeOptions,
    Pause,
    Rapid,
    SetBlend,
    SetOutput,
    Spindle,
    ToolChange,
    compile_text,
)

XYZ = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
XYZA = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3})


def run(text: str, opts: GCodeOptions = XYZ):
    return compile_text(text, opts)


def last_end(text: str, opts: GCodeOptions = XYZ):
    moves = [c for c in run(text, opts) if isinstance(c, (Rapid, Feed, ArcMove))]
    return moves[-1].end


def err(text: str, opts: GCodeOptions = XYZ) -> GCodeError:
    with pytest.raises(GCodeError) as info:
        run(text, opts)
    return info.value


def close(a, b, tol=1e-9):
    return all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


# -- straight moves, feed, modes ---------------------------------------------------------
def test_rapid_feed_modal_motion_and_feed_units():
    cmds = run("G21 G90\nG0 X1 Y2\nG1 Z-1 F600\nX3\nM2")
    assert cmds[0] == Rapid((1.0, 2.0, 0.0), 2)
    assert cmds[1] == Feed((1.0, 2.0, -1.0), 10.0, 3)   # 600 mm/min = 10 mm/s
    assert cmds[2] == Feed((3.0, 2.0, -1.0), 10.0, 4)   # modal G1 and F
    assert cmds[3] == End(False, 5)


def test_incremental_and_absolute():
    assert last_end("G91 G0 X1 Y1\nX1\nG90 X5") == (5.0, 1.0, 0.0)
    assert last_end("G0 X1\nG91 X2 Y-1\nX2") == (5.0, -1.0, 0.0)


def test_start_position_and_axis_mapping_order():
    opts = GCodeOptions(axes={"X": 1, "Y": 0, "Z": 3}, n_axes=4, start=(5, 6, 7, 8))
    assert last_end("G0 X1", opts) == (5.0, 1.0, 7.0, 8.0)
    assert last_end("G91 G0 Z1 Y1", opts) == (6.0, 6.0, 7.0, 9.0)


def test_missing_feed_for_g1_is_an_error():
    e = err("G0 X1\nG1 X2")
    assert (e.line, e.word) == (2, "G1") and "feed" in str(e)
    e = err("G1 X2 F0")
    assert "feed" in str(e)


def test_inverse_time_feed():
    cmds = run("G93 G1 X3 Y4 F30\nG1 X3 Y4 A90 F60\nG1 A0 F2", XYZA)
    assert cmds[0].duration == 2.0 and cmds[0].feed_per_s == pytest.approx(2.5)
    assert cmds[2].duration == 30.0 and cmds[2].feed_per_s == pytest.approx(3.0)  # rotary
    e = err("G93 G1 X3 F30\nG1 X4")
    assert e.line == 2 and "G93" in str(e)


def test_units_inch_converted_and_rotary_not_scaled():
    cmds = run("G20 G0 X1 A10\nG1 Y1 F60\nG21 G0 X1", XYZA)
    assert cmds[0].end == (25.4, 0.0, 0.0, 10.0)
    assert cmds[1].feed_per_s == pytest.approx(25.4)
    assert cmds[2].end[0] == 1.0
    inch_machine = GCodeOptions(axes={"X": 0}, machine_units="inch")
    assert last_end("G21 G0 X25.4", inch_machine) == (1.0,)


def test_dwell_blend_pause_end():
    cmds = run("G4 P0.5\nG61\nG61.1\nG64\nG64 P0.02 Q0.01\nM0\nM1\nM30\nG0 X9")
    assert cmds[0] == Dwell(0.5, 1)
    assert [(c.mode, c.tolerance) for c in cmds[1:5]] == [
        ("exact_path", None), ("exact_stop", None), ("blend", None), ("blend", 0.02)]
    assert cmds[4].naive_cam == 0.01
    assert cmds[5:] == [Pause(False, 6), Pause(True, 7), End(True, 8)]  # X9 never runs


def test_g64_tolerance_in_inches():
    cmds = run("G20 G64 P0.001")
    assert isinstance(cmds[0], SetBlend) and cmds[0].tolerance == pytest.approx(0.0254)


def test_spindle_coolant_tool_outputs():
    opts = GCodeOptions(axes={"X": 0}, spindle_output=3, mist_output=4, flood_output=5,
                        n_outputs=8)
    cmds = run("S1000 M3\nS2000\nM4\nM5\nM7 M8\nM9\nT2 M6\nM62 P1\nM63 P1\nM64 P7\nM65 P0",
               opts)
    assert cmds[0] == Spindle(True, True, 1000.0, 3, 1)
    assert cmds[1] == Spindle(True, True, 2000.0, 3, 2)
    assert cmds[2] == Spindle(True, False, 2000.0, 3, 3)
    assert cmds[3] == Spindle(False, False, 2000.0, 3, 4)
    assert cmds[4] == Coolant(True, True, 4, 5, 5)
    assert cmds[5] == Coolant(False, False, 4, 5, 6)
    assert cmds[6] == ToolChange(2, 7)
    assert cmds[7:] == [SetOutput(1, True, True, 8), SetOutput(1, False, True, 9),
                        SetOutput(7, True, False, 10), SetOutput(0, False, False, 11)]
    e = err("M62 P8", opts)
    assert e.word == "P8"
    e = err("M62")
    assert e.word == "M62"


def test_order_of_execution_within_a_line():
    cmds = run("G0 X1 M2 S100 M3 G4 P1 (MSG,hi)")
    kinds = [type(c).__name__ for c in cmds]
    assert kinds == ["Message", "Spindle", "Dwell", "Rapid", "End"]


# -- offsets -----------------------------------------------------------------------------
def test_work_offsets_from_parameters_and_g10():
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2},
                        parameters={5221: 10.0, 5242: 20.0})  # G54 X, G55 Y
    assert last_end("G54 G0 X1 Y1", opts) == (11.0, 1.0, 0.0)
    assert last_end("G55 G0 X1 Y1", opts) == (1.0, 21.0, 0.0)
    assert last_end("G10 L2 P3 X5 Z-2\nG56 G0 X0 Y0 Z0", opts) == (5.0, 0.0, -2.0)
    # L20: the current position becomes the given value in that system
    assert last_end("G0 X7\nG10 L20 P1 X0\nG0 X1", opts) == (18.0, 0.0, 0.0)
    assert last_end("G59.3 G0 X1\nG10 L2 P0 X100\nG0 X1", opts) == (101.0, 0.0, 0.0)


def test_g92_family():
    assert last_end("G0 X10\nG92 X0\nG0 X5") == (15.0, 0.0, 0.0)
    assert last_end("G0 X10\nG92 X0\nG92.1\nG0 X5") == (5.0, 0.0, 0.0)
    assert last_end("G0 X10\nG92 X0\nG92.2\nG0 X5\nG92.3\nG0 X1") == (11.0, 0.0, 0.0)
    # the offset is stored in #5211 and readable
    assert last_end("G0 X10\nG92 X4\nG0 X#5211") == (12.0, 0.0, 0.0)
    e = err("G92")
    assert e.word == "G92"


def test_g53_machine_coordinates():
    opts = GCodeOptions(axes={"X": 0, "Z": 2}, n_axes=3, parameters={5221: 50.0})
    assert last_end("G0 X1\nG53 G0 X2\nX3", opts) == (53.0, 0.0, 0.0)
    assert last_end("G1 F100\nG53 X2", opts) == (2.0, 0.0, 0.0)
    e = err("G91 G53 G0 X1", opts)
    assert e.word == "G53"
    e = err("G53 G2 X1 I1 F10", opts)
    assert "G0 or G1" in str(e)


def test_g28_g30():
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2},
                        parameters={5161: 1.0, 5162: 2.0, 5163: 3.0, 5183: 9.0})
    cmds = run("G0 X5 Y5 Z5\nG28", opts)
    assert cmds[-1] == Rapid((1.0, 2.0, 3.0), 2)
    cmds = run("G0 X5 Y5 Z5\nG28 Z7", opts)  # via Z7, then only Z goes home
    assert [c.end for c in cmds[-2:]] == [(5.0, 5.0, 7.0), (5.0, 5.0, 3.0)]
    cmds = run("G0 X5 Y5 Z5\nG30 Z1", opts)
    assert cmds[-1].end == (5.0, 5.0, 9.0)
    cmds = run("G0 X4 Y4\nG28.1\nG0 X0 Y0\nG28", opts)
    assert cmds[-1].end == (4.0, 4.0, 0.0)
    e = err("G28 G1 X1 F5", opts)
    assert "two commands" in str(e)


def test_tool_length_offset():
    opts = GCodeOptions(axes={"X": 0, "Z": 1}, tool_lengths={1: 10.0})
    assert last_end("T1 M6 G43\nG0 Z0", opts) == (0.0, 10.0)
    assert last_end("G43 H1\nG0 Z1\nG49\nG0 Z1", opts) == (0.0, 1.0)
    with pytest.raises(GCodeError, match="requested tool 5 is not in the tool table"):
        last_end("G43 H5\nG0 Z1", opts)  # LinuxCNC refuses a tool not in the table


# -- arcs --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "plane, words, end, centre, axes",
    [
        ("G17", "X10 Y10 I10 J0", (10.0, 10.0, 0.0), (10.0, 0.0, 0.0), (0, 1)),
        ("G18", "X10 Z10 I0 K10", (10.0, 0.0, 10.0), (0.0, 0.0, 10.0), (2, 0)),
        ("G19", "Y10 Z10 J10 K0", (0.0, 10.0, 10.0), (0.0, 10.0, 0.0), (1, 2)),
    ],
)
def test_arcs_in_three_planes(plane, words, end, centre, axes):
    arc = run(f"{plane} G2 {words} F60")[0]
    assert isinstance(arc, ArcMove)
    assert arc.end == end and close(arc.centre, centre)
    assert arc.plane == axes and arc.direction is Direction.CW
    assert arc.radius == pytest.approx(10.0) and arc.feed_per_s == 1.0
    path = arc.to_path()
    assert close(path.point(path.length), end)
    # a quarter circle CW: sweep pi/2, midpoint on the circle
    assert arc.sweep == pytest.approx(math.pi / 2)
    mid = path.point(path.length / 2)
    assert math.dist(mid, centre) == pytest.approx(10.0)


def test_g17_cw_goes_the_right_way():
    arc = run("G2 X10 Y10 I10 F60")[0]
    path = arc.to_path()
    mid = path.point(path.length / 2)
    # CW from (0,0) about (10,0) to (10,10) passes through x < 10, y > 0 (the left-upper)
    assert mid[0] == pytest.approx(10 - 10 / math.sqrt(2))
    assert mid[1] == pytest.approx(10 / math.sqrt(2))


def test_r_form_short_and_long_arcs():
    short = run("G2 X10 Y0 R-5.0 F60\n")[0]   # exactly half circle either way
    assert short.sweep == pytest.approx(math.pi)
    cw = run("G2 X10 R10 F60")[0]
    assert close(cw.centre[:2], (5.0, -math.sqrt(75)))
    assert cw.sweep == pytest.approx(math.pi / 3)
    ccw = run("G3 X10 R10 F60")[0]
    assert close(ccw.centre[:2], (5.0, math.sqrt(75)))
    long = run("G3 X10 R-10 F60")[0]
    assert close(long.centre[:2], (5.0, -math.sqrt(75)))
    assert long.sweep == pytest.approx(2 * math.pi - math.pi / 3)


def test_full_circles_turns_and_helix():
    arc = run("G3 I5 F60")[0]   # no end words: full circle back to the start
    assert arc.end == (0.0, 0.0, 0.0) and arc.sweep == pytest.approx(2 * math.pi)
    arc = run("G3 X0 Y0 Z-3 I5 P3 F60")[0]
    assert arc.turns == 2 and arc.sweep == pytest.approx(6 * math.pi)
    path = arc.to_path()
    assert close(path.point(path.length), (0.0, 0.0, -3.0))
    assert arc.length == pytest.approx(math.hypot(5 * 6 * math.pi, 3))
    e = err("G3 I5 P0 F60")
    assert e.word == "P0"


def test_absolute_arc_centre_g90_1():
    opts = GCodeOptions(axes={"X": 0, "Y": 1}, parameters={5221: 100.0})
    arc = run("G0 X10\nG90.1 G3 X-10 I0 J0 F60", opts)[-1]
    assert close(arc.centre, (100.0, 0.0)) and arc.end == (90.0, 0.0)
    e = err("G90.1 G3 X-10 I0 F60", opts)
    assert "needs both" in str(e)


def test_inconsistent_radius_is_an_error():
    e = err("G0 X0\nG2 X10 Y1 I5 F60")
    assert e.line == 2 and "differs" in str(e) and e.word == "I/J/K"
    # within LinuxCNC's tolerance (0.028 mm, 0.1 %): accepted as a slight spiral
    arc = run("G2 X100.02 Y0 I50 F60")[0]
    assert arc.end_radius - arc.radius == pytest.approx(0.02)
    path = arc.to_path()
    assert close(path.point(path.length), (100.02, 0.0, 0.0))
    # LinuxCNC's rule: within the absolute tolerance at any percentage ...
    assert run("G2 X10.02 Y0 I5 F60")[0].end_radius == pytest.approx(5.02)
    # ... or within 0.1 % beyond it (0.05 mm on 100 mm), but never beyond 100x it
    assert run("G2 X200.05 Y0 I100 F60")[0].end_radius == pytest.approx(100.05)
    assert "differs" in str(err("G2 X200.2 Y0 I100 F60"))
    assert "differs" in str(err("G2 X10003 Y0 I5000 F60"))
    e = err("G2 X30 R5 F60")
    assert "too small" in str(e) and e.word == "R"
    e = err("G2 X0 Y0 R5 F60")
    assert "different from the start" in str(e)


def test_arc_word_rules():
    assert "K" in str(err("G17 G2 X1 I1 K1 F60"))
    assert "either R or" in str(err("G2 X1 R1 I1 F60"))
    assert "needs R or a centre" in str(err("G2 X1 F60"))
    assert "plane needs a machine axis" in str(err("G18 G2 X1 I1 F1",
                                                   GCodeOptions(axes={"X": 0, "Y": 1})))


def test_arc_inverse_time_feed():
    arc = run("G93 G2 X10 Y10 I10 F6")[0]
    assert arc.duration == 10.0
    assert arc.feed_per_s == pytest.approx(10 * math.pi / 2 / 10.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.5, 50), st.floats(0, 2 * math.pi), st.floats(0.05, 2 * math.pi - 0.05),
       st.booleans(), st.floats(-5, 5))
def test_centre_arcs_end_exactly_on_target(r, a0, sweep, ccw, dz):
    cx, cy = 3.0, -2.0
    sx, sy = cx + r * math.cos(a0), cy + r * math.sin(a0)
    a1 = a0 + (sweep if ccw else -sweep)
    ex, ey = cx + r * math.cos(a1), cy + r * math.sin(a1)
    g = "G3" if ccw else "G2"
    prog = (f"G0 X{sx:.6f} Y{sy:.6f}\n"
            f"{g} X{ex:.6f} Y{ey:.6f} Z{dz:.6f} I{cx - sx:.6f} J{cy - sy:.6f} F100")
    arc = run(prog)[-1]
    assert arc.sweep == pytest.approx(sweep, abs=1e-4)
    path = arc.to_path()
    assert close(path.point(path.length), arc.end, 0.0)
    assert arc.end == (float(f"{ex:.6f}"), float(f"{ey:.6f}"), float(f"{dz:.6f}"))


@settings(max_examples=60, deadline=None)
@given(st.floats(-20, 20), st.floats(-20, 20), st.floats(1.01, 3.0), st.booleans(),
       st.booleans())
def test_r_form_centre_is_equidistant(ex, ey, k, ccw, long):
    chord = math.hypot(ex, ey)
    if chord < 0.1:
        return
    r = k * chord / 2 * (-1 if long else 1)
    arc = run(f"{'G3' if ccw else 'G2'} X{ex:.6f} Y{ey:.6f} R{r:.6f} F60")[0]
    c = arc.centre
    assert math.hypot(c[0], c[1]) == pytest.approx(abs(float(f"{r:.6f}")), rel=1e-9)
    assert (arc.sweep > math.pi - 1e-9) == long


# -- soft limits -------------------------------------------------------------------------
def test_soft_limits_caught_before_motion():
    opts = GCodeOptions(axes={"X": 0, "Y": 1}, soft_limits=[(-1, 100), None])
    assert last_end("G0 X100 Y500", opts) == (100.0, 500.0)
    e = err("G0 X10\nG1 X100.5 F100", opts)
    assert e.line == 2 and "soft limit" in str(e)
    # the arc's end points are inside but its bulge is not
    opts2 = GCodeOptions(axes={"X": 0, "Y": 1}, soft_limits=[(-1, 100), (-5, 100)])
    e = err("G0 X10\nG2 X30 I10 F100\nG3 X10 I-10 F100\nG3 X30 I10 F100", opts2)
    assert e.line == 4 and "Y would reach machine" in str(e) and "< min -5" in str(e)
    e = err("G0 X5\nG3 X5 Y0 I10 F100\n", GCodeOptions(axes={"X": 0, "Y": 1},
                                                       soft_limits=[(0, 30), (-9, 9)]))
    assert e.line == 2


# -- word and group rules ----------------------------------------------------------------
@pytest.mark.parametrize(
    "text, word, fragment",
    [
        ("G0 G1 X1", "G1", "same modal group"),
        ("M3 M5", "M5", "same modal group"),
        ("G0 X1 X2", "X2", "twice"),
        ("G1 X1 F10 I5", "I5", "not used"),
        ("G0 X1 R2", "R2", "not used"),
        ("G41 G19", "G41", "XY (G17) or XZ (G18)"),
        ("G96 M3", "G96", "S word missing with G96"),
        ("G1.5 X1", "G1.5", "unsupported"),
        ("M97", "M97", "unsupported M-code"),
        ("G0 V1", "V1", "no machine axis"),
        ("X1", "X1", "without a motion mode"),
        ("G80 X1", "G80", "G80"),
        ("G4", "G4", "needs P"),
        ("G10 L3 P1 X1", "L3", "L1, L2, L10, L11, L20"),
        ("T-1", "T-1", "integer"),
        ("S-5", "S-5", ">= 0"),
    ],
)
def test_refused_words_name_the_word(text, word, fragment):
    e = err("G21\n" + text)
    assert e.line == 2 and e.word == word and fragment in str(e)
    assert e.column >= 1


def test_nothing_returned_when_a_late_line_fails():
    text = "\n".join(["G1 X1 F100"] * 1000 + ["G1 Q5"])
    e = err(text)
    assert e.line == 1001


def test_m7_and_m8_together_but_not_m8_m9():
    assert run("M7 M8")[0] == Coolant(True, True, None, None, 1)
    assert "same modal group" in str(err("M8 M9"))


def test_current_position_parameters():
    assert last_end("G0 X3 Y4\nG92 X0\nG0 X[#5420 + 1] Y[#5421 * 2]") == (4.0, 8.0, 0.0)


def test_options_validation():
    from openmotion.errors import MotionError

    for bad in ({}, {"Q": 0}, {"X": -1}, {"X": 0, "Y": 0}, {"X": True}):
        with pytest.raises(MotionError, match="axes"):
            GCodeOptions(axes=bad)
    with pytest.raises(MotionError, match="machine_units"):
        GCodeOptions(axes={"X": 0}, machine_units="cm")
    with pytest.raises(MotionError, match="start"):
        GCodeOptions(axes={"X": 0}, start=(1.0, 2.0))
    with pytest.raises(MotionError, match="soft_limits"):
        GCodeOptions(axes={"X": 0}, soft_limits=[(5, 1)])
    with pytest.raises(MotionError, match="outside"):
        GCodeOptions(axes={"X": 0}, soft_limits=[(1, 5)])
    with pytest.raises(MotionError, match="parameters"):
        GCodeOptions(axes={"X": 0}, parameters={0: 1.0})
    with pytest.raises(MotionError, match="start"):
        GCodeOptions(axes={"X": 0}, start=(math.nan,))
    with pytest.raises(MotionError, match="n_axes"):
        GCodeOptions(axes={"X": 2}, n_axes=2)
    with pytest.raises(GCodeError, match="options"):
        compile_text("G0 X1", {"X": 0})  # type: ignore[arg-type]


# -- LinuxCNC's feed semantics (silent differences found by the rs274 oracle) ---------------
def _feeds(text: str, opts: GCodeOptions = XYZA) -> list[float]:
    return [c.feed_per_s * 60.0 for c in run(text, opts) if isinstance(c, (Feed, ArcMove))]


def test_rotary_only_feed_is_degrees_per_minute_in_any_units():
    # G20 F10 G1 A90 on a mm machine: 10 deg/min, not 254 (LinuxCNC never scales angles)
    assert _feeds("G20\nF10 G1 A90\nG21 G1 A0\n") == pytest.approx([10.0, 10.0])
    # a move with a linear axis feeds along it in the linear unit
    assert _feeds("G20\nF10 G1 X1 A90\n") == pytest.approx([254.0])


def test_f_on_the_units_line_is_read_in_the_old_units():
    # order of execution: F before G20/G21, so F10 here is 10 mm/min
    assert _feeds("G21\nG20 F10 G1 X1\nG1 X2\n") == pytest.approx([10.0, 10.0])
    assert _feeds("G20\nG21 F10 G1 X1\n") == pytest.approx([254.0])
    # a later F is in the new units; the feed survives unit changes unscaled physically
    assert _feeds("G21 F100 G1 X1\nG20\nG1 X2\nF4 G1 X3\n") == pytest.approx(
        [100.0, 100.0, 101.6])


def test_g64_p0_is_plain_g64():
    blends = [c for c in run("G64 P0\nG64 P0.1\nG64\n") if isinstance(c, SetBlend)]
    assert [b.tolerance for b in blends] == [None, pytest.approx(0.1), None]


def test_tool_table_g43_g10_l1_and_m61(tmp_path):
    from openmotion.program.tooltable import format_tool_table, parse_tool_table

    tbl = tmp_path / "t.tbl"
    tbl.write_text("T1 P3 Z10 X1 D6 ;drill\n\nT4 P4 Z-2 ;\n")
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2}, tool_table=str(tbl))
    assert opts.tool_table[1].pocket == 3 and opts.tool_table[1].radius == 3.0
    # G43 H applies every axis offset; M61 Q sets the tool without a change
    assert last_end("G43 H1\nG0 X0 Y0 Z0", opts) == (1.0, 0.0, 10.0)
    assert last_end("M61 Q4\nG43\nG0 X0 Z0", opts) == (0.0, 0.0, -2.0)
    # G10 L1 edits the table (R = radius), G10 L10 so that the position reads Z5
    assert last_end("G10 L1 P4 Z3 R1\nG43 H4\nG0 Z0", opts) == (0.0, 0.0, 3.0)
    assert last_end("G0 Z20\nG10 L10 P4 Z5\nG43 H4\nG0 Z5", opts) == (0.0, 0.0, 20.0)
    # G43.1 sets, G43.2 adds; G49 clears
    assert last_end("G43.1 Z2\nG43.2 Z1\nG0 X0 Z0\n", opts) == (0.0, 0.0, 3.0)
    assert last_end("G43 H1\nG49\nG0 X0 Z0\n", opts) == (0.0, 0.0, 0.0)
    table = parse_tool_table(format_tool_table(opts.tool_table))
    assert table == dict(opts.tool_table)
    with pytest.raises(GCodeError) as info:
        parse_tool_table("T1 P1 Z1\nT2 P2 K1\n", "x.tbl")
    assert info.value.line == 2 and info.value.file == "x.tbl"
    assert "M61 needs Q" in str(err("M61\n", opts))


@pytest.mark.parametrize("code, feature", [
    ("M101", "user M-code"), ("M60", "pallet")])
def test_unsupported_features_are_named_before_any_motion(code, feature):
    e = err(f"G0 X5 Y5\nG1 X6 F100\n{code}\n")
    assert e.line == 3 and e.column == 1 and feature in str(e)


def test_tool_parameters_5400_5413():
    from openmotion.program import Message
    from openmotion.program.tooltable import Tool

    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2},
                        tool_table={2: Tool(2, 2, (1.0, 0, 7.5) + (0,) * 6, 4.0)})
    cmds = run("T2 M6\n(debug, #5400 #5401 #5403 #5410)\nG10 L1 P2 Z3\n(debug, #5403)\n",
               opts)
    assert [c.text for c in cmds if isinstance(c, Message)] == [
        "2.000000 1.000000 7.500000 4.000000", "3.000000"]


def test_g95_feed_per_revolution_at_the_commanded_speed_and_g94_clears_f():
    assert _feeds("S600 M3\nG95 F0.2\nG1 X1\nS300\nG1 X2\n") == pytest.approx([120.0, 60.0])
    assert "S > 0" in str(err("G95 F0.2\nG1 X1\n"))
    assert "feed rate is zero" in str(err("G94 F100\nG1 X1\nG94\nG1 X2\n"))
