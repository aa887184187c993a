"""The runner's trace holds the actual (feedback) position of every cycle beside the
commanded one: the simulator's encoder at each cycle end, the same whether virtual time
jumps over cycles (jump observers) or runs them one by one."""

from __future__ import annotations

import re

import numpy as np

from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.control import Controller
from openmotion.program.runner import RunState, run_program

PROG = "G21 G90 G1 X5 Y2 F1200\nG4 P0.3\nG2 X9 Y2 R2\nG1 Y-1\nM2\n"


def _ctl(jumps: bool) -> Controller:
    servo = DriveConfig(type="servo", bandwidth_hz=20.0)
    axes = (AxisConfig(name="x", lead=10.0, max_speed=200.0, drive=servo),
            AxisConfig(name="y", lead=5.0, max_speed=200.0, drive=servo),
            AxisConfig(name="z", lead=10.0, max_speed=200.0))
    ctl = Controller(MachineConfig(name="servo", axes=axes))
    ctl.virtual_jumps = jumps
    ctl.enable_all()
    return ctl


def _run(jumps: bool):
    ctl = _ctl(jumps)
    enc = {}  # the simulator's raw encoder at each cycle end (a hook: every cycle runs)
    crossed = []  # cycles jumps crossed
    if jumps:
        ctl.add_jump_observer(lambda c, first, last, p, a: crossed.append(last - first + 1))
    else:
        ctl.add_cycle_hook(lambda c, t: enc.__setitem__(
            round(t / c.period), [c.axes[a].counters.encoder_raw() for a in range(3)]))
    n0 = ctl.cycles
    run = run_program(ctl, PROG, timeout=60)
    assert run.state is RunState.DONE
    return ctl, run, enc, ctl.cycles - n0, sum(crossed)


def test_actual_is_the_encoder_at_each_cycle_end_and_jumps_change_nothing():
    ctl_ref, ref, enc, n_ref, _ = _run(False)
    ctl, fast, _, n_fast, crossed = _run(True)
    t, idx, cmd = ref.trace()
    act = ref.actual_trace()
    ppu = ref.scales.ppu
    assert act.shape == cmd.shape and len(t) > 500
    # cycle by cycle: the encoder (pulses, move ratio 1, no offsets) at each cycle end
    k = np.round(t / ctl_ref.period).astype(int)
    want = np.array([enc[i] for i in k], dtype=float)
    np.testing.assert_array_equal(act, want / ppu)
    # the servos lag: a real following error while moving, none at the end
    err = cmd - act
    assert np.max(np.abs(err[:, 0])) > 0.01 and np.max(np.abs(err[:, 1])) > 0.01
    assert np.all(err[:, 2] == 0.0)
    # jumping over the dwell and the settling gives the same rows
    t2, idx2, cmd2 = fast.trace()
    np.testing.assert_array_equal(t2, t)
    np.testing.assert_array_equal(idx2, idx)
    np.testing.assert_array_equal(cmd2, cmd)
    np.testing.assert_array_equal(fast.actual_trace(), act)
    assert n_fast == n_ref and crossed > 100  # the fast run did jump


def test_report_plots_the_following_error_of_each_moving_axis(tmp_path):
    from openmotion.program.report import following_errors, write_report

    _, run, _, _, _ = _run(True)
    fe = following_errors(run)
    np.testing.assert_array_equal(fe, run.trace()[2] - run.actual_trace())
    html = write_report(run, tmp_path, "servo").read_text()
    assert "<h2>Following error</h2>" in html
    start = html.index("<h2>Following error</h2>")
    section = html[start:html.index("<h2>", start + 5)]
    names = re.findall(r'"name":\s*"([^"]*)"', section)
    assert names == ["X (mm)", "Y (mm)"]  # Z does not move
