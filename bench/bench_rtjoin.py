"""Real time: the controller's busy time per 1 ms cycle beside a no-op pacer, on the
compiled executor (control/core/realtime.py) and on the Python pacer (every cycle a
`Controller.step`, the reference), in one run.

Cases (wall clock; each run twice, "python" then "compiled"):
- no-op: a pacer running nothing (`clock.pacer_baseline`, time.sleep), and the compiled
  executor's own wait (`_kernel.rt_wait`) running nothing: the OS wake-up lateness.
- 4 idle: the default machine, 4 enabled axes at rest.
- 4 moving: the 4 axes moving back and forth (a new move whenever one ends).
- G-code: 4 axes (X Y Z A) streaming a program of lines, arcs and dwells through the
  program runner and a group.
- join stream: N blended 0.05 mm segments at 40 mm/s fed by a cycle hook (3 per cycle,
  queue at 256) with the join worker: a hook without `due`, so both executors step every
  cycle in Python (the fallback, reported as "py cycles").

Per run: cycles, busy p50/p99/max (the cycle itself: compiled, or the Python path, with a
landing's reactions), start lateness p99 (jitter: OS wake-up plus any Python work that
overflowed the gap), Python work between cycles p99/max (landing, feeding the pieces
ahead; compiled executor only), overruns (cycles that ended after the next slot began;
"own": those the controller's busy time plus its work before the next cycle caused alone,
the OS's lateness left out - wall time, so CPU starvation inside a cycle still counts;
"own by cpu": the same from the thread's CPU time, the figure to trust on a shared
machine; the compiled executor counts from each cycle's planned start, which the landing
lead puts up to realtime.LANDING_LEAD_S before the slot for the cycles before a landing),
cycles stepped in Python, compiled runs (each ends in a landing: Python's work). Compare
the lateness with the no-op rows: what exceeds them is the controller's.

    python bench/bench_rtjoin.py [N] [seconds]     (defaults 1000, 2)
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from openmotion import _kernel
from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.core import realtime
from openmotion.control.core.clock import CycleStats, pacer_baseline
from openmotion.control.groups.group import Group, GroupState
from openmotion.program.runner import ProgramRunner

#: The G-code job: a square with arcs in the corners, Z and A moving, a dwell; repeated.
GCODE = "G21 G90 G17\nG0 X0 Y0 Z0 A0\n" + "".join(
    f"G1 X{40 + k} Y0 Z{k} A{10 * k} F2400\nG3 X{50 + k} Y10 I0 J10\nG1 Y40 Z{k + 1}\n"
    f"G3 X{40 + k} Y50 I-10 J0\nG1 X0 A{10 * k + 5}\nG4 P0.05\nG1 Y0\n" for k in range(3)
) + "M2\n"


def busy_samples(ctl: Controller) -> np.ndarray:
    return ctl.cycle_samples()["busy"]


def show(name: str, mode: str, s: CycleStats, busy: np.ndarray | None = None,
         runs: int | None = None) -> None:
    p50 = float(np.percentile(busy, 50)) * 1e6 if busy is not None and len(busy) else 0.0
    work = (f"work p99 {s.p99_work * 1e6:5.0f} max {s.max_work * 1e6:6.0f} us; "
            if s.executor == "compiled" else "")
    if runs is not None:
        work += f"compiled runs {runs}; "
    print(f"{name:11s} {mode:8s} cycles {s.cycles:6d}: busy p50 {p50:6.1f} p99 "
          f"{s.p99_busy * 1e6:7.1f} max {s.max_busy * 1e6:7.0f} us; jitter p99 "
          f"{s.p99_jitter * 1e6:6.0f} us; {work}cpu p99 {s.p99_cpu * 1e6:6.1f} max "
          f"{s.max_cpu * 1e6:6.0f} us; overruns {s.overruns} (own {s.own_overruns}, own by "
          f"cpu {s.own_cpu_overruns}); py cycles {s.python_cycles}")


def compiled_noop(seconds: float) -> CycleStats:
    """The compiled executor's wait (rt_wait/rt_close) around no work at all."""
    st = np.zeros(realtime.RT_NFIELDS)
    rings = [np.zeros(65536) for _ in realtime.RINGS]
    st[realtime.RT_PENDING] = -1.0
    st[realtime.RT_PERIOD] = 0.001
    st[realtime.RT_WALL0] = _kernel.rt_now() - 0.001
    n = int(seconds / 0.001)
    for k in range(1, n + 1):
        _kernel.rt_wait(st, *rings, k)
        _kernel.rt_close(st, *rings)
    busy, late, cpu = rings[0][:n], rings[1][:n], rings[3][:n]
    return CycleStats(n, 0.001, float(busy.mean()), float(np.percentile(busy, 99)),
                      float(busy.max()), float(late.mean()), float(np.percentile(late, 99)),
                      float(late.max()), int(st[realtime.RT_OVERRUNS]), executor="compiled",
                      p99_cpu=float(np.percentile(cpu, 99)), max_cpu=float(cpu.max()),
                      own_cpu_overruns=int(np.count_nonzero(cpu > 0.001)))


