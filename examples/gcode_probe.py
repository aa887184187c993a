"""Probe a workpiece on the simulator and machine relative to what was measured.

A block of 40 x 30 mm stands at X 10..50, Y 8..38 with its top at Z 20 (machine mm); the
simulated probe (hw/sim/probe.py) is wired to board input di0 and touches it with a tip of
radius 1.5 mm. examples/gcode/probe_corner.ngc finds the top and two edges with G38.2,
moves G54 to the corner and mills a square relative to it.

    PYTHONPATH=src python examples/gcode_probe.py
"""

from __future__ import annotations

import math
from pathlib import Path

from openmotion.control.core.controller import Controller
from openmotion.hw.sim.probe import SimProbe
from openmotion.program import ProgramRunner, RunOptions, RunState

PROGRAM = Path(__file__).parent / "gcode" / "probe_corner.ngc"
TIP = 1.5  # mm, the probe's tip radius (the program subtracts it)


def main() -> ProgramRunner:
    ctl = Controller()
    probe = SimProbe.attach(ctl.hardware, "di0")
    ctl.enable_all()
    run = ProgramRunner(ctl, PROGRAM, options=RunOptions(probe_input="di0"))
    ppu = dict(zip(run.letters, run.scales.ppu, strict=True))
    ax = dict(zip(run.letters, run.axis_indices, strict=True))
    # the tip's centre touches the block TIP before its faces (in X and Y)
    block = {ax["X"]: ((10.0 - TIP) * ppu["X"], (50.0 + TIP) * ppu["X"]),
             ax["Y"]: ((8.0 - TIP) * ppu["Y"], (38.0 + TIP) * ppu["Y"]),
             ax["Z"]: (-math.inf, 20.0 * ppu["Z"])}
    probe.place([block])
    run.start()
    run.wait(600)
    if run.state is not RunState.DONE:
        raise SystemExit(f"probing failed: {run.error}")
    for e in run.events:
        if e.kind in ("probe_trip", "message"):
            print(f"t={e.t:8.3f}  line {e.line:2d}  {e.text}")
    return run


if __name__ == "__main__":
    main()
