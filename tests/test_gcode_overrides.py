"""M48-M53: the program switches the operator's feed / spindle overrides (overrides.py,
runoverride.py): the records, the refusals, rs274's canon calls, the effect on motion time
and spindle speed."""

from __future__ import annotations

import re
from dataclasses import replace

import pytest

from openmotion.config import default_machine
from openmotion.control.core.controller import Controller
from openmotion.errors import MotionError
from openmotion.hw.sim.spindle import spindle_axis
from openmotion.program import (
    GCodeError,
    GCodeOptions,
    ProgramRunner,
    RunOptions,
    RunState,
    compile_text,
)
from openmotion.program.overrides import OverrideSwitch

XZ = GCodeOptions(axes={"X": 0, "Z": 2})
SWITCHES = "M49\nM48\nM50 P0\nM50\nM51 P0\nM51 P1\nM50 P1\nM53 P0\nM53\nM52\nM52 P0\nM52 P1\n"


def switches(text: str) -> list[tuple[bool | None, bool | None]]:
    return [(c.feed, c.spindle) for c in compile_text(text, XZ)
            if isinstance(c, OverrideSwitch) and c.feed_hold is None and c.adaptive is None]


def test_records_of_each_word():
    assert switches(SWITCHES) == [(False, False), (True, True), (False, None), (True, None),
                                  (None, False), (None, True), (True, None)]


def test_the_same_switches_as_rs274():
    lcnc = pytest.importorskip("lcnc_oracle")
    exe = lcnc.rs274_path()
    if exe is None:
        pytest.skip("LinuxCNC rs274 is not installed")
    res = lcnc.run_rs274("G21\n" + SWITCHES + "M2\n", exe)
    assert res.error is None
    calls = re.findall(r"(ENABLE|DISABLE)_(FEED_OVERRIDE|SPEED_OVERRIDE|FEED_HOLD|"
                       r"ADAPTIVE_FEED)", res.listing)
    assert calls[-3:] == [("ENABLE", "ADAPTIVE_FEED"), ("DISABLE", "ADAPTIVE_FEED"),
                          ("ENABLE", "ADAPTIVE_FEED")]
    ours = []
    for c in compile_text(SWITCHES, XZ):
        if isinstance(c, OverrideSwitch):
            for on, what in ((c.feed, "FEED_OVERRIDE"), (c.spindle, "SPEED_OVERRIDE"),
                             (c.feed_hold, "FEED_HOLD"), (c.adaptive, "ADAPTIVE_FEED")):
                if on is not None:
                    ours.append(("ENABLE" if on else "DISABLE", what))
    assert ours == calls


@pytest.mark.parametrize("line, word, msg", [
    ("M50 P2", "P2", "P must be 0"),
    ("M51 P-1", "P-1", "P must be 0"),
    ("M52 P0.5", "P0.5", "P must be 0"),
    ("M53 P3", "P3", "P must be 0"),
    ("M48 M50", "M50", "same modal group"),
])
def test_refusals_name_line_column_word(line, word, msg):
    with pytest.raises(GCodeError, match=msg) as info:
        compile_text(f"G21\nG1 X1 F100\n{line}\nM2\n", XZ)
    assert info.value.line == 3 and info.value.word == word


def machine(spindle: bool = False) -> Controller:
    m = default_machine()
    if spindle:
        m = replace(m, axes=(*m.axes, spindle_axis(counts_per_rev=4096)))
    ctl = Controller(m)
    ctl.enable_all()
    return ctl


def run_time(text: str, feed_pct: float = 100.0, **opts) -> float:
    ctl = machine()
    run = ProgramRunner(ctl, text, options=RunOptions(**opts))
    run.set_feed_override(feed_pct)
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    return run.t_end - run.t_start


def test_feed_override_honoured_or_ignored():
    move = "G21 G1 X6 F600\nM2\n"
    base = run_time(move)
    # 6 mm at 5 instead of 10 mm/s: 0.6 s more (less half a ramp: the path acceleration
    # is the same, so the ramp to half the speed is half as long)
    assert run_time(move, 50.0) - base == pytest.approx(0.6, abs=0.05)
    assert run_time("M50 P0\n" + move, 50.0) == pytest.approx(base, abs=1e-9)
    assert run_time("M49\n" + move, 50.0) == pytest.approx(base, abs=1e-9)
    # off for the middle move only: the two others (3 mm each) take 0.3 s longer each
    three = "G21 G1 X3 F600\nM50 P0\nG1 X6\nM50 P1\nG1 X9\nM2\n"
    assert run_time(three, 50.0) - run_time(three) == pytest.approx(0.6, abs=0.06)
    # a pass that ended with the override off: the next pass starts with it on again
    two = run_time("G21 G1 X3 F600\nM50 P0\nG0 X0\nM2\n", 50.0, repeat=2)
    one = run_time("G21 G1 X3 F600\nM50 P0\nG0 X0\nM2\n", 50.0)
    assert two == pytest.approx(2 * one, rel=0.02)


