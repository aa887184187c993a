"""The demo the README's first command runs: single-axis motion on the simulated XYZU table.

Every kind of single-axis move runs on the built-in simulator in virtual time: a T-curve,
an S-curve, a time-optimal jerk-limited move, velocity mode with a change of speed on the
fly and a decelerating stop, an absolute move whose target is changed on the fly so that it
goes back, and an immediate stop. It prints what happened and writes the velocity curve and
a profile plot; then it runs a G-code laser contour as `openmotion run` does and writes its
HTML report.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .control import Controller
from .plot import plot_profile, plot_trace
from .profile import scurve


@dataclass
class Step:
    """One demo step and what came of it."""

    name: str
    axis: str
    t_start: float
    t_end: float = 0.0
    note: str = ""


def _wait(ctl: Controller, names: list[str], timeout: float = 60.0) -> None:
    axes = [ctl.axis(n) for n in names]
    if not ctl.run_until(lambda: not any(a.is_moving for a in axes), timeout):
        raise RuntimeError(f"demo: axes {names} still moving after {timeout} s")


def run_steps(ctl: Controller) -> list[Step]:
    """Run the demo's moves on `ctl` (virtual time) and return what each did."""
    x, y, z, u = (ctl.axis(n) for n in ("x", "y", "z", "u"))
    ctl.enable_all()
    steps: list[Step] = []

    def begin(name: str, axis: str) -> Step:
        s = Step(name, axis, ctl.time)
        steps.append(s)
        return s

    # 1. T-curve, relative, in millimetres.
    s = begin("T-curve relative 40 mm", "x")
    x.move_relative(40.0, max_vel=80.0, str_vel=2.0, tacc=0.15, tdec=0.25, units=True)
    _wait(ctl, ["x"])
    s.t_end = ctl.time

    # 2. S-curve, absolute, with S regions of 10 mm/s.
    s = begin("S-curve absolute to 30 mm", "y")
    y.move_absolute(30.0, max_vel=60.0, tacc=0.2, shape="S", vs_acc=10.0, vs_dec=10.0,
                    units=True)
    _wait(ctl, ["y"])
    s.t_end = ctl.time

    # 3. Time-optimal jerk-limited move on z.
    s = begin("jerk-limited relative 20 mm", "z")
    z.move_jerk_limited(20.0, v_max=40.0, a_max=400.0, j_max=8000.0, units=True)
    _wait(ctl, ["z"])
    s.t_end = ctl.time

    # 4. Velocity mode on the rotary axis, speed changed on the fly, then a decelerating stop.
    s = begin("velocity 90 deg/s, change to 180 deg/s, decelerating stop", "u")
    u.fix_speed_range(360.0, units=True)
    u.move_velocity(90.0, tacc=0.2, units=True)
    ctl.advance(0.5)
    u.change_speed(180.0, 0.2, units=True)
    ctl.advance(0.5)
    u.stop()
    _wait(ctl, ["u"])
    s.t_end = ctl.time

    # 5. Absolute move on x whose target is changed behind it on the fly: it goes back.
    s = begin("absolute to 0 mm, changed on the fly to 30 mm (go back)", "x")
    x.move_absolute(0.0, max_vel=60.0, tacc=0.1, units=True)
    ctl.advance(0.45)
    x_mm = x.units.to_units(x.position)
    x.change_position(30.0, units=True)
    s.note = f"changed at {x_mm:.2f} mm"
    _wait(ctl, ["x"])
    s.t_end = ctl.time

    # 6. Immediate stop in the middle of a move.
    s = begin("relative 50 mm, immediate stop after 0.4 s", "y")
    y.move_relative(50.0, max_vel=50.0, tacc=0.1, units=True)
    ctl.advance(0.4)
    y.stop_immediately()
    s.note = f"stopped at {y.units.to_units(y.position):.3f} mm"
    s.t_end = ctl.time
    ctl.advance(0.05)
    return steps


