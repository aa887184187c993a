"""Turn and thread a shaft with the spindle in the loop.

The XZ lathe of examples/lathe_xz.toml gets a spindle axis (hw/sim/spindle.py: a servo
motor with a 4096-count encoder and its index); the runner drives it for M3/M5 and locks
every G76 pass of examples/gcode/lathe_turn_thread.ngc to the spindle's measured position,
each pass starting at the index pulse.

    PYTHONPATH=src python examples/gcode_thread.py
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from openmotion.config_toml import load_machine
from openmotion.control.core.controller import Controller
from openmotion.hw.sim.spindle import spindle_axis
from openmotion.program import ProgramRunner, RunOptions, RunState

HERE = Path(__file__).parent


def main() -> ProgramRunner:
    lathe = load_machine(HERE / "lathe_xz.toml")
    ctl = Controller(replace(lathe, axes=(*lathe.axes, spindle_axis())))
    ctl.enable_all()
    run = ProgramRunner(ctl, HERE / "gcode" / "lathe_turn_thread.ngc",
                        options=RunOptions(spindle_axis="spindle"))
    run.start()
    run.wait(600)
    if run.state is not RunState.DONE:
        raise SystemExit(f"the run failed: {run.error}")
    for k, m in enumerate(run.sync_moves):
        print(f"pass {k + 1}: index at t={m.t0:.4f} s, count {m.c0:.0f}; tool within "
              f"{m.steady_error * 1000:.2f} um of pitch x revolutions")
    return run


if __name__ == "__main__":
    main()
