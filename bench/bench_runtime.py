"""Controller runtime benchmark: virtual seconds per CPU second, cycle by cycle and jumping.

Three runs per case: cycle by cycle (`virtual_jumps = False`, the reference), jumping with
the compiled inner loops switched off (the Python path: per-cycle pieces and the Python
stepper pipeline, as before the kernel) and jumping with them (openmotion._kernel: chunk
pieces and the stepper pipeline in C).

1, 4, 16 and 63 moving axes (ideal steppers on the default machine's X axis template, 1 ms
cycle, every axis doing back-to-back T/S moves for the whole run, each restarted as soon
as it is done) and 4 enabled idle axes; recorder off and on; each cycle by cycle
(`virtual_jumps = False`, the reference) and jumping (control/core/jump.py). The driver loop is
the same both ways: `run_until(any axis done, event_driven=True)`, then new moves. Figures
are CPU time (time.process_time), so they hold on a loaded machine. Prints the goals of
issue 13 beside them, and on each "recorder on" row the recorder's extra cost (CPU per
cycle with it on over off, cycle by cycle / jumping with the kernel) and whether both
stay within issue 13's +20 % (a last line gives the verdict over every case). Each
figure is the least CPU time of `--repeat` runs (4x as many for the idle case jumping,
a run of about a millisecond), recorder off and on interleaved. Then two jobs, cycle
by cycle and jumping: a G-code job (lines, arcs and a dwell through the program runner
and a group) and a homing run (mode 0: search ORG, stop, move to home).

    python bench/bench_runtime.py [--seconds 2] [--repeat 3] [--case idle4 --case moving1]
"""

from __future__ import annotations

import argparse
import contextlib
import math
import time
from collections.abc import Iterator
from dataclasses import replace

from openmotion.config import MachineConfig, default_machine
from openmotion.control import Controller
from openmotion.control.core import motion as _motion
from openmotion.control.home.homing import HomeConfig, home_search
from openmotion.program.runner import ProgramRunner

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
          recorder: bool, native: bool = True, repeat: int = 1) -> tuple[float, float]:
    """(virtual s per CPU s, CPU us per cycle), of the least CPU time of `repeat` runs."""
    best = math.inf
    for _ in range(repeat):
        c = Controller(machine(n_axes))
        c.virtual_jumps = jumping
        c.hardware.native = native
        if recorder:
            c.start_recording(capacity=int(seconds / c.period) + 10)
        with python_path(not native):
            t0 = time.process_time()
            job(c, seconds, moving)
            cpu = max(time.process_time() - t0, 1e-9)
        best = min(best, cpu)
    return seconds / best, best / c.cycles * 1e6


def pair(n_axes: int, seconds: float, moving: bool, jumping: bool, native: bool,
         repeat: int) -> list[tuple[float, float]]:
    """`speed` with the recorder off and on, the runs interleaved (off, on, off, on, ...)
    so a change in the machine's load weighs on both alike."""
    best = [(0.0, math.inf), (0.0, math.inf)]
    for _ in range(repeat):
        for k, rec in enumerate((False, True)):
            r = speed(n_axes, seconds, moving, jumping, rec, native)
            if r[1] < best[k][1]:
                best[k] = r
    return best


#: The G-code job row: a square of lines with arcs in the corners and a dwell, repeated.
GCODE = "G21 G90 G17\nG0 X0 Y0\n" + "".join(
    f"G1 X{40 + k} Y0 F2400\nG3 X{50 + k} Y10 I0 J10\nG1 Y40\nG3 X{40 + k} Y50 I-10 J0\n"
    f"G1 X0\nG4 P0.05\nG1 Y0\n" for k in range(3)) + "M2\n"


def gcode_job(c: Controller) -> None:
    c.enable_all()
    r = ProgramRunner(c, GCODE, axes={"X": 0, "Y": 1})
    r.start()
    c.run_until(lambda: not r.running, 600.0, event_driven=True)
    assert r.state.value == "done", r.error


def homing_run(c: Controller) -> None:
    c.enable_all()
    c.axes[0].move_relative(200_000, max_vel=100_000, tacc=0.05)
    c.wait_motion_done()
    h = home_search(c, 0, HomeConfig(mode=0, str_vel=2_000.0, max_vel=20_000.0, tacc=0.05))
    c.run_until(lambda: not h.running, 600.0, event_driven=True)
    assert h.done, h.status


