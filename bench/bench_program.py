"""Lines per second parsed + planned for a 100,000-line program (no motion executed).

"Planned" = compiled by the G-code front end and converted to pulse-space group operations
by the program runner (validation of every move), on the default XYZU table.
Run: python bench/bench_program.py [lines]
"""

from __future__ import annotations

import math
import sys
import time

from openmotion.control import Controller
from openmotion.program.runjob import work_origin
from openmotion.program.runner import ProgramRunner


def program(n: int) -> str:
    out = ["G21 G90 G64 P0.005 F2400"]
    for k in range(n - 2):
        t = 2 * math.pi * k / 5000
        out.append(f"G1 X{40 * math.cos(t):.4f} Y{40 * math.sin(3 * t) / 2:.4f}")
    out.append("M2")
    return "\n".join(out) + "\n"


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    text = program(n)
    ctl = Controller()
    t0 = time.perf_counter()
    run = ProgramRunner(ctl, text, gcode={"parameters": work_origin(ctl)})
    dt = time.perf_counter() - t0
    print(f"{n} lines -> {len(run.ops)} operations in {dt:.2f} s: {n / dt:,.0f} lines/s "
          "parsed + planned")


if __name__ == "__main__":
    main()
