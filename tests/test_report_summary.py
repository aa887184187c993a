"""The run summary's following-error lines and the contour error of the ACTUAL positions
(what the machine did), against independent computations from the runner's trace."""

from __future__ import annotations

import re

import numpy as np
import pytest

from contour_oracle import loop_contour_errors
from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.control import Controller
from openmotion.program import canon, report
from openmotion.program.runner import RunState, run_program

ARC = "G21 G90 G64 G1 X5 Y2 F1200\nG2 X9 Y2 R2\nG1 Y-1\nM2\n"
# 30 collinear 0.1 mm cuts: a 20 Hz servo trails about 0.29 mm, three cuts behind
STRAIGHT = "G21 G90 G64\n" + "".join(f"G1 X{0.1 * i:.1f} F1200\n" for i in range(1, 31)) \
    + "M2\n"


def _run(program: str, servo: bool):
    kw = {"drive": DriveConfig(type="servo", bandwidth_hz=20.0)} if servo else {}
    axes = (AxisConfig(name="x", lead=10.0, max_speed=200.0, **kw),
            AxisConfig(name="y", lead=5.0, max_speed=200.0, **kw),
            AxisConfig(name="z", lead=10.0, max_speed=200.0))
    ctl = Controller(MachineConfig(name="servo" if servo else "stepper", axes=axes))
    ctl.enable_all()
    run = run_program(ctl, program, timeout=60)
    assert run.state is RunState.DONE
    return run


def _programmed_polyline(step: float = 2e-4) -> np.ndarray:
    """ARC's programmed XY path, densely sampled (independent of the report's geometry)."""
    pts = [np.column_stack([np.linspace(0, 5, 25001), np.linspace(0, 2, 25001)])]
    # G2 X9 Y2 R2 from (5,2): centre (7,2), clockwise over the top
    a = np.linspace(np.pi, 0.0, int(np.pi * 2 / step))
    pts.append(np.column_stack([7 + 2 * np.cos(a), 2 + 2 * np.sin(a)]))
    pts.append(np.column_stack([np.full(15001, 9.0), np.linspace(2, -1, 15001)]))
    return np.concatenate(pts)


def test_summary_has_the_largest_following_error_of_each_moving_axis():
    run = _run(ARC, servo=True)
    s = report.summarize(run)
    t, idx, cmd = run.trace()
    fe = np.abs(cmd - run.actual_trace())
    assert [f.letter for f in s.following] == ["X", "Y"]  # Z does not move
    for f, k in zip(s.following, (0, 1), strict=True):
        w = int(np.argmax(fe[:, k]))
        assert f.max_error == fe[w, k] > 0.2          # the 20 Hz servo lags ~0.29 mm
        assert f.line == run.line_of(int(idx[w])) and f.line in (1, 2, 3)
        assert f.time == pytest.approx(t[w] - run.t_start)
    text = report.format_summary(s)
    for f in s.following:
        assert re.search(rf"^following {f.letter} +{f.max_error:.6f} mm max \(line {f.line}\)",
                         text, re.M)
    assert "following Z" not in text and "within one count" not in text


def test_contour_error_is_measured_on_the_actual_positions():
    run = _run(ARC, servo=True)
    err, idx = report.contour_errors(run, actual=True)
    cmd_err, _ = report.contour_errors(run)
    act = run.actual_trace()
    # the oracle: distance of each actual point to the densely sampled programmed path
    # (this path never comes back near itself, so the nearest point is the right one)
    poly = _programmed_polyline()
    sel = np.nonzero(np.isfinite(err))[0]
    near = np.array([np.min(np.hypot(*(poly - act[i, :2]).T)) for i in sel[::7]])
    np.testing.assert_allclose(err[sel[::7]], near, atol=2e-4)
    s = report.summarize(run)
    assert s.max_contour_error == pytest.approx(np.nanmax(err))
    assert s.commanded_contour_error == pytest.approx(np.nanmax(cmd_err))
    assert s.max_contour_error > 10 * s.commanded_contour_error  # the servo cuts the arc
    assert ", actual positions" in report.format_summary(s)


