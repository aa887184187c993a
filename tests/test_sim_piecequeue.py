"""The simulator's queue of timed pieces (hw.interface.QueuedHardware): bad pieces are
refused whole, queued pieces emit what per-cycle commands emit, run_cycles stops on edges."""

from __future__ import annotations

import math

import pytest

from openmotion.config import default_machine
from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand, QueuedHardware
from openmotion.hw.sim import SimMachine

P = 0.001


def ramp(n: int, v: float = 20_000.0, t0: float = 0.0) -> list[AxisCommand]:
    return [AxisCommand(t0 + k * P, P, v * k * P, v) for k in range(n)]


def test_sim_is_queued_hardware():
    assert isinstance(SimMachine(default_machine()), QueuedHardware)


@pytest.mark.parametrize("bad,match", [
    (AxisCommand(0.002, P, math.nan), r"pieces\[1\]\.p0 must be a finite"),
    (AxisCommand(0.002, -P, 0.0), r"pieces\[1\]\.dt must be >= 0"),
    (AxisCommand(0.0005, P, 0.0), r"pieces\[1\]\.t0 must be >= the end of the piece before"),
    (AxisCommand(0.002, P, 0.0, math.inf), r"pieces\[1\]\.v0 must be a finite"),
    ("piece", r"pieces\[1\] must be an AxisCommand"),
])
def test_a_malformed_piece_is_refused_and_the_queue_is_unchanged(bad, match):
    hw = SimMachine(default_machine())
    hw.queue_pieces(0, ramp(1))
    with pytest.raises(MotionError, match=match):
        hw.queue_pieces(0, [AxisCommand(0.001, P, 20.0, 20_000.0), bad])
    assert hw.queued(0) == 1
    with pytest.raises(MotionError, match="pieces must be a sequence"):
        hw.queue_pieces(0, AxisCommand(0.001, P, 0.0))
    with pytest.raises(MotionError, match="axis must be"):
        hw.queue_pieces(9, [])


def test_a_piece_in_the_past_is_refused():
    hw = SimMachine(default_machine())
    hw.advance(0.01)
    with pytest.raises(MotionError, match=r"pieces\[0\]\.t0 must be >= the hardware time"):
        hw.queue_pieces(0, ramp(2))
    assert hw.queued(0) == 0


def test_queued_pieces_emit_what_per_cycle_commands_emit():
    a, b = SimMachine(default_machine()), SimMachine(default_machine())
    for hw in (a, b):
        hw.record_pulses(True)
    pieces = ramp(50)
    for k, cmd in enumerate(pieces):
        a.command(1, cmd)
        a.advance((k + 1) * P)
    b.queue_pieces(1, pieces)
    run = b.run_cycles(0.0, P, 0, 50, wake=())  # no signal ends the run
    assert run.cycle == 50 and run.drained == (1,)
    assert a.read_axis(1) == b.read_axis(1)
    ta, ca = a.pulse_record(1).pulses()
    tb, cb = b.pulse_record(1).pulses()
    assert ta.tolist() == tb.tolist() and ca.tolist() == cb.tolist()


def test_run_cycles_stops_at_the_end_of_the_cycle_of_a_wake_edge():
    hw = SimMachine(default_machine())
    hw.scenario.set_input("di0", True, at=0.0123)
    hw.queue_pieces(0, ramp(100))
    run = hw.run_cycles(0.0, P, 0, 100, wake={"di0"})  # EZ index edges pass
    assert run.cycle == 13 and [e.signal for e in run.edges] == ["di0"]
    assert run.edges[0].time == 0.0123 and hw.time == pytest.approx(0.013)
    hw.clear_queue(0)
    assert hw.queued(0) == 0


def test_edges_on_signals_nobody_wakes_for_are_passed_over():
    hw = SimMachine(default_machine())
    hw.scenario.set_input("di0", True, at=0.0123)
    hw.scenario.set_input("di1", True, at=0.0456)
    run = hw.run_cycles(0.0, P, 0, 100, wake={"di1"})
    assert run.cycle == 46 and [e.signal for e in run.edges] == ["di1"]
    assert hw.read_input("di0")


@pytest.mark.parametrize("args,match", [
    ((0.0, 0.0, 0, 5), "period"), ((0.0, P, 5, 4), "stop"), ((0.0, P, 0.5, 4), "start"),
    ((math.nan, P, 0, 4), "origin"),
])
def test_run_cycles_validates(args, match):
    hw = SimMachine(default_machine())
    with pytest.raises(MotionError, match=match):
        hw.run_cycles(*args)
    assert hw.time == 0.0
