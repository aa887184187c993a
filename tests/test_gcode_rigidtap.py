"""G33.1 rigid tapping: the record and LinuxCNC's checks, the nominal run without a spindle
axis, and the synchronised tap against the simulated spindle (in, reversal with overrun,
out, second reversal, home)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from lcnc_oracle import OPTIONS
from openmotion.config import default_machine
from openmotion.control import Controller
from openmotion.hw.sim.spindle import spindle_axis
from openmotion.program import GCodeError, ProgramRunner, RunOptions, compile_text
from openmotion.program.convert import ConvertOptions, Scales, convert
from openmotion.program.rigidtap import RigidTap
from openmotion.program.runner import RunState
from openmotion.units import AxisUnits


def test_the_record_keeps_the_start_and_the_line_ends_there():
    cmds = compile_text("G21 S500 M3\nG0 X1 Y2 Z3\nG33.1 Z-10 K1.25 I0.5\n"
                        "(debug,#<_z>)\nG91 G33.1 Z-5 K1 I3\nM2\n", OPTIONS)
    taps = [c for c in cmds if isinstance(c, RigidTap)]
    assert taps[0].start[:3] == (1.0, 2.0, 3.0) and taps[0].end[:3] == (1.0, 2.0, -10.0)
    assert taps[0].pitch == 1.25 and taps[0].return_scale == 1.0  # I below 1 counts as 1
    assert taps[1].end[2] == -2.0 and taps[1].return_scale == 3.0  # G91 from the start
    assert [c.text for c in cmds if type(c).__name__ == "Message"] == ["3.000000"]


@pytest.mark.parametrize(("text", "needle"), [
    ("G21 S500 M3\nG33.1 Z-1 K0\nM2\n", "K must be > 0"),
    ("G21 S500 M3\nG33.1 Z-1 A5 K1\nM2\n", "X Y Z only"),
    ("G21 S500\nG33.1 Z-1 K1\nM2\n", "Spindle not turning in G33.1"),
    ("G21 S500 M3\nG33.1 Z-1\nM2\n", "K word missing"),
])
def test_refusals(text, needle):
    with pytest.raises(GCodeError, match=needle) as err:
        compile_text(text, OPTIONS)
    assert err.value.line == 2


def test_without_a_spindle_axis_it_runs_in_and_out_at_k_times_s():
    cmds = compile_text("G21 S600 M3\nG33.1 Z-4 K1.5 I2\nM2\n",
                        OPTIONS)
    units = [AxisUnits(L, "mm", 1000.0, 1, 1e6) for L in "XYZABC"]
    ops = convert(cmds, Scales.build(units, list("XYZABC"), "mm"), np.zeros(6),
                  ConvertOptions())
    lines = [o for o in ops if o.kind == "line"]
    assert [o.end[2] for o in lines] == [-4.0, 0.0]
    assert [o.feed for o in lines] == pytest.approx([1.5 * 10.0, 1.5 * 20.0])


def test_the_tap_follows_the_spindle_reverses_twice_and_ends_at_the_start():
    cfg = default_machine()
    ctl = Controller(replace(cfg, axes=(*cfg.axes, spindle_axis())))
    ctl.enable_all()
    prog = "G21 G90 G0 X10 Y10 Z20\nS1200 M3\nG4 P0.2\nG33.1 Z18 K0.5 I2\nM2\n"
    run = ProgramRunner(ctl, prog, options=RunOptions(spindle_axis="spindle",
                                                      spindle_acc_time=0.1),
                        gcode={"parameters": {}})
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    (tap,) = run.rigid_taps
    _t, idx, p = run.trace()
    on_tap = np.array([i >= 0 and run.line_of(int(i)) == 4 for i in idx])
    z = p[on_tap, run.letters.index("Z")]
    # the tool went past the end by the spindle's overrun, came back past the start, home
    assert tap.overrun_in > 0.0 and tap.overrun_out > 0.0
    assert z.min() == pytest.approx(18.0 - tap.overrun_in, abs=0.02)
    assert z.max() == pytest.approx(20.0 + tap.overrun_out, abs=0.02)
    assert ctl.axis("z").position == round(20.0 * run.scales.ppu[run.letters.index("Z")])
    # overrun = pitch x revolutions of a stop from 20 / 40 rps in 0.1 s x (speed/max)
    assert 0.05 < tap.overrun_in < 1.0 and tap.overrun_out > tap.overrun_in
    # following the spindle once the start lag is over: within 0.05 mm through both
    # reversals (measured 0.026 mm: a 1200 -> -2400 rpm reversal in 0.1 s; the override
    # follows the measured speed), within 0.005 mm where the spindle turns steadily
    e = np.array(tap.errors)
    settled = e[:, 0] > e[0, 0] + 0.15
    assert np.abs(e[settled, 2]).max() < 0.05
    assert np.median(np.abs(e[settled, 2])) < 0.01
    # the spindle turns clockwise at S again (M2 then stops it)
    assert [x.kind for x in run.events].count("tap_end") == 1