def test_actual_positions_trailing_several_short_cuts_are_on_the_contour(monkeypatch):
    run = _run(STRAIGHT, servo=True)
    s = report.summarize(run)
    assert s.following[0].max_error > 0.25   # about three 0.1 mm cuts behind
    assert s.max_contour_error < 1e-9        # but always on the programmed line
    # compared with the executing command and its neighbours only, the lag would count
    monkeypatch.setattr(report, "_lag_cycles", lambda *a: 0)
    assert np.nanmax(report.contour_errors(run, actual=True)[0]) > 0.1


def test_on_an_ideal_stepper_actual_and_commanded_differ_by_the_count_only():
    run = _run(ARC, servo=False)
    s = report.summarize(run)
    t, idx, cmd = run.trace()
    assert report._lag_cycles(t, cmd, run.actual_trace()) == 0
    count = 1.0 / np.abs(run.scales.ppu)
    assert all(f.max_error <= count[0 if f.letter == "X" else 1] for f in s.following)
    assert all(f.count == count[0 if f.letter == "X" else 1] for f in s.following)
    text = report.format_summary(s)
    assert text.count(", within one count") == len(s.following) == 2
    assert s.max_contour_error <= s.commanded_contour_error + float(np.max(count))


def test_report_marks_the_worst_contour_error_where_the_machine_was(tmp_path):
    run = _run(ARC, servo=True)
    html = report.write_report(run, tmp_path, "servo").read_text()
    err, idx = report.contour_errors(run, actual=True)
    w = int(np.nanargmax(err))
    assert f"worst contour error {err[w]:.4g} mm (line {run.line_of(int(idx[w]))}, " \
        "actual position)" in html
    assert '"name":"actual (feedback)"' in html.replace(": ", ":")
    assert "contour error (actual positions)" in html and "commanded positions" in html


def test_an_aborted_run_is_traced_until_the_axes_are_at_rest():
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, "G21 G90 G1 X100 F3000\nM2\n")
    run.start()
    assert ctl.run_until(lambda: ctl.time - run.t_start > 0.5, 10)
    run.abort()                                  # a decelerating stop along the path
    t_abort = run.t_end
    x = ctl.axis("x")
    assert x.is_moving
    assert ctl.run_until(lambda: not x.is_moving, 10)
    t, idx, pos = run.trace()
    assert t[-1] > t_abort + 0.01                # the stop is in the trace ...
    assert pos[-1, 0] == pytest.approx(x.position / run.scales.ppu[0])   # ... to rest
    assert idx[-1] == idx[np.searchsorted(t, t_abort)]   # as part of the aborted line
    n = len(t)
    t_more = ctl.time + 0.2
    ctl.run_until(lambda: ctl.time >= t_more, 1)
    assert len(run.trace()[0]) == n              # and stops there
    s = report.summarize(run)
    assert s.state == "aborted" and s.run_time == pytest.approx(t[-1] - run.t_start)


# arcs in the three planes, a multi-turn helix, a slight spiral, G0 between G64 P cuts
MIXED = ("G21 G90 G64 P0.01\nG0 X1 Y1\nG1 X6 Y1 F1500\nG3 X10 Y5 I0 J4\nG18 G2 X14 Z-4 I4 K0\n"
         "G19 G3 Y9 Z0 J4 K0\nG17 G2 X10 Y9 Z-3 I-2 J0 P2\nG1 X8.0005 Y9.0005\nG0 X2 Y2\n"
         "G1 X2 Y6\nG2 X2 Y6 I2 J0\nM2\n")


@pytest.mark.parametrize("program, servo", [(ARC, True), (STRAIGHT, True), (MIXED, False),
                                            (MIXED, True)])
def test_vectorised_contour_errors_equal_the_command_by_command_oracle(program, servo):
    run = _run(program, servo)
    if program is MIXED:   # the oracle's every branch: three planes, part/whole/multi-turn
        arcs = [o.source for o in run.ops if isinstance(o.source, canon.ArcMove)]
        assert {a.plane for a in arcs} == {(0, 1), (2, 0), (1, 2)}
        assert min(a.sweep for a in arcs) < 3 and max(a.sweep for a in arcs) > 7
    for actual in (False, True):
        err, idx = report.contour_errors(run, actual=actual)
        want, widx = loop_contour_errors(run, actual=actual)
        np.testing.assert_array_equal(idx, widx)
        np.testing.assert_array_equal(np.isnan(err), np.isnan(want))
        np.testing.assert_allclose(err, want, rtol=0, atol=1e-12)
