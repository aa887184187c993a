"""Active comments: MSG, DEBUG/PRINT formats, #5599, ABORT (LinuxCNC's convert_comment)."""

from __future__ import annotations

import pytest

from openmotion.program import GCodeError, GCodeOptions, Message, Rapid, compile_text

XYZ = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


def texts(program: str) -> list[str]:
    return [c.text for c in compile_text(program, XYZ) if isinstance(c, Message)]


def test_debug_formats_persist_within_the_comment():
    got = texts("#1=3.14159\n#2=-0.00000001\n(DEBUG, a=%d#1 b=%f#1 c=%.2f#1 d=#1 "
                "e=%lf#1 g=#2 h=#9999 i=#<_nope> j=%.x k=%.3g#1)\n")
    # the same text rs274 (LinuxCNC 2.9) prints for this line
    assert got == ["a=3 b=3.1416 c=3.14 d=3.14 e=%lf3.14 g=0.00 h=###### i=###### j=.x "
                   "k=.3g3.14"]


def test_default_six_decimals_print_and_named_locals():
    assert texts("#<_aa> = 2\n(print, v=#<_aa> #<_ a a>)\n") == ["v=2.000000 2.000000"]


def test_debug_off_while_5599_is_zero_msg_is_literal():
    assert texts("#5599=0\n(debug, hidden)\n#5599=1\n(debug, shown)\n(msg, m=#1)\n") == [
        "shown", "m=#1"]


def test_abort_stops_with_its_text_and_nothing_runs():
    prog = "G0 X1\n#<n> = 7\n( ABORT , n=%d#<n> too big)\nG0 X2\n"
    with pytest.raises(GCodeError) as info:
        compile_text(prog, XYZ)
    e = info.value
    assert (e.line, e.column) == (3, 1)
    assert "n=7 too big" in str(e)
    # an ABORT in a branch that is not taken does nothing
    cmds = compile_text("o1 if [0]\n(abort, no)\no1 endif\nG0 X3\n", XYZ)
    assert [c.end[0] for c in cmds if isinstance(c, Rapid)] == [3.0]


def test_predefined_parameters_read_state_and_are_read_only():
    prog = ("G20 G91 G18 G0 X1\n(debug, #<_imperial> #<_plane> #<_incremental> #<_x> "
            "#<_abs_x> #<_motion_mode> #<_line> #<_vmajor>)\n")
    assert texts(prog) == ["1.000000 180.000000 1.000000 1.000000 1.000000 0.000000 "
                           "2.000000 2.900000"]
    with pytest.raises(GCodeError, match="predefined"):
        compile_text("#<_x> = 3\n", XYZ)
    assert texts("(debug, EXISTS)\no1 if [EXISTS[#<_metric>]]\n(debug, yes)\no1 endif\n"
                 ) == ["EXISTS", "yes"]


def test_m70_m72_restore_spindle_and_coolant_records():
    from openmotion.program import Coolant, Spindle

    cmds = compile_text("S100 M3\nM70\nM5 M8\nM72\nG0 X1\n", XYZ)
    sp = [c for c in cmds if isinstance(c, Spindle)]
    co = [c for c in cmds if isinstance(c, Coolant)]
    assert [s.on for s in sp] == [True, False, True] and sp[-1].speed == 100
    assert [(c.mist, c.flood) for c in co] == [(False, True), (False, False)]
    with pytest.raises(GCodeError, match="M72"):
        compile_text("M72\n", XYZ)
