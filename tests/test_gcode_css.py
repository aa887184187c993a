"""G96/G97 constant surface speed and G95 feed per revolution on the measured spindle
speed: the records (LinuxCNC's SET_SPINDLE_MODE figures), the nominal feeds without a
spindle axis, and a facing cut on the simulated lathe + spindle."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from lcnc_oracle import OPTIONS, rs274_path, run_rs274
from openmotion.config_toml import load_machine
from openmotion.control import Controller
from openmotion.hw.sim.spindle import spindle_axis
from openmotion.program import Feed, GCodeError, ProgramRunner, RunOptions, compile_text
from openmotion.program.css import FeedMode, SpindleMode
from openmotion.program.runner import RunState

ROOT = Path(__file__).parent.parent


def test_g96_record_matches_linuxcncs_spindle_mode():
    text = "G21 G10 L2 P1 X3\nG96 S150 D-2500 M3\nG1 X10 F100\nG97 S500\nM2\n"
    cmds = compile_text(text, OPTIONS)
    modes = [c for c in cmds if isinstance(c, SpindleMode)]
    assert modes[0].max_rpm == 2500.0 and modes[0].x_origin == 3.0  # |D|, X0 of G54
    assert modes[0].per_s_unit == 1000.0 and modes[1].per_s_unit == 0.0  # m/min; G97
    assert modes[0].rpm(150.0, 3.0 + 20.0) == pytest.approx(150_000 / (2 * math.pi * 20))
    assert modes[0].rpm(150.0, 3.0) == 2500.0  # on the axis: D
    exe = rs274_path()
    if exe is not None:  # rs274 prints SET_SPINDLE_MODE(spindle css_max)
        listing = run_rs274(text, exe).listing
        assert "SET_SPINDLE_MODE(0 2500.0000)" in listing
        assert "SET_SPINDLE_MODE(0 0.0000)" in listing


def test_g96_in_inches_is_feet_per_minute_and_refuses_without_s():
    (mode,) = [c for c in compile_text("G20\nG96 S100 M3\nM2\n", OPTIONS)
               if isinstance(c, SpindleMode)]
    assert mode.per_s_unit == pytest.approx(12 * 25.4) and math.isinf(mode.max_rpm)
    with pytest.raises(GCodeError, match="S word missing with G96"):
        compile_text("G21 S100\nG96 M3\nM2\n", OPTIONS)


def test_m72_restoring_g96_or_g95_tells_the_runner():
    cmds = compile_text("G21 G96 S100 D2000 M3\nM70\nG97 S500 G95 F0.1\nM72\nM2\n",
                        OPTIONS)
    modes = [(type(c).__name__, getattr(c, "per_s_unit", getattr(c, "per_rev", None)))
             for c in cmds if isinstance(c, SpindleMode | FeedMode)]
    assert modes == [("SpindleMode", 1000.0), ("FeedMode", True), ("SpindleMode", 0.0),
                     ("SpindleMode", 1000.0), ("FeedMode", False)]


def test_g95_in_g96_plans_with_the_rpm_at_each_moves_start():
    cmds = compile_text("G21 G18 G0 X20 Z0\nG96 S100 D3000 M3\nG95 F0.1\nG1 Z-5\nX10\n"
                        "G94 F100 G1 Z0\nM2\n", OPTIONS)
    feeds = [c for c in cmds if isinstance(c, Feed)]
    rpm20 = 100_000 / (2 * math.pi * 20)
    assert feeds[0].feed_per_s == pytest.approx(0.1 * rpm20 / 60)
    assert feeds[1].feed_per_s == pytest.approx(0.1 * rpm20 / 60)  # starts at X20
    assert feeds[2].feed_per_s == pytest.approx(100 / 60)
    assert [c.per_rev for c in cmds if isinstance(c, FeedMode)] == [True, False]


def test_facing_with_constant_surface_speed_and_feed_per_revolution():
    lathe = load_machine(ROOT / "examples" / "lathe_xz.toml")
    ctl = Controller(replace(lathe, axes=(*lathe.axes, spindle_axis())))
    ctl.enable_all()
    prog = "G21 G18 G90 G0 X30 Z1\nG96 S150 D2500 M3\nG4 P0.6\nG95 F0.2\nG1 X4\nM5\nM2\n"
    run = ProgramRunner(ctl, prog, options=RunOptions(spindle_axis="spindle",
                                                      spindle_acc_time=0.2),
                        gcode={"parameters": {}})
    x_ax = ctl.axis("x")
    ppu = run.scales.ppu[run.letters.index("X")]
    run.start()
    samples = []
    while run.state is RunState.RUNNING and ctl.time < 30:
        run.wait(0.05)
        assert run.spindle is not None
        samples.append((ctl.time, x_ax.position / ppu, run.spindle.revs_per_s() * 60.0,
                        run.spindle.rpm))
    assert run.state is RunState.DONE, run.error
    checked = 0
    for (t0, x0, rpm0, cmd0), (t1, x1, _r, _c) in zip(samples, samples[1:], strict=False):
        if not 4.5 < x1 < x0 < 29.0:
            continue
        want = min(2500.0, 150_000 / (2 * math.pi * x0))
        # commanded: S / (2 pi x) at the tool's X (updated every 4 cycles, 0.2 % steps)
        assert cmd0 == pytest.approx(want, rel=0.01), (x0, cmd0, want)
        # measured: the spindle follows with its ramp (acc_time 0.2 s) and servo lag
        assert rpm0 == pytest.approx(want, rel=0.05), (x0, rpm0, want)
        # the X feed is 0.2 mm per measured revolution
        assert (x0 - x1) / (t1 - t0) == pytest.approx(0.2 * rpm0 / 60.0, rel=0.06)
        checked += 1
    assert checked > 20
    assert any(x < 9.0 for _t, x, _r, _c in samples)  # D limits it there (2500 rpm)
    assert max(c for _t, _x, _r, c in samples) == pytest.approx(2500.0)
