"""Streaming cost: N CAM-like segments through `Group` and through the program runner.

The path is a rose r = 30 cos(3t) mm traced lap after lap in short G1 segments (about
0.05 mm, like examples/programs/cam_rose.ngc), at F2400 (40 mm/s) with the corners blended
within 0.005 mm, on a two-axis table with 1000 pulses/mm and no limit switches. Virtual
time. Two feeders:

- group: a cycle hook keeps `Group`'s queue at QUEUE commands (the segments are generated
  as they are pushed, so nothing but the queue and the running chain is held);
- runner: `ProgramRunner` on the same path as G-code text (compiled up front, then
  streamed with its default window).

Per case it prints the wall time per command, the machine time, the largest wall time of
one controller cycle (`Controller.step`: the simulator, the group's hook with its joins
and re-plans, the feeder) in the first FILL cycles (the feeder fills the queue) and after
them (streaming), the 99th percentile and the mean, the peak number of elements in the
running chain, the number of cycles the path rested between its start and its end, the
end error (pulses), the process's peak RSS and, for the group feeder, the join cost: the
CPU time of the group's cycle hook (joins, blends, re-plans) per command. Each case runs in
a fresh process so the RSS figures do not mix. The last lines give the per-command cost of
the largest N over the smallest: flat streaming keeps it near 1.

    python bench/bench_stream.py [N ...]          (default 1000 10000 50000)
    python bench/bench_stream.py --against SRC [N] [ROUNDS]

`--against SRC` (another checkout's `src` directory, e.g. the commit before a planner
change) measures the join cost of the group feeder (N commands, default 1000) with that
code and with this one, in ROUNDS (default 5) alternating fresh processes, and prints
both series, their least values and the ratio: before and after in one run, each figure
CPU time (the least of the rounds is the one least disturbed by other load).
"""

from __future__ import annotations

import json
import math
import resource
import subprocess
import sys
import time
from collections.abc import Iterator

import numpy as np

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState

FEED = 40.0          # mm/s (F2400)
TOL = 0.005          # blend tolerance, mm
SEG = 0.05           # mean segment length, mm
QUEUE = 1024         # commands the group feeder keeps queued
ACC_TIME = 0.05      # s to the feed (the runner's default)
FILL = 5             # first cycles: the queue is filled


def controller() -> Controller:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xy")
    ctl = Controller(MachineConfig(name="stream", axes=axes, digital_outputs=8))
    ctl.enable_all()
    return ctl


def points(n: int) -> Iterator[tuple[float, float]]:
    """n points of the rose, lap after lap, about SEG apart on average (rounded to 1e-4
    mm like a CAM file); the path starts at (30, 0)."""
    lap = 0.0  # arc length of one lap (t in [0, pi)), by fine sampling
    t = np.linspace(0.0, math.pi, 200_001)
    r = 30.0 * np.cos(3.0 * t)
    lap = float(np.sum(np.hypot(np.diff(r * np.cos(t)), np.diff(r * np.sin(t)))))
    dt = math.pi * SEG / lap
    for k in range(1, n + 1):
        u = k * dt
        rr = 30.0 * math.cos(3.0 * u)
        yield round(rr * math.cos(u), 4), round(rr * math.sin(u), 4)


def gcode(n: int) -> str:
    out = [f"G21 G90 G17 G64 P{TOL}", "G0 X30 Y0", f"G1 F{FEED * 60:g}"]
    out += [f"X{x:.4f} Y{y:.4f}" for x, y in points(n)]
    return "\n".join(out) + "\nM2\n"


