"""Controller runtime benchmark: simulated seconds per wall-clock second in virtual time.

Runs 1, 4 and 16 axes (ideal steppers on the default machine's X axis template, 1 ms
cycle), every axis doing back-to-back T-curve moves for the whole run, with the motion
history on and recording off. Reports the speed ratio, the cycle cost, and peak memory
(Python allocations via tracemalloc in a separate, shorter run; process peak RSS).

    python bench/bench_runtime.py [--seconds 5]
"""

from __future__ import annotations

import argparse
import resource
import time
import tracemalloc
from dataclasses import replace

from openmotion.config import MachineConfig, default_machine
from openmotion.control import Controller


def machine(n_axes: int) -> MachineConfig:
    x = default_machine().axes[0]
    return MachineConfig(name=f"bench{n_axes}",
                         axes=tuple(replace(x, name=f"a{i}") for i in range(n_axes)))


def job(c: Controller, seconds: float) -> int:
    """Back-and-forth moves on every axis until `seconds` of virtual time; returns moves."""
    c.enable_all()
    moves = 0
    direction = [1] * len(c.axes)
    end = c.time + seconds
    while c.time < end:
        for i, ax in enumerate(c.axes):
            if ax.motion_done == 0:
                ax.move_relative(direction[i] * (20_000 + 1000 * i), max_vel=100_000,
                                 tacc=0.05, tdec=0.05, shape="T" if i % 2 else "S")
                direction[i] = -direction[i]
                moves += 1
        c.step()
    return moves


def speed(n_axes: int, seconds: float) -> tuple[float, float, int]:
    c = Controller(machine(n_axes))
    t0 = time.perf_counter()
    moves = job(c, seconds)
    wall = time.perf_counter() - t0
    return seconds / wall, wall / c.cycles * 1e6, moves


def peak_python_mb(n_axes: int, seconds: float) -> float:
    tracemalloc.start()
    c = Controller(machine(n_axes))
    job(c, seconds)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated seconds per run")
    args = ap.parse_args()
    print(f"virtual time, 1 ms cycle, {args.seconds:g} simulated s per run")
    print(f"{'axes':>4} {'sim s / wall s':>15} {'us / cycle':>11} {'moves':>6} "
          f"{'peak py MB (1 s)':>17}")
    for n in (1, 4, 16):
        ratio, us, moves = speed(n, args.seconds)
        mb = peak_python_mb(n, 1.0)
        print(f"{n:>4} {ratio:>15.2f} {us:>11.1f} {moves:>6} {mb:>17.2f}")
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"process peak RSS: {rss:.1f} MB")


if __name__ == "__main__":
    main()
