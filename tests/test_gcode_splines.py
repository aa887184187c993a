"""G5 / G5.1 / G5.2-G5.3 splines: the curve (independent references), LinuxCNC's end points
and refusals (rs274), the chords within tolerance, and a run on the simulator."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from lcnc_oracle import OPTIONS, rs274_path, run_rs274
from openmotion.control.core.controller import Controller
from openmotion.program import GCodeError, GCodeOptions, Message, compile_text, run_program
from openmotion.program.runner import RunState
from openmotion.program.splines import SplineFeed, bezier

HERE = Path(__file__).parent
XY = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


def splines(text: str, opts: GCodeOptions = XY) -> list[SplineFeed]:
    return [c for c in compile_text(text, opts) if isinstance(c, SplineFeed)]


def test_g5_is_the_cubic_bezier_of_the_documented_control_points():
    (sp,) = splines("G21 G0 X1 Y2\nF600 G5 I0 J3 P0 Q-3 X4 Y5\nM2\n")
    ctrl = np.array([p[:2] for p in sp.points])
    assert ctrl.tolist() == [[1, 2], [1, 5], [4, 2], [4, 5]]  # start+IJ, end+PQ
    t = np.linspace(0.0, 1.0, 33)
    ref = bezier(ctrl, t)
    assert np.allclose(sp.evaluate(t)[:, :2], ref, atol=1e-12)


def test_g5_without_ij_continues_the_tangent_of_the_previous_g5():
    a, b = splines("G21 G0 X0 Y0\nF600 G5 I0 J3 P0 Q-3 X1 Y1\nG5 P0 Q-3 X2 Y2\nM2\n")
    # the second starts along -(P, Q) of the first: a smooth joint
    assert b.points[1][:2] == (1.0, 4.0)
    da = np.subtract(a.points[3], a.points[2])[:2]
    db = np.subtract(b.points[1], b.points[0])[:2]
    assert np.allclose(da / np.linalg.norm(da), db / np.linalg.norm(db))


def test_g51_is_the_documented_parabola():
    (sp,) = splines("G21 G0 X-2 Y4\nF600 G5.1 X2 I2 J-8\nM2\n")
    pts = sp.evaluate(np.linspace(0.0, 1.0, 21))
    assert np.allclose(pts[:, 1], pts[:, 0] ** 2, atol=1e-12)  # y = x^2 through the origin
    assert sp.order == 3 and len(sp.points) == 3


def test_nurbs_weights_make_an_exact_circle_arc():
    w = 1.0 / math.sqrt(2.0)
    (sp,) = splines(f"G21 G0 X10 Y0\nF600 G5.2 X10 Y10 P{w!r} L3\nX0 Y10 P1\nG5.3\nM2\n")
    u = np.linspace(0.0, float(sp.knots()[-1]), 101)
    r = np.hypot(*sp.evaluate(u)[:, :2].T)
    assert np.allclose(r, 10.0, atol=1e-9)
    assert sp.weights == (1.0, w, 1.0)


def test_nurbs_knots_and_order_follow_linuxcnc():
    (sp,) = splines("G21 G0 X0 Y0\nF600 G5.2 P2 L4\nX0 Y1 P1\nX1 Y1 P1\nX1 Y0 P1\n"
                    "X2 Y2 P1\nG5.3\nM2\n")
    assert sp.order == 4 and sp.weights == (2.0, 1.0, 1.0, 1.0, 1.0)
    assert sp.knots().tolist() == [0, 0, 0, 0, 1, 2, 2, 2, 2]
    ends = sp.evaluate(np.array([0.0, 2.0]))[:, :2]
    assert ends.tolist() == [[0.0, 0.0], [2.0, 2.0]]  # clamped: starts and ends on points
    # L below 4 keeps LinuxCNC's default order 3
    (q,) = splines("G21 G0 X0 Y0\nF600 G5.2 X0 Y1 P1 L2\nX1 Y1 P1\nG5.3\nM2\n")
    assert q.order == 3


def _farthest_from_polyline(points: np.ndarray, poly: np.ndarray, r: float) -> float:
    """max over `points` of the distance to the polyline `poly`, exact wherever it is <= r
    (else some value > r). Per block of points only the segments whose bounding box comes
    within r of the block's are measured: any segment nearer than r to a point is one."""
    a_all, b_all = poly[:-1], poly[1:]
    seg_lo, seg_hi = np.minimum(a_all, b_all), np.maximum(a_all, b_all)
    worst = 0.0
    for k in range(0, len(points), 200):
        p = points[k:k + 200]
        near = np.all((seg_hi >= p.min(axis=0) - r) & (seg_lo <= p.max(axis=0) + r), axis=1)
        if not near.any():
            return math.inf
        a, b = a_all[near][:, None, :], b_all[near][:, None, :]
        ab = b - a
        t = np.clip(np.sum((p[None] - a) * ab, axis=2)
                    / np.maximum(np.sum(ab * ab, axis=2), 1e-300), 0, 1)
        d = np.linalg.norm(p[None] - (a + t[..., None] * ab), axis=2).min(axis=0)
        worst = max(worst, float(d.max()))
    return worst


