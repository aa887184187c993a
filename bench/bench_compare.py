"""Compare engine cost per cycle with 1, 4 and 16 active jobs (virtual time, 1 ms cycle).

Three job kinds: 1-D tables on an axis (a point every 20 pulses), vector distance (every
20 pulses of path), 2-D window points (maxerr 5) along the path. Two axes move a straight
line at 100,000 pps for 0.5 s; the CPU time (time.process_time, so the figures hold on a
loaded machine) spent inside the engine's hooks (pre-advance and cycle hook) is measured,
beside issue 13's goal (16 jobs <= 200 us per cycle). With --oracle each row also runs on
the plain-Python solvers (tests/compare_oracle.py, what the engine ran before they were
compiled) in the same run, and prints the ratio. With --loop each row also runs with the
compiled scan driver off (every job through the engine's per-job Python loop, every
output line sent on its own: the engine before the driver) and prints the ratio.
Run: python bench/bench_compare.py [--oracle] [--loop]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.trigger import compare_math
from openmotion.control.trigger.compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    Pulse,
    VectorSource,
    WindowJob,
    every_distance,
)
from openmotion.profile.jerk import jerk_limited
from openmotion.profile.segments import Profile, State


def run(kind: str, n_jobs: int) -> tuple[float, int]:
    cfg = MachineConfig("b", (AxisConfig(name="x"), AxisConfig(name="y")),
                        digital_outputs=16)
    c = Controller(cfg)
    c.enable_all()
    eng = CompareEngine(c)
    for k in range(n_jobs):
        act = Pulse(k % 16, 2e-6)
        if kind == "axis":
            eng.add(LevelJob(AxisSource(0), np.arange(20.0 + k, 60_000, 20), act, direction=1))
        elif kind == "vector":
            eng.add(every_distance(VectorSource((0, 1)), 20.0, act, start=20.0 + k))
        else:
            s = np.arange(1, 2500) * 25.0 + k
            eng.add(WindowJob((0, 1), np.column_stack([0.6 * s, 0.8 * s]), 5.0, act))
    ref = jerk_limited(50_000.0, 100_000.0, 2e6, 1e8)
    for ax, kx in enumerate((0.6, 0.8)):
        p = Profile(ref.t0, kx * ref.p0, kx * ref.v0, kx * ref.a0, kx * ref.j, ref.duration,
                    State(0.0), State(kx * 50_000.0), ref.labels, ref.dt)
        c.axes[ax].run_profile(p, stop_accel=2e6, stop_jerk=1e8)
    spent = 0.0
    hook = eng._on_cycle

    def timed(ctl: Controller, t: float) -> None:
        nonlocal spent
        t0 = time.process_time()
        hook(ctl, t)
        spent += time.process_time() - t0

    pre = eng._pre_advance  # timed hardware: the DPOS work runs before the advance

    def timed_pre(ctl: Controller, t0: float, t1: float) -> None:
        nonlocal spent
        s0 = time.process_time()
        pre(ctl, t0, t1)
        spent += time.process_time() - s0

    c.remove_cycle_hook(hook)
    c.add_cycle_hook(timed)
    if eng.timed:
        c.remove_pre_advance_hook(pre)
        c.add_pre_advance_hook(timed_pre)
    n0 = c.cycles
    c.advance(0.5)
    return spent / (c.cycles - n0), len(eng.log)


def on_oracle(kind: str, n_jobs: int) -> tuple[float, int]:
    """`run` with the plain-Python solvers in place of the compiled ones."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    import compare_oracle

    compare_oracle.set_gauss(compare_math._GL_X, compare_math._GL_W)
    built = compare_math._ck
    compare_math._ck = compare_oracle
    try:
        return run(kind, n_jobs)
    finally:
        compare_math._ck = built


def per_job_loop(kind: str, n_jobs: int) -> tuple[float, int]:
    """`run` with the scan driver off: each job scanned and each line sent from Python."""
    from openmotion.control.trigger import compare, compare_io

    actions, send = compare._ACTIONS, compare.send_lines

    def one_by_one(lines, hw, t0, t1):  # noqa: ANN001, ANN202
        for line in lines:
            line.send(hw, t0, t1)

    compare._ACTIONS, compare.send_lines = {}, one_by_one
    try:
        return run(kind, n_jobs)
    finally:
        compare._ACTIONS, compare.send_lines = actions, send
        assert compare_io.send_lines is send


def main() -> None:
    oracle = "--oracle" in sys.argv
    loop = "--loop" in sys.argv
    head = f"{'kind':8s} {'jobs':>4s} {'us/cycle':>9s} {'firings':>8s} {'goal':>6s}"
    print(head + (f" {'loop us':>8s} {'ratio':>6s}" if loop else "")
          + (f" {'python us':>10s} {'ratio':>6s}" if oracle else ""))
    for kind in ("axis", "vector", "window"):
        for n in (1, 4, 16):
            cost, fired = run(kind, n)
            goal = "" if n != 16 else ("met" if cost <= 200e-6 else "no")
            row = f"{kind:8s} {n:4d} {cost * 1e6:9.1f} {fired:8d} {goal:>6s}"
            if loop:
                ref, ref_fired = per_job_loop(kind, n)
                assert ref_fired == fired, "the per-job loop fired differently"
                row += f" {ref * 1e6:8.1f} {ref / cost:5.1f}x"
            if oracle:
                ref, ref_fired = on_oracle(kind, n)
                assert ref_fired == fired, "the oracle fired differently"
                row += f" {ref * 1e6:10.1f} {ref / cost:5.1f}x"
            print(row)


if __name__ == "__main__":
    main()
