"""M48-M53 at the next segment's start (no stop on a blended path), M52 P1 adaptive feed
from an analog input, and G33/G76/G33.1 outside the operator's feed override, as
LinuxCNC's motion controller runs them (runoverride.py). Virtual time, exact cycles."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.config import default_machine
from openmotion.control.core.controller import Controller
from openmotion.errors import MotionError
from openmotion.program import (
    GCodeError,
    GCodeOptions,
    Message,
    ProgramRunner,
    RunOptions,
    RunState,
    compile_text,
)
from openmotion.program.runoverride import adaptive_factor


def machine() -> Controller:
    ctl = Controller(default_machine())
    ctl.enable_all()
    return ctl


def run_job(text: str, pct: float = 100.0, ctl: Controller | None = None, **opts
            ) -> ProgramRunner:
    ctl = machine() if ctl is None else ctl
    run = ProgramRunner(ctl, text, options=RunOptions(**opts))
    run.set_feed_override(pct)
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    return run


def speeds(run: ProgramRunner) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per cycle: end time, command index executing, path speed (machine units/s)."""
    t, idx, p = run.trace()
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
    return t[1:], idx[1:], v


def events(run: ProgramRunner, *kinds: str) -> list[tuple[float, str]]:
    return [(e.t, e.text) for e in run.events if e.kind in kinds]


# ------------------------------------------------------------------ M48-M53 at segments
BLENDED = "G21 G64 G1 X3 F600\nM50 P0\nG1 X6\nM50 P1\nG1 X9\nM2\n"


def test_m50_switches_at_the_segment_start_without_a_stop():
    run = run_job(BLENDED, 50.0)
    t, idx, v = speeds(run)
    moving = (t > 0.1) & (t < run.t_end - 0.1)
    assert v[moving].min() > 4.9  # never stops (was: a stop at each switch)
    # 50 % (5 mm/s) on the first move, 100 % on the second, 50 % again on the third
    assert v[idx == 0].max() == pytest.approx(5.0)
    assert v[idx == 1].max() == pytest.approx(10.0)
    assert v[(idx == 2) & (t > t[np.argmax(idx == 2)] + 0.1)].max() == pytest.approx(5.0)
    # the switch takes effect in the cycle the group starts that move, at its speed
    starts = [t[np.argmax(idx == k)] for k in (1, 2)]
    sw = events(run, "action")
    assert [txt for _, txt in sw] == ["feed override off", "feed override on"]
    for (te, _), ts in zip(sw, starts, strict=True):
        assert te == pytest.approx(ts, abs=1.5 * run._ctl.period)
    k1 = np.argmax(idx == 1)
    assert v[k1 - 1] == pytest.approx(5.0) and v[k1 + 5] > 5.0  # accelerates in move 1


def test_m50_switch_speed_is_the_same_as_event_driven_cycles():
    # the cycle hook's due wakes at the command's start: virtual-time jumps change nothing
    a = run_job(BLENDED, 50.0)
    ctl = machine()
    ctl.virtual_jumps = False
    b = run_job(BLENDED, 50.0, ctl=ctl)
    assert events(a, "action") == events(b, "action")
    assert a.t_end == b.t_end
    assert np.array_equal(a.trace()[2], b.trace()[2])


def test_switch_with_the_group_at_rest_and_at_the_end():
    run = run_job("M50 P0\nG21 G1 X3 F600\nM50 P1\nM2\n", 50.0)
    texts = events(run, "action")
    assert [x for _, x in texts] == ["feed override off", "feed override on"]
    assert texts[0][0] <= 2 * run._ctl.period  # at once: nothing ran before it
    assert speeds(run)[2].max() == pytest.approx(10.0)  # the move ran at 100 %


def test_spindle_override_switch_before_m3_takes_effect_first():
    from dataclasses import replace

    from openmotion.hw.sim.spindle import spindle_axis

    m = default_machine()
    ctl = Controller(replace(m, axes=(*m.axes, spindle_axis(counts_per_rev=4096))))
    ctl.enable_all()
    run = ProgramRunner(ctl, "G21 G1 X3 F600\nM51 P0\nS600 M3\nG4 P0.01\nM0\nM2\n",
                        options=RunOptions(spindle_axis="spindle"))
    run.set_spindle_override(50.0)
    run.start()
    run.wait(30)
    assert run.state is RunState.PAUSED and run.spindle is not None
    assert run.spindle.rpm == pytest.approx(600.0)


