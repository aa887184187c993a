"""M62/M63 (and M67) around moves that end where they begin: the output switches at the
instant the group starts the move after it, not where the path passes its end point
(a full circle passes it at its start too: the beam was on 1 ms instead of the circle)."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.program.runner import RunState, run_program

# tangent entry and exit (direction -Y at X0 Y0): the corners are passed at speed with G64
HOLE = ("G21 G90 {blend} G1 X0 Y5 F1800\nG1 Y0\nM62 P2\n{closed}\nM63 P2\nG1 Y-5\n"
        "G1 X1\nM2\n")
CLOSED = {
    "circle": "G3 X0 Y0 I5 J0",
    "circle_2_turns": "G3 X0 Y0 I5 J0 P2",
    "helix": "G3 X0 Y0 Z-1 I5 J0",
}


def _ctl() -> Controller:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xyz")
    ctl = Controller(MachineConfig(name="iso", axes=axes, digital_outputs=8))
    ctl.enable_all()
    return ctl


def _circle_index(run) -> int:
    return next(i for i, op in run.op_of.items() if op.kind == "arc")


@pytest.mark.parametrize("blend", ["G61", "G64 P0.01"])
@pytest.mark.parametrize("closed", sorted(CLOSED))
def test_m63_after_a_closed_move_fires_when_the_next_move_starts(blend, closed):
    ctl = _ctl()
    run = run_program(ctl, HOLE.format(blend=blend, closed=CLOSED[closed]), timeout=60)
    assert run.state is RunState.DONE
    ev = [(e.t, e.level) for e in run.events if e.kind == "sync_output"]
    assert [lv for _, lv in ev] == [True, False]
    t_on, t_off = ev[0][0], ev[1][0]
    # the physical line (timed outputs) switches at the same instants
    assert ctl.hardware.output_record.edges("do2") == [(t_on, True), (t_off, False)]
    # each edge lies in the cycle in which the trace's command index changes
    t, idx, _ = run.trace()
    arc = _circle_index(run)
    for te, before, after in ((t_on, arc - 1, arc), (t_off, arc, arc + 1)):
        k = int(np.searchsorted(t, te))
        assert t[k - 1] < te <= t[k]
        assert (idx[k - 1], idx[k]) == (before, after)
    # on for the whole closed move: its length at F1800 (30 mm/s) and more
    turns = 2 if closed == "circle_2_turns" else 1
    assert t_off - t_on >= turns * 2 * np.pi * 5 / 30
    assert t_off - t_on <= turns * 2 * np.pi * 5 / 30 + 0.5
    # at both edges the tool is on the corner X0 Y0 (and Z at the helix's end for M63)
    for te, z in ((t_on, 0.0), (t_off, -1000.0 if closed == "helix" else 0.0)):
        p = [ctl.history.state_at(a, te).p for a in range(3)]
        assert np.allclose(p, [0.0, 0.0, z], atol=1e-6)
    if blend.startswith("G64") and closed != "helix":  # (the helix's climb is a corner)
        # passed at speed: the edges are the exact instants Y crosses 0 going down
        # (the circle's start and its end; it crosses upward at X10 in between)
        down = [float(tc) for tc in ctl.history.crossings(1, 0.0, 0.0, ctl.time, -1)]
        assert down[0] == pytest.approx(t_on, abs=1e-9)
        assert down[-1] == pytest.approx(t_off, abs=1e-9)
        assert ctl.history.state_at(1, t_off).v < -20_000.0  # 30 mm/s, not at rest


def test_m67_after_a_full_circle_is_written_when_the_next_move_starts():
    """M67 (synchronised analog) is bound to the next move's start like M62/M63, at the
    cycle resolution LinuxCNC has; M68 and M64 after the motion before them."""
    ctl = _ctl()
    prog = ("G21 G90 G64 P0.01 G1 X0 Y5 F1800\nG1 Y0\nM67 E0 Q2.5\nG3 X0 Y0 I5 J0\n"
            "M67 E0 Q0\nM64 P3\nG1 Y-5\nM68 E1 Q1\nG1 X1\nM2\n")
    run = run_program(ctl, prog, timeout=60)
    assert run.state is RunState.DONE
    t, idx, _ = run.trace()
    arc = _circle_index(run)
    first = {i: float(t[np.argmax(idx == i)]) for i in (arc, arc + 1)}  # first cycle end
    rec = ctl.hardware.analog_record
    assert [(ch, v) for _, ch, v in rec] == [(0, 2.5), (0, 0.0), (1, 1.0)]
    assert rec[0][0] == pytest.approx(first[arc], abs=1e-12)
    assert rec[1][0] == pytest.approx(first[arc + 1], abs=1e-12)
    assert rec[1][0] - rec[0][0] >= 2 * np.pi * 5 / 30 - ctl.period
    t_end_y = float(t[np.flatnonzero(idx == arc + 1)[-1]])  # M68: after G1 Y-5 ended
    assert rec[2][0] > t_end_y
    m64 = next(e for e in run.events if e.kind == "output")
    t_end_arc = float(t[np.flatnonzero(idx == arc)[-1]])  # M64: after the circle ended
    assert m64.index == 3 and t_end_arc <= m64.t <= first[arc + 1]
