"""Differential oracle: openmotion.program against LinuxCNC's own interpreter (rs274).

Every program in tests/gcode_oracle/ (our own programs, each naming the LinuxCNC test or
sample it mirrors), examples/gcode/ and /work/shared/gcode-corpus/ (when present) is run
through both; the motions (end points, arc centres, planes and directions, feeds, rapid or
feed) must agree within 1e-4 program units. Programs in tests/gcode_oracle/bad/ must be
refused by both. rs274 comes from Debian's linuxcnc-uspace (tools/setup_rs274.sh); without
it these tests skip, except under CI (env CI set), where a missing oracle is a failure.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import pytest

from lcnc_oracle import (
    OPTIONS,
    Motion,
    compare,
    openmotion_motions,
    parse_listing,
    rs274_path,
    run_rs274,
)
from openmotion.program import GCodeError, Message, compile_file, compile_text

HERE = Path(__file__).parent
ROOT = HERE.parent
CORPUS = Path("/work/shared/gcode-corpus")
GOOD = sorted((HERE / "gcode_oracle").glob("*.ngc")) + sorted(
    (ROOT / "examples" / "gcode").glob("*.ngc")) + (
    sorted(CORPUS.glob("*.ngc")) if CORPUS.is_dir() else [])
BAD = sorted((HERE / "gcode_oracle" / "bad").glob("*.ngc"))


@pytest.fixture(scope="module")
def rs274() -> str:
    exe = rs274_path()
    if exe is None:
        reason = ("LinuxCNC rs274 is not installed: run tools/setup_rs274.sh (Debian "
                  "package linuxcnc-uspace unpacked to /opt/linuxcnc-rs274) or set "
                  "OPENMOTION_RS274")
        if os.environ.get("CI"):
            pytest.fail(f"CI needs the oracle: {reason}")
        pytest.skip(reason)
    return exe


def _name(p: Path) -> str:
    return str(p.relative_to(ROOT)) if p.is_relative_to(ROOT) else p.name


@pytest.mark.parametrize("path", GOOD, ids=_name)
def test_same_motion_as_linuxcnc(rs274: str, path: Path) -> None:
    text = path.read_text()
    theirs = run_rs274(text, rs274)
    assert theirs.error is None, f"rs274 refused {path.name}: {theirs.error}"
    assert theirs.motions, "rs274 produced no motion"
    ours = openmotion_motions(text)
    diffs = compare(ours, theirs.motions)
    assert not diffs, "\n".join(diffs[:20])


@pytest.mark.parametrize("path", BAD, ids=_name)
def test_refused_by_both(rs274: str, path: Path) -> None:
    text = path.read_text()
    theirs = run_rs274(text, rs274)
    assert theirs.error is not None, "rs274 accepted a program meant to be bad"
    with pytest.raises(GCodeError):
        openmotion_motions(text)


def test_oracle_sees_a_difference(rs274: str) -> None:
    """The comparison can fail: a program changed on our side only differs."""
    text = "G21 G0 X1 Y2\nG1 X5 F100\nG2 X9 Y2 I2 J0\nM2\n"
    theirs = run_rs274(text, rs274).motions
    assert not compare(openmotion_motions(text), theirs)
    assert compare(openmotion_motions(text.replace("X9", "X9.001")), theirs)
    assert compare(openmotion_motions(text.replace("F100", "F101")), theirs)
    assert compare(openmotion_motions(text.replace("G2 ", "G3 ")), theirs)


LISTING = """\
    1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)
    2 N..... SET_G5X_OFFSET(1, 10.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    3 N..... SET_G92_OFFSET(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    4 N..... SET_XY_ROTATION(90.0000)
    5 N..... SET_FEED_RATE(10.0000)
    6 N..... USE_LENGTH_UNITS(CANON_UNITS_INCHES)
    7 N..... STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    8 N..... STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 90.0000, 0.0000, 0.0000)
    9 N..... SELECT_PLANE(CANON_PLANE_XZ)
   10 N..... ARC_FEED(0.0000, 2.0000, 0.0000, 1.5000, -2, 0.0000, 90.0000, 0.0000, 0.0000)
"""


def test_listing_replays_the_canon_layer() -> None:
    """Units at the time of each call, G92 then rotation about the G5x origin, feeds."""
    ms = parse_listing(LISTING)
    assert [m.kind for m in ms] == ["feed", "feed", "arc"]
    # X1 in = 25.4 mm, + G92 1 mm, rotated 90 deg, + G5x 10 mm
    assert ms[0].end[:2] == pytest.approx((10.0, 26.4))
    assert ms[0].feed == pytest.approx(10.0)  # F set while in mm: 10 mm/min
    assert ms[1].feed == pytest.approx(10.0)  # rotary only: angular feed, unscaled
    arc = ms[2]
    assert (arc.plane, arc.rotation) == ("XZ", -2)
    assert isinstance(arc, Motion) and arc.tol == pytest.approx(25.4e-4)


def test_debug_messages_as_linuxcnc_prints_them(rs274: str) -> None:

    text = ("#1=3.14159\n#2=-2.5\n#<_g>=12\n(DEBUG, a=%d#1 b=%f#1 c=%.2f#1 d=#1 e=%lf#1 "
            "g=#2 h=#9999 i=#<_nope> j=%.x k=%.3g#1 l=#<_g>)\n(debug,#1%.9f#2)\n"
            "#5599=0\n(debug, hidden)\n#5599=1\n(msg, m=#1)\nG0 X1\nM2\n")
    theirs = [t.strip() for t in run_rs274(text, rs274).messages]
    ours = [c.text for c in compile_text(text, OPTIONS) if isinstance(c, Message)]
    assert ours == theirs


@pytest.mark.parametrize("name", ["predefined_params.ngc", "fanuc_params.ngc", "tool_offsets.ngc",
                                  "modal_state.ngc", "rotation.ngc", "probing.ngc"])
def test_messages_as_linuxcnc_prints_them(rs274: str, name: str) -> None:
    """Programs whose DEBUG lines print modal state: the same text from both."""

    text = (HERE / "gcode_oracle" / name).read_text()
    theirs = [t.strip() for t in run_rs274(text, rs274).messages]
    ours = [c.text for c in compile_text(text, OPTIONS) if isinstance(c, Message)]
    assert ours == theirs


SUB_FILES = {
    "probe_hole.ngc": "o<probe_hole> sub\nG0 X#1 Y#2\nG1 Z-1 F100\n"
                      "o<probe_hole> endsub [#1 + #2]\n",
    "100.ngc": "o100 sub\nG0 X100\no100 return [7]\no100 endsub\n",
}
SUB_MAIN = ("(external subroutine files on the search path, computed O numbers, return values)\n"
            "(mirrors LinuxCNC tests/interp/subroutine-path and 14-o-expression-call)\n"
            "G21\no<probe_hole> call [3] [4]\n(debug, v=#<_value> r=#<_value_returned>)\n"
            "#5=50\no[#5*2] call\n(debug, v=#<_value>)\nG0 X[#<_value> * 2]\nM2\n")


def test_external_subroutine_files_as_linuxcnc(rs274: str, tmp_path: Path) -> None:

    theirs = run_rs274(SUB_MAIN, rs274, extra_files=SUB_FILES)
    assert theirs.error is None
    for name, body in SUB_FILES.items():
        (tmp_path / name).write_text(body)
    (tmp_path / "main.ngc").write_text(SUB_MAIN)
    # found next to the program ...
    cmds = compile_file(tmp_path / "main.ngc", OPTIONS)
    assert [c.text for c in cmds if isinstance(c, Message)] == [
        t.strip() for t in theirs.messages]
    # ... or on the search path for a program given as text
    opts = replace(OPTIONS, subroutine_path=(str(tmp_path),))
    assert not compare(openmotion_motions(SUB_MAIN, opts), theirs.motions)
