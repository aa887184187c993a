"""Scenario actions inside a compiled cycle give what the Python pipeline gives (the
oracle: `SimMachine.native = False`), and no stepper cycle runs in the Python pipeline.

The kernel runs up to an action's time inside the cycle, the action applies to the axes
(step loss, switch placed or removed, alarm, E-stop with an armed EMG stop, a digital
input, an axis output at a time), and the kernel runs on: random stepper machines with
armed edge stops, queued pieces and cycle-by-cycle commands, run by `run_cycles` and by
`advance` (whole and partial cycles). Same cycles reached, edges (exact times, every
axis's count), stop times and state of every generator, plant, transmission, decoder and
switch.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.hw.interface import AxisCommand, PieceBlock
from openmotion.hw.sim import SimMachine
from test_kernel_equivalence import bits, machine, random_pieces, state


def edges_of(edges) -> list:
    return [(bits([e.time]), e.axis, e.signal, e.level, e.encoders) for e in edges]


def schedule(hw: SimMachine, rng: np.random.Generator, n_axes: int, span: float) -> None:
    """Random scenario actions at random instants in [0, span] (some on a cycle end)."""
    for _ in range(int(rng.integers(1, 7))):
        at = float(rng.uniform(0, span))
        if rng.random() < 0.2:
            at = round(at, 3)  # on the cycle grid
        axis = int(rng.integers(n_axes))
        kind = int(rng.integers(8))
        sc = hw.scenario
        if kind == 0:
            sc.inject_step_loss(axis, int(rng.integers(-9, 10)), at=at)
        elif kind == 1:
            sig = str(rng.choice(["pel", "mel", "org", "sd", "ltc"]))
            sc.place_switch(axis, sig, float(rng.uniform(-2000, 2000)),
                            float(rng.uniform(5, 800)), float(rng.choice([0.0, 3.0])), at=at)
        elif kind == 2:
            sc.remove_switch(axis, str(rng.choice(["pel", "mel", "org", "sd"])), at=at)
        elif kind == 3:
            sc.trip_alarm(axis, at=at)
            if rng.random() < 0.5:
                sc.clear_alarm(axis, at=at + float(rng.uniform(0, 0.005)))
        elif kind == 4:
            sc.press_estop(at=at)
            sc.release_estop(at=at + float(rng.uniform(0, 0.01)))
        elif kind == 5:
            if hw.config.digital_inputs:
                sc.set_input("di0", bool(rng.random() < 0.5), at=at)
        elif kind == 6:
            hw.write_output_at(at, axis, "svon", bool(rng.random() < 0.5))
        else:
            sc.set_drive_ready(axis, bool(rng.random() < 0.5), at=at)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_actions_inside_a_kernel_cycle_are_the_python_path(seed):
    rng = np.random.default_rng(seed)
    n_axes = int(rng.integers(1, 4))
    cfg, half_off = machine(rng, n_axes)
    cfg = replace(cfg, digital_inputs=2)
    period = 0.001
    cycles = int(rng.integers(10, 80))
    plans = [random_pieces(rng, cycles, period, 0.0) for _ in range(n_axes)]
    arms = [(int(rng.integers(n_axes)), str(rng.choice(["pel", "mel", "org", "sd", "ltc"])),
             bool(rng.random() < 0.5), int(rng.integers(-1, 2)))
            for _ in range(int(rng.integers(0, 3)))]
    emg_armed = bool(rng.random() < 0.5)
    stepping = bool(rng.random() < 0.5)  # command + advance, else queues + run_cycles
    splits = [bool(rng.random() < 0.3) for _ in range(cycles)]
    runs = []
    python_cycles = []
    for native in (False, True):
        hw = SimMachine(cfg)
        hw.native = native
        calls = [0]
        slow = hw._advance_python

        def counted(t, slow=slow, calls=calls):  # noqa: ANN001, ANN202
            calls[0] += 1
            return slow(t)

        hw._advance_python = counted  # type: ignore[method-assign]
        if half_off:
            hw.set_half_pulse(False)
        for axis, sig, level, direction in arms:
            hw.arm_stop(axis, sig, level, direction)
        if emg_armed:
            hw.arm_stop(None, "emg", True)
        schedule(hw, np.random.default_rng(seed + 1), n_axes, cycles * period)
        seen: list = []
        if stepping:
            for k in range(cycles):
                for i, rows in enumerate(plans):
                    t0, dt, p0, v0, a0, j = rows[k]
                    hw.command(i, AxisCommand(t0, dt, p0, v0, a0, j))
                t1 = (k + 1) * period
                if splits[k]:
                    seen.append(edges_of(hw.advance(t1 - period / 3)))
                seen.append(edges_of(hw.advance(t1)))
                seen.append([hw.stop_time(i) for i in range(n_axes)])
        else:
            for i, rows in enumerate(plans):
                hw.queue_pieces(i, PieceBlock(rows))
            k = 0
            while k < cycles:
                r = hw.run_cycles(0.0, period, k, cycles, frozenset({"pel", "mel"}))
                seen.append((r.cycle, edges_of(r.edges),
                             [hw.stop_time(i) for i in range(n_axes)]))
                k = r.cycle
        seen.append(state(hw))
        seen.append([hw.steps_lost(i) for i in range(n_axes)])
        runs.append(seen)
        python_cycles.append(calls[0])
    assert runs[0] == runs[1]
    assert python_cycles[1] == 0  # not one stretch in the Python pipeline
