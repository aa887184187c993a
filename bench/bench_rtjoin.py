"""Real-time joins: the cycle's busy time with joins on the worker thread and in the cycle.

N blended 0.05 mm segments on a wavy line at 40 mm/s (the stream of bench_stream.py,
without its 1024-command feeder burst: a cycle hook pushes at most 3 commands per cycle,
the queue kept at 256), run with `Controller.start_realtime()` at 1 ms, twice: with the
join worker (control/groups/groupjoin.py) and with every join forced into the cycle (the old
behaviour). Per run it prints the joins done each way, the path rests (0: it never stopped
inside), the end error, and the cycle statistics (`Controller.cycle_stats`) without the
first cycles (the first chain's start is planned in the cycle either way).

    python bench/bench_rtjoin.py [N]          (default 1000)
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.core.clock import CycleStats, pacer_baseline
from openmotion.control.groups.group import Group, GroupState

SKIP = 30  # first cycles left out of the figures (the first chain starts there)


def run(n: int, worker: bool) -> None:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xy")
    ctl = Controller(MachineConfig(name="rtjoin", axes=axes))
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], units=True, feed=40.0, acc_time=0.05, queue_size=1024)
    g.enable_blend(0.005)
    if not worker:
        g._use_worker = lambda plan: False  # type: ignore[method-assign]
    pts = [(0.05 * k, 0.5 * math.sin(k / 15.0)) for k in range(1, n + 1)]
    it = iter(pts)
    rests = [0]

    def feed(c: Controller, t: float) -> None:
        for _ in range(3):
            p = next(it, None) if g.queue_length < 256 else None
            if p is None:
                return
            g.line(p)

    def watch(c: Controller, t: float) -> None:
        if g.state is GroupState.MOVING and g.queue_length and \
                not any(a.is_moving for a in g.axes):
            rests[0] += 1

    ctl.add_cycle_hook(feed)
    ctl.add_cycle_hook(watch)
    with ctl.start_realtime():
        deadline = time.monotonic() + 120.0
        while time.monotonic() < deadline:
            with ctl.lock:
                if g.state is GroupState.IDLE and g.queue_length == 0 and g._job is None:
                    break
            time.sleep(0.01)
    s = ctl.cycle_stats()
    busy = ctl._pacer._busy[SKIP:min(s.cycles, len(ctl._pacer._busy))] * 1e3
    err = max(abs(a.position - e * 1000.0) for a, e in zip(g.axes, pts[-1], strict=True))
    print(f"{'worker' if worker else 'in cycle':8s} N={n}: joins {g.async_joins} on the "
          f"worker, {g.sync_joins} in the cycle; rests {rests[0]}; end error {err:g} pulse; "
          f"busy mean {busy.mean():.2f} p99 {np.percentile(busy, 99):.2f} "
          f"max {busy.max():.2f} ms; cycles over 2 ms {int(np.sum(busy > 2.0))}; "
          f"overruns {s.overruns}/{s.cycles}")


def percentiles(name: str, s: CycleStats) -> None:
    print(f"{name:8s} cycles {s.cycles}: jitter (start lateness) mean {s.mean_jitter * 1e6:.0f}"
          f" p99 {s.p99_jitter * 1e6:.0f} max {s.max_jitter * 1e6:.0f} us; busy mean "
          f"{s.mean_busy * 1e6:.0f} p99 {s.p99_busy * 1e6:.0f} max {s.max_busy * 1e6:.0f} us;"
          f" overruns {s.overruns}")


def idle_realtime(seconds: float) -> CycleStats:
    """4 enabled idle axes on the default machine in real time: the cycle's floor."""
    ctl = Controller()
    ctl.enable_all()
    with ctl.start_realtime():
        time.sleep(seconds)
    return ctl.cycle_stats()


if __name__ == "__main__":
    n_seg = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    print("no-op pacer beside the controller (OS wake-up lateness vs the controller's busy "
          "time), 1 ms, 2 s each:")
    percentiles("no-op", pacer_baseline(0.001, 2.0))
    percentiles("4 idle", idle_realtime(2.0))
    run(n_seg, True)
    run(n_seg, False)
