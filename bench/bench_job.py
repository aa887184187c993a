"""A G-code job end to end: compile, plan and run (virtual time, no report), by CPU time.

Issue 14's goal: examples/programs/cam_rose.ngc (4,000 G1 segments of 0.05 mm, blended
within 0.005 mm, F2400) and a 100k-line program of the same kind run at >= 50x real time
by CPU once the runtime issue's executor has landed (>= 10x before it). "x real time" is
machine seconds of the job over the CPU seconds (time.process_time) of compiling it
(`ProgramRunner`, the G-code front end and the conversion to group operations) and running
it to the end as `ProgramRunner.wait` does (`Controller.run_until(..., event_driven=True)`:
virtual time jumps over the cycles no hook needs, docs/runtime.md; the simulator, the
group's joins and re-plans, the runner's feed). `--stepping` runs every cycle instead
(`event_driven=False`, the reference: the cycles a jump crosses cost a kernel pass, a
stepped cycle the whole Python cycle). "landed" counts the cycles Python ran. The generated
program is bench_stream.py's rose traced lap after lap, N lines. Each case runs in a fresh
process (its peak RSS is its own).

    python bench/bench_job.py [--lines N] [--stepping]   (N default 100000; 0: cam_rose only)
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CAM_ROSE = ROOT / "examples" / "programs" / "cam_rose.ngc"
GOAL = 50.0          # x real time with the compiled executor
GOAL_BEFORE = 10.0   # x real time before it


def run_case(path: Path, stepping: bool = False) -> dict:
    """Compile and run one program on the default table; CPU and machine seconds."""
    from openmotion.control import Controller
    from openmotion.program.runjob import work_origin
    from openmotion.program.runner import ProgramRunner, RunState

    c0 = time.process_time()
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, path, gcode={"parameters": work_origin(ctl)})
    c1 = time.process_time()
    run.start()
    landed = [0]
    finish = ctl._finish_cycle

    def counting(n, edges) -> None:  # noqa: ANN001 - the cycles Python runs
        landed[0] += 1
        finish(n, edges)

    ctl._finish_cycle = counting  # type: ignore[method-assign]
    ctl.run_until(lambda: run.state is not RunState.RUNNING, 1e7, event_driven=not stepping)
    c2 = time.process_time()
    if run.state is not RunState.DONE:
        raise SystemExit(f"{path.name}: {run.state} {run.error}")
    machine = ctl.time - run.t_start
    return {"lines": sum(1 for _ in path.open()), "compile_s": c1 - c0, "run_s": c2 - c1,
            "machine_s": machine, "x_real_time": machine / (c2 - c0),
            "cycles": ctl.cycles, "landed": landed[0],
            "us_per_line": 1e6 * (c2 - c0) / max(1, len(run.ops)),
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}


def generated(n: int, folder: Path) -> Path:
    sys.path.insert(0, str(ROOT / "bench"))
    import bench_stream

    path = folder / f"rose_{n}.ngc"
    path.write_text(bench_stream.gcode(n))
    return path


def main() -> None:
    args = sys.argv[1:]
    if len(args) == 3 and args[0] == "--case":
        print(json.dumps(run_case(Path(args[1]), args[2] == "stepping")))
        return
    stepping = "--stepping" in args
    args = [a for a in args if a != "--stepping"]
    lines = 100_000
    if args[:1] == ["--lines"] and len(args) == 2:
        lines = int(args[1])
    elif args:
        raise SystemExit(__doc__)
    print(f"{'program':16} {'lines':>7} {'compile s':>9} {'run s':>8} {'machine s':>9} "
          f"{'x real time':>11} {'us/move':>8} {'RSS MB':>6} {'landed':>13}")
    with tempfile.TemporaryDirectory() as tmp:
        cases = [("cam_rose.ngc", CAM_ROSE)]
        if lines > 0:
            cases.append((f"rose {lines}", generated(lines, Path(tmp))))
        for name, path in cases:
            out = subprocess.run([sys.executable, __file__, "--case", str(path),
                                  "stepping" if stepping else "jumping"], check=True,
                                 capture_output=True, text=True).stdout
            r = json.loads(out.strip().splitlines()[-1])
            print(f"{name:16} {r['lines']:7d} {r['compile_s']:9.2f} {r['run_s']:8.2f} "
                  f"{r['machine_s']:9.2f} {r['x_real_time']:11.2f} {r['us_per_line']:8.0f} "
                  f"{r['peak_rss_mb']:6.0f} {r['landed']:6d}/{r['cycles']:<6d}  "
                  f"goal >= {GOAL:g}x (>= {GOAL_BEFORE:g}x before "
                  f"the executor): {'met' if r['x_real_time'] >= GOAL else 'NOT met'}",
                  flush=True)


if __name__ == "__main__":
    main()