#: The G-code job the demo runs after the single-axis moves: a laser contour with arcs and
#: a hole, the laser on output 0 switched in sync with motion (M62/M63).
DEMO_PROGRAM = """(openmotion demo: laser contour with arcs and a hole)
G21 G90 G17 G94
G64 P0.01
G0 X-30 Y-20
M62 P0
G1 X20 F1800
G3 X30 Y-10 R10
G1 Y20
G1 X-10
G2 X-30 Y0 I0 J-20
G1 Y-20
M63 P0
G0 X0 Y0
M62 P0
G3 X0 Y0 I5 J0 (5 mm hole)
M63 P0
G0 X-30 Y-20
M2
"""


def run_gcode_job(out: Path) -> int:
    """Run DEMO_PROGRAM like `openmotion run` does and write its HTML report."""
    import argparse

    from .program.runjob import run_job

    program = out / "demo_laser.ngc"
    program.write_text(DEMO_PROGRAM)
    print("\nG-code job (as `openmotion run` runs it):")
    return run_job(argparse.Namespace(program=str(program), machine=None, repeat=1,
                                      realtime=False, out=str(out)))


def run_demo(out: Path) -> int:
    """Run the demo, print a summary and write plots into `out`. Returns an exit code."""
    out.mkdir(parents=True, exist_ok=True)
    ctl = Controller()
    ctl.start_recording(capacity=20_000)
    steps = run_steps(ctl)
    rec = ctl.stop_recording()

    print(f"openmotion demo: simulated {ctl.config.name} ({len(ctl.axes)} axes), "
          f"cycle {ctl.period * 1e3:g} ms, {ctl.cycles} cycles in virtual time\n")
    print(f"{'step':<58}{'axis':>5}{'start s':>9}{'duration s':>12}  note")
    for s in steps:
        print(f"{s.name:<58}{s.axis:>5}{s.t_start:>9.3f}{s.t_end - s.t_start:>12.3f}  {s.note}")
    print(f"\n{'axis':<6}{'command':>10}{'feedback':>10}{'error':>7}{'position':>12}  state")
    for ax in ctl.axes:
        c = ax.counters
        pos = ax.units.to_units(ax.position)
        print(f"{ax.name:<6}{c.command:>10}{c.feedback:>10}{c.error:>7}"
              f"{pos:>10.3f} {ax.config.unit:<4} {ax.state.value}")

    written = plot_trace(rec, out / "demo_trace.png", title="openmotion demo: velocity curve",
                         html=True, machine=ctl.config)
    move = scurve(distance=30000, str_vel=0, max_vel=60000, tacc=0.2, tdec=0.2,
                  vs_acc=10000, vs_dec=10000)
    written += plot_profile(move, out / "demo_scurve.png", title="S-curve of step 2",
                            html=True)
    print()
    for p in written:
        print(f"wrote {p}")
    return run_gcode_job(out)


def run_realtime_demo(seconds: float = 2.0) -> int:
    """Run a 4-axis job paced to the wall clock at 1 ms and print the cycle statistics."""
    import time

    ctl = Controller()
    ctl.enable_all()
    with ctl.start_realtime():
        t_end = time.monotonic() + seconds
        # each axis goes back and forth on its own (a shared direction flipped by the
        # polling loop made axes that finish at different times drift onto their -EL)
        direction = [1.0] * len(ctl.axes)
        while time.monotonic() < t_end:
            for k, ax in enumerate(ctl.axes):
                if not ax.is_moving:
                    ax.move_relative(direction[k] * (5.0 + k), max_vel=50.0, tacc=0.1,
                                     shape="S" if k % 2 else "T", units=True)
                    direction[k] = -direction[k]
            time.sleep(0.02)
        stats = ctl.cycle_stats()
    ctl.stop_realtime()
    us = 1e6
    print(f"real time: {stats.cycles} cycles of {stats.period * 1e3:g} ms, 4 axes moving")
    print(f"busy    mean {stats.mean_busy * us:8.1f} us  p99 {stats.p99_busy * us:8.1f} us  "
          f"max {stats.max_busy * us:8.1f} us")
    print(f"jitter  mean {stats.mean_jitter * us:8.1f} us  p99 {stats.p99_jitter * us:8.1f} us"
          f"  max {stats.max_jitter * us:8.1f} us")
    print(f"overruns {stats.overruns}")
    return 0
