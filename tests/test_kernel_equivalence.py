"""The compiled inner loops (openmotion._kernel) give exactly what the Python path gives.

- `ActiveMotion.pieces` (a chunk of cycles in C) against `ActiveMotion.piece` called once
  per cycle: the same floats, bit for bit, for random T/S/jerk moves, velocity moves and
  chunks that start before, inside and after the profile.
- `SimMachine.run_cycles` with the kernel (`native = True`) against the Python path
  (`native = False`) on random stepper machines (ideal and stalling drives, backlash, every
  encoder mode and mis-wiring, half-pulse rule on and off, switches at random places, some
  of them reported) and random queued cubic pieces: the same cycle reached, the same edges
  (exact times, counts), the same state of every generator, plant, transmission, decoder
  and switch, the same recorded pulses.

The kernel must be built (`pip install -e .`, or `python setup.py build_ext --inplace`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import MachineConfig, SwitchConfig, default_machine
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand, PieceBlock
from openmotion.hw.sim import SimMachine
from openmotion.hw.sim import kernel as simkernel

try:
    from openmotion import _kernel
except ImportError:  # pragma: no cover
    _kernel = None


def test_the_kernel_is_built():
    assert _kernel is not None, ("openmotion._kernel is not built: run pip install -e . or "
                                 "python setup.py build_ext --inplace")
    assert simkernel.AVAILABLE


def bits(a) -> bytes:
    return np.asarray(a, dtype=float).tobytes()


# -- motion pieces ------------------------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_chunk_pieces_are_the_per_cycle_pieces_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    c = Controller(default_machine())
    c.enable_all()
    ax = c.axes[0]
    c.advance(float(rng.integers(0, 5)) * c.period)
    kind = rng.integers(4)
    dist = float(rng.choice([-1, 1]) * rng.uniform(1, 60_000))
    vmax = float(rng.uniform(500, 150_000))
    tacc = float(rng.uniform(0.0005, 0.2))
    if kind == 0:
        ax.move_relative(dist, max_vel=vmax, tacc=tacc, tdec=tacc, shape="T")
    elif kind == 1:
        ax.move_relative(dist, max_vel=vmax, tacc=tacc, tdec=float(rng.uniform(0.001, 0.2)),
                         shape="S")
    elif kind == 2:
        ax.move_velocity(float(rng.choice([-1, 1]) * vmax), tacc=tacc, shape="S")
    else:
        ax.move_relative(dist, max_vel=vmax, tacc=tacc, tdec=tacc, shape="S",
                         str_vel=float(rng.uniform(0, min(vmax, 400.0))))
    m = ax._motion
    origin, period = c._t_origin, c.period
    n0 = c._n + int(rng.integers(0, 40))
    cycles = int(np.ceil((m.t_end - origin) / period)) - n0 + int(rng.integers(1, 60))
    cycles = max(cycles, 1)
    t0 = origin + n0 * period
    rows, ends = m.pieces(t0, origin, period, n0, cycles)
    want_rows, want_ends = [], []
    ta = t0
    for k in range(n0 + 1, n0 + cycles + 1):
        t1 = origin + k * period
        p0, v0, a0, j, p1, v1 = m.piece(ta, t1)
        want_rows.append((ta, t1 - ta, p0, v0, a0, j))
        want_ends.append((p1, v1))
        ta = t1
    assert bits(rows) == bits(want_rows)
    assert bits(ends) == bits(want_ends)


# -- the stepper pipeline ------------------------------------------------------------------
def machine(rng: np.random.Generator, n_axes: int) -> tuple[MachineConfig, bool]:
    x = default_machine().axes[0]
    axes = []
    for i in range(n_axes):
        kw: dict = {}
        mode = str(rng.choice(["ab_x4", "ab_x2", "ab_x1", "cw_ccw", "pulse_dir"]))
        kw.update(encoder_mode=mode, move_ratio=float(rng.choice([1.0, 0.5, 2.0, 4.0])),
                  swap_ab=bool(rng.random() < 0.2), invert_a=bool(rng.random() < 0.2),
                  invert_b=bool(rng.random() < 0.2), invert_z=bool(rng.random() < 0.2),
                  pulses_per_rev=int(rng.choice([200, 1000, 10_000])))
        spans = {"pel": (200, 3000), "mel": (-3000, -200), "org": (-3000, 3000),
                 "sd": (-3000, 3000)}
        for name, (lo, hi) in spans.items():
            if rng.random() < 0.5:
                kw[name] = SwitchConfig(position=float(rng.uniform(lo, hi)),
                                        width=float(rng.uniform(-800, 800) or 1.0),
                                        hysteresis=float(rng.choice([0.0, 0.5, 20.0])))
            else:
                kw[name] = None
        if rng.random() < 0.5:
            kw["drive"] = replace(x.drive, type="stepper",
                                  pullout_speed=float(rng.choice([1e12, 30_000.0])),
                                  pullout_accel=float(rng.choice([1e15, 2e6])),
                                  backlash=float(rng.choice([0.0, 0.4, 3.0])))
        if rng.random() < 0.4:  # a pitch-error table (the screw: one revolution apart)
            spr = kw["pulses_per_rev"] * x.gear_ratio
            errs = tuple(float(e) for e in rng.uniform(-0.3, 0.3, int(rng.integers(1, 8)))
                         * min(spr, 400.0))
            kw["drive"] = replace(kw.get("drive", x.drive), pitch_error=errs)
        axes.append(replace(x, name=f"a{i}", **kw))
    return MachineConfig(name="kernel", axes=tuple(axes)), bool(rng.random() < 0.5)


def random_pieces(rng: np.random.Generator, cycles: int, period: float,
                  t0: float) -> np.ndarray:
    """Random cubic pieces on the cycle grid: moves, jitter, jumps, reversals, holds."""
    rows = []
    p = float(rng.uniform(-50, 50))
    for k in range(cycles):
        ta = t0 + k * period
        kind = rng.random()
        if kind < 0.1:  # the command jumps by whole pulses
            p += float(rng.integers(-40, 40))
        v = float(rng.choice([0.0, 1.0]) * rng.normal(0, 60_000))
        a = float(rng.choice([0.0, 1.0]) * rng.normal(0, 5e6))
        j = float(rng.choice([0.0, 1.0]) * rng.normal(0, 1e9))
        if kind > 0.9:  # a piece that starts inside the cycle and ends early
            off = float(rng.uniform(0, period / 2))
            rows.append((ta + off, float(rng.uniform(0, period / 2)), p, v, a, j))
        else:
            rows.append((ta, period, p, v, a, j))
        h = period
        p = p + h * (v + h * (a * 0.5 + h * j / 6.0))
    return np.array(rows)


def state(hw: SimMachine) -> list:
    out: list = [hw.time]
    for ax in hw._axes:
        g, d = ax.gen, ax.decoder
        out.append((g.count, tuple(g.cubic), g.tc, g.te, ax.plant.lost, float(ax.trans.z),
                    float(ax.y), d.q, d.last_dir, d.count,
                    tuple((n, s.active) for n, s in ax.switches.items()),
                    ax.stop_time, len(hw._queues[ax.index])))
    return out


def pulses(hw: SimMachine) -> list:
    out = []
    for i in range(hw.n_axes):
        t, k = hw.pulse_record(i).pulses()
        out.append((bits(t), k.tolist(), bits(hw.pulse_record(i).command_at(t))))
    return out


@settings(max_examples=120, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_run_cycles_in_the_kernel_is_the_python_path(seed):
    rng = np.random.default_rng(seed)
    n_axes = int(rng.integers(1, 4))
    cfg, half_off = machine(rng, n_axes)
    period = 0.001
    cycles = int(rng.integers(5, 120))
    sigs = ["pel", "mel", "org", "sd", "ltc", "ez"]
    wake = None if rng.random() < 0.2 else frozenset(
        s for s in sigs if rng.random() < 0.3)
    plans = [random_pieces(rng, cycles, period, 0.0) for _ in range(n_axes)]
    record = bool(rng.random() < 0.7)
    arms = [(int(rng.integers(n_axes)), str(rng.choice(["pel", "mel", "org", "sd", "ltc",
                                                         "ez", "alm"])),
             bool(rng.random() < 0.5), int(rng.integers(-1, 2)))
            for _ in range(int(rng.integers(0, 4)) if rng.random() < 0.5 else 0)]
    runs = []
    for native in (False, True):
        hw = SimMachine(cfg)
        hw.native = native
        if half_off:
            hw.set_half_pulse(False)
        if record:
            hw.record_pulses()
        for axis, sig, level, direction in arms:  # armed edge stops (homing, latches)
            hw.arm_stop(axis, sig, level, direction)
        for i, rows in enumerate(plans):
            hw.queue_pieces(i, PieceBlock(rows))
        trace = []
        k = 0
        while k < cycles:
            r = hw.run_cycles(0.0, period, k, cycles, wake)
            trace.append((r.cycle, [(bits([e.time]), e.axis, e.signal, e.level, e.encoders)
                                    for e in r.edges], r.drained,
                          [hw.stop_time(i) for i in range(n_axes)], state(hw)))
            k = r.cycle
        runs.append((trace, pulses(hw) if record else None))
    assert simkernel.usable(SimMachine(cfg)._axes)
    assert runs[0] == runs[1]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_the_state_kept_in_the_kernels_arrays_reads_and_writes_back_as_python(seed):
    """Runs in a row keep the axes' state in the kernel's arrays (nothing written back):
    read_axis, queued and stop_time read from them, and the first Python access (a
    scenario action, a command, an output, a readout of the objects) writes them back
    first; the result is the Python path's at every step."""
    rng = np.random.default_rng(seed)
    n_axes = int(rng.integers(1, 4))
    cfg, half_off = machine(rng, n_axes)
    period = 0.001
    cycles = int(rng.integers(20, 150))
    plans = [random_pieces(rng, cycles, period, 0.0) for _ in range(n_axes)]
    stops = sorted({int(k) for k in rng.integers(1, cycles, size=int(rng.integers(1, 6)))})
    touch = [str(rng.choice(["none", "read", "command", "output", "loss", "half"]))
             for _ in stops]
    wake = frozenset(s for s in ("pel", "mel", "org") if rng.random() < 0.5)
    runs = []
    for native in (False, True):
        hw = SimMachine(cfg)
        hw.native = native
        if half_off:
            hw.set_half_pulse(False)
        for i, rows in enumerate(plans):
            hw.queue_pieces(i, PieceBlock(rows))
        seen = []
        k = 0
        for stop, what in [*zip(stops, touch, strict=True), (cycles, "none")]:
            while k < stop:
                r = hw.run_cycles(0.0, period, k, stop, wake)
                k = r.cycle
                seen.append((k, [(bits([e.time]), e.axis, e.signal, e.level, e.encoders)
                                 for e in r.edges]))
                seen.append([(rb.pulses_out, rb.encoder, rb.inputs) for rb in
                             (hw.read_axis(i) for i in range(n_axes))])
                seen.append([(hw.queued(i), hw.stop_time(i)) for i in range(n_axes)])
            if what == "read":
                seen.append(state(hw))
            elif what == "command":  # a cycle-by-cycle command replaces the queue's
                hw.clear_queue(0)
                p = float(hw.read_axis(0).pulses_out)
                hw.command(0, AxisCommand(hw.time, period, p, 1000.0, 0.0, 0.0))
            elif what == "output":
                hw.write_output(0, "svon", True)
            elif what == "loss":
                hw.scenario.inject_step_loss(0, 3, at=hw.time + period / 2)
            elif what == "half":
                hw.set_half_pulse(True)
        seen.append(state(hw))
        runs.append(seen)
    assert runs[0] == runs[1]


