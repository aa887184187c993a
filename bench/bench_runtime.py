"""Controller runtime benchmark: virtual seconds per CPU second, cycle by cycle and jumping.

Three runs per case: cycle by cycle (`virtual_jumps = False`, the reference), jumping with
the compiled inner loops switched off (the Python path: per-cycle pieces and the Python
stepper pipeline, as before the kernel) and jumping with them (openmotion._kernel: chunk
pieces and the stepper pipeline in C).

1, 4, 16 and 63 moving axes (ideal steppers on the default machine's X axis template, 1 ms
cycle, every axis doing back-to-back T/S moves for the whole run, each restarted as soon
as it is done) and 4 enabled idle axes; recorder off and on; each cycle by cycle
(`virtual_jumps = False`, the reference) and jumping (control/jump.py). The driver loop is
the same both ways: `run_until(any axis done, event_driven=True)`, then new moves. Figures
are CPU time (time.process_time), so they hold on a loaded machine. Prints the goals of
issue 13 beside them, and the recorder's extra cost.

    python bench/bench_runtime.py [--seconds 2]
"""

from __future__ import annotations

import argparse
import contextlib
import time
from collections.abc import Iterator
from dataclasses import replace

from openmotion.config import MachineConfig, default_machine
from openmotion.control import Controller
from openmotion.control import motion as _motion

#: issue 13's goals (virtual s per CPU s)
GOALS = {("moving", 4): 200.0, ("moving", 16): 50.0, ("moving", 63): 10.0,
         ("idle", 4): 2000.0}
RECORDER_GOAL = 0.20  # at most +20 % cycle cost with the recorder on


def machine(n_axes: int) -> MachineConfig:
    x = default_machine().axes[0]
    return MachineConfig(name=f"bench{n_axes}",
                         axes=tuple(replace(x, name=f"a{i}") for i in range(n_axes)))


def job(c: Controller, seconds: float, moving: bool) -> int:
    """Back-and-forth moves on every axis (if `moving`) until `seconds` of virtual time;
    returns the moves started."""
    c.enable_all()
    moves = 0
    direction = [1] * len(c.axes)
    end = c.time + seconds
    axes = c.axes
    while c.time < end - 1e-9:
        if moving:
            for i, ax in enumerate(axes):
                if ax.motion_done == 0:
                    ax.move_relative(direction[i] * (20_000 + 1000 * (i % 16)),
                                     max_vel=100_000, tacc=0.05, tdec=0.05,
                                     shape="T" if i % 2 else "S")
                    direction[i] = -direction[i]
                    moves += 1
            c.run_until(lambda: any(a.motion_done == 0 for a in axes), end - c.time,
                        event_driven=True)
        else:
            c.advance(end - c.time)
    return moves


@contextlib.contextmanager
def python_path(on: bool) -> Iterator[None]:
    """With `on`, the compiled pieces are off (ActiveMotion.pieces runs `piece` per cycle);
    the machine's own switch (SimMachine.native) is set by `speed`."""
    saved = _motion._kernel
    if on:
        _motion._kernel = None
    try:
        yield
    finally:
        _motion._kernel = saved


def speed(n_axes: int, seconds: float, moving: bool, jumping: bool,
          recorder: bool, native: bool = True) -> tuple[float, float]:
    """(virtual s per CPU s, CPU us per cycle)."""
    c = Controller(machine(n_axes))
    c.virtual_jumps = jumping
    c.hardware.native = native
    if recorder:
        c.start_recording(capacity=int(seconds / c.period) + 10)
    with python_path(not native):
        t0 = time.process_time()
        job(c, seconds, moving)
        cpu = max(time.process_time() - t0, 1e-9)
    return seconds / cpu, cpu / c.cycles * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=2.0,
                    help="virtual seconds per run (63 axes: half, idle: 20x)")
    args = ap.parse_args()
    print(f"virtual time, 1 ms cycle, CPU time; {args.seconds:g} virtual s per run")
    print(f"{'case':>10} {'recorder':>8} {'cycle by cycle':>15} {'jump, Python':>13} "
          f"{'jump, C':>9} {'C/Python':>9} {'goal':>7} {'met':>4}")
    cases = [("moving", 1), ("moving", 4), ("moving", 16), ("moving", 63), ("idle", 4)]
    rec_cost: dict[tuple[str, int], float] = {}
    rec_fast: dict[tuple[str, int], float] = {}
    for kind, n in cases:
        secs = args.seconds * (0.5 if n == 63 else 20.0 if kind == "idle" else 1.0)
        for rec in (False, True):
            slow, us_s = speed(n, secs, kind == "moving", False, rec)
            py, _ = speed(n, secs, kind == "moving", True, rec, native=False)
            fast, _ = speed(n, secs, kind == "moving", True, rec)
            goal = GOALS.get((kind, n))
            best = max(slow, fast)
            met = "" if goal is None or rec else ("yes" if best >= goal else "no")
            print(f"{kind + ' ' + str(n):>10} {'on' if rec else 'off':>8} {slow:>14.1f}x "
                  f"{py:>12.1f}x {fast:>8.1f}x {fast / py:>8.1f}x "
                  f"{'' if goal is None or rec else f'{goal:.0f}x':>7} {met:>4}")
            rec_cost[(kind, n)] = us_s if not rec else us_s / rec_cost[(kind, n)] - 1.0
            rec_fast[(kind, n)] = fast if not rec else rec_fast[(kind, n)] / fast - 1.0
    print("recorder on, extra cost cycle by cycle: " + ", ".join(
        f"{k} {n}: {rec_cost[(k, n)]:+.0%}" for k, n in cases))
    print(f"recorder on, extra cost jumping with the kernel (goal <= +{RECORDER_GOAL:.0%}): "
          + ", ".join(f"{k} {n}: {rec_fast[(k, n)]:+.0%}" for k, n in cases))


if __name__ == "__main__":
    main()
