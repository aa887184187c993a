"""M99 in the main program (LinuxCNC's Fanuc-style endless main program): compile_text runs
one pass and ends there as rs274 does; the runner starts the program again from its top
with every state kept, each restart a pass, until abort() or RunOptions.repeat passes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.program import GCodeError, GCodeOptions, compile_file, compile_text
from openmotion.program.canon import End, Feed
from openmotion.program.interp import Interpreter
from openmotion.program.parser import parse_program
from openmotion.program.runner import ProgramRunner, RunOptions, RunState
from openmotion.program.stream import stream_file

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
ORACLE = Path(__file__).parent / "gcode_oracle" / "m99_main_restart.ngc"

# LinuxCNC's tests/interp/m98m99/12 in our words: a counter in #100 survives the restarts
COUNTER = """#100 = [#100 + 1]
O1000 if [#100 GT 3]
  M30
O1000 endif
G21 G1 X1 F600
M98 P100
G1 X5
M99
O100
G1 Y-4
M99
"""


def ctl3() -> Controller:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xyz")
    ctl = Controller(MachineConfig(name="iso", axes=axes, digital_outputs=8))
    ctl.enable_all()
    return ctl


def ends(run: ProgramRunner) -> list[tuple[float, float]]:
    """The group's line ends in the order they were queued (X, Y)."""
    return [(round(float(op.end[0]), 6), round(float(op.end[1]), 6))
            for _, op in sorted(run.op_of.items()) if op.kind == "line"]


def test_compile_runs_one_pass_ending_in_a_restart_record():
    cmds = compile_text(COUNTER, OPTS)
    assert [c.end[:2] for c in cmds if isinstance(c, Feed)] == [(1, 0), (1, -4), (5, -4)]
    assert cmds[-1] == End(False, 8, "", restart=True)
    assert compile_file(ORACLE, OPTS) == list(stream_file(ORACLE, OPTS))


def test_session_restarts_with_the_state_kept():
    s = Interpreter(parse_program("G1 X1 F60\nG91\nM99\n", "", 256), OPTS).session()
    xs = []
    for k in range(3):
        chunk = s.advance(True if k else None)
        xs.append([c.end[0] for c in chunk if isinstance(c, Feed)])
        assert isinstance(s.request, End) and s.request.restart
    assert xs == [[1.0], [2.0], [3.0]]  # G91 from the first pass on
    assert s.advance(False) == [] and s.done
    t = Interpreter(parse_program("G1 X1 F60\nM99\n", "", 256), OPTS).session()
    t.advance()
    with pytest.raises(GCodeError, match="True or False"):
        t.advance(None)  # type: ignore[arg-type]
    with pytest.raises(GCodeError, match="True or False"):
        t.advance(1.0)  # type: ignore[arg-type]


def test_runner_loops_until_the_program_ends_itself():
    ctl = ctl3()
    run = ProgramRunner(ctl, COUNTER)
    assert run.restarts and run.passes is None
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE
    assert run.passes_done == 4  # three M99 restarts, the fourth pass ends at M30
    # LinuxCNC's motion: pass 2 starts where pass 1 ended (X1 keeps Y-4)
    assert ends(run) == [(1, 0), (1, -4), (5, -4)] + [(1, -4), (5, -4)] * 2
    assert [e.text for e in run.events if e.kind == "repeat"] == [
        "pass 2", "pass 3", "pass 4"]


def test_endless_until_abort_and_repeat_counts_passes():
    prog = "G1 X1 F6000\nG91\nM99\n"   # pass n ends at X = n
    ctl = ctl3()
    run = ProgramRunner(ctl, prog)
    run.start()
    assert not run.wait(1.0)  # still running: M99 restarts it forever
    assert run.state is RunState.RUNNING and run.passes_done >= 3
    run.abort()
    ctl.run_until(lambda: not any(a.is_moving for a in ctl.axes), 5.0)
    assert run.state is RunState.ABORTED
    ctl2 = ctl3()
    run2 = ProgramRunner(ctl2, prog, options=RunOptions(repeat=3))
    run2.start()
    run2.wait(30)
    assert run2.state is RunState.DONE and run2.passes_done == 3
    assert run2._positions()[0] / run2.scales.ppu[0] == pytest.approx(3.0)
    # an M2 program repeats from scratch: G91 is reset, X ends at 1
    ctl3_ = ctl3()
    run3 = ProgramRunner(ctl3_, "G1 X1 F6000\nG91\nM2\n", options=RunOptions(repeat=3))
    run3.start()
    run3.wait(30)
    assert run3.state is RunState.DONE
    assert run3._positions()[0] / run3.scales.ppu[0] == pytest.approx(1.0)


def test_state_carried_over_in_the_runner_overrides_and_units():
    # M50 P0 in pass 1 stays in force (LinuxCNC resets nothing at M99; M2 would)
    ctl = ctl3()
    run = ProgramRunner(ctl, "G1 X1 F6000\nM50 P0\nG20\nG1 X[#<_x> + 0.1]\nM99\n",
                        options=RunOptions(repeat=2))
    run.set_feed_override(50.0)
    run.start()
    run.wait(30)
    assert run.state is RunState.DONE
    # pass 2 runs in G20 from the start: its X1 is an inch
    assert [x for x, _ in ends(run)] == [1.0, 3.54, 25.4, 27.94]
    assert run.feed_override_on is False


def test_a_pass_that_does_nothing_is_a_fault_not_a_hang():
    ctl = ctl3()
    run = ProgramRunner(ctl, "G0 X1\nO1 if [#1 GT 0]\nG0 X1\nO1 endif\n#1 = 1\nM99\n")
    run.start()
    run.wait(10)
    assert run.state is RunState.ERROR
    assert "line 6" in run.error and "repeat endlessly" in run.error
    assert run.passes_done == 2


def test_refusals_name_the_m99():
    with pytest.raises(GCodeError, match=r"cutter compensation.*") as e:
        compile_text("G41.1 D1\nG1 X10 Y0 F100\nG1 Y10\nM99\n", OPTS)
    assert e.value.line == 4 and e.value.word == "M99"
    with pytest.raises(GCodeError) as e:
        compile_text("G5.2 X0 Y0 P1 L3\nX1 Y1 P1\nX2 Y0 P1\nM99\n", OPTS)
    assert e.value.line == 1  # the open NURBS block is named
    with pytest.raises(MotionError, match="repeat must be an integer >= 1 or None"):
        RunOptions(repeat=0)


def test_command_list_with_a_restart_repeats_as_is():
    ctl = ctl3()
    cmds = compile_text("G1 X1 F6000\nG1 X2\nG0 X0\nM99\n", OPTS)
    run = ProgramRunner(ctl, cmds, options=RunOptions(repeat=2))
    run.start()
    run.wait(30)
    assert run.state is RunState.DONE and run.passes_done == 2
    assert np.allclose(run._positions(), 0.0)
