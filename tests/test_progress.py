"""The `openmotion run` progress line: executed (not queued) work, terminal only."""

import io

from openmotion.control import Controller
from openmotion.program.progress import RunProgress
from openmotion.program.runner import ProgramRunner, RunState

PROGRAM = "G21 G91 G1 X4 F600\nG1 Y4\nG4 P0.2\nG1 X-4\nM2\n"


def _runner():
    ctl = Controller()
    ctl.enable_all()
    return ctl, ProgramRunner(ctl, PROGRAM)


def test_fraction_counts_executed_work_not_the_queue():
    ctl, run = _runner()
    bar = RunProgress(ctl, run, io.StringIO(), force_terminal=True)
    run.start()
    ctl.run_until(lambda: run.current_line == 2, 30)
    mid = bar.fraction()
    assert run.progress >= 0.8  # the moves and the dwell are all in the queue ...
    assert 0.2 < mid < 0.5  # ... but one of three 4 mm moves has run
    fractions = []
    while run.state is RunState.RUNNING:
        ctl.run_until(lambda: run.state is not RunState.RUNNING, 0.1)
        fractions.append(bar.fraction())
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    bar.close()


def test_terminal_shows_line_machine_time_percent_eta():
    ctl, run = _runner()
    out = io.StringIO()
    bar = RunProgress(ctl, run, out, force_terminal=True)
    run.start()
    ctl.run_until(lambda: run.current_line == 4, 30)
    bar.update()
    text = out.getvalue()
    assert "line      4" in text and "machine " in text and "%" in text and "ETA" in text
    bar.close()


def test_silent_when_not_a_terminal():
    ctl, run = _runner()
    out = io.StringIO()
    bar = RunProgress(ctl, run, out)
    assert not bar.enabled
    run.start()
    run.wait(30)
    bar.update()
    bar.status("writing the report ...")
    bar.close()
    assert out.getvalue() == ""


def test_a_long_helix_advances_the_fraction_while_it_runs():
    """A 3-turn helix weighs its whole length (not the 3 mm between its end points), and
    the bar moves on while it runs instead of waiting for the next command."""
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, "G21 G90 G17\nG1 X5 F600\nG3 X5 Y0 Z-3 I-5 J0 P3\nG1 X0\nM2\n")
    bar = RunProgress(ctl, run, io.StringIO(), force_terminal=True)
    run.start()
    assert ctl.run_until(lambda: run.current_line == 3, 30)
    t0, f0 = ctl.time, bar.fraction()
    helix_s = 3 * 2 * 3.141592653589793 * 5.0 / 10.0    # 94 mm at 10 mm/s
    seen = [f0]
    while ctl.time - t0 < helix_s - 0.5:
        ctl.run_until(lambda: False, 1.0)
        seen.append(bar.fraction())
    assert all(b > a for a, b in zip(seen, seen[1:], strict=False))   # moves every second
    assert seen[-1] - f0 > 0.5          # the helix is most of the job: 94 of ~104 mm


def test_the_current_line_never_runs_ahead_of_the_machine():
    """Before the first command starts the runner has queued lines 3..7 already: the line
    shown is the one executing (or the last executed), never the last one queued (it
    showed 7, then 4, 5, 6, 7: the UI's current line jumped forward and back)."""
    import itertools

    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, "(square)\nG21 G90 G17\nG1 F1200 X10 Y0\nG1 X10 Y10\n"
                        "G1 X0 Y10\nG1 X0 Y0\nM0\nG1 X5 Y5\nM30\n")
    seen: list[int] = []
    ctl.add_cycle_hook(lambda c, t: seen.append(run.current_line) if run.running else None)
    run.start()
    assert run.wait(60) and run.state is RunState.PAUSED
    shown = [k for k, _ in itertools.groupby(x for x in seen if x)]
    assert shown == [3, 4, 5, 6], shown
    assert run.current_line == 7            # paused at the M0