def test_m53_switch_reaches_the_feed_hold_at_its_segment():
    ctl = machine()
    sc = ctl.hardware.scenario
    sc.set_input("di1", True, at=0.1)
    # the input is active from 0.1 s; the switch is off for the first move (it runs on)
    # and on from the second: the path holds where the second move starts
    run = ProgramRunner(ctl, "G21 G64 M53 P0\nG1 X3 F600\nM53 P1\nG1 X6\nM2\n",
                        options=RunOptions(feed_hold_input="di1"))
    run.start()
    ctl.run_until(lambda: run.state is not RunState.RUNNING, 10.0)
    assert run.state is RunState.PAUSED
    assert run.group is not None and run.current_line == 4
    assert events(run, "feed_hold") == [(pytest.approx(events(run, "action")[1][0]),
                                         "feed stop di1 active: holding")]


def test_overrides_refused_under_cutter_compensation():
    with pytest.raises(GCodeError, match="cutter compensation") as info:
        compile_text("G21 G1 X0 Y0 F100\nG41.1 D1\nG1 X10\nM52 P1\nG40 G1 X0\nM2\n",
                     GCodeOptions(axes={"X": 0, "Y": 1}))
    assert info.value.line == 4 and info.value.word == "M52"


# ------------------------------------------------------------------ adaptive feed
def adaptive_run(text: str, values: list[tuple[float, float]], **opts) -> ProgramRunner:
    ctl = machine()
    for at, value in values:
        ctl.hardware.scenario.set_analog_input(0, value, at=at)
    return run_job(text, ctl=ctl, adaptive_feed_input="ai0", **opts)


def window(run: ProgramRunner, a: float, b: float) -> np.ndarray:
    t, _, v = speeds(run)
    return v[(t > a) & (t <= b)]


def test_m52_scales_the_feed_live_and_holds_at_zero():
    run = adaptive_run("G21 G64 M52 P1\nG1 X3 F600\nG1 X6\nM52 P0\nG1 X9\nM2\n",
                       [(0.0, 1.0), (0.2, 0.5), (0.5, 0.0), (0.8, 2.0)])
    assert window(run, 0.1, 0.2) == pytest.approx(10.0)   # 1.0: the programmed feed
    assert window(run, 0.35, 0.5) == pytest.approx(5.0)   # 0.5: half of it, live
    assert window(run, 0.7, 0.8) == pytest.approx(0.0)    # 0: held along the path
    assert window(run, 0.9, 1.0) == pytest.approx(10.0)   # 2.0 clamped to 1 (2.9)
    assert [x for _, x in events(run, "adaptive_feed")] == [
        "adaptive feed ai0 = 0: holding", "adaptive feed: going on"]
    assert events(run, "adaptive_feed")[0][0] == pytest.approx(0.5, abs=2e-3)


def test_m52_p0_ignores_the_input_and_m52_scales_rapids_as_linuxcnc():
    off = run_job("G21 G1 X3 F600\nG0 X0\nM2\n")
    run = adaptive_run("G21 M52 P0\nG1 X3 F600\nG0 X0\nM2\n", [(0.0, 0.25)])
    assert run.t_end - run.t_start == pytest.approx(off.t_end - off.t_start, abs=1e-9)
    # on: the rapid runs at a quarter of its speed too (control.c scales every
    # coordinated move by motion.adaptive-feed)
    run = adaptive_run("G21 M52\nG1 X3 F600\nG0 X0\nM2\n", [(0.0, 0.25)])
    _, idx, v = speeds(run)
    assert v[idx == 0].max() == pytest.approx(2.5)
    rapid = run.op_of[1].feed  # the rapid's speed (machine units/s)
    assert v[idx == 1].max() == pytest.approx(rapid / 4, rel=1e-9)
    assert speeds(off)[2].max() > rapid / 4 + 1.0  # at 100 % it ran faster than that