def job_speed(run, jumping: bool) -> tuple[float, float, float]:  # noqa: ANN001
    """(virtual s per CPU s, CPU us per cycle, of which in the control layer) of one job
    on the default machine (the rest is the simulator's `advance`/`run_cycles`)."""
    c = Controller()
    c.virtual_jumps = jumping
    hw = c.hardware
    in_hw = [0.0]
    depth = [0]  # run_cycles calls advance: count the outer call only

    def timed(fn):  # noqa: ANN001, ANN202
        def call(*a, **k):  # noqa: ANN002, ANN003, ANN202
            depth[0] += 1
            t = time.process_time()
            try:
                return fn(*a, **k)
            finally:
                depth[0] -= 1
                if not depth[0]:
                    in_hw[0] += time.process_time() - t
        return call

    hw.advance = timed(hw.advance)  # type: ignore[method-assign]
    hw.run_cycles = timed(hw.run_cycles)  # type: ignore[method-assign]
    t0 = time.process_time()
    run(c)
    cpu = max(time.process_time() - t0, 1e-9)
    return c.time / cpu, cpu / c.cycles * 1e6, (cpu - in_hw[0]) / c.cycles * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=2.0,
                    help="virtual seconds per run (63 axes: half, idle: 20x)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="runs per figure; the least CPU time is kept")
    ap.add_argument("--case", action="append", default=None,
                    help="only these cases (moving1, moving4, moving16, moving63, idle4); "
                         "skips the jobs")
    args = ap.parse_args()
    rep = max(1, args.repeat)
    print(f"virtual time, 1 ms cycle, CPU time (least of {rep}); {args.seconds:g} virtual s "
          "per run")
    print(f"{'case':>10} {'recorder':>8} {'cycle by cycle':>15} {'jump, Python':>13} "
          f"{'jump, C':>9} {'C/Python':>9} {'goal':>7} {'met':>4} "
          f"{'rec extra c/j':>14} {'<=+20%':>6}")
    cases = [("moving", 1), ("moving", 4), ("moving", 16), ("moving", 63), ("idle", 4)]
    if args.case:
        cases = [c for c in cases if f"{c[0]}{c[1]}" in args.case]
    worst: list[tuple[float, str]] = []  # the recorder's extra cost per case
    for kind, n in cases:
        secs = args.seconds * (0.5 if n == 63 else 20.0 if kind == "idle" else 1.0)
        mv = kind == "moving"
        slow = pair(n, secs, mv, False, True, rep)
        py = pair(n, secs, mv, True, False, rep)
        fast = pair(n, secs, mv, True, True, rep * (1 if mv else 4))  # idle: ~1 ms a run
        goal = GOALS.get((kind, n))
        for k, rec in enumerate((False, True)):
            met = "" if goal is None or rec else (
                "yes" if max(slow[k][0], fast[k][0]) >= goal else "no")
            extra = rmet = ""
            if rec:  # CPU per cycle with the recorder over without, minus one
                xs, xf = slow[1][1] / slow[0][1] - 1.0, fast[1][1] / fast[0][1] - 1.0
                extra = f"{xs:+.0%}/{xf:+.0%}"
                rmet = "yes" if max(xs, xf) <= RECORDER_GOAL else "no"  # both ways
                worst.append((max(xs, xf), f"{kind} {n}"))
            print(f"{kind + ' ' + str(n):>10} {'on' if rec else 'off':>8} "
                  f"{slow[k][0]:>14.1f}x {py[k][0]:>12.1f}x {fast[k][0]:>8.1f}x "
                  f"{fast[k][0] / py[k][0]:>8.1f}x "
                  f"{'' if goal is None or rec else f'{goal:.0f}x':>7} {met:>4} "
                  f"{extra:>14} {rmet:>6}")
    if worst:
        x, case = max(worst)
        print(f"recorder on: at most {RECORDER_GOAL:+.0%} cycle cost over off, cycle by cycle "
              f"and jumping, in every case: {'met' if x <= RECORDER_GOAL else 'not met'} "
              f"(worst {x:+.0%}, {case})")
    if args.case:
        return
    print("jobs (default machine, 4 axes, recorder off); control us/cycle = the part "
          "outside the simulator")
    print(f"{'job':>10} {'':>8} {'cycle by cycle':>15} {'jumping':>12} {'us/cycle c/j':>14} "
          f"{'ratio':>7} {'control us/cycle c/j':>22}")
    for name, run in (("G-code", gcode_job), ("homing", homing_run)):
        slow, us_s, ctl_s = job_speed(run, False)
        fast, us_f, ctl_f = job_speed(run, True)
        print(f"{name:>10} {'off':>8} {slow:>14.1f}x {fast:>11.1f}x {us_s:>7.1f}/{us_f:<6.1f} "
              f"{fast / slow:>6.1f}x {ctl_s:>12.1f}/{ctl_f:<9.2f}")


if __name__ == "__main__":
    main()
