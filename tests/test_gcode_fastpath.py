"""The compile fast path (program/fastpath.py) gives what parse_program + interpret give:
the same commands, or the same error, on random programs mixing plain and general lines."""

from __future__ import annotations

import gc
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.program import GCodeError, GCodeOptions, compile_text, fastpath
from openmotion.program.interp import _compile_full
from openmotion.program.modal import Modal
from openmotion.program.params import Parameters

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3})
ROOT = Path(__file__).resolve().parents[1]


def outcome(fn, text, opts):
    try:
        return ("ok", fn(text, opts, "f.ngc"))
    except GCodeError as exc:
        return ("error", str(exc))


def assert_same(text, opts=OPTS):
    full = outcome(_compile_full, text, opts)
    assert outcome(compile_text, text, opts) == full
    # the fast engine alone, without compile_plain's fallback on its errors: it may defer
    # or stop at an execution error before a later line's parse error, nothing else
    try:
        mine = ("ok", list(fastpath.plain_commands(text.splitlines(), opts, "f.ngc")))
    except fastpath._Defer:
        return
    except GCodeError as exc:
        mine = ("error", str(exc))
    assert mine == full or mine[0] == full[0] == "error"


num = st.one_of(st.integers(-500, 500).map(str),
                st.floats(-500, 500, allow_nan=False).map(lambda v: f"{v:.4f}"),
                st.sampled_from([".5", "-.25", "+3", "1.", "007"]))
plain_word = st.tuples(st.sampled_from("XYZAFB"), num).map(lambda t: t[0] + t[1])
plain = st.builds(lambda n, g, ws, sep: sep.join(([n] if n else []) + ([g] if g else []) + ws),
                  st.sampled_from(["", "N10", "N7"]),
                  st.sampled_from(["", "G0", "G1", "G01", "G00", "G2", "G1.0"]),
                  st.lists(plain_word, max_size=4), st.sampled_from([" ", "", "\t", "  "]))
general = st.sampled_from([
    "G20", "G21", "G90", "G91", "G93", "G94", "G54", "G55", "G92 X1 Y2", "G92.1",
    "G10 L2 P2 X5 Y-3", "G1 X1 (comment) Y2", "; only a comment", "#1 = 2.5",
    "G1 X[#1*2] F100", "M3 S1000", "M5", "G4 P0.1", "G64 P0.01", "G61", "", "   ",
    "%", "M2", "M30", "G17 G2 X1 Y0 I0.5 J0", "G80", "F-1", "G1 X1 X2", "Q1", "X 1",
    "/G1 X9", "g1 x3", "N5.5 G1 X1", "O100 sub", "O100 endsub", "O100 call", "G28",
    "G53 G0 X1", "T1 M6", "M7 M8", "M9",
])
programs = st.lists(st.one_of(plain, plain, plain, general), min_size=1, max_size=25)


@settings(max_examples=400, deadline=None)
@given(programs, st.booleans(), st.booleans())
def test_random_programs_same_as_general_path(lines, soft, block_delete):
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}, block_delete=block_delete,
                        soft_limits=[(-100, 100)] * 4 if soft else None, max_blocks=20)
    assert_same("\n".join(["G1 F600", *lines]), opts)
    assert_same("\n".join(lines), opts)


def test_plain_program_takes_the_fast_path(monkeypatch):
    """Catches a Modal that grew state this module does not know (KNOWN_STATE)."""
    assert fastpath.fast_path_available(Modal(OPTS, Parameters(OPTS.parameters)))
    text = "G21 G90\nG1 F600\n" + "\n".join(f"N{k} G1 X{k}.5 Y-{k} Z.25" for k in range(50))
    calls = []
    real = fastpath.parse_line
    monkeypatch.setattr(fastpath, "parse_line", lambda *a: calls.append(a) or real(*a))
    cmds = compile_text(text + "\nM2", OPTS)
    assert len(calls) == 2  # "G21 G90" and "M2"; the G1 lines never became Blocks
    assert cmds == _compile_full(text + "\nM2", OPTS, "")


