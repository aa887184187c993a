"""A streamed, blended G-code job jumps over the cycles between its joins: the runner's and
the group's hooks are due only where they act (program/runner.py `_due`,
control/groups/groupdue.py; the corners are blended by the join itself when no quiet cycle
prepared them), and every result is the cycle-by-cycle run's: counters, states, events,
histories, pulses, outputs, the runner's events and trace (tests/test_jump_jobs.both)."""

from __future__ import annotations

import math

from openmotion.control import Controller
from openmotion.program.runner import ProgramRunner
from test_jump_jobs import both


def _wave(n: int) -> str:
    """n short blended segments of a wave (as examples/programs/cam_rose.ngc's), with an
    M67 and an M62/M63 pair bound to
    moves, an M64/M65 pair after the motion, a dwell and an arc."""
    lines = ["G21 G90 G17 G64 P0.01", "G0 X1 Y1", "G1 F6000"]
    for k in range(1, n + 1):
        lines.append(f"X{1.0 + 0.3 * k:.4f} Y{1.0 + 0.5 * math.sin(k / 5.0):.4f}")
        if k == n // 4:
            lines.append("M67 E0 Q2.5")
        if k == n // 3:
            lines.append("M62 P1")
        if k == n // 2:
            lines.append("M63 P1")
    lines += ["M64 P2", "G4 P0.02", "G2 I1 J0", "M65 P2", "M2"]
    return "\n".join(lines) + "\n"


def test_a_blended_streamed_job_jumps_with_every_result_identical():
    prog = _wave(100)

    def run(ctl: Controller) -> object:
        r = ProgramRunner(ctl, prog, axes={"X": 0, "Y": 1})
        r.start()
        ctl.run_until(lambda: not r.running, 60.0, event_driven=True)
        t, idx, p = r.trace()
        return (r.state, r.error, list(r.events), t.tolist(), idx.tolist(), p.tolist(),
                r.actual_trace().tolist())
    res, cycles, crossed = both(run)
    assert res[0].value == "done", res[1]
    kinds = [e.kind for e in res[2]]
    assert kinds.count("sync_output") == 2 and kinds.count("analog_output") == 1
    assert len(res[3]) == cycles - 1 or len(res[3]) > 0.9 * cycles
    assert crossed > 0.9 * cycles  # the joins and the few barriers land, nothing else