@pytest.mark.parametrize("tol", [0.1, 0.001, 1e-5])
def test_chords_stay_within_the_tolerance(tol):
    (sp,) = splines("G21 G0 X0 Y0\nF600 G5.2 P1 L3\nX0 Y10 P1\nX20 Y20 P3\nX20 Y0 P1\n"
                    "X0 Y0 P2\nG5.3\nM2\n")
    poly = sp.polyline(tol)
    assert tuple(poly[0]) == sp.points[0] and tuple(poly[-1]) == sp.points[-1]
    dense = sp.evaluate(np.linspace(0.0, float(sp.knots()[-1]), 4001))
    assert _farthest_from_polyline(dense[:, :2], poly[:, :2], tol * 1.01) <= tol * 1.01
    if tol >= 0.001:
        assert len(poly) < 400  # not needlessly fine


def test_spline_ends_and_messages_match_linuxcnc():
    exe = rs274_path()
    if exe is None:
        pytest.skip("rs274 not installed (tools/setup_rs274.sh)")
    text = (HERE / "gcode_oracle" / "splines.ngc").read_text()
    theirs = [t.strip() for t in run_rs274(text, exe).messages]
    ours = [c.text for c in compile_text(text, OPTIONS) if isinstance(c, Message)]
    assert ours == theirs and len(ours) == 7


@pytest.mark.parametrize(("text", "needle"), [
    ("G21 F100 G0 X0 Y0\nG5 P1 Q1 X1 Y1\nM2\n", "must follow a G5"),
    ("G21 F100 G0 X0 Y0\nG5 I1 J0 P1 Q1 X1 Y1\nG1 X2\nG5 P1 Q1 X3 Y3\nM2\n",
     "must follow a G5"),
    ("G21 F100 G5.2 X1 Y1 P1\nX2 Y0 P1\nG1 X5\nG5.3\nM2\n", "not closed with G5.3"),
    ("G21 F100 G5.2 X1 Y1 P1\nX2 Y0 P1\nM2\n", "not closed with G5.3"),
    ("G21 F100 G5.2 X1 Y1 P1\nX2 Y0 P1\n", "before the end of the program"),
    ("G21 G5.2 X1 Y1 P1\n", "0 feedrate"),
    ("G21 F100 G5.2 X1 Y1\nX2 Y0 P1\nG5.3\nM2\n", "positive weight"),
    ("G21 G93 G5.2 X1 Y1 P1 F1\nX2 Y0 P1\nG5.3 F1\nM2\n", "inverse time"),
    ("G21 F100 G41 D1 G5 I1 J0 P1 Q1 X1 Y1\nM2\n", "cutter radius compensation"),
    ("G21 F100 G5.1 X1 Y1 I0 J0\nM2\n", "both zero"),
])
def test_refusals_name_line_and_word(text, needle):
    with pytest.raises(GCodeError, match=needle) as err:
        compile_text(text, OPTIONS)
    assert err.value.line > 0


def nearest_distances(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Each 2-D point's distance to the nearest of `curve`'s points (in row blocks: the
    whole (points x curve) difference array would take ~2 GB and 13 s)."""
    cx, cy = curve[:, 0], curve[:, 1]
    out = np.empty(len(points))
    for i in range(0, len(points), 256):
        q = points[i:i + 256]
        out[i:i + 256] = np.min((q[:, 0, None] - cx) ** 2 + (q[:, 1, None] - cy) ** 2, axis=1)
    return np.sqrt(out)


def test_spline_runs_on_the_machine_to_the_exact_end():
    ctl = Controller()
    ctl.enable_all()
    prog = ("G21 G90 G0 X5 Y5\nF1200\nG5 I0 J10 P0 Q-10 X25 Y5\nG5 P0 Q-10 X45 Y5\n"
            "G5.1 X65 I10 J-10\nM2\n")
    run = run_program(ctl, prog, gcode={"parameters": {}})
    assert run.state is RunState.DONE, run.error
    xs = run.scales.ppu
    assert ctl.axis("x").position == round(65 * xs[0])
    assert ctl.axis("y").position == round(5 * xs[1])
    # every traced point lies within the chord tolerance (+ one cycle of corner rounding
    # the group may blend) of the programmed curves
    t, _i, p = run.trace()
    assert len(t) > 10
    (a, b, c) = splines(prog, GCodeOptions(axes={"X": 0, "Y": 1}))
    dense = np.vstack([s.evaluate(np.linspace(0, float(s.knots()[-1]), 3000))[:, :2]
                       for s in (a, b, c)])
    pos = np.asarray(p)[:, :2]  # machine units
    moving = pos[:, 0] > 5.0 + 1e-6
    assert nearest_distances(pos[moving], dense).max() < 0.02


@pytest.mark.parametrize("gword", ["G5.2", "G[5.2]", "G#1", "g [ 5 + 0.2 ]"])
def test_open_nurbs_block_at_the_end_is_refused_also_when_the_code_is_computed(gword):
    """compile_text's fast path never sees the end of a program: a computed G5.2 must take
    the general path too, which refuses the block left open."""
    text = f"G21 F100\n#1=5.2\n{gword} X0 Y0 P1 L3\nX1 Y1 P1\nX2 Y0 P1\n"
    with pytest.raises(GCodeError, match="not closed with G5.3"):
        compile_text(text, GCodeOptions(axes={"X": 0, "Y": 1}))