def test_gc_state_restored():
    assert gc.isenabled()
    compile_text("G1 X1 F100", OPTS)
    assert gc.isenabled()
    with pytest.raises(GCodeError):
        compile_text("G1 X1", OPTS)
    assert gc.isenabled()
    gc.disable()
    try:
        compile_text("G1 X1 F100", OPTS)
        assert not gc.isenabled()
    finally:
        gc.enable()


@pytest.mark.parametrize("path", sorted((ROOT / "examples" / "programs").glob("*.ngc"))
                         + sorted(Path("/work/shared/gcode-corpus").glob("*.ngc")),
                         ids=lambda p: p.name)
def test_example_and_corpus_programs(path):
    text = path.read_text()
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
    assert_same(text, opts)


# -- dialect state: every modal feature a plain line may meet --------------------------
ORACLE = ROOT / "tests" / "gcode_oracle"

dialect = st.sampled_from([
    # units and feeds: F is fixed in the units active when it is set (feed_lin/feed_ang)
    "G20", "G21", "G20 F10", "G21 F250", "G1 A30 F90", "G0 A-10", "G1 A5 B3", "G1 X1 A5",
    "G93", "G94", "G95", "M3 S1200", "M4 S300", "M5", "G1 X2 F0", "F0", "G93 G1 X1 F2",
    # work, G92 and tool offsets, rotation, G52
    "G54", "G55", "G59.3", "G10 L2 P1 X3 Y-2 R30", "G10 L2 P2 R0", "G10 L2 P1 R0",
    "G10 L20 P1 X0", "G92 X1 Y2", "G92.1", "G92.2", "G92.3", "G52 X2 Y1", "G52 X0 Y0",
    "T1 M6", "T2 M6 G43", "G43 H1", "G43.1 Z0.5", "G49", "G43.2 H2", "M61 Q1",
    "#5221 = 3", "#5223 = -1",
    # cutter compensation and its exit move
    "G41.1 D2", "G42.1 D1", "G40", "G41.1 D0", "G41.1 D2 G1 X10 Y0",
    # canned cycles, their series and retract modes
    "G81 X1 Y1 Z-1 R1", "G82 X2 Y2 Z-1 R1 P0.5", "G83 X3 Y1 Z-2 R1 Q0.5", "G80", "G98",
    "G99", "X4 Y4", "G73 X1 Y2 Z-1 R1 Q0.3",
    # planes, diameter mode, polar words, machine coordinates, saved state
    "G18", "G19", "G17", "G7", "G8", "G0 @5 ^30", "G1 @2 ^45", "G53 G0 X1", "G53 G1 Y2",
    "G28", "G30", "G28.1", "M70", "M72", "M73", "M71", "G90.1", "G91.1",
    "G2 X0 Y0 I1 J0", "G3 X1 Y1 R1", "G90", "G91", "G61", "G64 P0.1", "G61.1",
    "#<v> = 7", "G1 X#<v>", "(MSG, hello)", "M0", "M1", "M62 P0", "G4 P0",
])
#: what the general path refuses or defers
refused = st.sampled_from([
    "M98 P100", "M99", "G1 X1 Y2 Z3 A4 B5 C6 U1", "G33 X1 K0.1", "G76 P1 Z-1 I-0.1 J0.1 K0.2",
    "O200 call", "G1 X1 X2", "G2 X1", "N5 G5 X1"])
plain_move = st.builds(lambda g, ws: " ".join([g, *ws]), st.sampled_from(["", "G1", "G0"]),
                       st.lists(st.tuples(st.sampled_from("XYZA"), num).map("".join),
                                min_size=1, max_size=3, unique_by=lambda w: w[0]))
mixed = st.builds(
    lambda body, bad, at: body[:at] + bad + body[at:],
    st.lists(st.one_of(plain_move, plain_move, plain_move, plain_move, plain, dialect,
                       dialect, dialect),
             min_size=1, max_size=40),
    st.one_of(st.just([]), st.just([]), st.lists(st.one_of(refused, general), max_size=1)),
    st.integers(0, 40))


def _tooled(**kw):
    return GCodeOptions(**kw, tool_table=ORACLE / "tools.tbl")


@settings(max_examples=300, deadline=None)
@given(mixed, st.booleans(), st.sampled_from(["mm", "inch"]),
       st.sampled_from(["XYZA", "XYZ", "XZ", "XYZABC"]))
