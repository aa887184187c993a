"""Virtual time that jumps gives what cycle-by-cycle execution gives (control/core/jump.py).

Random scenarios on ideal steppers, stalling steppers with backlash and servo drives
(moves, velocity moves, speed changes, stops, end limits, E-stop, alarms,
step losses, soft limits, digital inputs, group lines/arcs/delays, homing in three modes,
G-code with arcs and dwells, compare tables with pulses and windows) run twice on
the same machine: once cycle by cycle (`virtual_jumps = False`) through the Python
pipeline (`SimMachine.native = False`: the reference) and once jumping with the compiled
kernel. After every operation the two controllers must agree on everything observable:
time and cycle count, every axis's state, fault, position, velocity, motion_done and
counters, the event log with exact times, the safety stop records, the motion history,
every output edge, every pulse the generators emitted (exact times), in part of the
scenarios every row the recorder kept (jumps record the cycles they cross), and what each job
shows (group state and position, homing status, the program's events and per-cycle trace,
the compare log and output waveforms). The jobs declare when they act (`due`), so the
fast run must also jump while they are attached. 60 seeded
scenarios in the normal run, 600 with --long.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from openmotion.config import MachineConfig, SwitchConfig, default_machine
from openmotion.control import Controller
from openmotion.control.core.jump import (
    FIRST_CHUNK,
    FIRST_CHUNK_COMPILED,
    first_cycle_at,
    plan_jump,
)
from openmotion.control.groups.group import Group
from openmotion.control.home.homing import HomeConfig, home_search
from openmotion.errors import MotionError

AXES = 3


def machine(rng: np.random.Generator) -> MachineConfig:
    x = default_machine().axes[0]
    axes = []
    for i in range(AXES):
        kw = {}
        if rng.random() < 0.3:
            kw["pel"] = SwitchConfig(position=float(rng.uniform(30_000, 60_000)), width=500.0)
        k = rng.random()
        if k < 0.2:  # a stepper that stalls and loses pulses above its pull-out limits
            kw["drive"] = replace(x.drive, type="stepper", pullout_speed=60_000.0,
                                  pullout_accel=3e6, backlash=float(rng.choice([0.0, 3.0])))
        elif k < 0.4:  # a servo drive (plant dynamics, INP and RDY from the drive)
            kw["drive"] = replace(x.drive, type="servo")
        axes.append(replace(x, name="xyz"[i], **kw))
    return MachineConfig(name="jump", axes=tuple(axes), digital_inputs=2)


def script(rng: np.random.Generator) -> list[tuple]:
    """A random list of operations (plain tuples, applied by `apply`)."""
    ops: list[tuple] = [("record_pulses",)]
    for _ in range(int(rng.integers(4, 14))):
        a = int(rng.integers(AXES))
        k = rng.random()
        at = float(rng.uniform(0.0, 0.4))
        if k < 0.22:
            ops.append(("rel", a, float(rng.choice([-1, 1]) * rng.uniform(50, 40_000)),
                        float(rng.uniform(2_000, 90_000)), float(rng.uniform(0.005, 0.1)),
                        str(rng.choice(["T", "S"]))))
        elif k < 0.30:
            ops.append(("abs", a, float(rng.uniform(-20_000, 50_000)),
                        float(rng.uniform(2_000, 90_000)), float(rng.uniform(0.005, 0.1))))
        elif k < 0.36:
            ops.append(("vel", a, float(rng.choice([-1, 1]) * rng.uniform(1_000, 50_000))))
        elif k < 0.40:
            ops.append(("speed", a, float(rng.uniform(1_000, 60_000))))
        elif k < 0.44:
            ops.append(("stop", a, bool(rng.random() < 0.5)))
        elif k < 0.62:
            ops.append(("advance", float(rng.uniform(0.0, 0.6))))
        elif k < 0.72:
            ops.append(("wait", float(rng.uniform(0.05, 2.0))))
        elif k < 0.75:
            ops.append(("estop", at, float(rng.uniform(0.01, 0.2))))
        elif k < 0.78:
            ops.append(("alarm", a, at, float(rng.uniform(0.01, 0.2))))
        elif k < 0.81:
            ops.append(("loss", a, int(rng.integers(-30, 30)), at))
        elif k < 0.84:
            ops.append(("di", f"di{int(rng.integers(2))}", bool(rng.random() < 0.5), at))
        elif k < 0.87:
            lo = float(rng.uniform(-30_000, 0))
            ops.append(("soft", a, lo, lo + float(rng.uniform(5_000, 60_000)),
                        str(rng.choice(["immediate", "decel"]))))
        elif k < 0.92:
            ops.append(("switch", a, str(rng.choice(["pel", "mel", "org"])),
                        float(rng.uniform(-10_000, 40_000)), at))
        elif k < 0.95:
            ops.append(("reset",))
        elif k < 0.962:
            ops.append(("line", float(rng.uniform(-20_000, 20_000)),
                        float(rng.uniform(-20_000, 20_000)), float(rng.uniform(0.0, 0.05)),
                        bool(rng.random() < 0.5)))
        elif k < 0.972:
            ops.append(("home", a, int(rng.choice([0, 1, 2])),
                        float(rng.choice([0.0, 0.0123]))))
        elif k < 0.984:
            ops.append(("gcode", float(rng.uniform(1, 20)), float(rng.uniform(1, 20)),
                        float(rng.choice([0.0, 0.0137]))))
        elif k < 0.992:
            ops.append(("compare", float(rng.uniform(-20_000, 20_000)),
                        float(rng.uniform(500, 5_000)), float(rng.uniform(-20_000, 20_000)),
                        float(rng.uniform(-20_000, 20_000)), bool(rng.random() < 0.5)))
        else:
            ops.append(("errcheck", a, int(rng.integers(1, 20))))
    ops.append(("wait", 3.0))
    return ops


def apply(ctl: Controller, op: tuple) -> object:
    """Run one operation; its result or the MotionError message (both must agree)."""
    kind, *args = op
    jobs = ctl.__dict__.setdefault("test_jobs", [])
    ax = ctl.axes[args[0]] if args and isinstance(args[0], int) else None
    sc = ctl.hardware.scenario
    t = ctl.time
    try:
        if kind == "record_pulses":
            ctl.hardware.record_pulses(True)
        elif kind == "rel":
            ax.move_relative(args[1], max_vel=args[2], tacc=args[3], tdec=args[3],
                             shape=args[4])
        elif kind == "abs":
            ax.move_absolute(args[1], max_vel=args[2], tacc=args[3], tdec=args[3])
        elif kind == "vel":
            ax.move_velocity(args[1], tacc=0.05)
        elif kind == "speed":
            ax.change_speed(args[1], 0.05)
        elif kind == "stop":
            ax.stop_immediately() if args[1] else ax.stop()
        elif kind == "advance":
            ctl.advance(args[0])
        elif kind == "wait":
            return ctl.wait_motion_done(timeout=args[0])
        elif kind == "estop":
            sc.press_estop(at=t + args[0])
            sc.release_estop(at=t + args[0] + args[1])
        elif kind == "alarm":
            sc.trip_alarm(args[0], at=t + args[1])
            sc.clear_alarm(args[0], at=t + args[1] + args[2])
        elif kind == "loss":
            sc.inject_step_loss(args[0], args[1], at=t + args[2])
        elif kind == "di":
            sc.set_input(args[0], args[1], at=t + args[2])
        elif kind == "soft":
            ctl.safety.soft.set(args[0], args[1], args[2])
            ctl.safety.soft.enable(args[0], args[3])
        elif kind == "switch":
            sc.place_switch(args[0], args[1], args[2], 300.0, at=t + args[3])
        elif kind == "reset":
            for a in ctl.axes:
                if a.state.name == "ERROR_STOP":
                    a.reset()
        elif kind == "line":  # a line, an arc back through the start, maybe a delay
            g = Group(ctl, [0, 1], feed=30_000.0, acc_time=0.05)
            jobs.append(g)
            p = g.position
            g.line([args[0], args[1]])
            if args[3]:
                g.enable_blend(20.0)
            if args[2]:
                g.delay(args[2])
            g.arc([(args[0] + p[0]) / 2, (args[1] + p[1]) / 2], [float(p[0]), float(p[1])])
        elif kind == "home":
            jobs.append(home_search(ctl, args[0], HomeConfig(
                mode=args[1], str_vel=2000.0, max_vel=20000.0, tacc=0.05, timeout_s=1.0,
                settle_s=args[2])))
        elif kind == "gcode":
            from openmotion.program.runner import ProgramRunner

            dwell = f"G4 P{args[2]}\n" if args[2] else ""
            run = ProgramRunner(ctl, f"G91 G1 X{args[0]:.3f} Y{args[1]:.3f} F3000\n{dwell}"
                                f"G2 X{args[0]:.3f} Y0 I{args[0] / 2:.3f} J0\nM2\n",
                                axes={"X": 0, "Y": 1})
            jobs.append(run)
            run.start()
        elif kind == "compare":
            from openmotion.control.trigger.compare import (
                AxisSource,
                CompareEngine,
                LevelJob,
                Pulse,
                Toggle,
                WindowJob,
            )

            eng = CompareEngine(ctl)
            jobs.append(eng)
            lo, step = args[0], args[1]
            eng.add(LevelJob(AxisSource(0), lo + step * np.arange(8.0),
                             Pulse(0, 0.0021) if args[4] else Toggle(0)))
            eng.add(WindowJob([0, 1], [[args[2], args[3]], [args[3], args[2]]], 300.0,
                              Toggle(1)))
        elif kind == "errcheck":
            ctl.safety.cmp.set_error_counter_check(args[0], args[1], True)
        return None
    except MotionError as exc:
        return f"MotionError: {exc}"


def observe(ctl: Controller) -> tuple:
    """Everything the two runs must agree on."""
    hw = ctl.hardware
    axes = tuple((a.state, a.fault, a.position, a.velocity, a.motion_done,
                  a.counters.snapshot()) for a in ctl.axes)
    events = tuple((e.time, e.kind, e.axis, e.position, e.detail) for e in ctl.events.events())
    stops = tuple(ctl.safety.stops) if ctl.safety is not None else ()
    hist = tuple(tuple(np.concatenate([v.ravel() for v in ctl.history.records(i).values()])
                       .tolist()) for i in range(len(ctl.axes)))
    outs = tuple(hw.output_record._edges)
    pulses = []
    for i in range(len(ctl.axes)):
        try:
            t, c = hw.pulse_record(i).pulses()
            pulses.append((tuple(t.tolist()), tuple(c.tolist())))
        except MotionError:
            pulses.append(None)
    rec = ctl.recorder
    trace = None if rec is None else (len(rec), rec.total, tuple(
        (k, v.tobytes()) for k, v in rec.arrays().items()))
    jobs = tuple(_job_view(j) for j in ctl.__dict__.get("test_jobs", ()))
    return (ctl.time, ctl.cycles, axes, events, stops, hist, outs, tuple(pulses), trace,
            jobs)


def _job_view(job: object) -> tuple:
    """What a group, homing, program run or compare engine shows of itself."""
    from openmotion.control.home.homing import Homing
    from openmotion.control.trigger.compare import CompareEngine
    from openmotion.program.runner import ProgramRunner

    if isinstance(job, Group):
        return (job.state, job.error_code, job.error_message, job.queue_length,
                job.current_index, tuple(job.position.tolist()))
    if isinstance(job, Homing):
        st = job.status
        return (st.state, st.phase, st.mark, st.mark_time, st.reason, tuple(st.history))
    if isinstance(job, ProgramRunner):
        t, idx, p = job.trace()
        return (job.state, job.error, tuple(job.events), tuple(t.tolist()),
                tuple(idx.tolist()), tuple(map(tuple, p.tolist())))
    assert isinstance(job, CompareEngine)
    return (tuple((k, tuple(v.ravel().tolist())) for k, v in job.log.arrays().items()),
            tuple(tuple(job.output(n).edges) for n in sorted(job._lines)),
            tuple((j.index, j.hits, j.active) for j in job.jobs.values()))


def run_both(seed: int) -> tuple[list, list, int]:
    rng = np.random.default_rng(seed)
    cfg = machine(rng)
    ops = script(rng)
    got = []
    jumps = 0
    # the recorder on in half the scenarios, some with a ring shorter than the run
    capacity = int(rng.choice([0, 0, 40, 700, 100_000]))
    for jumping in (False, True):
        ctl = Controller(cfg)
        ctl.virtual_jumps = jumping
        # the reference steps every cycle through the Python pipeline (the oracle); the
        # fast run jumps with the compiled kernel
        ctl.hardware.native = jumping
        ctl.enable_all()
        if capacity:
            ctl.start_recording(capacity=capacity)
        trace = []
        if jumping:
            real = ctl._run_cycles
            base = len(ctl._cycle_hooks)  # the safety reactions' hook

            def counting(n: int, real=real, ctl=ctl, base=base) -> None:
                nonlocal jumps
                n0 = ctl.cycles
                jobs = len(ctl._cycle_hooks) > base  # a job's hook is attached
                real(n)
                jumps += ctl.cycles - n0 - 1
                if jobs:
                    JOB_JUMPS[0] += ctl.cycles - n0 - 1

            ctl._run_cycles = counting  # type: ignore[method-assign]
        for op in ops:
            res = apply(ctl, op)
            trace.append((op, res, observe(ctl)))
        got.append(trace)
    return got[0], got[1], jumps


def _check(seed: int) -> int:
    """Both runs agree; returns the cycles the fast run jumped over."""
    ref, fast, jumps = run_both(seed)
    for (op, r0, o0), (_, r1, o1) in zip(ref, fast, strict=True):
        assert r0 == r1, (seed, op)
        for name, a, b in zip(("time", "cycles", "axes", "events", "stops", "history",
                               "outputs", "pulses", "recorder", "jobs"), o0, o1,
                              strict=True):
            assert a == b, (seed, op, name)
    return jumps


#: Cycles jumped over while a job (group, homing, program, compare engine) was attached.
JOB_JUMPS = [0]


def test_random_scenarios_jump_like_cycle_by_cycle(long_run):
    global JOB_JUMPS  # noqa: PLW0603
    JOB_JUMPS = [0]
    n = 600 if long_run else 12  # 12 seeds in the normal run (~4 s CPU), 600 with --long
    jumps = sum(_check(seed) for seed in range(n))
    assert jumps > 300 * n  # the fast runs did jump over many cycles
    assert JOB_JUMPS[0] > 10 * n  # ... also while groups, homings, programs, compares ran
    print(f"{n} seeds: {jumps} cycles jumped over, {JOB_JUMPS[0]} of them with a job "
          "attached")


def test_idle_controller_jumps_to_the_end_in_one_go():
    ctl = Controller()
    ctl.enable_all()
    ctl.hardware.scenario.set_input("di0", True, at=0.5004)
    assert plan_jump(ctl, 1000) == 1000
    ctl.advance(1.0)
    assert ctl.cycles == 1000 and ctl.time == pytest.approx(1.0)
    assert ctl.hardware.read_input("di0")


def test_first_cycle_at_is_exact_on_the_grid():
    ctl = Controller()
    ctl.advance(0.003)
    assert first_cycle_at(ctl, ctl.time) == ctl.cycles
    assert first_cycle_at(ctl, 0.0105) == 11
    assert first_cycle_at(ctl, 0.010) == 10
    assert first_cycle_at(ctl, 0.0100000001) == 11


def test_a_cycle_hook_without_due_keeps_every_cycle():
    ctl = Controller()
    seen = []
    ctl.add_cycle_hook(lambda c, t: seen.append(t))
    ctl.advance(0.05)
    assert len(seen) == 50


@pytest.mark.parametrize("cycle", [FIRST_CHUNK - 1, FIRST_CHUNK, FIRST_CHUNK + 1,
                                   3 * FIRST_CHUNK, FIRST_CHUNK_COMPILED - 1,
                                   FIRST_CHUNK_COMPILED, FIRST_CHUNK_COMPILED + 1])
def test_an_edge_in_the_last_cycle_of_a_fed_chunk_ends_the_jump(cycle):
    """Pieces are fed in chunks (FIRST_CHUNK, or FIRST_CHUNK_COMPILED with the compiled
    pieces, doubling): an E-stop in a chunk's last cycle
    must land there, not be carried into the next chunk."""
    seen = []
    for jumping in (False, True):
        ctl = Controller()
        ctl.virtual_jumps = jumping
        ctl.enable_all()
        ctl.axes[0].move_relative(50_000, max_vel=50_000, tacc=0.05)
        ctl.hardware.scenario.press_estop(at=(cycle - 0.5) * ctl.period)
        ctl.advance(0.3)
        ev = ctl.events.events("estop")
        seen.append((ev[0].time, ev[0].position, ctl.axes[0].position,
                     ctl.axes[0].counters.snapshot(),
                     [v.tolist() for v in ctl.history.records(0).values()]))
    assert seen[0] == seen[1]


class _PlainHardware:
    """Only the base Hardware protocol of a simulator (no QueuedHardware)."""

    def __init__(self, sim) -> None:  # noqa: ANN001
        self._sim = sim
        self.n_axes = sim.n_axes

    @property
    def time(self) -> float:
        return self._sim.time

    def command(self, axis, cmd):  # noqa: ANN001, ANN201
        return self._sim.command(axis, cmd)

    def advance(self, t):  # noqa: ANN001, ANN201
        return self._sim.advance(t)

    def read_axis(self, axis):  # noqa: ANN001, ANN201
        return self._sim.read_axis(axis)

    def write_output(self, axis, signal, level):  # noqa: ANN001, ANN201
        return self._sim.write_output(axis, signal, level)

    def read_input(self, signal):  # noqa: ANN001, ANN201
        return self._sim.read_input(signal)


def test_a_back_end_without_the_queue_runs_every_cycle_with_the_same_result():
    from openmotion.hw.interface import QueuedHardware
    from openmotion.hw.sim import SimMachine

    cfg = default_machine()
    plain = _PlainHardware(SimMachine(cfg))
    assert not isinstance(plain, QueuedHardware)
    out = []
    for hw in (SimMachine(cfg), plain):
        ctl = Controller(cfg, hw)
        ctl.enable_all()
        ctl.axes[1].move_relative(12_345, max_vel=40_000, tacc=0.03)
        assert plan_jump(ctl, 100) == (100 if hw is not plain else 1)
        ctl.wait_motion_done(timeout=2.0)
        out.append((ctl.time, ctl.cycles, ctl.axes[1].counters.snapshot()))
    assert out[0] == out[1]
