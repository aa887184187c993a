"""G70/G71/G72 lathe cycles (program/latheprofile.py, lathecycles.py, lathegeom.py).

The motion itself is compared against rs274 by test_gcode_linuxcnc.py (tests/gcode_oracle/
lathe_roughing.ngc, lathe_modes.ngc and bad/g7*.ngc); these tests check what a lathe user
relies on without the oracle: roughing never cuts into the profile plus D, every layer is
I deep, the finish pass runs on the profile, and the refusals name line, column and word.
"""

from __future__ import annotations

import math

import pytest

from openmotion.program import ArcMove, Feed, GCodeError, GCodeOptions, Rapid, compile_text

OPTS = GCodeOptions(axes={"X": 0, "Z": 1})
SHAFT = """G18 G21 G90 G8 F120
O10 sub
  G1 X4 Z0
  G1 Z-6
  G1 X7 Z-10
  G1 Z-16
  G1 X10
O10 endsub
G0 X12 Z2
"""


def profile_x(z: float) -> float:
    """The SHAFT profile's radius at z (the finished part)."""
    if z >= -6:
        return 4.0
    if z >= -10:
        return 4.0 + (z + 6) / -4 * 3
    return 7.0


def _moves(text: str):
    return [c for c in compile_text(text, OPTS) if isinstance(c, Rapid | Feed | ArcMove)]


def test_g71_layers_are_i_deep_and_leave_d_over_the_profile():
    moves = _moves(SHAFT + "G71 Q10 X12 Z2 D0.5 I1 R0.3\nM2\n")
    cuts = [(a, b) for a, b in zip(moves, moves[1:], strict=False)
            if isinstance(a, Rapid) and isinstance(b, Feed) and abs(a.end[0] - b.end[0]) < 1e-9
            and b.end[1] < a.end[1] - 1e-9]  # the layers: Z cuts at one X after a rapid
    levels = sorted({round(b.end[0], 9) for _a, b in cuts}, reverse=True)
    assert levels[0] == pytest.approx(12.0)
    steps = [a - b for a, b in zip(levels, levels[1:], strict=False)]
    assert all(d == pytest.approx(1.0) for d in steps[:-1]) and 0 < steps[-1] <= 1 + 1e-9
    for _a, b in cuts:  # each layer stops at the profile + D, never inside it
        x, z = b.end[0], b.end[1]
        gap = min(math.hypot(z - zz, x - profile_x(zz)) for zz in
                  [zi / 100 for zi in range(-1600, 1)])
        assert gap >= 0.5 - 1e-6
    assert min(b.end[0] for _a, b in cuts) >= 4.5 - 1e-9


def test_g70_passes_run_on_the_profile_at_the_distances_asked():
    moves = _moves(SHAFT + "G70 Q10 X12 Z2 D1 E0 P2\nM2\n")
    rapids = [k for k, m in enumerate(moves) if isinstance(m, Rapid)]
    last = moves[rapids[-1] + 1:]  # the second pass: the profile itself (E0)
    assert [tuple(round(v, 9) for v in m.end[:2]) for m in last] == [
        (4.0, -6.0), (7.0, -10.0), (7.0, -16.0), (10.0, -16.0)]
    assert moves[rapids[-1]].end[:2] == pytest.approx((4.0, 0.0))
    # the first pass (pass-1)(D-E)/P + E = 0.5 mm off the profile, towards the start
    first_start = moves[rapids[-3]].end
    assert first_start[:2] == pytest.approx((4.5, 0.0))


def test_g72_faces_along_x():
    text = """G18 G21 G8 F100
O1 sub
  G1 X2 Z-3
  G1 X6
  G1 X8 Z-1.5
  G1 X12
O1 endsub
G0 X2 Z1
G72 Q1 I0.5 R0.2
M2
"""
    moves = _moves(text)
    cuts = [b for a, b in zip(moves, moves[1:], strict=False) if isinstance(a, Rapid)
            and isinstance(b, Feed) and abs(a.end[1] - b.end[1]) < 1e-9
            and b.end[0] > a.end[0] + 1e-9]  # the layers: X cuts at one Z after a rapid
    zs = sorted({round(b.end[1], 9) for b in cuts}, reverse=True)
    assert zs[:4] == pytest.approx([1.0, 0.5, 0.0, -0.5])
    assert all(b.end[0] == pytest.approx(12.0) for b in cuts if b.end[1] > -1.5)
    assert min(zs) >= -3.0 - 1e-9  # D0: the last layer on the face


