"""Random programs over the LinuxCNC features (cycles, compensation, rotation, polar, M98,
M70-M73, tool offsets): compiling either succeeds or raises GCodeError - nothing else."""

from __future__ import annotations

import contextlib

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from openmotion.program import GCodeError, GCodeOptions, compile_text
from openmotion.program.tooltable import Tool

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}, max_blocks=20_000,
                    tool_table={1: Tool(1, 1, diameter=2.0), 2: Tool(2, 2, diameter=-1.0,
                                                                  offsets=(0, 0, 5) + (0,) * 6)})
num = st.sampled_from(["0", "1", "-1", "2.5", "-3", "10", "0.001", "1e3", "45", "-0.5", "90",
                       "1000000"])
word = st.tuples(st.sampled_from(list("XYZAIJKRPQLDH@^F")), num).map("".join)
gcode = st.sampled_from([
    "G0", "G1", "G2", "G3", "G17", "G18", "G19", "G20", "G21", "G90", "G91", "G90.1",
    "G91.1", "G40", "G41", "G42", "G41.1", "G42.1", "G43", "G43.1", "G43.2", "G49", "G52",
    "G54", "G55", "G7", "G8", "G73", "G81", "G82", "G83", "G85", "G86", "G88", "G89", "G80",
    "G98", "G99", "G92", "G92.1", "G10 L2 P1", "G10 L1 P1", "G10 L10 P2", "G10 L20 P0",
    "G28", "G30", "G61", "G64", "G93", "G94", "M3", "M5", "M70", "M71", "M72", "M73", "M61",
    "M98 P7", "M6 T1", "G33 K1", "G76 P1 I-1 J0.1 K0.5"])
line = st.tuples(st.lists(gcode, max_size=2), st.lists(word, max_size=4)).map(
    lambda t: " ".join(t[0] + t[1]))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(line, min_size=1, max_size=12))
def test_only_gcode_errors_escape(lines):
    prog = "F100 S100\n" + "\n".join(lines) + "\nM2\nO7\nG1 X1\nM99\n"
    with contextlib.suppress(GCodeError):
        compile_text(prog, OPTS)
