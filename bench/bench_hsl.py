"""Benchmark: the cost of a legacy HSL polling loop in virtual time.

The same 10 000-pulse move at 10 000 pps (1 s) waited for three ways, CPU time each:
the plain controller (`Controller.run_until`, the reference), the HSL library's polling
loop `while hsl.HSL_M_motion_done(0): pass` on one module (0.497 ms a call: ~2000 polls)
and on eight modules (1 ms a call, eight controllers stepped). Prints the figures and the
ratios to the reference.

    python bench/bench_hsl.py
"""

from __future__ import annotations

import time

from openmotion.compat.hsl import HslLibrary
from openmotion.config_network import default_module
from openmotion.control import Controller


def plain() -> tuple[float, int]:
    ctl = Controller(default_module())
    ctl.enable_all()
    t0 = time.process_time()
    ctl.axes[0].move_relative(10_000, max_vel=10_000, tacc=0.1)
    ctl.run_until(lambda: ctl.axes[0].motion_done == 0, 10.0)
    return time.process_time() - t0, ctl.cycles


def polling(modules: int) -> tuple[float, int]:
    hsl = HslLibrary.simulated(modules)
    hsl.HSL_initial(0)
    t0 = time.process_time()
    hsl.HSL_M_start_tr_move(0, 10_000, 0, 10_000, 0.1, 0.1)
    polls = 0
    while hsl.HSL_M_motion_done(0):
        polls += 1
    return time.process_time() - t0, polls


def main() -> None:
    ref, cycles = plain()
    print(f"plain controller run_until: {ref * 1e3:8.1f} ms CPU ({cycles} cycles)")
    for n in (1, 8):
        t, polls = polling(n)
        print(f"HSL polling loop, {n} module(s): {t * 1e3:8.1f} ms CPU ({polls} polls), "
              f"ratio to plain {t / ref:5.1f}x, per module-cycle {t / ref / n:4.2f}x")


if __name__ == "__main__":
    main()