def test_random_dialect_programs_same_as_general_path(lines, soft, units, axes):
    opts = _tooled(axes={L: k for k, L in enumerate(axes)}, machine_units=units,
                   soft_limits=[(-60, 60)] * len(axes) if soft else None,
                   max_blocks=40)
    assert_same("\n".join(["G1 F600", *lines]), opts)
    assert_same("\n".join(lines), opts)


def _oracle_opts():
    import sys
    sys.path.insert(0, str(ROOT / "tests"))
    from lcnc_oracle import OPTIONS
    return OPTIONS


@pytest.mark.parametrize("path", sorted(ORACLE.glob("*.ngc")) + sorted(
    (ORACLE / "bad").glob("*.ngc")) + sorted((ROOT / "examples" / "gcode").glob("*.ngc")),
    ids=lambda p: p.name)
def test_oracle_programs_same_as_general_path(path):
    """The LinuxCNC-oracle programs (dialect features of every kind) and the bad ones."""
    assert_same(path.read_text(), _oracle_opts())


def test_plain_lines_take_the_fast_path_in_dialect_state(monkeypatch):
    """Offsets, G20, tool length, G92 and a finished cycle series keep plain lines fast;
    comp and rotation send them to the general path, and they come back after."""
    opts = _tooled(axes={"X": 0, "Y": 1, "Z": 2, "A": 3})
    body = [f"G1 X{k}.5 Y-{k} Z.25" for k in range(5)]
    text = "\n".join(["G20 G55 G1 F20", "G10 L2 P2 X1 Y2", "G92 X1", "G43.1 Z0.5", *body,
                      "G81 X1 Y1 Z-0.1 R0.1", "G80", *body, "G41.1 D0.1", *body, "G40",
                      *body, "G1 A30", "M2"])
    calls = []
    real = fastpath.parse_line
    monkeypatch.setattr(fastpath, "parse_line", lambda *a: calls.append(a[0]) or real(*a))
    assert compile_text(text, opts) == _compile_full(text, opts, "")
    assert calls.count(body[0]) == 1  # once, while compensation was on
    assert "G1 A30" not in calls


