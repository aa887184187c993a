"""Running G-code programs on the simulated machine (virtual time): positions, arcs in all
planes, units, offsets, outputs, pause/resume/abort/single-block, repeat, bad input."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.program import GCodeError
from openmotion.program.report import contour_errors, summarize
from openmotion.program.runner import ProgramRunner, RunOptions, RunState, run_program


def iso_ctl(n: int = 3) -> Controller:
    """Equal scales (1000 pulses/mm), no switches."""
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xyz"[:n])
    ctl = Controller(MachineConfig(name="iso", axes=axes, digital_outputs=8))
    ctl.enable_all()
    return ctl


def units(run: ProgramRunner) -> np.ndarray:
    return run._positions() / run.scales.ppu


def test_lines_end_exactly_and_feed_is_respected():
    ctl = iso_ctl()
    run = run_program(ctl, "G21 G90 G1 X10 Y5 F600\nG1 Z-2\nG0 X0 Y0\nM2", timeout=60)
    assert run.state is RunState.DONE
    assert np.array_equal(units(run), [0.0, 0.0, -2.0])
    t, idx, p = run.trace()
    feed = [k for k, o in run.op_of.items() if not o.rapid]
    sel = np.isin(idx, feed)
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
    assert v[sel[1:]].max() <= 10.0 * (1 + 1e-6)   # 600 mm/min
    assert v[sel[1:]].max() > 9.9


@pytest.mark.parametrize("plane,code,axes", [((0, 1), "G17", "XY"), ((2, 0), "G18", "ZX"),
                                             ((1, 2), "G19", "YZ")])
def test_arc_in_each_plane_lies_on_circle(plane, code, axes):
    ctl = iso_ctl()
    a, b = axes
    prog = f"G21 G90 {code}\nG1 {a}10 F1200\nG3 {a}-10 R10\nM2"
    if code == "G17":
        prog = "G21 G90 G17\nG1 X10 F1200\nG3 X-10 Y0 I-10 J0\nM2"
    run = run_program(ctl, prog, timeout=60)
    assert run.state is RunState.DONE
    end = units(run)
    assert end[plane[0]] == pytest.approx(-10.0, abs=1e-9)
    t, idx, p = run.trace()
    arc_idx = [k for k, o in run.op_of.items() if o.kind == "arc"]
    assert arc_idx, "an equal-scale arc runs as one group arc"
    sel = np.isin(idx, arc_idx)
    r = np.hypot(p[sel, plane[0]], p[sel, plane[1]])
    assert np.max(np.abs(r - 10.0)) < 1e-3
    # CCW from the first plane axis to the second: the second coordinate goes positive
    assert p[sel, plane[1]].max() > 9.0
    err, _ = contour_errors(run)
    assert np.nanmax(err) < 1e-3


def xyzu_ctl() -> Controller:
    ctl = Controller()  # XYZU table: x 1000, y 2000 pulses/mm
    ctl.enable_all()
    return ctl


def test_anisotropic_machine_runs_true_arcs():
    """Mixed pulse scales: the group works in mm, so the arc is one true group arc."""
    ctl = xyzu_ctl()
    run = run_program(ctl, "G21 G90 G64 P0.001\nG1 X20 Y10 F1200\nG2 X30 Y10 I5 J0\nM2",
                      timeout=60)
    assert run.state is RunState.DONE
    assert np.allclose(units(run)[:2], [30.0, 10.0], atol=1e-9)
    assert [o.kind for o in run.ops if o.kind in ("line", "arc")] == ["line", "arc"]
    t, idx, p = run.trace()
    sel = np.isin(idx, [k for k, o in run.op_of.items() if o.kind == "arc"])
    sel &= np.hypot(p[:, 0] - 20.0, p[:, 1] - 10.0) > 0.05  # past the G64 P corner blend
    assert np.max(np.abs(np.hypot(p[sel, 0] - 25.0, p[sel, 1] - 10.0) - 5.0)) < 1e-6
    assert summarize(run).commanded_contour_error < 0.001 + 1e-6


def _cruise_speeds(run: ProgramRunner, kind: str) -> np.ndarray:
    """Vector speed (machine units/s) per cycle inside moves of `kind`, accel/decel ends
    dropped (cycles whose speed is below 99.9 % of the top speed)."""
    t, idx, p = run.trace()
    sel = np.isin(idx, [k for k, o in run.op_of.items() if o.kind == kind and not o.rapid])
    v = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1) / np.diff(t)
    v = v[sel[1:] & sel[:-1]]
    return v[v > 0.999 * v.max()]


@pytest.mark.parametrize("prog,kind", [
    ("G21 G90 G1 X40 Y40 F1200\nM2", "line"),                      # 45 degrees in XY
    ("G21 G90 G1 X20 F6000\nG1 X30 F1200\nG3 X10 Y0 I-10 J0\nM2", "arc"),   # half circle
])
def test_vector_speed_equals_f_on_the_xyzu_table(prog, kind):
    """x has 1000, y 2000 pulses/mm: the tool still moves at exactly F (20 mm/s) along the
    45-degree line and around the arc (the old pulse-space feed gave F/2 along y)."""
    ctl = xyzu_ctl()
    run = run_program(ctl, prog, timeout=60)
    assert run.state is RunState.DONE
    v = _cruise_speeds(run, kind)
    assert len(v) > 10
    assert v.max() <= 20.0 * (1 + 1e-6)
    assert v.min() >= 20.0 * (1 - 1e-3)  # chord of a cycle on the arc: slightly shorter
    if kind == "arc":
        t, idx, p = run.trace()
        sel = np.isin(idx, [k for k, o in run.op_of.items() if o.kind == "arc"])
        assert np.max(np.abs(np.hypot(p[sel, 0] - 20.0, p[sel, 1]) - 10.0)) < 1e-6


@pytest.mark.parametrize("mode,linear_speed", [("uniform", 10.0 * 10 / math.hypot(10, 30)),
                                               ("exact", 10.0)])
def test_feed_mode_on_a_linear_plus_rotary_move(mode, linear_speed):
    """G1 X10 A30 F600: "uniform" runs the mm+deg vector at F, "exact" the X part at F."""
    ctl = xyzu_ctl()
    run = run_program(ctl, "G21 G90 G1 X10 A30 F600\nM2", timeout=60,
                      options=RunOptions(feed_mode=mode))
    assert run.state is RunState.DONE
    assert units(run)[run.letters.index("A")] == pytest.approx(30.0, abs=1e-9)
    t, idx, p = run.trace()
    vx = np.diff(p[:, 0]) / np.diff(t)
    assert vx.max() == pytest.approx(linear_speed, rel=1e-6)


def test_spiral_arc_end_is_sent_as_chords_within_tolerance():
    """An end point off the circle (LinuxCNC tolerates it) cannot be a group arc: chords."""
    ctl = iso_ctl()
    run = run_program(ctl, "G21 G90 G1 X10 F1200\nG3 X-10.0005 Y0 I-10 J0\nM2", timeout=60,
                      options=RunOptions(chord_tol=0.002))
    assert run.state is RunState.DONE
    assert units(run)[0] == pytest.approx(-10.0005, abs=1e-9)
    assert sum(o.kind == "line" for o in run.ops) > 10
    assert not any(o.kind == "arc" for o in run.ops)
    assert summarize(run).commanded_contour_error < 0.002 + 1e-3


def test_inch_units_and_work_offset():
    ctl = iso_ctl()
    run = run_program(ctl, "G20 G90 G1 X1 F1000\nM2", timeout=60,
                      gcode={"parameters": {5221: 5.0}})
    assert run.state is RunState.DONE
    assert units(run)[0] == pytest.approx(30.4, abs=1e-9)


def test_inch_feed_is_converted():
    ctl = iso_ctl()
    run = ProgramRunner(ctl, "G20\nG90 G1 X1 F60\nM2")
    assert run.ops[0].feed == pytest.approx(25.4)  # F60 inch/min = 25.4 mm/s
    # F on the G20 line is read before the unit change (LinuxCNC): 60 mm/min
    run = ProgramRunner(ctl, "G20 G90 G1 X1 F60\nM2")
    assert run.ops[0].feed == pytest.approx(1.0)


def test_synced_output_fires_with_next_motion_and_immediate_at_once():
    ctl = iso_ctl()
    prog = "G21 G90 G1 X5 F600\nM64 P1\nM62 P2\nG1 X10\nM63 P2\nG1 X12\nM2"
    run = run_program(ctl, prog, timeout=60)
    ev = {(e.index, e.level): e for e in run.events if e.index is not None}
    assert set(ev) == {(1, True), (2, True), (2, False)}
    # M64 once the first move has ended (LinuxCNC waits for it); M62 when X10 starts
    t, idx, p = run.trace()
    k1 = int(np.searchsorted(t, ev[(1, True)].t))
    assert p[k1, 0] == pytest.approx(5.0, abs=1e-9)  # the X5 move is over
    assert ev[(1, True)].t <= ev[(2, True)].t
    t_start_2 = ev[(2, True)].t
    k = int(np.searchsorted(t, t_start_2))
    assert p[k, 0] == pytest.approx(5.0, abs=0.02)


def test_pause_resume_and_abort():
    ctl = iso_ctl()
    run = ProgramRunner(ctl, "G21 G90 G1 X50 F600\nG1 Y20\nM2")
    run.start()
    ctl.advance(1.0)
    run.pause()
    ctl.advance(1.0)
    x_held = units(run)[0]
    ctl.advance(1.0)
    assert units(run)[0] == x_held and 0 < x_held < 50
    run.resume()
    assert run.wait(60)
    assert run.state is RunState.DONE
    assert np.allclose(units(run)[:2], [50, 20])

    ctl2 = iso_ctl()
    run2 = ProgramRunner(ctl2, "G21 G90 G1 X50 F600\nG1 Y20\nM2")
    run2.start()
    ctl2.advance(1.0)
    run2.abort()
    ctl2.advance(2.0)
    assert run2.state is RunState.ABORTED
    x = units(run2)
    assert 0 < x[0] < 50 and x[1] == 0.0
    assert not any(a.is_moving for a in ctl2.axes)


def test_single_block_and_m0():
    ctl = iso_ctl()
    run = ProgramRunner(ctl, "G21 G90 G1 X1 F600\nG1 X2\nM0\nG1 X3\nM2",
                        options=RunOptions(single_block=True))
    run.start()
    stops = []
    for _ in range(6):
        ctl.run_until(lambda: run.state is not RunState.RUNNING, 30)
        if run.state is not RunState.PAUSED:
            break
        stops.append(round(float(units(run)[0]), 9))
        run.resume()
    assert run.state is RunState.DONE
    assert stops[:2] == [1.0, 2.0] and 3.0 not in stops[:-1]


def test_repeat_runs_n_passes_and_current_line():
    ctl = iso_ctl()
    run = ProgramRunner(ctl, "G21 G91 G1 X2 F600\nG1 X1\nM2",  # relative: no return
                        options=RunOptions(repeat=3))
    run.start()
    lines = set()
    ctl.run_until(lambda: (lines.add(run.current_line), run.state)[1]
                  is not RunState.RUNNING, 60)
    assert run.state is RunState.DONE and run.passes_done == 3
    assert units(run)[0] == pytest.approx(9.0)
    assert {1, 2} <= lines


def test_bad_program_moves_nothing():
    ctl = iso_ctl()
    with pytest.raises(GCodeError, match="line 3"):
        ProgramRunner(ctl, "G21 G90 G1 X1 F600\nG1 X2\nG1 X3 Q\nM2")
    with pytest.raises(GCodeError):
        ProgramRunner(ctl, "G1 X1\nM2")  # no feed
    default = Controller()
    default.enable_all()
    with pytest.raises(GCodeError, match="soft limit"):
        ProgramRunner(default, "G21 G90 G1 X-40 F600\nM2")  # past the MEL switch
    assert all(a.position == 0.0 for a in ctl.axes + default.axes)


def test_bad_arguments():
    ctl = iso_ctl()
    with pytest.raises(MotionError):
        RunOptions(repeat=0)
    with pytest.raises(MotionError):
        RunOptions(feed_mode="fast")
    with pytest.raises(MotionError):
        ProgramRunner(ctl, 42)  # type: ignore[arg-type]
    with pytest.raises(MotionError):
        ProgramRunner(ctl, "G0 X1", axes={"Q": 0})
    run = ProgramRunner(ctl, "G0 X1\nM2")
    with pytest.raises(MotionError):
        run.resume()


def test_window_streams_a_long_program():
    ctl = iso_ctl()
    text = "G21 G90 G64 P0.01 F3000\n" + "\n".join(
        f"G1 X{10 * math.cos(k / 20):.4f} Y{10 * math.sin(k / 20):.4f}" for k in range(400)) \
        + "\nM2\n"
    run = ProgramRunner(ctl, text, options=RunOptions(window=64))
    run.start()
    ql = []
    # the queue grows only when the runner's hook pushes, in a cycle that runs (after it):
    # the observer need not keep every cycle (due inf: time may jump between its calls)
    ctl.add_cycle_hook(lambda c, t: ql.append(run.group.queue_length if run.group and
                                              run.state is RunState.RUNNING else 0),
                       due=lambda c: math.inf)
    assert run.wait(300)
    assert run.state is RunState.DONE and max(ql) <= 64
    end = units(run)
    assert end[0] == pytest.approx(10 * math.cos(399 / 20), abs=1e-4)


def _g1_speeds(run: ProgramRunner, first_line: int, last_line: int) -> np.ndarray:
    """Path speed (machine units/s) per cycle while commands of lines first..last run."""
    t, idx, p = run.trace()
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
    lines = np.array([run.line_of(int(i)) for i in idx])
    inside = np.nonzero((lines >= first_line) & (lines <= last_line))[0]
    k0, k1 = int(inside[0]), int(inside[-1])
    # cycles strictly between the first move's start and the last move's end
    return v[k0 + 1:k1 - 1]


def test_cam_example_streams_without_resting():
    """The 4,000-segment CAM file runs as one blended chain: the path speed never drops to
    zero between the first and the last G1 (it used to re-plan per pushed command)."""
    from pathlib import Path

    from longrun import long_run
    from openmotion.program.runjob import work_origin

    ctl = Controller()
    ctl.enable_all()
    path = Path(__file__).parents[1] / "examples" / "programs" / "cam_rose.ngc"
    if long_run():
        text = path.read_text()
    else:  # the same rose from the same generator, 1,000 segments instead of 4,000
        spec = importlib.util.spec_from_file_location("make_cam", path.with_name("make_cam.py"))
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        text = mod.rose(1000)
    run = ProgramRunner(ctl, text, gcode={"parameters": work_origin(ctl)})
    run.start()
    assert run.wait(60) and run.state is RunState.DONE
    lines = text.splitlines()
    first = lines.index("G1 F2400") + 2          # first segment (1-based line numbers)
    last = len(lines) - 2                        # last segment, before "G0 X0 Y0", "M2"
    v = _g1_speeds(run, first, last)
    assert len(v) > 1000 and float(v.min()) > 0.0
    fast = np.nonzero(v > 10.0)[0]   # mm/s; the feed is 40 mm/s (F2400)
    cruise = v[fast[0]:fast[-1] + 1]  # from the end of the start ramp to the final braking
    assert len(cruise) > 0.9 * len(v) and float(cruise.min()) > 1.0


def _raster(rows: int, *, synced: dict[tuple[int, int], str] | None = None) -> str:
    """A raster of `rows` rows 10 mm long, 0.5 mm apart, each cut in 200 collinear
    segments of 0.05 mm (F3000 = 50 mm/s, G64 P0.01); `synced`: (row, segment) -> a line
    put before that segment (M62/M63)."""
    out = ["G21 G90 G64 P0.01 F3000"]
    for r in range(rows):
        if r:
            out.append(f"G1 Y{r * 0.5:g}")
        for k in range(1, 201):
            if synced and (r, k) in synced:
                out.append(synced[(r, k)])
            out.append(f"G1 X{(k if r % 2 == 0 else 200 - k) * 0.05:.2f}")
    return "\n".join(out) + "\nM2\n"


def _raster_point(row: int, k: int) -> np.ndarray:
    """Where segment k of a row ends (k = 0: where the row starts)."""
    return np.array([(k if row % 2 == 0 else 200 - k) * 0.05, row * 0.5])


def test_a_program_longer_than_the_window_streams_without_resting():
    """2,000 short segments through a window of 32: the runner keeps the group's queue
    topped up while the chain runs, so the path never rests between its start and its
    end (the old runner waited for the chain to end at every window: it rested about 60
    times on such a program), the feed is kept, M62/M63 fire at their corners and the end
    is exact."""
    ctl = iso_ctl()
    window = 32
    text = _raster(10, synced={(3, 100): "M62 P3", (7, 41): "M63 P3"})
    run = ProgramRunner(ctl, text, options=RunOptions(window=window))
    run.start()
    ql = []
    ctl.add_cycle_hook(lambda c, t: ql.append(run.group.queue_length if run.group else 0),
                       due=lambda c: math.inf)  # as in test_window_streams_a_long_program
    assert run.wait(60) and run.state is RunState.DONE
    assert max(ql) <= window and len(run.op_of) == 2009
    t, idx, p = run.trace()
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
    moving = np.nonzero(v > 0.0)[0]
    inside = v[moving[0]:moving[-1] + 1]
    assert len(inside) > 2000 and float(inside.min()) > 0.0   # no rest inside
    assert float(v.max()) <= 50.0 * (1 + 1e-9)
    assert float(np.mean(inside > 49.0)) > 0.45  # cruises along the rows (ramps: 0.1 s per row)
    assert np.array_equal(units(run)[:2], _raster_point(9, 200))   # exact end
    # the synced outputs fire once each, at the exact time the path passes their corner
    # (collinear: passed at speed); G64 P0.01 opens the window 0.01 mm wide per axis
    ev = {(e.index, e.level): e.t for e in run.events if e.kind == "sync_output"}
    assert set(ev) == {(3, True), (3, False)}
    for level, (row, k) in ((True, (3, 100)), (False, (7, 41))):
        te = ev[(3, level)]
        at = np.array([ctl.history.state_at(i, te).p for i in (0, 1)])   # pulses
        assert np.all(np.abs(at - 1000.0 * _raster_point(row, k - 1)) <= 10.0 + 2e-6)
        assert abs(ctl.history.state_at(0, te).v) > 40_000.0   # pulses/s: at speed
        assert abs(te / ctl.period - round(te / ctl.period)) > 1e-6  # inside a cycle


def test_pause_resume_abort_and_single_block_while_streaming():
    """Hold, continue and abort act on a chain that is streaming past the window; single
    block stops exactly on every block also when the program is longer than the window."""
    ctl = iso_ctl()
    run = ProgramRunner(ctl, _raster(3), options=RunOptions(window=16))
    run.start()
    ctl.advance(0.3)
    run.pause()
    ctl.advance(0.3)
    held = units(run)
    ctl.advance(0.2)
    assert np.array_equal(units(run), held) and run.progress < 1.0
    run.resume()
    assert run.wait(30) and run.state is RunState.DONE
    assert np.array_equal(units(run)[:2], _raster_point(2, 200))

    ctl2 = iso_ctl()
    run2 = ProgramRunner(ctl2, _raster(3), options=RunOptions(window=16))
    run2.start()
    ctl2.advance(0.3)
    run2.abort()
    ctl2.advance(0.5)
    assert run2.state is RunState.ABORTED and not any(a.is_moving for a in ctl2.axes)
    assert run2.group is not None and run2.group.queue_length == 0
    x, y = units(run2)[:2]
    assert y == 0.5 and 0.0 < x < 10.0                 # stopped on the second row

    ctl3 = iso_ctl()
    prog = "G21 G90 G1 F600\n" + "".join(f"G1 X{k * 0.5:g} Y{(k % 2) * 0.5:g}\n"
                                           for k in range(1, 13)) + "M2\n"
    run3 = ProgramRunner(ctl3, prog, options=RunOptions(window=4, single_block=True))
    run3.start()
    stops = []
    while ctl3.run_until(lambda: run3.state is not RunState.RUNNING, 30) \
            and run3.state is RunState.PAUSED:
        stops.append(tuple(np.round(units(run3)[:2], 9)))
        run3.resume()
    assert run3.state is RunState.DONE
    assert stops == [(k * 0.5, (k % 2) * 0.5) for k in range(1, 13)]


@pytest.mark.parametrize(("blend", "early_mm"), [("G61", 1e-9), ("G64 P0.01", 0.01)])
def test_m62_fires_at_the_exact_position_the_next_move_starts(blend, early_mm):
    """M62/M63 go through the compare engine: the output switches at the exact time the
    path passes the corner where the next move starts (inside a cycle), not per cycle."""
    ctl = iso_ctl()
    prog = (f"G21 G90 {blend} G1 X3 F1130\nM62 P3\nG1 X7\nM63 P3\nG1 X11\n"
            "M62 P4\nG1 X11 Y2\nM2")
    run = run_program(ctl, prog, timeout=60)
    assert run.state is RunState.DONE
    ev = {(e.index, e.level): e.t for e in run.events if e.kind == "sync_output"}
    assert set(ev) == {(3, True), (3, False), (4, True)}
    period = ctl.period
    for level_mm, key in ((3.0, (3, True)), (7.0, (3, False))):
        t_cross = ctl.history.crossings(0, level_mm * 1000.0, 0.0, ctl.time, 1)
        assert len(t_cross) == 1
        # collinear corners pass at speed; with G64 P the window is the tolerance wide
        x = ctl.history.state_at(0, ev[key])
        assert x.v > 1000.0 and ev[key] <= float(t_cross[0]) + 1e-12
        assert x.p >= level_mm * 1000.0 - early_mm * 1000.0 - 1e-6
    # the collinear corners are not on the cycle grid: per-cycle firing could not hit them
    assert any(abs(ev[k] / period - round(ev[k] / period)) > 1e-3 for k in ev)
    # the corner before the Y move: G61 stops exactly there and the output fires on
    # arrival (within 1e-6 pulse); G64 P starts the Y move at the blend's start (the
    # blend arc belongs to it), a little before the corner
    t4 = ev[(4, True)]
    t11 = float(ctl.history.crossings(0, 11000.0, 0.0, ctl.time, 1)[-1])
    slack = 1e-6 + 5000.0 * early_mm
    assert t4 <= t11 + 1e-12
    assert ctl.history.state_at(0, t4).p >= 11000.0 - slack
    assert abs(ctl.history.state_at(1, t4).p) <= slack


def test_g33_runs_at_pitch_times_the_commanded_speed():
    ctl = iso_ctl()
    run = ProgramRunner(ctl, "G21 S120 M3\nG33 X3 K0.5\nM5 M2")
    line = [op for op in run.ops if op.kind == "line"][0]
    assert line.feed == pytest.approx(0.5 * 120 / 60)  # 0.5 mm/rev at 2 rev/s
    with pytest.raises(MotionError, match="spindle"):
        ProgramRunner(ctl, "G21 M3\nG33 X3 K0.5\nM2")


def test_lathe_example_on_the_xz_machine():
    """examples/lathe_xz.toml + lathe_turn_thread.ngc: G18, G7 diameters, G76 passes."""
    from pathlib import Path

    from openmotion.config import load_machine
    from openmotion.program import SyncedFeed

    root = Path(__file__).parent.parent
    ctl = Controller(load_machine(root / "examples" / "lathe_xz.toml"))
    ctl.enable_all()
    run = ProgramRunner(ctl, root / "examples" / "gcode" / "lathe_turn_thread.ngc")
    synced = [op for op in run.ops if isinstance(op.source, SyncedFeed)]
    # G7 halves I/J/K: depth 1 + 0.2 n^(1/1.5) reaches 1 + 1.535 after 22 cuts, + 1 spring
    # pass; each pass is the synchronised cut and its exit taper
    assert len(synced) == 2 * 23
    # the cut along Z at pitch 2.5 mm x 800 rpm = 33.3 mm/s; the exit taper faster, at
    # the taper pitch 2.5 * hypot(2, 1.535) / 2
    feeds = sorted({round(op.feed, 9) for op in synced})
    assert feeds == pytest.approx([2.5 * 800 / 60, 2.5 * math.hypot(2, 1.535) / 2 * 800 / 60])
