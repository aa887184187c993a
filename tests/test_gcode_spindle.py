"""The spindle as an axis: M3/M4/M5/S on the simulated spindle, G33/G76 locked to its
measured position (index start, phase tracking), M19 orientation."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from openmotion.config import default_machine
from openmotion.control.core.controller import Controller
from openmotion.control.core.states import AxisState
from openmotion.errors import MotionError
from openmotion.hw.sim.spindle import spindle_axis
from openmotion.program import ProgramRunner, RunOptions, RunState, compile_text
from openmotion.program.orient import Orient

CPR = 4096


def machine() -> Controller:
    m = default_machine()
    ctl = Controller(replace(m, axes=(*m.axes, spindle_axis(counts_per_rev=CPR))))
    ctl.enable_all()
    return ctl


def runner(text: str, **opts) -> tuple[Controller, ProgramRunner]:
    ctl = machine()
    run = ProgramRunner(ctl, text, options=RunOptions(spindle_axis="spindle", **opts))
    return ctl, run


def test_spindle_axis_configuration():
    a = spindle_axis(counts_per_rev=1024, max_rpm=3000)
    assert a.unit == "degree" and a.pulses_per_rev == 1024 and a.encoder_lines_per_rev == 256
    assert a.max_speed == pytest.approx(18000.0) and a.drive.type == "servo"
    for bad in ({"counts_per_rev": 1022}, {"counts_per_rev": True}, {"max_rpm": 0}):
        with pytest.raises(MotionError):
            spindle_axis(**bad)  # type: ignore[arg-type]


def test_m3_m4_m5_and_s_drive_the_spindle_axis():
    ctl, run = runner("S600 M3\nG4 P1\nS1200\nG4 P1\nM4\nG4 P2\nM5\nG4 P1\nS300 M3\n"
                      "G4 P1\nM2\n")
    sp = ctl.axis("spindle")
    speeds = []

    def watch(c, t):
        if run.spindle is not None:
            speeds.append((t, run.spindle.revs_per_s() * 60.0))

    ctl.add_cycle_hook(watch)
    run.start()
    run.wait(30)
    assert run.state is RunState.DONE, run.error
    ctl.remove_cycle_hook(watch)

    def rpm_at(t):
        return min(speeds, key=lambda x: abs(x[0] - t))[1]

    assert rpm_at(0.9) == pytest.approx(600, rel=0.02)
    assert rpm_at(1.9) == pytest.approx(1200, rel=0.02)
    assert rpm_at(3.9) == pytest.approx(-1200, rel=0.02)  # M4: stopped, then reversed
    assert abs(rpm_at(4.9)) < 1.0  # M5
    assert rpm_at(5.9) == pytest.approx(300, rel=0.03)
    ctl.run_until(lambda: sp.state is AxisState.STANDSTILL, 5)  # M2 stopped it
    assert sp.state is AxisState.STANDSTILL


THREAD = """G21 G90 G18
S{s} M3
G0 X10 Z60
G33 Z50 K1.5
G0 X12
G0 Z60
G0 X9.5
G33 Z50 K1.5
G0 X12
M5 M2
"""


def _track(ctl: Controller, run: ProgramRunner):
    """Per cycle: time, Z (mm), spindle feedback count."""
    rows = []
    kz = run.letters.index("Z")

    def rec(c, t):
        if run.spindle is not None:
            rows.append((t, c.axes[run.axis_indices[kz]].position / run.scales.ppu[kz],
                         run.spindle.count()))

    ctl.add_cycle_hook(rec)
    return rows


def test_g33_follows_the_measured_spindle_position_from_its_index():
    # G33 right after M3: the spindle is still accelerating (0.5 s ramp)
    ctl, run = runner(THREAD.format(s=600))
    rows = _track(ctl, run)
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    assert len(run.sync_moves) == 2
    for m in run.sync_moves:
        assert m.c0 is not None and m.steady_error < 2e-3
        assert (m.c0 - run.sync_moves[0].c0) % CPR == 0  # every pass at the index
        # independent check: Z against the spindle's own count, cycle by cycle
        mid = [(z, c) for t, z, c in rows if m.t0 < t <= m.errors[-1][0] and 53 < z < 55.5]
        assert len(mid) > 20
        for z, c in mid:
            assert 60.0 - z == pytest.approx(1.5 * (c - m.c0) / CPR, abs=2e-3)
    starts = [e.t for e in run.events if e.kind == "sync_start"]
    assert starts[0] > 0.0  # waited for the index


def test_g33_tracks_a_spindle_slower_than_commanded():
    """A spindle whose drive lags (low bandwidth) runs behind its command while ramping:
    the thread still follows the measured position, not the nominal S."""
    m = default_machine()
    ctl = Controller(replace(m, axes=(*m.axes, spindle_axis(counts_per_rev=CPR,
                                                             bandwidth_hz=3.0))))
    ctl.enable_all()
    run = ProgramRunner(ctl, THREAD.format(s=900), options=RunOptions(
        spindle_axis="spindle", spindle_acc_time=2.0))
    rows = _track(ctl, run)
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    first = run.sync_moves[0]
    mid = [(t, z, c) for t, z, c in rows
           if first.t0 < t <= first.errors[-1][0] and 53 < z < 55.5]
    speed = np.diff([c for _, _, c in mid]) / CPR / ctl.period * 60.0
    assert speed.min() < 800  # still ramping to 900 rpm during the pass
    for _t, z, c in mid:
        assert 60.0 - z == pytest.approx(1.5 * (c - first.c0) / CPR, abs=5e-3)


def test_g76_passes_all_start_at_the_index():
    ctl, run = runner("G21 G90 G18\nS500 M3\nG0 X12 Z60\n"
                      "G76 P1.5 Z55 I-0.5 J0.25 K0.6 Q29.5 H1\nM5 M2\n")
    run.start()
    run.wait(120)
    assert run.state is RunState.DONE, run.error
    n = sum(1 for c in run.commands if type(c).__name__ == "SyncedFeed")
    assert len(run.sync_moves) == n > 3
    assert all((m.c0 - run.sync_moves[0].c0) % CPR == 0 for m in run.sync_moves)
    assert max(m.steady_error for m in run.sync_moves) < 2e-3


@pytest.mark.parametrize("angle, mode", [(90.0, 0), (270.0, 1), (10.0, 2)])
def test_m19_orients_the_spindle_from_its_index(angle, mode):
    ctl, run = runner(f"S300 M3\nG4 P0.8\nM19 R{angle:g} P{mode} Q5\nG0 X1\nM2\n")
    run.start()
    run.wait(30)
    assert run.state is RunState.DONE, run.error
    sp = run.spindle
    assert sp is not None and sp.index_count is not None
    turned = (sp.count() - sp.index_count) % CPR
    miss = abs(turned - round(angle / 360 * CPR))
    assert min(miss, CPR - miss) <= 1


def test_m19_errors():
    ctl, run = runner("M19 R90\nM2\n")  # the index has never passed
    run.start()
    run.wait(10)
    assert run.state is RunState.ERROR and "index pulse has not been seen" in run.error
    ctl, run = runner("S3000 M3\nG4 P0.6\nM19 R180 Q0.01\nM2\n")
    run.start()
    run.wait(10)
    assert run.state is RunState.ERROR and "within 0.01 s" in run.error


def test_m19_words_and_without_spindle_axis():
    from openmotion.program import GCodeError, GCodeOptions

    o = GCodeOptions(axes={"X": 0, "Z": 2})
    cmds = compile_text("S100 M3\nM19 R370 P2 Q1\n(DEBUG, #<_spindle_on>)\nM19\nM2\n", o)
    orient = [c for c in cmds if isinstance(c, Orient)]
    assert orient == [Orient(10.0, 2, 1.0, 2)]  # plain M19: no orientation command
    for bad, msg in (("M19 R1 P3", "P must be"), ("M19 R1 Q0", "Q word with M19")):
        with pytest.raises(GCodeError, match=msg):
            compile_text(bad + "\nM2\n", o)
    ctl = machine()
    run = ProgramRunner(ctl, "S100 M3\nM19 R5\nG0 X1\nM2\n")
    run.start()
    run.wait(10)
    assert run.state is RunState.DONE
    assert any("no spindle axis" in e.text for e in run.events)


def test_spindle_options_are_checked():
    ctl = machine()
    with pytest.raises(MotionError, match="spindle_axis"):
        RunOptions(spindle_axis=1.5)  # type: ignore[arg-type]
    with pytest.raises(MotionError, match="spindle_acc_time"):
        RunOptions(spindle_acc_time=0)
    with pytest.raises(MotionError, match="program's axes"):
        ProgramRunner(ctl, "G0 X1\nM2\n", options=RunOptions(spindle_axis="x"))
    with pytest.raises(MotionError):
        ProgramRunner(ctl, "G0 X1\nM2\n", options=RunOptions(spindle_axis="nope"))
    ctl, run = runner("S99999 M3\nM2\n")
    run.start()
    run.wait(5)
    assert run.state is RunState.ERROR and "maximum is 6000 rpm" in run.error


def test_g87_orients_before_it_enters_the_hole_and_restarts_the_spindle():
    ctl, run = runner("G21 S1200 M3\nG4 P0.3\nG0 X0 Y0 Z1\n"
                      "G87 X0.2 Y0 R0.5 Z-0.5 I0.1 J0 K-0.2 F1200\nG80\nM2\n")
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    assert [e.text for e in run.events if "M19" in e.text] == ["M19 R0 P0"] * 2
    sp = run.spindle
    assert sp is not None and sp.index_count is not None


def test_g87_stops_when_the_spindle_cannot_orient():
    ctl, run = runner("G21 S300 M3\nG0 X0 Y0 Z5\nG87 X1 Y0 R2 Z-2 I0.5 J0 K-1 F600\nM2\n")
    run.start()  # the index has never passed: the tool must not go down into the hole
    run.wait(30)
    assert run.state is RunState.ERROR and "index pulse" in run.error
    z = ctl.axes[2]
    assert z.position / z.units.pulses_per_unit == pytest.approx(2.0)  # stopped at R