def test_diameter_mode_reads_x_as_diameters():
    radius = _moves(SHAFT + "G71 Q10 X12 Z2 I1\nM2\n")
    text = SHAFT.replace("G8", "G7").replace("X4 ", "X8 ").replace("X7 ", "X14 ").replace(
        "X10", "X20").replace("X12", "X24")
    diameter = _moves(text + "G71 Q10 X24 Z2 I1\nM2\n")
    assert [m.end for m in diameter] == [m.end for m in radius]


def test_the_motion_mode_after_a_cycle_is_its_last_move():
    cmds = _moves(SHAFT + "G71 Q10 X12 Z2 I1\nX11\nM2\n")
    assert isinstance(cmds[-1], Feed) and cmds[-1].end[0] == pytest.approx(11.0)


def test_the_profile_sub_may_come_from_a_file(tmp_path):
    (tmp_path / "10.ngc").write_text("O10 sub\n  G1 X4 Z0\n  G1 Z-6\n  G1 X10\nO10 endsub\n")
    main = tmp_path / "main.ngc"
    main.write_text("G18 G21 G8 F120\nG0 X12 Z2\nG71 Q10 I1\nM2\n")
    from openmotion.program import compile_file

    cmds = compile_file(main, OPTS)
    assert sum(isinstance(c, Feed) for c in cmds) > 5
    from openmotion.program.stream import stream_file

    assert list(stream_file(main, OPTS)) == cmds  # the streaming compile hands it over


@pytest.mark.parametrize("body, line, column, word, text", [
    ("G71 P10 Q20 U0.5\n", 10, 5, "P10", "Fanuc form"),
    ("G71 Q10 U0.5\n", 10, 9, "U0.5", "displacement"),
    ("G17\nG71 Q10\n", 11, 1, "G71", "XZ plane"),
    ("G71 Q10 I0\n", 10, 9, "I0", "greater than zero"),
    ("G70 Q10 J1\n", 10, 9, "J1", "not used"),
    ("G41.1 D0.2\nG1 X12 Z3\nG70 Q10\n", 12, 1, "G70", "cutter compensation"),
    ("G71 Q11\n", 10, 1, "G71 Q11", "O11 is not defined"),
])
def test_refusals_name_line_column_and_word(body, line, column, word, text):
    with pytest.raises(GCodeError) as info:
        compile_text(SHAFT + body + "M2\n", OPTS)
    e = info.value
    assert (e.line, e.column, e.word) == (line, column, word) and text in str(e)


def test_unsupported_moves_in_the_profile_are_named():
    bad = SHAFT.replace("  G1 X7 Z-10\n", "  G33 X7 Z-10 K1\n")
    with pytest.raises(GCodeError) as info:
        compile_text(bad + "G71 Q10\nM2\n", OPTS)
    assert info.value.line == 5 and "G33 in the profile of G71" in str(info.value)


def test_a_profile_the_cycle_cannot_finish_is_refused_not_looped():
    # LinuxCNC 2.9.0~pre1 loops forever here (its tests/interp/g71-endless-loop)
    text = """G21 G18 G8 G91.1 F225
O200 SUB
G01 X10 Z0
G01 X10 Z-14
G01 X3
G01 X7 Z-22
O200 ENDSUB
G71.2 Q200 X15.0 Z0 D0.04 I0.5 R1
M2
"""
    with pytest.raises(GCodeError, match="no progress"):
        compile_text(text, OPTS)


