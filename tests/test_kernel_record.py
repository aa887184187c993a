"""The compiled recorder of a jump's crossed cycles (`_kernel.record_rows` through
`Recorder.record_into`) writes the very rows the numpy path (`Recorder.record_block`)
writes: time, command position and velocity, feedback (either source, with offsets),
state and io words (normally-closed contacts, E-stop), a ring shorter than the run, a
subset of channels; and a bad value is refused before anything is stored."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from openmotion.config import MachineConfig, SwitchConfig, default_machine
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.recording import Recorder


def run(compiled: bool, capacity: int, channels, monkeypatch) -> dict:
    with monkeypatch.context() as mp:
        if not compiled:
            mp.setattr(Recorder, "record_into", lambda *a: False)
            mp.setattr(Recorder, "row_sink", lambda *a: None)
        x = default_machine().axes[0]
        axes = (replace(x, name="x", pel=SwitchConfig(position=30_000.0, width=400.0),
                        logic={"org": "nc"}),
                replace(x, name="y"), replace(x, name="z"))
        c = Controller(MachineConfig(name="rec", axes=axes))
        c.enable_all()
        c.start_recording(capacity=capacity, channels=channels)
        c.axes[1].counters.set_feedback_source("internal")
        c.axes[1].counters.set_feedback(1234)
        c.axes[0].move_relative(40_000, max_vel=80_000, tacc=0.05)
        c.axes[1].move_relative(-9_000, max_vel=30_000, tacc=0.02, shape="S")
        c.wait_motion_done()
        c.advance(0.05)
        c.hardware.scenario.press_estop(at=c.time + 0.0105)
        c.axes[2].move_velocity(20_000, tacc=0.05)
        c.advance(0.1)
        return c.recorder.arrays()


@pytest.mark.parametrize("capacity,channels", [
    (5000, ("cmd_pos", "fb_pos", "cmd_vel", "state", "io")),
    (37, ("cmd_pos", "fb_pos", "cmd_vel", "state", "io")),
    (800, ("fb_pos", "io")),
    (800, ("state",)),
])
def test_compiled_jump_rows_are_the_numpy_rows(capacity, channels, monkeypatch):
    got = run(True, capacity, channels, monkeypatch)
    want = run(False, capacity, channels, monkeypatch)
    assert got.keys() == want.keys()
    for k in want:
        assert got[k].dtype == want[k].dtype
        assert got[k].tobytes() == want[k].tobytes(), k
    assert len(got["t"]) == min(capacity, len(want["t"]))


def test_a_bad_row_is_refused_and_nothing_stored():
    from openmotion import _kernel

    r = Recorder(2, 10)
    r.record(0.0, cmd_pos=[0, 0], fb_pos=[0, 0], cmd_vel=[0, 0], state=[0, 0], io=[0, 0])
    before = {k: v.copy() for k, v in r.arrays().items()}
    tr = np.zeros((3, 2, 3), dtype=np.int64)
    ends = (np.array([[1.0, 0.0], [np.nan, 0.0], [3.0, 0.0]]),)

    def fill(rt, rf, rstate, rio, head, slots):
        try:
            _kernel.record_rows(rt, rf, rstate, rio, head, slots, 0.0, 0.001, 0, tr,
                                [0.0] * 4, np.array([0]), ends, np.zeros(1), [0] * 6,
                                np.zeros(2, dtype=np.int64),
                                np.zeros(512, dtype=np.int64), False)
        except ValueError as exc:
            raise MotionError(str(exc)) from None

    with pytest.raises(MotionError, match="finite"):
        r.record_into(3, 0.001, 0.003, fill)
    after = r.arrays()
    assert all(after[k].tobytes() == before[k].tobytes() for k in before)
    assert r.total == 1
    with pytest.raises(MotionError, match="non-decreasing"):
        r.record_into(1, -1.0, -1.0, fill)


def stepped(compiled: bool, jumping: bool, monkeypatch) -> dict:
    from openmotion.control.core import controller as ctlmod

    with monkeypatch.context() as mp:
        if not compiled:
            mp.setattr(ctlmod, "record_now", lambda *a: False)
        x = default_machine().axes[0]
        axes = (replace(x, name="x", org=SwitchConfig(position=2_000.0, width=300.0),
                        logic={"org": "nc", "alm": "nc"}),
                replace(x, name="s", drive=replace(x.drive, type="servo")),
                replace(x, name="z"))
        c = Controller(MachineConfig(name="rec", axes=axes))
        c.virtual_jumps = jumping
        c.enable_all()
        c.start_recording(capacity=3000)
        c.axes[2].counters.set_feedback_source("internal")
        c.axes[0].move_relative(6_000, max_vel=60_000, tacc=0.02)
        c.axes[1].move_relative(3_000, max_vel=40_000, tacc=0.02)
        c.advance(0.03)

        def toggle(ctl, t):  # read in this cycle, then change RDY: the row shows the read
            if ctl.cycles in (40, 41):
                _ = ctl.axes[0].counters.feedback, ctl.axes[1].counters.feedback
                _ = ctl.input_active(1, "rdy")
                ctl.hardware.write_output(1, "svon", ctl.cycles == 41)

        c.add_cycle_hook(toggle)
        c.advance(0.02)
        c.remove_cycle_hook(toggle)
        c.hardware.scenario.trip_alarm(2, at=c.time + 0.0042)
        c.axes[2].move_velocity(-20_000, tacc=0.02)
        c.advance(0.1)
        return c.recorder.arrays()


@pytest.mark.parametrize("jumping", [False, True])
def test_the_compiled_landing_row_is_the_python_row(jumping, monkeypatch):
    got = stepped(True, jumping, monkeypatch)
    want = stepped(False, jumping, monkeypatch)
    for k in want:
        assert got[k].tobytes() == want[k].tobytes(), k
    assert len(want["t"]) > 100


def idle(jumping: bool, capacity: int, spill, held: list) -> dict:  # noqa: ANN001
    x = default_machine().axes[0]
    axes = (replace(x, name="x", logic={"org": "nc"}), replace(x, name="y"))
    c = Controller(MachineConfig(name="idle", axes=axes))
    c.virtual_jumps = jumping
    c.enable_all()
    c.start_recording(capacity=capacity, spill_path=spill)
    c.axes[1].counters.set_feedback_source("internal")
    c.advance(2.5)  # idle: virtual time jumps, the recorder holds the readback
    held.append(len(c.recorder._held))
    c.axes[0].move_relative(3_000, max_vel=60_000, tacc=0.02)
    c.wait_motion_done()
    c.advance(1.7)
    c.hardware.scenario.press_estop(at=c.time + 0.0105)
    c.advance(0.9)  # idle again, E-stop bit set in every row
    held.append(len(c.recorder._held))
    return c.recorder.all_arrays()


@pytest.mark.parametrize("capacity,spill", [(10_000, False), (700, False), (1200, True)])
def test_an_idle_stretch_recorded_jumping_is_the_per_cycle_recording(capacity, spill,
                                                                     tmp_path):
    held: list = []
    want = idle(False, capacity, tmp_path / "a.bin" if spill else None, [])
    got = idle(True, capacity, tmp_path / "b.bin" if spill else None, held)
    assert got.keys() == want.keys()
    for k in want:
        assert got[k].tobytes() == want[k].tobytes(), k
    cycles = round(want["t"][-1] / 1e-3)  # every cycle from 1 on, spilled or kept
    assert cycles > 5000 and len(want["t"]) == (cycles if spill else min(capacity, cycles))
    assert (max(held) > 0) != spill  # held runs were used (a spilling recorder takes rows)
