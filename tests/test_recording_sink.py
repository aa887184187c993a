"""The compiled row writer (`Recorder.row_sink`, `_kernel.RowSink`: a cycle-by-cycle step's
row, control/core/jump.record_now, and a jump's crossed cycles, `put_block`) stores the very
rows `Recorder.record` / `record_block` store:
stepped against the Python row (`record_now` off) with several channel sets, a ring shorter
than the run, feedback from either source with offsets, normally-closed contacts, E-stop,
and steps mixed with jumps whose held idle runs the stepped rows later overwrite (the sink
stops, the held rows settle, it goes on); and a bad value is refused with nothing stored."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from openmotion.config import MachineConfig, SwitchConfig, default_machine
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.recording import CHANNELS, Recorder

ALL = CHANNELS


def scripted(compiled: bool, capacity: int, channels, mixed: bool, monkeypatch) -> dict:
    from openmotion.control.core import controller as ctlmod

    with monkeypatch.context() as mp:
        if not compiled:  # every row through Recorder.record / record_block
            mp.setattr(ctlmod, "record_now", lambda *a: False)
            mp.setattr(Recorder, "row_sink", lambda *a: None)
            mp.setattr(Recorder, "record_into", lambda *a: False)
        x = default_machine().axes[0]
        axes = (replace(x, name="x", pel=SwitchConfig(position=30_000.0, width=400.0),
                        logic={"org": "nc"}),
                replace(x, name="y"), replace(x, name="z"))
        c = Controller(MachineConfig(name="sink", axes=axes))
        c.virtual_jumps = False
        c.enable_all()
        c.start_recording(capacity=capacity, channels=channels)
        c.axes[1].counters.set_feedback_source("internal")
        c.axes[1].counters.set_feedback(1234)
        c.axes[2].counters.set_command(-77)
        if mixed:  # an idle jump first: its rows are held, the steps overwrite them
            c.virtual_jumps = True
            c.advance(0.9)
            c.virtual_jumps = False
        c.axes[0].move_relative(40_000, max_vel=80_000, tacc=0.05)
        c.axes[1].move_relative(-9_000, max_vel=30_000, tacc=0.02, shape="S")
        c.advance(0.3)
        if mixed:
            c.virtual_jumps = True
            c.wait_motion_done()
            c.advance(0.4)
            c.virtual_jumps = False
        c.wait_motion_done()
        _ = len(c.recorder), c.recorder.total  # a read between steps takes the rows back
        c.hardware.scenario.press_estop(at=c.time + 0.0105)
        c.axes[2].move_velocity(20_000, tacc=0.05)
        c.advance(0.1)
        rec = c.recorder
        return {"total": np.array([rec.total, len(rec), rec.dropped]), **rec.arrays()}


@pytest.mark.parametrize("capacity,channels,mixed", [
    (5000, ALL, False),
    (5000, ALL, True),
    (37, ALL, False),
    (300, ALL, True),
    (800, ("fb_pos", "io"), True),
    (800, ("state",), False),
    (800, ("cmd_pos", "cmd_vel"), True),
])
def test_stepped_rows_are_the_python_rows(capacity, channels, mixed, monkeypatch):
    got = scripted(True, capacity, channels, mixed, monkeypatch)
    want = scripted(False, capacity, channels, mixed, monkeypatch)
    assert got.keys() == want.keys()
    for k in want:
        assert got[k].dtype == want[k].dtype
        assert got[k].tobytes() == want[k].tobytes(), k
    assert len(got["t"]) == min(capacity, len(want["t"])) and len(want["t"]) > 30


def armed(n: int = 2, capacity: int = 10) -> tuple[Recorder, object]:
    from openmotion.control.core import jump

    r = Recorder(n, capacity)
    r.record(0.0, cmd_pos=[0] * n, fb_pos=[0] * n, cmd_vel=[0] * n, state=[0] * n,
             io=[0] * n)
    return r, r.row_sink(jump._io_table(), *jump._state_table())


def test_a_bad_row_is_refused_and_nothing_stored():
    from openmotion.control.core.axis import AxisState

    r, sink = armed()
    st = next(iter(AxisState))
    good = [1.0, 0, 2.0, False, 0, st] * 2
    rb = np.zeros((2, 3), dtype=np.int64)
    nc = np.zeros(2, dtype=np.int64)
    before = {k: v.copy() for k, v in r.arrays().items()}
    sink = r.row_sink(*_tables())
    bad = [
        (0.001, [np.nan, 0, 2.0, False, 0, st] + good[6:], rb, nc),  # not finite
        (0.001, good[:6] + [1.0, 0, np.inf, False, 0, st], rb, nc),
        (0.001, good[:-1] + ["nope"], rb, nc),  # not an axis state
        (0.001, good[:-1], rb, nc),  # too few values
        (0.001, good, np.zeros((3, 3), dtype=np.int64), nc),  # readback of 3 axes
        (0.001, good, rb.astype(np.float64), nc),
        (0.001, good, rb, np.zeros(3, dtype=np.int64)),
        (-1.0, good, rb, nc),  # earlier than the newest row
        (np.nan, good, rb, nc),
    ]
    for t, vals, readback, ncw in bad:
        with pytest.raises((ValueError, TypeError)):
            sink.put(t, vals, readback, ncw, False)
    after = r.arrays()  # (takes the sink's rows back: none)
    assert all(after[k].tobytes() == before[k].tobytes() for k in before)
    assert r.total == 1 and len(r) == 1
    sink = r.row_sink(*_tables())
    assert sink.put(0.001, good, rb, nc, True)
    assert r.total == 2 and r.arrays()["io"][-1].tolist() == [64, 64]


def test_the_sink_is_disarmed_by_any_other_access():
    r, sink = armed()
    from openmotion.control.core.axis import AxisState

    st = next(iter(AxisState))
    vals = [1.0, 0, 2.0, False, 0, st] * 2
    rb = np.zeros((2, 3), dtype=np.int64)
    nc = np.zeros(2, dtype=np.int64)
    assert sink.put(0.001, vals, rb, nc, False) and r.sink is sink
    r.record(0.002, cmd_pos=[5, 5], fb_pos=[0, 0], cmd_vel=[0, 0], state=[0, 0],
             io=[0, 0])
    assert r.sink is None
    assert sink.put(0.003, vals, rb, nc, False) is False  # nothing written: arm again
    assert r.arrays()["t"].tolist() == [0.0, 0.001, 0.002]


def test_a_spilling_recorder_has_no_sink(tmp_path):
    r = Recorder(2, 10, spill_path=tmp_path / "s.bin")
    assert r.row_sink(*_tables()) is None


def test_a_bad_binding_is_refused():
    r = Recorder(2, 10)
    with pytest.raises(MotionError):
        r.row_sink(np.zeros(4), *_tables()[1:])  # a float table


def _tables() -> tuple:
    from openmotion.control.core import jump

    return (jump._io_table(), *jump._state_table())


def test_a_bad_block_is_refused_and_nothing_stored():
    from openmotion.control.core.axis import AxisState

    r, sink = armed()
    st = next(iter(AxisState))
    vals = [1.0, 0, 2.0, False, 0, st] * 2
    tr = np.zeros((3, 2, 3), dtype=np.int64)
    nc = np.zeros(2, dtype=np.int64)
    good_end = np.array([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    before = {k: v.copy() for k, v in r.arrays().items()}
    sink = r.row_sink(*_tables(), 3)
    bad = [
        (0, tr, [0], (np.array([[1.0, 0.0], [np.nan, 0.0], [3.0, 0.0]]),), [0.0]),
        (0, tr, [0], (good_end[:2],), [0.0]),  # ends too short
        (0, tr, [2], (good_end,), [0.0]),  # not an axis
        (0, tr, [0], (good_end,), []),  # an offset missing
        (0, tr.astype(np.float64), [0], (good_end,), [0.0]),
        (-5, tr, [0], (good_end,), [0.0]),  # earlier than the newest row
    ]
    for n0, trace, movers, ends, offs in bad:
        with pytest.raises((ValueError, TypeError)):
            sink.put_block(n0, 0.0, 0.001, trace, vals, movers, ends, offs, nc, False)
    after = r.arrays()
    assert all(after[k].tobytes() == before[k].tobytes() for k in before)
    assert r.total == 1
    sink = r.row_sink(*_tables(), 3)
    assert sink.put_block(0, 0.0, 0.001, tr, vals, [1], (good_end,), [5.0], nc, False)
    got = r.arrays()
    assert got["t"].tolist() == [0.0, 0.001, 0.002, 0.003]
    assert got["cmd_pos"][1:].tolist() == [[1.0, 6.0], [1.0, 7.0], [1.0, 8.0]]


@pytest.mark.parametrize("jumping", [False, True])
def test_a_contact_logic_changed_on_the_way_shows_in_the_io_words(jumping, monkeypatch):
    from openmotion.control.core import controller as ctlmod

    def io(compiled: bool) -> list:
        with monkeypatch.context() as mp:
            if not compiled:
                mp.setattr(ctlmod, "record_now", lambda *a: False)
                mp.setattr(Recorder, "row_sink", lambda *a: None)
                mp.setattr(Recorder, "record_into", lambda *a: False)
            c = Controller(MachineConfig(name="nc", axes=(default_machine().axes[0],)))
            c.virtual_jumps = jumping
            c.enable_all()
            c.start_recording(capacity=500)
            c.advance(0.05)
            c.reconfigure_axis(0, logic={"org": "nc", "pel": "nc"})
            c.advance(0.05)
            c.reconfigure_axis(0, logic={})
            c.advance(0.05)
            return c.recorder.arrays()["io"][:, 0].tolist()

    got, want = io(True), io(False)
    assert got == want and len(set(want)) >= 2  # the rows change with the logic