def test_the_cycle_of_a_scenario_action_runs_in_the_kernel_as_in_python():
    cfgm = default_machine()
    results = []
    for native in (False, True):
        hw = SimMachine(cfgm)
        hw.native = native
        rows = random_pieces(np.random.default_rng(5), 50, 0.001, 0.0)
        hw.queue_pieces(0, PieceBlock(rows))
        hw.scenario.inject_step_loss(0, 7, at=0.0205)
        hw.scenario.press_estop(at=0.0301)
        hw.scenario.place_switch(0, "org", 10.0, 5.0, at=0.0402)
        r = hw.run_cycles(0.0, 0.001, 0, 50, None)
        results.append((r.cycle, [(e.time, e.signal, e.encoders) for e in r.edges],
                        state(hw), hw.steps_lost(0)))
    assert results[0] == results[1]


def test_machines_the_kernel_does_not_model_run_in_python():
    x = default_machine().axes[0]
    servo = replace(x, name="s", drive=replace(x.drive, type="servo"))
    hw = SimMachine(MachineConfig(name="m", axes=(x, servo)))
    assert not simkernel.usable(hw._axes)
    pitch = replace(x, name="p", drive=replace(x.drive, pitch_error=(0.0, 1.0, -0.5)))
    hw = SimMachine(MachineConfig(name="m", axes=(x, pitch)))  # pitch tables run in C
    assert simkernel.usable(hw._axes)
    hw = SimMachine(MachineConfig(name="m", axes=(x,)))
    assert simkernel.usable(hw._axes)
    hw.arm_stop(0, "org", True)  # armed edge stops run in the kernel
    assert simkernel.usable(hw._axes)


@pytest.mark.parametrize("rows,match", [
    (np.array([[0.001, 0.001, 0.0, 0.0, 0.0, 0.0], [0.002, 0.001, np.nan, 0, 0, 0]]),
     r"pieces\[1\]\.p0 must be a finite"),
    (np.array([[0.001, -0.001, 0.0, 0.0, 0.0, 0.0]]), r"pieces\[0\]\.dt must be >= 0"),
    (np.array([[0.001, 0.001, 0, 0, 0, 0], [0.0015, 0.001, 0, 0, 0, 0]]),
     r"pieces\[1\]\.t0 must be >= the end of the piece before"),
    (np.zeros((2, 5)), r"pieces\.rows must be an \(n, 6\) array"),
    ([["a"] * 6], r"pieces\.rows must be an \(n, 6\) array of numbers"),
])
def test_a_malformed_block_is_refused_whole(rows, match):
    hw = SimMachine(default_machine())
    hw.queue_pieces(0, PieceBlock(np.array([[0.0, 0.001, 0.0, 0.0, 0.0, 0.0]])))
    with pytest.raises(MotionError, match=match):
        hw.queue_pieces(0, PieceBlock(rows))
    assert hw.queued(0) == 1