def timed_run(ctl: Controller, compiled: bool, body, limit: float = 120.0) -> None:  # noqa: ANN001
    ctl.compiled_realtime = compiled
    with ctl.start_realtime():
        deadline = time.monotonic() + limit
        while time.monotonic() < deadline and not body():
            time.sleep(0.01)


def idle(compiled: bool, seconds: float) -> Controller:
    ctl = Controller()
    ctl.enable_all()
    t_end = time.monotonic() + seconds
    timed_run(ctl, compiled, lambda: time.monotonic() >= t_end)
    return ctl


def moving(compiled: bool, seconds: float) -> Controller:
    ctl = Controller()
    ctl.enable_all()
    sign = [-1.0] * len(ctl.axes)  # the first moves go up, away from MEL
    t_end = time.monotonic() + seconds

    def body() -> bool:
        # look without the lock (a move's end lands, so motion_done is current then); take
        # it only to start the next moves (a handover at a cycle boundary)
        ended = [k for k, ax in enumerate(ctl.axes) if ax.motion_done == 0]
        if ended:
            with ctl.lock:
                for k in ended:
                    sign[k] = -sign[k]
                    ctl.axes[k].move_relative(sign[k] * 20_000 * (k + 1), max_vel=60_000,
                                              tacc=0.05)
        return time.monotonic() >= t_end

    timed_run(ctl, compiled, body)
    return ctl


def gcode(compiled: bool) -> Controller:
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, GCODE)
    with ctl.lock:
        run.start()
    timed_run(ctl, compiled, lambda: not run.running)  # no lock: no handover per look
    assert run.state.value == "done", run.error
    return ctl


def join_stream(n: int, compiled: bool) -> Controller:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xy")
    ctl = Controller(MachineConfig(name="rtjoin", axes=axes))
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], units=True, feed=40.0, acc_time=0.05, queue_size=1024)
    g.enable_blend(0.005)
    pts = iter([(0.05 * k, 0.5 * math.sin(k / 15.0)) for k in range(1, n + 1)])
    fed = [False]

    def feed(c: Controller, t: float) -> None:
        for _ in range(3):
            p = next(pts, None) if g.queue_length < 256 else None
            if p is None:
                fed[0] = fed[0] or g.queue_length < 256
                return
            g.line(p)

    ctl.add_cycle_hook(feed)

    def done() -> bool:
        with ctl.lock:
            return fed[0] and g.state is GroupState.IDLE and g.queue_length == 0 and \
                g._job is None

    timed_run(ctl, compiled, done)
    return ctl


def main() -> None:
    n_seg = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 2.0
    print(f"real time, 1 ms cycle; the no-op rows are the OS's own wake-up lateness "
          f"({seconds:g} s each where timed)")
    show("no-op", "python", pacer_baseline(0.001, seconds))
    show("no-op", "compiled", compiled_noop(seconds))
    cases = (("4 idle", lambda c: idle(c, seconds)), ("4 moving", lambda c: moving(c, seconds)),
             ("G-code", gcode), (f"join N={n_seg}", lambda c: join_stream(n_seg, c)))
    for name, case in cases:
        for compiled in (False, True):
            ctl = case(compiled)
            p = ctl._pacer
            show(name, "compiled" if compiled else "python", ctl.cycle_stats(),
                 busy_samples(ctl), p.compiled_runs if compiled else None)


if __name__ == "__main__":
    main()
