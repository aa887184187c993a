"""PulseRecord.pulses keeps what it expanded and expands only the stretches added since:
the same arrays, bit for bit, as expanding every stretch again (also after a rewind)."""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.hw.sim.cubic import Cubic
from openmotion.hw.sim.pulserecord import PulseRecord, _expand
from openmotion.hw.sim.pulses import Stretch


def _same(rec: PulseRecord) -> int:
    t, k = rec.pulses()
    t_all, k_all = _expand(rec._rows)  # every stretch, from scratch
    assert t.dtype == t_all.dtype and k.dtype == k_all.dtype
    assert t.tobytes() == t_all.tobytes() and k.tobytes() == k_all.tobytes()
    return len(t)


def test_pulses_asked_while_moving_are_those_of_one_expansion():
    ctl = Controller()
    ctl.enable_all()
    ctl.hardware.record_pulses()
    ctl.axis("x").move_relative(40_000, max_vel=60_000, tacc=0.05)
    ctl.axis("y").move_relative(-9_000, max_vel=20_000, tacc=0.02)
    seen = []
    for _ in range(12):
        ctl.advance(0.05)
        seen.append(_same(ctl.hardware.pulse_record(0)) + _same(ctl.hardware.pulse_record(1)))
    assert ctl.wait_motion_done()
    seen.append(_same(ctl.hardware.pulse_record(0)) + _same(ctl.hardware.pulse_record(1)))
    assert seen == sorted(seen) and len(set(seen)) > 5
    for i in (0, 1):  # the last count is where the axis ended
        assert ctl.hardware.pulse_record(i).pulses()[1][-1] == ctl.axes[i].position
    t, k = ctl.hardware.pulse_record(0).pulses()
    t[:] = -1.0  # the caller's copy: the record's own arrays are not touched
    assert _same(ctl.hardware.pulse_record(0)) == 40_000


def test_a_rewind_below_what_was_expanded_starts_again():
    rec = PulseRecord(0, 100, 0.0, Cubic(0.0), 0.0, 0.0)
    c = Cubic(0.0, 1000.0, 0.0, 0.0)  # 1000 pulses/s from tc = 0
    rec.add(Stretch(0.0, 0.01, c, 0.0, 1, 0, 10), 0.5)
    rec.add(Stretch(0.01, 0.02, c, 0.0, 1, 10, 20), 0.5)
    assert _same(rec) == 20
    mark = rec.mark()
    rec.add(Stretch(0.02, 0.03, c, 0.0, 1, 20, 30), 0.5)
    assert _same(rec) == 30
    rec.rewind(mark)  # down to what was expanded before the last add
    assert _same(rec) == 20
    rec.rewind(1)     # below it
    rec.add(Stretch(0.01, 0.01, None, 0.01, -1, 10, 7), 0.0)  # a jump back
    assert _same(rec) == 13
    t, k = rec.pulses()
    assert k.tolist()[-3:] == [9, 8, 7] and np.all(t[-3:] == 0.01)
