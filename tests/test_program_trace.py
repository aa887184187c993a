"""The runner's trace of jumped cycles in bulk (program/trace.py): `Group.indices_at` gives
the very command indices `Group.index_at` gives cycle by cycle, and the rows keep their
cycle order and values whether a run jumps or steps."""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.program.runner import RunState, run_program
from openmotion.program.trace import CycleTrace

#: Blended short lines, arcs, a dwell, a corner stop, a rotary axis: many command changes
#: inside the spans a jump crosses.
PROG = ("G21 G90 G64 P0.01\nG1 X2 Y0 A5 F3000\nG1 X2.5 Y0.4\nG1 X3 Y0.2\nG2 X5 Y0.2 R1.2\n"
        "G1 X5 Y3 F1500\nG4 P0.05\nG3 X2 Y3 I-1.5 J0\nG61\nG1 X0 Y0 A0\nG1 X0.2\nM2\n")


def test_indices_at_equals_index_at_over_every_jumped_span():
    ctl = Controller()
    ctl.enable_all()
    spans: list[int] = []

    def check(c: Controller, first: int, last: int, p: np.ndarray, a: np.ndarray) -> None:
        g = run.group
        assert g is not None and p.shape == a.shape == (last - first + 1, len(c.axes))
        t = c._t_origin + np.arange(first - 2, last + 3) * c.period  # and a little beyond
        want = [g.index_at(float(x)) for x in t]
        assert g.indices_at(t).tolist() == want
        spans.append(len(set(want)))

    from openmotion.program.runner import ProgramRunner

    run = ProgramRunner(ctl, PROG)
    ctl.add_jump_observer(check)
    run.start()
    assert ctl.run_until(lambda: not run.running, 60.0, event_driven=True)
    assert run.state is RunState.DONE
    assert len(spans) > 5 and max(spans) >= 2  # spans that cross command changes
    g = run.group
    assert g is not None and g.indices_at(np.array([ctl.time])).tolist() == [-1]


def test_a_jumped_trace_equals_the_stepped_one():
    def trace(jumps: bool):  # noqa: ANN202
        ctl = Controller()
        ctl.virtual_jumps = jumps
        ctl.enable_all()
        run = run_program(ctl, PROG, timeout=60)
        assert run.state is RunState.DONE
        return (*run.trace(), run.actual_trace())

    ref, fast = trace(False), trace(True)
    assert len(ref[0]) > 300
    for a, b in zip(ref, fast, strict=True):
        np.testing.assert_array_equal(a, b)


def test_cycle_trace_keeps_the_cycle_order_of_rows_and_spans():
    class _G:
        def index_lookup(self):  # noqa: ANN202
            return lambda t: np.full(len(t), 7, dtype=np.int64)

    class _C:
        _t_origin, period = 0.0, 0.001

    tr = CycleTrace([2, 0])
    tr.add(0.001, 3, [1.0, 2.0], [1.5, 2.5])
    pos = np.arange(12, dtype=float).reshape(3, 4)
    tr.add_span(_C(), _G(), 2, 4, pos, -pos)  # type: ignore[arg-type]
    tr.add(0.005, 8, [9.0, 9.5], [9.0, 9.5])
    t, i, p, a = tr.arrays()
    assert len(tr) == 5
    np.testing.assert_array_equal(t, [0.001, 0.002, 0.003, 0.004, 0.005])
    assert i.tolist() == [3, 7, 7, 7, 8]
    assert p.tolist() == [[1.0, 2.0], [2.0, 0.0], [6.0, 4.0], [10.0, 8.0], [9.0, 9.5]]
    assert a[1:4].tolist() == (-p[1:4]).tolist()
    p[0, 0] = 99.0  # a copy: the trace is unchanged
    assert tr.arrays()[2][0, 0] == 1.0
    assert [x.shape for x in CycleTrace([0]).arrays()] == [(0,), (0,), (0, 1), (0, 1)]