def test_feed_override_changed_while_running_and_checked():
    ctl = machine()
    run = ProgramRunner(ctl, "G21 G1 X6 F600\nM2\n")
    run.start()
    ctl.run_until(lambda: False, 0.2)
    run.set_feed_override(200.0)
    assert run.group is not None and run.group.override == 200.0
    run.wait(60)
    assert run.state is RunState.DONE
    for bad in (0.5, 201, float("nan"), True, "50"):
        with pytest.raises(MotionError, match="override"):
            run.set_feed_override(bad)  # type: ignore[arg-type]
    assert run.feed_override == 200.0


def test_spindle_override_scales_s_unless_m51_p0():
    def rpm_after(text: str) -> float:
        ctl = machine(spindle=True)
        run = ProgramRunner(ctl, text, options=RunOptions(spindle_axis="spindle"))
        run.set_spindle_override(50.0)
        run.start()
        run.wait(30)  # to the M0 (M2 would stop the spindle)
        assert run.state is RunState.PAUSED, run.error
        assert run.spindle is not None
        return run.spindle.rpm

    assert rpm_after("S600 M3\nG4 P0.01\nM0\nM2\n") == pytest.approx(300.0)
    assert rpm_after("M51 P0\nS600 M3\nG4 P0.01\nM0\nM2\n") == pytest.approx(600.0)
    # switched back on while turning: the speed changes at once
    assert rpm_after("M49\nS600 M3\nG4 P0.01\nM48\nG4 P0.01\nM0\nM2\n") == \
        pytest.approx(300.0)


def test_predefined_parameters_read_the_switches():
    from openmotion.program import Message

    show = "(DEBUG, #<_feed_override> #<_speed_override> #<_feed_hold>)\n"
    text = (show + "M50 P0\n" + show + "M49\nM53 P0\n" + show + "M48\nM53\n" + show
            + "M2\n")
    msgs = [c.text for c in compile_text(text, XZ) if isinstance(c, Message)]
    assert [[float(x) for x in m.split()] for m in msgs] == [
        [1, 1, 1], [0, 1, 1], [0, 0, 0], [1, 1, 1]]


def test_cli_feed_override_and_m50_p0(tmp_path, capsys):
    from openmotion.cli import main

    def run_time_cli(text: str, *flags: str) -> float:
        p = tmp_path / "job.ngc"
        p.write_text(text)
        assert main(["run", str(p), "--out", str(tmp_path), *flags]) == 0
        return float(capsys.readouterr().out.split("run time")[1].split()[0])

    job = "G21 G91 G1 X3 F600\nM2\n"
    base = run_time_cli(job)
    assert run_time_cli(job, "--feed-override", "50") - base == pytest.approx(0.3, abs=0.05)
    assert run_time_cli("M50 P0\n" + job, "--feed-override", "50") == \
        pytest.approx(base, abs=2e-3)
    p = tmp_path / "job.ngc"
    assert main(["run", str(p), "--out", str(tmp_path), "--spindle-override", "0"]) == 2
    assert "--spindle-override" in capsys.readouterr().err


def test_g95_feeds_follow_the_feed_override():
    def g95_time(pct: float, prefix: str = "") -> float:
        ctl = machine(spindle=True)
        run = ProgramRunner(ctl, prefix + "G21 S600 M3\nG4 P0.5\nG95 G1 X3 F1\nM2\n",
                            options=RunOptions(spindle_axis="spindle"))
        run.set_feed_override(pct)
        run.start()
        run.wait(30)
        assert run.state is RunState.DONE, run.error
        return run.t_end - run.t_start

    base = g95_time(100.0)  # 1 mm per revolution at 10 rev/s: 0.3 s for the 3 mm
    assert g95_time(50.0) - base == pytest.approx(0.3, abs=0.05)
    assert g95_time(50.0, "M50 P0\n") == pytest.approx(base, abs=5e-3)


def test_m53_feed_stop_input_holds_the_path_unless_switched_off():
    def held_run(text: str, **opts) -> tuple[float, list[str]]:
        ctl = machine()
        sc = ctl.hardware.scenario
        sc.set_input("di1", True, at=0.2)
        sc.set_input("di1", False, at=0.8)
        run = ProgramRunner(ctl, text, options=RunOptions(**opts))
        run.start()
        ctl.run_until(lambda: run.state in (RunState.DONE, RunState.ERROR), 10.0)
        assert run.state is RunState.DONE, run.error
        return run.t_end - run.t_start, [e.text for e in run.events
                                         if e.kind == "feed_hold"]

    job = "G21 G1 X6 F600\nM2\n"
    base, none = held_run(job)  # no feed_hold_input: no switch
    assert none == []
    t, texts = held_run(job, feed_hold_input="di1")
    assert texts == ["feed stop di1 active: holding", "feed stop di1 released"]
    assert t - base == pytest.approx(0.6, abs=0.12)  # held 0.6 s (+ the ramps)
    t_off, none = held_run("M53 P0\n" + job, feed_hold_input="di1")
    assert none == [] and t_off == pytest.approx(base, abs=2e-3)
    with pytest.raises(MotionError, match="feed_hold_input"):
        RunOptions(feed_hold_input="X1")