def test_generated_corpus_equivalence_big():
    """A 3000-line CAM program with unit, offset and feed changes sprinkled in."""
    import math
    lines = ["G21 G90 G64 P0.01", "G0 X0 Y0 Z5", "G1 Z-1 F300"]
    extra = ["G20", "G21", "G55", "G54", "G92 X1", "G92.1", "F900", "G91", "G90",
             "G43.1 Z1", "G49", "G1 A10", "G0 A0"]
    for k in range(3000):
        t = k * 0.01
        f = f" F{1200 + (k % 7) * 10}" if k % 50 == 0 else ""
        lines.append(f"N{k + 10} G1 X{50 * math.cos(t):.4f} Y{50 * math.sin(3 * t):.4f}"
                     f" Z{-1 - 0.5 * math.sin(t):.4f}{f}")
        if k % 97 == 0:
            lines.append(extra[k // 97 % len(extra)])
    text = "\n".join([*lines, "M2"])
    assert_same(text)


safe_dialect = st.sampled_from([
    "G20", "G21", "G20 F10", "G21 F250", "G1 A30 F90", "G0 A-10", "G54", "G55", "G59.3",
    "G10 L2 P1 X3 Y-2 R30", "G10 L2 P1 R0", "G10 L2 P2 X-1 Y4", "G92 X1 Y2", "G92.1",
    "G92.2", "G92.3", "G52 X2 Y1", "G43.1 Z0.5", "G49", "G43 H2", "#5221 = 3", "G90",
    "G91", "G7", "G8", "G98", "G99", "G81 X1 Y1 Z-1 R1", "G80", "G0 @5 ^30", "M70", "M73",
    "G41.1 D2\nG1 X20 Y20\nG1 X30 Y25\nG40\nG1 X0 Y0",
    "G93\nG1 X3 Y4 F30\nG1 X1 F60\nG94\nF700",
    "M3 S1000\nG95 F0.1\nG1 X5 Y1\nG94 F800\nM5", "G64 P0.05", "G61", "M7 M8", "M9",
])
long_programs = st.lists(st.one_of(plain_move, plain_move, plain_move, safe_dialect),
                         min_size=5, max_size=80)


@settings(max_examples=150, deadline=None)
@given(long_programs, st.sampled_from(["mm", "inch"]))
def test_long_dialect_programs_same_as_general_path(lines, units):
    opts = _tooled(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}, machine_units=units)
    assert_same("\n".join(["G1 F600", *lines, "M2"]), opts)


#: One program per piece of modal state a plain line reads or writes: a fast path that
#: ignored it would give another result or error (motion_prev excepted: every motion line
#: of the general path sets it before reading it).
STATE_CASES = {
    "feed_lin fixed in the units of F": "G20\nG1 X1 F10\nG21\nG1 X2 Y1",
    "feed_ang for rotary-only moves": "G20\nF10\nG1 A30\nG1 X1 A40\nG1 A10 F5",
    "work offset G55": "G10 L2 P2 X5 Y-3\nG55\nG1 X1 Y1 F100",
    "G92": "G92 X3\nG0 X1\nG92.1\nG0 X1",
    "G52": "G52 X2 Y1\nG0 X1 Y1",
    "tool length": "T2 M6 G43\nG0 Z1\nG43.1 Z-2\nG0 Z1\nG49\nG0 Z1",
    "rotation": "G10 L2 P1 X1 R30\nG0 X1 Y1\nG10 L2 P1 R0\nG0 X1 Y1",
    "G91": "G91\nG0 X1\nX1\nG90\nX1",
    "G20 positions": "G20\nG0 X1 Y2\nG21\nG0 X1",
    "diameter mode": "G7\nG0 X10\nG8\nG0 X10",
    "cutter comp": "G41.1 D2\nG1 X10 Y0 F100\nG1 X10 Y10\nG40\nG1 X0 Y0",
    "arc after comp exit": "G41.1 D2\nG1 X10 Y0 F100\nG40\nG1 X0 Y10\nG2 X5 Y5 R5",
    "cycle series ends at a plain move":
        "G98 G81 X1 Y1 Z-1 R1 F100\nG1 Z10\nG81 X2 Y2 Z-1 R1\nG80",
    "sticky cycle words need the same cycle": "G81 X1 Y1 Z-1 R1 F100\nG1 X3\nG81 X2 Y2",
    "motion_prev after a motion word": "G81 X1 Y1 Z-1 R1 F100\nG1\nG81 X2 Y2",
    "inverse time": "G93\nG1 X3 Y4 F30\nG1 X1 F60\nG94 F600\nG1 X0",
    "feed per rev": "M3 S1000\nG95 F0.1\nG1 X5 Y1\nG94 F800\nG1 X0",
    "G94 clears F": "G1 F600 X1\nG94\nG1 X2",
    "saved state M70/M72": "G20 F10\nM70\nG21 F300\nG1 X5\nM72\nG1 X1",
    "polar words": "G0 @5 ^30\nG1 X1 F100",
    "G53": "G10 L2 P1 X5\nG53 G0 X1\nG0 X1",
    "soft limit error": "G0 X200",
    "zero feed error": "G1 X1",
    "M98 without the program": "G1 X1 F100\nM98 P7\nG1 X2",
    "M99 in the main program": "G1 X1 F100\nM99",
    "parameter on a later line": "#5221 = 4\nG0 X1",
}


@pytest.mark.parametrize("name", sorted(STATE_CASES))
def test_modal_state_catalogue(name):
    """The fast engine itself (no fallback on its errors) against the general path."""
    opts = _tooled(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}, soft_limits=[(-100, 100)] * 4)
    for text in (STATE_CASES[name] + "\nM2", "G1 F500\n" + STATE_CASES[name] + "\nM2"):
        try:
            mine = ("ok", list(fastpath.plain_commands(text.splitlines(), opts, "f.ngc")))
        except fastpath._Defer:
            assert name.startswith("M9")  # M98/M99 go to the interpreter
            continue
        except GCodeError as exc:
            mine = ("error", str(exc))
        assert mine == outcome(_compile_full, text, opts)
