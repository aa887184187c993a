"""Laser marking: fire a 20 us pulse every 0.5 mm of path along a rounded rectangle (lines
and quarter arcs, run by a Group at 50 mm/s), as Aerotech's PSO distance mode does.
Writes <outdir>/laser_marking.png (firings over the XY path) and laser_marking.csv.
Run: python examples/pso_laser_marking.py [outdir]
"""

import math
import sys
from pathlib import Path

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.control.trigger.compare import CompareEngine, Pulse, VectorSource, every_distance
from openmotion.control.trigger.compare_io import plot_firings

MM = 1000.0  # pulses per mm


def main(outdir: str = "out") -> dict:
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    c = Controller(MachineConfig("laser", (AxisConfig(name="x"), AxisConfig(name="y"))))
    c.enable_all()
    eng = CompareEngine(c)
    src = VectorSource((0, 1), (MM, MM))  # vector distance in mm
    jid = eng.add(every_distance(src, 0.5, Pulse(0, 20e-6)))
    rec = c.start_recording()
    g = Group(c, [0, 1], feed=50 * MM, acc_time=0.05)
    w, h, r = 35.0, 20.0, 5.0
    pts = [((w - r, 0), None), ((w, r), (w - r, r)), ((w, h - r), None),
           ((w - r, h), (w - r, h - r)), ((0, h), None), ((-r, h - r), (0, h - r)),
           ((-r, r), None), ((0, 0), (0, r))]
    for end, centre in pts:
        e = [v * MM for v in end]
        if centre is None:
            g.line(e)
        else:
            g.arc([v * MM for v in centre], e)
    c.run_until(lambda: g.queue_length == 0 and all(a.motion_done == 0 for a in c.axes), 30)
    length = 2 * (w - r) + 2 * (h - 2 * r) + 2 * math.pi * r
    log = eng.log.for_job(jid)
    xy = rec.arrays()["cmd_pos"][:, :2]
    print(f"contour {length:.6f} mm, VECTOR_MOVED {eng.vector_moved(src):.6f} mm, "
          f"{log['time'].size} pulses (expected {math.floor(length / 0.5)})")
    eng.log.save_csv(out / "laser_marking.csv")
    png = plot_firings(eng.log, out / "laser_marking.png", path_xy=xy,
                       title="laser pulses every 0.5 mm")
    print(f"plot written to {png}")
    return {"fired": int(log["time"].size), "length": length}


if __name__ == "__main__":
    main(*sys.argv[1:2])
