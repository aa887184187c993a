"""Cycle-by-cycle stepping runs through the compiled kernel and gives what the Python
pipeline gives (the oracle: `SimMachine.native = False`).

- `SimMachine.command` + `advance` (what `Controller.step` calls every cycle) on random
  stepper machines with switches everywhere (every crossing is an edge: exact time, level,
  every axis's count at its instant), advances of whole and partial cycles, queued pieces
  in between and scenario actions (inside the kernel's cycle): the same edges
  and the same state of every generator, plant, transmission, decoder and switch.
- A controller stepped cycle by cycle (`virtual_jumps = False`) into limit switches, with
  an E-stop and a step loss: the same events (exact times), counters, states and history.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import MachineConfig, SwitchConfig, default_machine
from openmotion.control import Controller
from openmotion.hw.interface import AxisCommand, PieceBlock
from openmotion.hw.sim import SimMachine
from openmotion.hw.sim import kernel as simkernel
from test_kernel_equivalence import bits, machine, random_pieces, state


def edges_of(edges) -> list:
    return [(bits([e.time]), e.axis, e.signal, e.level, e.encoders) for e in edges]


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_command_and_advance_in_the_kernel_is_the_python_path(seed):
    rng = np.random.default_rng(seed)
    n_axes = int(rng.integers(1, 4))
    cfg, half_off = machine(rng, n_axes)
    period = 0.001
    cycles = int(rng.integers(5, 80))
    plans = [random_pieces(rng, cycles, period, 0.0) for _ in range(n_axes)]
    queued_from = int(rng.integers(0, cycles))
    loss_at = float(rng.uniform(0, cycles * period)) if rng.random() < 0.3 else None
    record = bool(rng.random() < 0.3)
    splits = [bool(rng.random() < 0.2) for _ in range(cycles)]
    runs = []
    for native in (False, True):
        hw = SimMachine(cfg)
        hw.native = native
        if half_off:
            hw.set_half_pulse(False)
        if record:
            hw.record_pulses()
        if loss_at is not None:
            hw.scenario.inject_step_loss(0, 5, at=loss_at)
        seen = []
        for k in range(cycles):
            if k == queued_from:  # the rest of one axis's plan as a queue
                hw.queue_pieces(0, PieceBlock(plans[0][k:]))
            for i, rows in enumerate(plans):
                if i == 0 and k >= queued_from:
                    continue
                t0, dt, p0, v0, a0, j = rows[k]
                hw.command(i, AxisCommand(t0, dt, p0, v0, a0, j))
            t1 = (k + 1) * period
            if splits[k]:
                seen.append(edges_of(hw.advance(t1 - period / 3)))
            seen.append(edges_of(hw.advance(t1)))
            seen.append([(rb.pulses_out, rb.encoder, rb.inputs) for rb in
                         (hw.read_axis(i) for i in range(n_axes))])
            seen.append([hw.stop_time(i) for i in range(n_axes)])
        seen.append(state(hw))
        if record:
            seen.append([(bits(t), c.tolist()) for t, c in
                         (hw.pulse_record(i).pulses() for i in range(n_axes))])
        runs.append(seen)
    assert simkernel.usable(SimMachine(cfg)._axes)
    assert runs[0] == runs[1]


def limits_machine() -> MachineConfig:
    x = default_machine().axes[0]
    axes = (replace(x, name="x", pel=SwitchConfig(position=12_000.0, width=400.0),
                    org=SwitchConfig(position=3_000.0, width=200.0)),
            replace(x, name="y", mel=SwitchConfig(position=-8_000.0, width=400.0),
                    drive=replace(x.drive, backlash=2.0)),
            replace(x, name="z"))
    return MachineConfig(name="limits", axes=axes, digital_inputs=2)


def test_a_controller_stepped_in_the_kernel_is_the_python_path():
    runs = []
    for native in (False, True):
        c = Controller(limits_machine())
        c.virtual_jumps = False
        c.hardware.native = native
        c.enable_all()
        c.start_recording()
        c.axes[0].move_relative(20_000, max_vel=60_000, tacc=0.03)
        c.axes[1].move_relative(-15_000, max_vel=50_000, tacc=0.02, shape="S")
        c.axes[2].move_velocity(30_000, tacc=0.05)
        c.hardware.scenario.inject_step_loss(2, 4, at=0.1234)
        c.hardware.scenario.press_estop(at=0.4567)
        c.advance(0.6)
        runs.append(([(e.time, e.kind, e.axis, e.position, e.detail) for e in c.events.events()],
                     [(a.state, a.counters.command, a.counters.feedback, a.position)
                      for a in c.axes],
                     [[bits(r) for r in c.history.rows(i, 0.0, c.time)] for i in range(3)],
                     state(c.hardware)))
    events = runs[0][0]
    assert {e[1] for e in events} >= {"limit", "estop"}, events
    assert runs[0] == runs[1]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_board_outputs_at_a_time_run_through_the_kernel_as_in_python(seed):
    """Board outputs at a time touch no axis: the kernel runs through their cycles (no
    Python cycle) and they are emitted at their exact times, in their order."""
    rng = np.random.default_rng(seed)
    cfg, _ = machine(rng, 2)
    cfg = replace(cfg, digital_outputs=3)
    period = 0.001
    cycles = int(rng.integers(10, 60))
    plans = [random_pieces(rng, cycles, period, 0.0) for _ in range(2)]
    times = np.sort(rng.uniform(0.0, cycles * period, size=int(rng.integers(1, 40))))
    times[rng.random(len(times)) < 0.2] = times[0]  # equal times keep their order
    lines = [f"do{int(k)}" for k in rng.integers(0, 3, size=len(times))]
    levels = [bool(b) for b in rng.random(len(times)) < 0.5]
    step = bool(rng.random() < 0.5)
    runs = []
    for native in (False, True):
        hw = SimMachine(cfg)
        hw.native = native
        for i, rows in enumerate(plans):
            hw.queue_pieces(i, PieceBlock(rows))
        for t, line, lv in zip(times.tolist(), lines, levels, strict=True):
            hw.write_output_at(t, None, line, lv)
        seen = []
        k = 0
        while k < cycles:
            if step:
                k += 1
                seen.append(edges_of(hw.advance(k * period)))
            else:
                r = hw.run_cycles(0.0, period, k, cycles, frozenset({"pel", "mel"}))
                k = r.cycle
                seen.append((k, edges_of(r.edges)))
            seen.append([hw.read_output(None, f"do{d}") for d in range(3)])
        seen.append([hw.output_record.edges(f"do{d}") for d in range(3)])
        seen.append(state(hw))
        runs.append(seen)
    assert runs[0] == runs[1]


@pytest.mark.parametrize("mode,jumping", [(0, False), (0, True), (1, True), (2, False)])
def test_homing_with_armed_stops_in_the_kernel_is_the_python_path(mode, jumping):
    """Homing arms edge stops (ORG, EZ, EL): the dry scan, the cut at the armed edge's
    exact time and the run on are the kernel's now; the Python pipeline is the oracle."""
    from openmotion.control.home.homing import HomeConfig, home_search

    runs = []
    for native in (False, True):
        c = Controller()
        c.virtual_jumps = jumping
        c.hardware.native = native
        c.enable_all()
        c.axes[0].move_relative(60_000, max_vel=100_000, tacc=0.05)
        c.wait_motion_done()
        h = home_search(c, 0, HomeConfig(mode=mode, str_vel=2_000.0, max_vel=20_000.0,
                                         tacc=0.05))
        c.run_until(lambda h=h: not h.running, 60.0, event_driven=True)
        ax = c.axes[0]
        runs.append((h.status, c.time, ax.counters.command, ax.counters.feedback,
                     ax.position, [(e.time, e.kind, e.detail)
                                   for e in c.events.events()],
                     [bits(r) for r in c.history.rows(0, 0.0, c.time)], state(c.hardware)))
    assert runs[0][0].state == "done", runs[0][0]
    assert runs[0] == runs[1]