def test_negative_adaptive_feed_holds_and_says_so():
    run = adaptive_run("G21 M52 P1\nG1 X3 F600\nM2\n", [(0.0, 1.0), (0.1, -0.3),
                                                        (0.4, 1.0)])
    assert window(run, 0.3, 0.4) == pytest.approx(0.0)  # never runs forwards
    assert [x for _, x in events(run, "adaptive_feed")] == [
        "adaptive feed ai0 = -0.3: reverse run is not supported; holding",
        "adaptive feed: going on"]
    assert run.trace()[2][-1, 0] == pytest.approx(3.0)


def test_adaptive_parameter_and_factor():
    text = "(DEBUG, #<_adaptive_feed>)\nM52\n(DEBUG, #<_adaptive_feed>)\nM52 P0\n" \
           "(DEBUG, #<_adaptive_feed>)\nM2\n"
    msgs = [c.text for c in compile_text(text, GCodeOptions(axes={"X": 0}))
            if isinstance(c, Message)]
    assert [float(m) for m in msgs] == [0, 1, 0]
    assert [adaptive_factor(v) for v in (-1.0, 0.0, 0.0004, 0.0006, 0.25, 1.0, 7.0,
                                         float("nan"))] == [0, 0, 0, 0.001, 0.25, 1, 1, 0]


def test_adaptive_feed_input_validated():
    ctl = machine()
    with pytest.raises(MotionError, match="line 2: M52 P1.*adaptive_feed_input"):
        ProgramRunner(ctl, "G21\nM52 P1\nG1 X1 F600\nM2\n")
    for bad in ("di0", "ai", "ai-1", 0, True):
        with pytest.raises(MotionError, match="adaptive_feed_input"):
            RunOptions(adaptive_feed_input=bad)  # type: ignore[arg-type]
    with pytest.raises(MotionError, match="adaptive_feed_input 'ai9'.*channel"):
        ProgramRunner(ctl, "G21 M52\nG1 X1 F600\nM2\n",
                      options=RunOptions(adaptive_feed_input="ai9"))
    ProgramRunner(ctl, "G21 M52 P0\nG1 X1 F600\nM2\n")  # P0 needs no input


# ------------------------------------------------------------------ G33/G76 and overrides
@pytest.mark.parametrize("pct", [50.0, 200.0])
def test_g33_without_spindle_axis_ignores_the_feed_override(pct):
    text = "G21 G64 S600 M3\nG1 X3 F600\nG33 X6 K0.5\nG1 X9\nM2\n"
    run = run_job(text, pct)
    t, idx, v = speeds(run)
    assert v[idx == 1].max() == pytest.approx(5.0)  # pitch x S whatever the override
    assert v[idx == 0].max() == pytest.approx(10.0 * pct / 100.0)
    # LinuxCNC does not blend into position-synchronised motion: a stop before G33
    k1 = np.argmax(idx == 1)
    assert v[k1 - 1] <= 0.1 + 1e-9  # the last cycle of a stop (200 mm/s^2, 1 ms)
    # out of it the path blends on and takes the override back at the next move
    k2 = np.argmax(idx == 2)
    assert v[k2 - 1] == pytest.approx(5.0) and v[idx == 2].max() == pytest.approx(
        10.0 * pct / 100.0)


def test_g76_and_g331_without_spindle_axis_ignore_override_and_adaptive():
    g76 = "G21 S600 M3\nG76 P0.5 Z-3 I-0.5 J0.2 K0.6\nM2\n"
    for pct in (50.0, 200.0):
        run = run_job(g76, pct)
        _, idx, v = speeds(run)
        synced = [i for i, op in run.op_of.items() if type(op.source).__name__ ==
                  "SyncedFeed"]
        assert synced and max(v[idx == i].max() for i in synced) == pytest.approx(5.0)
    tap = "G21 S600 M3\nM52\nG33.1 Z-3 K0.5\nM2\n"
    base = run_job(tap.replace("M52\n", ""))
    run = adaptive_run(tap, [(0.0, 0.5)])
    assert run.t_end - run.t_start == pytest.approx(base.t_end - base.t_start, abs=1e-9)
    held = adaptive_run(tap, [(0.0, 0.0)])  # 0 does not hold a synchronised move
    assert held.t_end - held.t_start == pytest.approx(base.t_end - base.t_start, abs=1e-9)
