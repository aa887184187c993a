"""The landing lead of the compiled real-time executor (control/core/realtime.py,
_kernel_rt.c): the last cycles before a planned landing run back to back from the slot of
the first of them, so the Python work of the landing has the lead plus a period before the
next cycle's slot. Only planned, timing-independent facts are asserted: which cycles ran
ahead and by how many periods (never how long anything took), that the motion is the
virtual-time motion, and the own-overrun count of synthetic rings.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from openmotion import _kernel
from openmotion.control import Controller
from openmotion.control.core import realtime
from openmotion.control.core.realtime import _own_overruns

pytestmark = pytest.mark.skipif(not realtime.AVAILABLE, reason="the kernel is not built")

T = 0.001


def _moves(ctl: Controller) -> None:
    ctl.hardware.record_pulses()
    ctl.enable_all()
    for k, ax in enumerate(ctl.axes):  # ends at different cycles: one landing each
        ax.move_relative(4_000 * (k + 1), max_vel=30_000, tacc=0.02)


def _observe(ctl: Controller) -> tuple:
    hw = ctl.hardware
    return (ctl.cycles, tuple((a.state, a.position, a.motion_done, a.counters.snapshot())
                              for a in ctl.axes),
            tuple(tuple(map(tuple, (t.tolist(), c.tolist())))
                  for t, c in (hw.pulse_record(i).pulses() for i in range(len(ctl.axes)))))


def test_the_cycles_before_each_landing_run_ahead_with_the_virtual_time_result():
    rt = Controller()
    _moves(rt)
    hw = rt.hardware
    real = hw.run_cycles
    runs: list[tuple[int, int, int]] = []  # (first cycle, planned stop, cycle landed on)

    def logged(origin, period, n, stop, *a, **k):  # noqa: ANN001, ANN002, ANN003, ANN202
        run = real(origin, period, n, stop, *a, **k)
        runs.append((n + 1, stop, run.cycle))
        return run

    hw.run_cycles = logged
    with rt.start_realtime():
        deadline = time.monotonic() + 60.0
        while rt.cycles < 700 and time.monotonic() < deadline:
            time.sleep(0.01)
    assert rt.cycles >= 700
    lead = rt.cycle_samples()["lead"]
    assert len(lead) == rt.cycles  # ring i is cycle i + 1
    d = math.ceil(realtime.LANDING_LEAD_S / T - 1e-9)
    first = max(d, math.ceil(realtime.START_LEAD_S / T - 1e-9))
    assert np.all(lead == np.round(lead)) and lead.min() == 0 and lead.max() <= first
    checked = 0
    for i, (k0, stop, landed) in enumerate(runs[:-1]):  # the last one ends at the stop
        assert landed == stop  # one chunk per run, nothing interrupts it
        m = first if i == 0 else d
        if stop - k0 + 1 > m:  # long enough for the whole lead: 1 .. m up to the landing
            want = np.arange(stop - m, stop + 1) - (stop - m)
            assert lead[stop - m - 1:stop].tolist() == want.tolist()
            checked += 1
    assert checked >= len(rt.axes)  # every move's end, at least
    vt = Controller()
    _moves(vt)
    vt.advance(rt.cycles * vt.period)
    assert _observe(rt) == _observe(vt)


def _rings(own: list[float], lead: list[float]) -> dict[str, np.ndarray]:
    busy = np.array(own) * T
    return {"busy": busy, "work": np.zeros(len(own)), "cpu": busy.copy(),
            "lead": np.array(lead, dtype=float)}


@pytest.mark.parametrize("by", ["busy", "cpu"])
def test_own_overruns_count_from_the_planned_start(by):
    quiet = [0.1] * 20
    assert _own_overruns(_rings(quiet, [0] * 20), T, by) == 0
    # a cycle at its slot that takes 1.5 periods: one (the next one catches up in time)
    assert _own_overruns(_rings([0.1] * 5 + [1.5] + [0.1] * 5, [0] * 11), T, by) == 1
    # 3.5 periods: the next cycles start late by the controller's doing too
    assert _own_overruns(_rings([0.1] * 5 + [3.5] + [0.1] * 5, [0] * 11), T, by) == 3
    # a landing with a lead of 8 cycles may take up to 9 periods after the block's start
    lead = [0] * 5 + list(range(9)) + [0] * 5
    own = [0.1] * 13 + [8.0] + [0.1] * 5
    assert _own_overruns(_rings(own, lead), T, by) == 0
    own[13] = 9.95  # beyond it: that one and the next
    assert _own_overruns(_rings(own, lead), T, by) == 2
    # the start: the first cycle's slot 25 periods on, it may take up to 26
    start = [25] + [0] * 5
    assert _own_overruns(_rings([20.0] + [0.1] * 5, start), T, by) == 0
    assert _own_overruns(_rings([27.0] + [0.1] * 5, start), T, by) == 2
    # a cycle planned ahead still starts only when the one before it has ended
    assert _own_overruns(_rings([0.1, 5.5, 0.1], [0, 5, 0]), T, by) == 2


def test_the_pacing_context_needs_every_ring():
    st = np.zeros(realtime.RT_NFIELDS)
    st[realtime.RT_PENDING] = -1.0
    rings = [np.zeros(8) for _ in realtime.RINGS]
    _kernel.rt_close(st, *rings)
    with pytest.raises(TypeError):
        _kernel.rt_close(st, *rings[:-1])
    with pytest.raises(ValueError, match="wrong sizes"):
        _kernel.rt_close(st, *rings[:-1], np.zeros(4))