def test_the_lathe_example_binds_to_the_xz_machine():
    """examples/gcode/lathe_rough_finish.ngc on examples/lathe_xz.toml: compiled against
    its travel (soft limits from the switches), roughing layers, the groove's pocket and
    the finishing arcs all there (the run itself: test_examples_run with --long)."""
    from pathlib import Path

    from openmotion.config import load_machine
    from openmotion.control import Controller
    from openmotion.program.runner import ProgramRunner

    root = Path(__file__).resolve().parent.parent / "examples"
    ctl = Controller(load_machine(root / "lathe_xz.toml"))
    run = ProgramRunner(ctl, root / "gcode" / "lathe_rough_finish.ngc",
                        gcode={"parameters": {5221: 1.0, 5223: -60.0}})
    kinds = [op.kind for op in run.ops]
    assert kinds.count("arc") >= 10 and kinds.count("line") > 80
    # the groove (a G2 R6 between Z-26 and Z-34 on the 18 mm diameter, 1.5 mm deep) is
    # roughed as a pocket: cuts below radius 8.5 (machine = program + G54 X1 Z-60)
    groove = [op.end[0] - 1.0 for op in run.ops if op.kind == "line"
              and op.end is not None and -33.5 < op.end[1] + 60.0 < -26.5]
    assert min(groove) < 8.5


def _random_profile(rng, facing: bool) -> tuple[str, float]:
    """A random profile (lines, R arcs, fillets, chamfers), monotonic along Z for G71 and
    along X for G72 as those cycles need (a non-monotonic draw is refused by both)."""
    lines = []
    if facing:
        x, z = 1.0, -rng.uniform(2, 5)
    else:
        x, z = rng.uniform(2, 5), 0.0
    lines.append(f"  G1 X{x:.3f} Z{z:.3f}")
    for _ in range(rng.randint(2, 6)):
        if facing:
            nx, nz = x + rng.uniform(1, 5), min(-0.3, z + rng.uniform(-3, 3))
        else:
            nx, nz = max(0.5, x + rng.uniform(-3, 4)), z - rng.uniform(1, 6)
        corner = ""
        if rng.random() < 0.2:
            corner = f" A{rng.uniform(0.1, 0.6):.2f}"
        elif rng.random() < 0.2:
            corner = f" C{rng.uniform(0.1, 0.6):.2f}"
        if rng.random() < 0.25:
            r = math.hypot(nx - x, nz - z) / 2 * rng.uniform(1.05, 2)
            lines.append(f"  G{rng.choice([2, 3])} X{nx:.3f} Z{nz:.3f} R{r:.3f}{corner}")
        else:
            lines.append(f"  G1 X{nx:.3f} Z{nz:.3f}{corner}")
        x, z = nx, nz
    top = x + 2 if facing else max(float(s.split("X")[1].split()[0]) for s in lines) + 2
    lines.append(f"  G1 X{top:.3f}")
    return "\n".join(lines), (1.0 if facing else top)


@pytest.mark.parametrize("family", ["G71", "G72"])
def test_random_profiles_against_rs274(family, fuzz_long):
    """--fuzz-long: random profiles through every cycle variant, against LinuxCNC's rs274
    (found 0 differences in 94 G71 and 40 G72 programs; rs274 2.9.0~pre1 loops forever on
    some G72.2 profiles, which must then be refused here)."""
    import random
    import subprocess

    from lcnc_oracle import compare, openmotion_motions, rs274_path, run_rs274

    if not fuzz_long:
        pytest.skip("random lathe profiles against rs274 with --fuzz-long")
    if rs274_path() is None:
        pytest.skip("rs274 is not installed (tools/setup_rs274.sh)")
    rng = random.Random(18)
    for _ in range(60):
        body, start_x = _random_profile(rng, family == "G72")
        cyc = rng.choice([family, family + ".1", family + ".2", "G70"])
        d = rng.choice([0, 0.2, 0.5])
        words = (f" D{d} P{rng.randint(1, 3)}" if cyc == "G70" else
                 f" D{d} I{rng.uniform(0.3, 1.5):.2f} R{rng.uniform(0.1, 0.6):.2f}")
        prog = (f"G18 G21 G8 F200\nO1 sub\n{body}\nO1 endsub\nG0 X{start_x:.3f} Z2\n"
                f"{cyc} Q1 X{start_x:.3f} Z2{words}\nM2\n")
        try:
            theirs = run_rs274(prog, timeout=10.0)
        except subprocess.TimeoutExpired:  # rs274 loops: we must refuse, not loop
            with pytest.raises(GCodeError, match="no progress"):
                openmotion_motions(prog)
            continue
        if theirs.error is not None:
            with pytest.raises(GCodeError):
                openmotion_motions(prog)
            continue
        diffs = compare(openmotion_motions(prog), theirs.motions)
        assert not diffs, prog + "\n" + "\n".join(diffs[:5])
