"""M66 E: analog inputs (hw.interface.AnalogInputHardware, the simulator's bank set from
the scenario, control AnalogInputs, #5399)."""

from __future__ import annotations

import pytest

from openmotion.control import AnalogInputs, Controller
from openmotion.errors import MotionError
from openmotion.hw.interface import AnalogInputHardware
from openmotion.program import GCodeError, ProgramRunner, RunState


def test_m66_e_reads_the_value_the_scenario_set():
    ctl = Controller()
    ctl.enable_all()
    assert isinstance(ctl.hardware, AnalogInputHardware)
    sc = ctl.hardware.scenario
    sc.set_analog_input(1, 2.5, at=0.1)
    sc.set_analog_input(3, -1.25, at=0.1)
    text = ("M66 E1 L0\n(DEBUG, before #5399)\nG4 P0.2\nM66 E1 L0\n(DEBUG, after #5399)\n"
            "M66 E3\n(DEBUG, three #5399)\nG0 X[#5399 + 3]\nM2\n")
    run = ProgramRunner(ctl, text)
    run.start()
    run.wait(30)
    assert run.state is RunState.DONE, run.error
    msgs = [e.text for e in run.events if e.kind == "message"]
    assert msgs == ["debug: before 0.000000", "debug: after 2.500000",
                    "debug: three -1.250000"]
    assert ctl.axes[0].position == pytest.approx(1.75 * run.scales.ppu[0])


def test_analog_input_channels_are_checked():
    ctl = Controller()
    ctl.enable_all()
    with pytest.raises(GCodeError, match="analog"):  # 4 inputs: E4 is refused compiling
        ProgramRunner(ctl, "M66 E4 L0\nM2\n")
    sc = ctl.hardware.scenario
    for bad in ((4, 1.0), (-1, 1.0), (True, 1.0), (0, float("nan")), (0, "1")):
        with pytest.raises(MotionError):
            sc.set_analog_input(*bad)  # type: ignore[arg-type]
    ai = AnalogInputs(ctl)
    assert ai.count == 4 and ai.read(0) == 0.0
    with pytest.raises(MotionError, match="channel"):
        ai.read(9)
    ctl.hardware.configure_analog_inputs(0)
    with pytest.raises(GCodeError, match="analog"):  # now the hardware has none
        ProgramRunner(ctl, "M66 E0 L0\nM2\n")
    with pytest.raises(MotionError, match="no analog inputs"):
        AnalogInputs(ctl).read(0)