class Probe:
    """Per-cycle figures: step wall time, chain length, rests of the path."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.steps: list[float] = []
        self.chain = 0
        self.moving: list[bool] = []

    def step(self, group: Group | None) -> None:
        t0 = time.perf_counter()
        self.ctl.step()
        self.steps.append(time.perf_counter() - t0)
        if group is not None:
            r = group._run
            if r is not None and r.plan is not None:
                self.chain = max(self.chain, len(r.plan.chain.elements))
        self.moving.append(any(a.is_moving for a in self.ctl.axes))

    def worst(self) -> tuple[float, float]:
        """Largest cycle (ms) of the first FILL cycles (the feeder fills the queue: up to
        QUEUE pushes in one cycle) and of the rest (streaming: joins and re-plans)."""
        st = np.array(self.steps)
        return 1e3 * float(st[:FILL].max()), 1e3 * float(st[FILL:].max(initial=0.0))

    def rests(self) -> int:
        m = np.array(self.moving)
        on = np.nonzero(m)[0]
        return 0 if len(on) == 0 else int(np.sum(~m[on[0]:on[-1] + 1]))


def case_group(n: int) -> dict:
    ctl = controller()
    g = Group(ctl, ["x", "y"], units=True, feed=FEED, acc_time=ACC_TIME)
    g.set_axis_limit_policy("slow")
    g.enable_blend(TOL)
    g.ptp([30.0, 0.0])
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0, 10.0)
    hook_cpu = [0.0]
    group_hook = g._on_cycle

    def timed_hook(c: Controller, t: float) -> None:  # the group's joins, blends, re-plans
        t0 = time.process_time()
        group_hook(c, t)
        hook_cpu[0] += time.process_time() - t0

    ctl.remove_cycle_hook(group_hook)
    ctl.add_cycle_hook(timed_hook)
    pts = points(n)
    last = [None]

    def feed(c: Controller, t: float) -> None:
        while g.queue_length < QUEUE:
            p = next(pts, None)
            if p is None:
                return
            g.line(p)
            last[0] = p

    probe = Probe(ctl)
    t_start = ctl.time
    ctl.add_cycle_hook(feed)
    w0 = time.perf_counter()
    while True:
        probe.step(g)
        if last[0] is not None and g.state is GroupState.IDLE and g.queue_length == 0 \
                and next(pts, None) is None:
            break
    wall = time.perf_counter() - w0
    end = np.array([a.position for a in g.axes])
    err = float(np.max(np.abs(end - np.array(last[0]) * 1000.0)))
    out = _figures("group", n, wall, ctl.time - t_start, probe, err, 0.0)
    out["join_us_per_cmd"] = 1e6 * hook_cpu[0] / n
    return out


def case_runner(n: int) -> dict:
    from openmotion.program.runner import ProgramRunner, RunState

    ctl = controller()
    text = gcode(n)
    w0 = time.perf_counter()
    run = ProgramRunner(ctl, text)
    compile_s = time.perf_counter() - w0
    probe = Probe(ctl)
    run.start()
    w0 = time.perf_counter()
    while run.state is RunState.RUNNING:
        probe.step(run.group)
    wall = time.perf_counter() - w0
    assert run.state is RunState.DONE, run.error
    x, y = text.splitlines()[-2].split()
    err = float(np.max(np.abs(np.array([a.position for a in ctl.axes])
                              - np.array([float(x[1:]), float(y[1:])]) * 1000.0)))
    return _figures("runner", n, wall, ctl.time - run.t_start, probe, err, compile_s)


def _figures(kind: str, n: int, wall: float, machine: float, probe: Probe, err: float,
             compile_s: float) -> dict:
    st = np.array(probe.steps)
    fill, worst = probe.worst()
    return {"kind": kind, "n": n, "wall_s": wall, "us_per_cmd": 1e6 * wall / n,
            "machine_s": machine, "fill_cycle_ms": fill, "max_cycle_ms": worst,
            "p99_cycle_ms": 1e3 * float(np.percentile(st, 99)),
            "mean_cycle_ms": 1e3 * float(st.mean()), "peak_chain": probe.chain,
            "rests": probe.rests(), "end_err_pulses": err, "compile_s": compile_s,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}


def against(src: str, n: int, rounds: int) -> None:
    """Join us/command of the group feeder: `src`'s code against this checkout's."""
    import os
    from pathlib import Path

    here = str(Path(__file__).resolve().parents[1] / "src")
    series: dict[str, list[float]] = {"before": [], "after": []}
    for _ in range(rounds):
        for name, path in (("before", src), ("after", here)):
            env = dict(os.environ, PYTHONPATH=path)
            out = subprocess.run([sys.executable, __file__, "--case", "group", str(n)],
                                 check=True, capture_output=True, text=True, env=env).stdout
            series[name].append(json.loads(out.strip().splitlines()[-1])["join_us_per_cmd"])
    for name, xs in series.items():
        print(f"join us/cmd {name:6} ({'SRC' if name == 'before' else 'this checkout'}): "
              + " ".join(f"{x:.0f}" for x in xs) + f"   least {min(xs):.0f}")
    print(f"after / before (least of {rounds}): {min(series['after']) / min(series['before']):.2f}")


def main() -> None:
    if len(sys.argv) >= 3 and sys.argv[1] == "--against":
        n = int(sys.argv[3]) if len(sys.argv) > 3 else 1000
        against(sys.argv[2], n, int(sys.argv[4]) if len(sys.argv) > 4 else 5)
        return
    if len(sys.argv) == 4 and sys.argv[1] == "--case":
        fn = case_group if sys.argv[2] == "group" else case_runner
        print(json.dumps(fn(int(sys.argv[3]))))
        return
    if any(not a.isdigit() for a in sys.argv[1:]):  # --help, or a typo: the usage
        raise SystemExit(__doc__)
    ns = [int(a) for a in sys.argv[1:]] or [1000, 10_000, 50_000]
    print(f"{'feeder':7} {'N':>6} {'us/cmd':>7} {'machine s':>9} {'fill ms':>7} "
          f"{'max cycle ms':>12} {'p99 ms':>7} {'mean ms':>7} {'chain':>5} {'rests':>5} "
          f"{'end err':>7} {'RSS MB':>6} {'compile s':>9} {'join us/cmd':>11}")
    rows: dict[str, list[dict]] = {"group": [], "runner": []}
    for kind in rows:
        for n in ns:
            out = subprocess.run([sys.executable, __file__, "--case", kind, str(n)],
                                 check=True, capture_output=True, text=True).stdout
            r = json.loads(out.strip().splitlines()[-1])
            rows[kind].append(r)
            join = f"{r['join_us_per_cmd']:.0f}" if "join_us_per_cmd" in r else "-"
            print(f"{kind:7} {n:6d} {r['us_per_cmd']:7.0f} {r['machine_s']:9.2f} "
                  f"{r['fill_cycle_ms']:7.1f} {r['max_cycle_ms']:12.2f} {r['p99_cycle_ms']:7.2f} "
                  f"{r['mean_cycle_ms']:7.3f} {r['peak_chain']:5d} {r['rests']:5d} "
                  f"{r['end_err_pulses']:7.1g} {r['peak_rss_mb']:6.0f} "
                  f"{r['compile_s']:9.2f} {join:>11}", flush=True)
    for kind, rs in rows.items():
        if len(rs) > 1:
            a, b = rs[0], rs[-1]
            print(f"{kind}: cost per command N={b['n']} / N={a['n']}: "
                  f"{b['us_per_cmd'] / a['us_per_cmd']:.2f}; largest cycle "
                  f"{b['max_cycle_ms'] / a['max_cycle_ms']:.2f}x")


if __name__ == "__main__":
    main()
