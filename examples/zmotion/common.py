"""The article's main-program initialisation and Clean_Pos(), shared by the examples.

Seed: zmotion-pso-2d-3d-and-hw-timer.txt ("Please see the codes"). Each BASIC line is kept
as a comment above its Python line. `report()` prints the firings and writes the scope plot
(and the XY firing plot for the 2-D/3-D modes) to the output folder (default out/zmotion,
git-ignored).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from openmotion.compat.zmotion import OFF, ON, ZController
from openmotion.control.trigger.compare_io import plot_firings
from openmotion.control.trigger.compare_scope import plot_scope

OUT = Path("out") / "zmotion"


def controller() -> ZController:
    """The article's program head on a fresh simulated 3-axis controller."""
    c = ZController(n_axes=3)
    c.RAPIDSTOP(2)                  # RAPIDSTOP(2)
    c.WAIT_IDLE(0)                  # WAIT  IDLE(0)
    c.WAIT_IDLE(1)                  # WAIT  IDLE(1)
    c.WAIT_IDLE(2)                  # WAIT  IDLE(2)
    c.BASE(0, 1, 2)                 # BASE(0,1,2)      'select axis X Y
    c.ATYPE = 1, 1, 1               # ATYPE=1,1,1      '1-pulse axis type, compare DPOS
    c.UNITS = 100, 100, 100         # UNITS=100,100,100
    c.SPEED = 100, 100, 100         # SPEED=100,100,100
    c.ACCEL = 1000, 1000, 1000      # ACCEL=1000,1000,1000
    c.DECEL = 1000, 1000, 1000      # DECEL=1000,1000,1000
    c.MERGE = ON, ON, ON            # MERGE=ON,ON,ON
    c.SRAMP = 50, 50, 50            # SRAMP=50,50,50    'S curve speed smooths
    c.OP(0, OFF)                    # OP(0,OFF)  'initialize to turn off the OUT used by PSO
    c.VECTOR_MOVED = 0              # VECTOR_MOVED = 0  'clear interpolation vector distance
    return c


def clean_pos(c: ZController) -> None:
    """GLOBAL SUB Clean_Pos()"""
    c.RAPIDSTOP(2)                  # RAPIDSTOP(2)  'axis stops
    c.WAIT_IDLE(0)                  # WAIT  IDLE(0)
    c.WAIT_IDLE(1)                  # WAIT  IDLE(1)
    c.WAIT_IDLE(2)                  # WAIT  IDLE(2)
    c.DPOS = 0, 0, 0                # DPOS=0,0,0    'set the current position to 0
    c.MPOS = 0, 0, 0                # MPOS=0,0,0
    c.OP(0, OFF)                    # OP(0,OFF)    'close the output


def finish(c: ZController, settle: float = 0.3) -> None:
    """Wait for the BASE axes, then let the last timer pulses finish."""
    for a in c.base:
        c.WAIT_IDLE(a)
    c.run(settle)


def report(c: ZController, job: int, name: str, outdir: Path | str = OUT,
           xy: tuple[int, int] | None = None) -> dict:
    """Print the job's firings and the OUT0 pulses since TRIGGER; plot the scope (and the
    XY firings); return them."""
    log = c.engine.log.for_job(job)
    units = np.array([c.UNITS[a] for a in range(len(c.ctl.axes))])
    pos = log["positions"] / units
    t0 = c.scope.t_trigger
    widths = c.scope.pulse_widths(0)
    print(f"{name}: {log['time'].size} firings")
    for t, k, p, st in zip(log["time"], log["index"], pos, log["state"], strict=True):
        print(f"  t={t - t0:8.4f} s  point {k}  at {np.round(p, 3).tolist()}  OUT0 -> {st}")
    print(f"  OUT0 pulses: {widths.size}, widths {np.round(widths, 6).tolist()} s")
    out = Path(outdir)
    files = [plot_scope(c.scope, out / f"{name}_scope.png", title=name)]
    if xy is not None:
        path = c.scope.arrays()["dpos"][:, list(xy)] * units[list(xy)]  # pulses, as the log
        files.append(plot_firings(c.engine.log, out / f"{name}_xy.png", path_xy=path,
                                  axes=xy, title=f"{name} (pulses)"))
    return {"times": log["time"] - t0, "index": log["index"], "positions": pos,
            "states": log["state"], "widths": widths, "files": files}
