"""M67/M68 analog outputs: the records and their order against rs274, LinuxCNC's refusals,
the control-layer API and the simulator's outputs, and when the runner writes them."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from lcnc_oracle import OPTIONS, rs274_path, run_rs274
from openmotion.control import AnalogOutputs, Controller
from openmotion.errors import MotionError
from openmotion.hw.interface import AnalogOutputHardware
from openmotion.program import GCodeError, ProgramRunner, compile_text, run_program
from openmotion.program.analogout import AnalogOut
from openmotion.program.runner import RunState

HERE = Path(__file__).parent
_OUT = re.compile(r"(SET_MOTION_OUTPUT_VALUE|SET_AUX_OUTPUT_VALUE|STRAIGHT_\w+)\((.*)\)")


def _sequence_ours(text: str) -> list[tuple]:
    out = []
    for c in compile_text(text, OPTIONS):
        if isinstance(c, AnalogOut):
            out.append(("sync" if c.synced else "now", c.index, round(c.value, 6)))
        elif type(c).__name__ in ("Rapid", "Feed"):
            out.append(("move",))
    return out


def test_records_and_order_match_linuxcnc():
    exe = rs274_path()
    if exe is None:
        pytest.skip("rs274 not installed (tools/setup_rs274.sh)")
    text = (HERE / "gcode_oracle" / "analog_outputs.ngc").read_text()
    theirs = []
    for name, args in _OUT.findall(run_rs274(text, exe).listing):
        if name.startswith("STRAIGHT"):
            theirs.append(("move",))
        else:
            i, v = args.split(",")
            theirs.append(("sync" if "MOTION" in name else "now", int(i), round(float(v), 6)))
    assert _sequence_ours(text) == theirs
    assert ("now", 3, 2.5) in theirs


@pytest.mark.parametrize(("text", "needle"), [
    ("M67 E0\n", "needs Q"), ("M68 E1.5 Q1\n", "must be an integer"),
    ("M68 E4 Q1\n", "must be below 4"), ("M67 Q1\n", "Invalid analog index with M67"),
])
def test_refusals_name_the_word(text, needle):
    with pytest.raises(GCodeError, match=needle) as err:
        compile_text("G21 G0 X1\n" + text + "M2\n", OPTIONS)
    assert err.value.line == 2


def test_the_control_api_validates_and_leaves_outputs_as_they_were():
    ctl = Controller()
    ao = AnalogOutputs(ctl)
    assert isinstance(ctl.hardware, AnalogOutputHardware)
    assert ao.count == 4 and ao.value_range == (-10.0, 10.0)
    ao.set(2, -7.5)
    for bad in [(4, 1.0), (-1, 1.0), (True, 1.0), (0, 10.5), (0, float("nan")), (0, "1")]:
        with pytest.raises(MotionError):
            ao.set(*bad)
    assert [ao.value(k) for k in range(4)] == [0.0, 0.0, -7.5, 0.0]
    assert ctl.hardware.analog_record == [(0.0, 2, -7.5)]
    ctl.hardware.configure_analog(2, (0.0, 5.0))
    assert ao.count == 2
    with pytest.raises(MotionError, match=r"\[0, 5\]"):
        ao.set(1, 6.0)
    with pytest.raises(MotionError, match="channels"):
        ctl.hardware.configure_analog(65)


def test_hardware_without_analog_outputs_refuses_m67_before_motion():
    ctl = Controller()
    ctl.hardware.configure_analog(0)
    ctl.enable_all()
    with pytest.raises(GCodeError, match="M67 E must be below 0") as err:
        ProgramRunner(ctl, "G21 G0 X1\nM67 E0 Q1\nG1 X2 F100\nM2\n")
    assert err.value.line == 2
    assert ctl.axis("x").position == 0


def test_a_value_outside_the_boards_range_fails_before_anything_moves():
    ctl = Controller()
    ctl.enable_all()
    with pytest.raises(GCodeError, match=r"M68: value of ao1 must be a number in \[-10, 10\]"):
        ProgramRunner(ctl, "G21 G0 X1\nG1 X3 F100\nM68 E1 Q12\nM2\n")
    assert ctl.axis("x").position == 0 and ctl.hardware.analog_record == []


def test_m67_lands_where_the_next_move_starts_and_m68_after_the_move_before_it():
    ctl = Controller()
    ctl.enable_all()
    run = run_program(ctl, "G21 G0 X5 Y5\nM68 E1 Q3\nM67 E0 Q2.5\nG1 X20 F600\n"
                      "M67 E0 Q0\nG1 X30\nM68 E1 Q-1\nG1 X35\nM2\n")
    assert run.state is RunState.DONE, run.error
    rec = ctl.hardware.analog_record
    assert [(k, v) for _t, k, v in rec] == [(1, 3.0), (0, 2.5), (0, 0.0), (1, -1.0)]
    t, idx, pos = run.trace()
    line_at = {i: run.line_of(i) for i in set(idx.tolist()) if i >= 0}

    def row(time: float) -> int:
        return int(abs(t - time).argmin())

    # M68 E1 Q3: the G0 has ended (at rest on X5 Y5), nothing after it has started
    r = row(rec[0][0])
    assert pos[r, 0] == pytest.approx(5.0) and (idx[r] < 0 or line_at[idx[r]] == 1)
    # M67 E0 Q2.5: in the cycle the G1 of line 4 starts
    r = row(rec[1][0])
    assert line_at[idx[r]] == 4 and pos[r - 1, 0] == pytest.approx(5.0, abs=1e-3)
    # M67 E0 Q0: in the cycle the G1 of line 6 takes over (blended corner or not)
    r = row(rec[2][0])
    assert line_at[idx[r]] == 6 and (idx[r - 1] < 0 or line_at[idx[r - 1]] == 4)
    # M68 E1 Q-1 waits for the G1 of line 6 to end: at rest on X30
    r = row(rec[3][0])
    assert pos[r, 0] == pytest.approx(30.0)
    assert [e.text for e in run.events if e.kind == "analog_output"] == [
        "ao1 = 3", "ao0 = 2.5", "ao0 = 0", "ao1 = -1"]
