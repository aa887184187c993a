"""Cost of scenario actions and a touch probe inside compiled cycles (virtual time, 1 ms).

Two jobs on the default machine (4 steppers), 2 s of virtual time each:
- actions: three axes move at constant speed while a board input toggles inside every
  5th cycle (400 scenario actions, each cutting its cycle into kernel parts);
- probe: a probe floor at X = 0 that axis 0 crosses back and forth 20 times while the
  other axes move (a probe's interval bounds are hidden switches the kernel runs).
Each job runs jumping with the compiled kernel (`SimMachine.native = True`) and on the
Python pipeline (`native = False`, the oracle: what the action and probe cycles ran on
before session 9, with every other cycle too); the CPU time (time.process_time, so the
figures hold on a loaded machine) of the best of three runs, and the ratio.
Run: python bench/bench_actions.py
"""

from __future__ import annotations

import time
from dataclasses import replace

from openmotion.config import default_machine
from openmotion.control import Controller
from openmotion.hw.sim.probe import SimProbe


def run(kind: str, native: bool) -> float:
    """CPU seconds of the job."""
    ctl = Controller(replace(default_machine(), digital_inputs=2))
    ctl.hardware.native = native
    ctl.enable_all()
    hw = ctl.hardware
    if kind == "actions":
        for k in range(400):
            hw.scenario.set_input("di1", bool(k % 2), at=k * 0.005 + 0.0003)
    else:
        probe = SimProbe.attach(hw, "di0")
        probe.place([{0: (-1e9, 0.0)}])
    for i, v in enumerate((20_000.0, -15_000.0, 30_000.0, 10_000.0)[:len(ctl.axes)]):
        if kind == "probe" and i == 0:
            ctl.axes[0].move_relative(-750.0, max_vel=20_000.0, tacc=0.01, tdec=0.01)
        else:
            ctl.axes[i].move_velocity(v, tacc=0.05)
    c0 = time.process_time()
    for k in range(20):
        ctl.advance(0.1)
        if kind == "probe":
            ctl.axes[0].stop_immediately()
            ctl.advance(0.002)
            ctl.axes[0].move_relative(-1500.0 if k % 2 else 1500.0, max_vel=20_000.0,
                                      tacc=0.01, tdec=0.01)
    return time.process_time() - c0


def main() -> None:
    print(f"{'job':<10}{'kernel CPU s':>14}{'Python CPU s':>14}{'ratio':>8}")
    for kind in ("actions", "probe"):
        fast = min(run(kind, True) for _ in range(3))
        slow = min(run(kind, False) for _ in range(3))
        print(f"{kind:<10}{fast:>14.3f}{slow:>14.3f}{slow / fast:>7.1f}x")


if __name__ == "__main__":
    main()
