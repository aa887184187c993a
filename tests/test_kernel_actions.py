"""Scenario actions inside a compiled cycle give what the Python pipeline gives (the
oracle: `SimMachine.native = False`), and no stepper cycle runs in the Python pipeline.

The kernel runs up to an action's time inside the cycle, the action applies to the axes
(step loss, switch placed or removed, alarm, E-stop with an armed EMG stop, a digital
input, an axis output at a time), and the kernel runs on: random stepper machines with
armed edge stops, queued pieces and cycle-by-cycle commands, run by `run_cycles` and by
`advance` (whole and partial cycles), with and without a pulse record (then the kernel
writes its state back after every run: the stop times carried across the parts must land
in the objects too; the jump equivalence's seed 41 found that). Same cycles reached,
edges (exact times, every axis's count), stop times and state of every generator, plant,
transmission, decoder and switch, the same recorded pulses.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.hw.interface import AxisCommand, PieceBlock
from openmotion.hw.sim import SimMachine
from test_kernel_equivalence import bits, machine, pulses, random_pieces, state


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
    record = bool(rng.random() < 0.4)
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
        if record:
            hw.record_pulses()
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
        seen.append([hw.stop_time(i) for i in range(n_axes)])  # (before the objects are read)
        seen.append(state(hw))
        seen.append([hw.steps_lost(i) for i in range(n_axes)])
        if record:
            seen.append(pulses(hw))
        runs.append(seen)
        python_cycles.append(calls[0])
    assert runs[0] == runs[1]
    assert python_cycles[1] == 0  # not one stretch in the Python pipeline


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_a_probe_runs_in_the_kernel_as_in_python(seed):
    """A touch probe's hidden switches (hw/sim/probe.py) run in the kernel; their edges go
    through the probe's filter: the same di edges (exact times, every axis's count), the
    same input level and state as the Python path; workpieces placed and removed inside
    cycles."""
    from openmotion.hw.sim.probe import SimProbe

    rng = np.random.default_rng(seed)
    n_axes = int(rng.integers(1, 4))
    cfg, half_off = machine(rng, n_axes)
    cfg = replace(cfg, digital_inputs=2)
    period = 0.001
    cycles = int(rng.integers(10, 80))
    plans = [random_pieces(rng, cycles, period, 0.0) for _ in range(n_axes)]
    places = []
    for _ in range(int(rng.integers(1, 4))):
        boxes = []
        for _ in range(int(rng.integers(0, 3))):
            box = {}
            for a in range(n_axes):
                if rng.random() < 0.7 or not box:
                    lo = float(rng.uniform(-800, 400))
                    box[a] = (lo, lo + float(rng.uniform(1, 900)))
            boxes.append(box)
        places.append((float(rng.uniform(0, cycles * period)), boxes))
    wake = frozenset({"di0"}) if rng.random() < 0.5 else frozenset({"pel"})
    stepping = bool(rng.random() < 0.4)
    record = bool(rng.random() < 0.3)
    runs, python_cycles = [], []
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
        if record:
            hw.record_pulses()
        probe = SimProbe.attach(hw, "di0", normally_closed=bool(seed % 2))
        probe.place(places[0][1])
        for at, boxes in places[1:]:
            probe.place(boxes, at=at)
        seen: list = []
        if stepping:
            for k in range(cycles):
                for i, rows in enumerate(plans):
                    hw.command(i, AxisCommand(*rows[k]))
                seen.append((edges_of(hw.advance((k + 1) * period)), hw.read_input("di0")))
        else:
            for i, rows in enumerate(plans):
                hw.queue_pieces(i, PieceBlock(rows))
            k = 0
            while k < cycles:
                r = hw.run_cycles(0.0, period, k, cycles, wake)
                seen.append((r.cycle, edges_of(r.edges), hw.read_input("di0")))
                k = r.cycle
        seen.append((state(hw), probe.in_contact))
        if record:
            seen.append(pulses(hw))
        runs.append(seen)
        python_cycles.append(calls[0])
    assert runs[0] == runs[1]
    assert python_cycles[1] == 0


def test_an_estop_inside_a_recorded_cycle_stops_the_axes_where_the_python_path_does():
    """The jump equivalence's seed 41: pulses recorded, three axes moving, an E-stop inside a
    cycle with the EMG stop armed. The kernel runs up to the press, the cut applies, the
    kernel runs on; the stop times reach the controller, so every axis rests on the count
    it emitted at the press (not on its command at the cycle end), as in the Python path."""
    from openmotion.config import default_machine
    from openmotion.control import Controller

    runs = []
    for native in (False, True):
        ctl = Controller(default_machine())
        ctl.virtual_jumps = native
        ctl.hardware.native = native
        ctl.enable_all()
        ctl.hardware.record_pulses(True)
        for i, v in enumerate((43_000.0, -48_000.0, 30_000.0)[:len(ctl.axes)]):
            ctl.axes[i].move_velocity(v, tacc=0.05)
        ctl.hardware.scenario.press_estop(at=0.0210753)
        ctl.advance(0.03)
        runs.append((
            [(a.state, a.fault, a.position, a.counters.snapshot()) for a in ctl.axes],
            [(e.time, e.kind, e.axis, e.position) for e in ctl.events.events()],
            [ctl.hardware.pulse_record(i).pulses()[1].tolist() for i in range(len(ctl.axes))]))
    assert runs[0] == runs[1]
    estops = [e for e in runs[1][1] if e[1] == "estop"]
    assert estops and all(e[0] == 0.0210753 and e[3] == int(e[3]) for e in estops)


def test_an_action_that_touches_no_axis_keeps_the_kernels_arrays():
    """A board input (or an E-stop with no armed EMG stop) inside a cycle: the kernel runs
    on on the same arrays (nothing written back or rebuilt), with the Python path's edges
    and counts; an axis action drops them."""
    from openmotion.config import default_machine

    seen = []
    for native in (False, True):
        hw = SimMachine(replace(default_machine(), digital_inputs=2))
        hw.native = native
        for i in range(hw.n_axes):
            hw.command(i, AxisCommand(0.0, 0.01, 0.0, 20_000.0 + 1000.0 * i))
        hw.advance(0.001)
        ks = hw._ks
        hw.scenario.set_input("di1", True, at=0.0013)
        hw.scenario.press_estop(at=0.0017)
        edges = hw.advance(0.002)
        assert hw._ks is ks and (ks is not None) == native
        assert [(e.time, e.signal, e.level) for e in edges] == [(0.0013, "di1", True),
                                                                (0.0017, "emg", True)]
        hw.scenario.inject_step_loss(0, 3, at=0.0025)
        hw.advance(0.003)
        if native:
            assert hw._ks is not ks
        seen.append((edges_of(edges), state(hw), hw.steps_lost(0)))
    assert seen[0] == seen[1]
