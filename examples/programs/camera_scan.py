"""Camera scan: take a picture of every part of a 5 x 4 grid on the fly.

camera_scan.ngc drives the serpentine rows (and gates the camera with M62/M63 P2 per
row); this script loads the trigger table into the compare engine before the program
runs: one 2-D window point per part (+-1e-6 pulse; HSL-4XMO trigger table / ZMotion
HW_PSWITCH2 style, in table order), each firing a 2 ms pulse on do3 at the exact time
the X/Y command position passes the part. Prints the number of pictures and the worst
position error at the trigger times. Run: python examples/programs/camera_scan.py
(`openmotion run examples/programs/camera_scan.ngc` runs the motion and the row gate.)
"""

from pathlib import Path

import numpy as np

from openmotion.control import Controller
from openmotion.control.trigger.compare import CompareEngine, Pulse, WindowJob
from openmotion.program.runjob import work_origin
from openmotion.program.runner import ProgramRunner
from openmotion.units import AxisUnits

HERE = Path(__file__).resolve().parent
XS = [-16.0, -8.0, 0.0, 8.0, 16.0]    # part columns, program mm
YS = [-9.0, -3.0, 3.0, 9.0]           # rows, as in camera_scan.ngc
CAMERA = 3                            # output do3
WIDTH = 2e-3                          # s


def part_table() -> np.ndarray:
    """Parts in the order the serpentine passes them (program mm, rows = parts)."""
    rows = []
    for k, y in enumerate(YS):
        xs = XS if k % 2 == 0 else XS[::-1]
        rows += [(x, y) for x in xs]
    return np.array(rows)


def main() -> dict:
    ctl = Controller()
    ctl.enable_all()
    params = work_origin(ctl)  # program zero at the middle of the travel (openmotion run)
    units = [AxisUnits.from_axis(ctl.config.axes[i]) for i in (0, 1)]
    offset = np.array([params.get(5221, 0.0), params.get(5222, 0.0)])
    parts = part_table()
    machine_mm = parts + offset
    pulses = np.column_stack([u.to_pulses(machine_mm[:, k]) for k, u in enumerate(units)])
    eng = CompareEngine(ctl)
    job = WindowJob((0, 1), pulses, 1e-6, Pulse(CAMERA, WIDTH), name="camera")
    eng.add(job)
    run = ProgramRunner(ctl, HERE / "camera_scan.ngc", gcode={"parameters": params},
                        compare=eng)
    run.start()
    run.wait(120)
    shots = [t for t, level in eng.output(CAMERA).edges if level]
    at = np.array([[ctl.history.state_at(a, t).p for a in (0, 1)] for t in shots])
    err_mm = (np.max(np.abs(at - pulses[:len(shots)]) / [u.pulses_per_unit for u in units])
              if shots else float("nan"))
    gates = [e for e in run.events if e.kind == "sync_output"]
    result = {"state": run.state.value, "pictures": len(shots), "parts": len(parts),
              "max_error_mm": float(err_mm), "row_gates": len(gates),
              "run_time_s": run.t_end - run.t_start}
    print(f"camera scan: {result['pictures']}/{result['parts']} pictures, worst position "
          f"error {result['max_error_mm']:.2e} mm, {len(gates)} gate edges, "
          f"{result['run_time_s']:.2f} s ({result['state']})")
    return result


if __name__ == "__main__":
    main()
