"""Benchmark: G-code parse and parse+interpret speed, lines per second.

Generates a CAM-like program of N G1 moves (3 axes, literal numbers, some F changes) plus a
program of the same size using named parameters and expressions, then times
`parse_program` and `compile_text` on each. Run: python bench/bench_gcode.py [N]
"""

from __future__ import annotations

import math
import sys
import time
import tracemalloc

from openmotion.program import GCodeOptions, compile_text, parse_program


def cam_program(n: int) -> str:
    lines = ["G21 G90 G64 P0.01", "G0 X0 Y0 Z5", "G1 Z-1 F300"]
    for k in range(n):
        t = k * 0.001
        x = 50.0 * math.cos(t) + 0.01 * k
        y = 50.0 * math.sin(3 * t)
        z = -1.0 - 0.5 * math.sin(t)
        f = f" F{1200 + (k % 7) * 10}" if k % 50 == 0 else ""
        lines.append(f"N{k + 10} G1 X{x:.4f} Y{y:.4f} Z{z:.4f}{f}")
    lines.append("M2")
    return "\n".join(lines)


def param_program(n: int) -> str:
    lines = ["G21 G90", "#<s> = 1.5", "G0 X0 Y0", "G1 F600"]
    for k in range(n):
        lines.append(f"X[#<s>*{k % 100}.5] Y[SIN[{k % 360}]*10]")
    lines.append("M2")
    return "\n".join(lines)


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - t0


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
    for name, make in (("G1 literal", cam_program), ("params+expr", param_program)):
        text = make(n)
        _, tp = timed(parse_program, text)
        tracemalloc.start()
        cmds, tc = timed(compile_text, text, opts)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"{name:12s} {n} lines: parse {tp:.2f} s ({n / tp:,.0f} lines/s), "
              f"parse+interpret {tc:.2f} s ({n / tc:,.0f} lines/s), {len(cmds)} commands, "
              f"peak {peak / 2**20:.0f} MiB (traced, slows the run)")
        _, tc = timed(compile_text, text, opts)
        print(f"{'':12s} parse+interpret untraced {tc:.2f} s ({n / tc:,.0f} lines/s)")


if __name__ == "__main__":
    main()
