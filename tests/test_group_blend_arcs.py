"""Blended line-arc and arc-arc corners on recorded group runs and through the G-code
runner: no stop at the corners, contour error within the tolerance, axis limits, exact
ends, faster than exact stops."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.groups.pathexec import contour_error
from openmotion.path import Arc, Line
from openmotion.program.report import contour_errors
from openmotion.program.runner import ProgramRunner, RunState

VMAX = 50_000.0
AMAX = 500_000.0

# line -> arc (90 deg corner) -> line (45 deg corner)
LAL = [("line", [20_000, 0]),
       ("arc", [25_000, 0], [30_000, 0], "CW"),          # leaves (20000, 0) going +y
       ("line", [40_000, -10_000])]                        # arc arrives going -y
# arc -> arc corners (90 and 45 deg), then arc -> line (90 deg)
AA = [("arc", [0, 10_000], [10_000, 10_000], "CCW"),      # ends going +y
      ("arc", [10_000, 20_000], [0, 20_000], "CW"),       # leaves going -x, ends going +y
      ("arc", [-5_000, 25_000], [0, 30_000], "CCW"),      # leaves going (1, 1)/sqrt(2)
      ("line", [5_000, 35_000])]                          # arc ends going (-1, 1)/sqrt(2)


def _elements(prog) -> list:
    els, p = [], np.zeros(2)
    for cmd in prog:
        if cmd[0] == "line":
            els.append(Line(p, cmd[1]))
        else:
            els.append(Arc(p, cmd[1], cmd[2], direction=cmd[3]))
        p = np.array(els[-1].end, dtype=float)
    return els


def _run(prog, tol: float | None, *, stream: bool = False):
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=40_000.0, acc_time=0.1)
    g.set_max_pulse_speed([VMAX, VMAX])
    g.set_max_pulse_acc([AMAX, AMAX])
    if tol is not None:
        g.enable_blend(tol)
    t0 = ctl.time
    for k, cmd in enumerate(prog):
        if cmd[0] == "line":
            g.line(cmd[1])
        else:
            g.arc(cmd[1], cmd[2], direction=cmd[3])
        if stream and k == 0:
            ctl.advance(0.05)  # the rest joins the running chain (_extend_running)
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                         and not any(a.is_moving for a in g.axes), 30, event_driven=True)
    t = np.linspace(t0, ctl.time, 30001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    return ctl.time - t0, g.position, t, sx, sy


@pytest.mark.parametrize(("prog", "tol"), [(LAL, 40.0), (AA, 40.0)],
                         ids=["line-arc-line", "arc-arc"])
def test_arc_corners_blend_without_stopping(prog, tol):
    els = _elements(prog)
    t_exact, end_e, *_ = _run(prog, 0.0)
    t_blend, end_b, t, sx, sy = _run(prog, tol)
    assert end_b.tolist() == end_e.tolist() == list(els[-1].end)  # exact end
    xy = np.stack([sx.p, sy.p], axis=1)
    err = contour_error(xy, els)
    assert err.max() <= tol * (1 + 1e-6)
    assert err.max() > 0.5 * tol  # the corners are rounded, not stopped at
    for s in (sx, sy):
        assert np.abs(s.v).max() <= VMAX * (1 + 1e-9)
        assert np.abs(s.a).max() <= AMAX * (1 + 1e-9)
    speed = np.hypot(sx.v, sy.v)
    inner = (t > t[0] + 0.05) & (t < t[-1] - 0.05)
    assert speed[inner].min() > 1000.0  # never stops at a corner
    assert t_blend < t_exact


def test_arc_corner_streamed_into_a_running_chain_is_blended():
    t_stream, end, t, sx, sy = _run(LAL, 40.0, stream=True)
    assert end.tolist() == [40_000.0, -10_000.0]
    speed = np.hypot(sx.v, sy.v)
    inner = (t > t[0] + 0.05) & (t < t[-1] - 0.05)
    assert speed[inner].min() > 1000.0
    xy = np.stack([sx.p, sy.p], axis=1)
    err = contour_error(xy, _elements(LAL))
    assert 20.0 < err.max() <= 40.0 * (1 + 1e-6)  # both corners rounded


def _iso_ctl() -> Controller:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xyz")
    ctl = Controller(MachineConfig(name="iso", axes=axes, digital_outputs=8))
    ctl.enable_all()
    return ctl


GCODE = """G21 G90 G17 {mode} F3000
G1 X10 Y0
G2 X20 Y0 I5 J0
G1 X25 Y-5
G3 X35 Y-5 I5 J0
G2 X45 Y-5 I5 J0
G1 X55 Y-5
M2
"""


def test_gcode_g64_p_blends_g2_g3_corners():
    runs = {}
    for mode in ("G61", "G64 P0.02"):
        ctl = _iso_ctl()
        run = ProgramRunner(ctl, GCODE.format(mode=mode))
        run.start()
        assert run.wait(60) and run.state is RunState.DONE
        t, idx, p = run.trace()
        end = run._positions() / run.scales.ppu
        assert end[:2].tolist() == [55.0, -5.0]
        err, _ = contour_errors(run)
        runs[mode] = (t[-1] - t[0], float(np.nanmax(err)), t, p)
    t_exact, err_exact, *_ = runs["G61"]
    t_blend, err_blend, t, p = runs["G64 P0.02"]
    assert err_exact < 1e-3
    assert 0.005 < err_blend <= 0.02 * (1 + 1e-6)  # mm: corners rounded within P
    assert t_blend < t_exact
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
    moving = np.nonzero(v > 1e-9)[0]
    assert v[moving[0] + 5:moving[-1] - 5].min() > 1.0  # mm/s: no stop at any corner


def test_example_prints_faster_blended_runs_within_tolerance():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "group_arc_blend.py"
    spec = importlib.util.spec_from_file_location("group_arc_blend", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    exact, blended = mod.run(0.0), mod.run(50.0)
    for r in (exact, blended):
        assert r["end"] == [10_000.0, 0.0]
        assert r["accel"] <= 1.0 + 1e-9
    assert exact["deviation"] < 1e-6
    assert 25.0 < blended["deviation"] <= 50.0 * (1 + 1e-6)
    assert blended["time"] < exact["time"]
