"""The compare scenarios of the ZMotion and HSL-4XMO manuals on the simulated machine:

1. ZMotion HW_PSWITCH2 mode 25: the 2-D table of 8 points with maxerr 10 (UNITS=100), the
   XY axes driven through the points by straight lines; OUT0 inverts at each point.
2. ZMotion mode 35 with HW_TIMER(2, 100000, 50000, 1, OFF, 0): the 3-D table of 6 points.
3. HSL-4XMO 4.12 CCD camera scan: 0 -> 36000 at 6000 pps, trigger points 1001..35000 every
   pulse ("="), 34,000 CMP pulses.

Writes <outdir>/pso_2d.png, pso_2d.csv and pso_ccd.npz (default outdir: out/).
Run: python examples/pso_manual_scenarios.py [outdir]
"""

import sys
from pathlib import Path

import numpy as np

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.trigger.compare import CompareEngine
from openmotion.control.trigger.compare_io import plot_firings
from openmotion.control.trigger.hsl_trigger import HslTrigger
from openmotion.control.trigger.pso import ZPso
from openmotion.profile.jerk import jerk_limited
from openmotion.profile.segments import Profile, State

UNITS = 100.0
TABLE_2D = (0, 0, 50, 50, 100, 100, 50, 150, 0, 200, -50, 150, -100, 100, -50, 50)
TABLE_3D = (20, 20, 20, 40, 40, 40, 70, 70, 70, 100, 100, 100, 140, 140, 140, 180, 180, 180)


def machine(n: int) -> Controller:
    c = Controller(MachineConfig("pso", tuple(AxisConfig(name=k) for k in "xyz"[:n])))
    c.enable_all()
    return c


def line_to(c: Controller, end_units, v: float = 20_000.0) -> None:
    """Straight line (every axis a scaled copy of one jerk-limited move), then wait."""
    start = np.array([c.axes[i].position for i in range(len(end_units))])
    d = np.asarray(end_units, float) * UNITS - start
    length = float(np.linalg.norm(d))
    ref = jerk_limited(length, v, 2e5, 2e7)
    for ax, (p0, dk) in enumerate(zip(start, d, strict=True)):
        k = dk / length
        c.axes[ax].run_profile(Profile(ref.t0, p0 + k * ref.p0, k * ref.v0, k * ref.a0,
                                       k * ref.j, ref.duration, State(p0), State(p0 + dk),
                                       ref.labels, ref.dt), stop_accel=2e5, stop_jerk=2e7)
    c.wait_motion_done(timeout=30)


def scenario_2d(out: Path) -> dict:
    c = machine(2)
    eng = CompareEngine(c)
    z = ZPso(eng)
    z.base(0, 1)
    for a in (0, 1):
        z.set_units(a, UNITS)
    z.table(0, *TABLE_2D)
    jid = z.hw_pswitch2(25, 0, 1, 10, 8, 0)
    pts = np.array(TABLE_2D, float).reshape(8, 2)
    path = [pts[0]]
    for p in [*pts[1:], pts[0]]:
        line_to(c, p)
        path.append(p)
    log = eng.log.for_job(jid)
    print("mode 25: points fired", log["index"].tolist(), "OUT0 states", log["state"].tolist())
    eng.log.save_csv(out / "pso_2d.csv")
    plot_firings(eng.log, out / "pso_2d.png", path_xy=np.array(path) * UNITS,
                 title="HW_PSWITCH2 mode 25, maxerr 10")
    return {"fired": int(log["time"].size)}


def scenario_3d() -> dict:
    c = machine(3)
    eng = CompareEngine(c)
    z = ZPso(eng)
    for a in range(3):
        z.set_units(a, UNITS)
    z.table(0, *TABLE_3D)
    z.hw_timer(2, 100000, 50000, 1, 0, 0)
    jid = z.hw_pswitch2(35, 0, 1, 10, 6, 0)
    for p in np.array(TABLE_3D, float).reshape(6, 3):
        line_to(c, p)
    log = eng.log.for_job(jid)
    print("mode 35: points fired", log["index"].tolist(), "at t =",
          np.round(log["time"], 4).tolist())
    return {"fired": int(log["time"].size)}


def scenario_ccd(out: Path) -> dict:
    c = machine(1)
    eng = CompareEngine(c)
    h = HslTrigger(eng)
    h.set_trigger_comparator(0, 0, "=", 0)
    n = h.build_compare_function(0, 1001, 35000, 1)
    h.set_auto_compare(0, 1)
    c.axes[0].move_relative(36000, max_vel=6000, tacc=0.05, tdec=0.05)
    c.wait_motion_done(timeout=10)
    a = eng.log.arrays()
    rate = 1.0 / float(np.median(np.diff(a["time"])))
    print(f"CCD scan: {n} points loaded, {a['time'].size} CMP pulses, "
          f"{rate:.0f} pts/s at cruise, after-final value {h.check_compare_data(0):g}")
    eng.log.save_npz(out / "pso_ccd.npz")
    return {"fired": int(a["time"].size), "rate": rate}


def main(outdir: str = "out") -> dict:
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    out.mkdir(parents=True, exist_ok=True)
    return {"2d": scenario_2d(out), "3d": scenario_3d(), "ccd": scenario_ccd(out)}


if __name__ == "__main__":
    main(*sys.argv[1:2])
