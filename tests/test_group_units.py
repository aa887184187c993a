"""Groups in user units: geometry, feed and limits in mm on axes with different pulses/mm
(default XYZU table: x 1000, y 2000 pulses/mm)."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import finish_group, table_without_mel
from openmotion.control import Controller
from openmotion.control.groups.group import ERR_SPEED, Group, GroupError
from openmotion.errors import MotionError
from openmotion.units import AxisUnits

FEED = 20.0  # mm/s


def make(**kw) -> tuple[Controller, Group]:
    ctl = table_without_mel(safety=False)
    units = kw.pop("units", True)
    return ctl, Group(ctl, ["x", "y"], feed=FEED, acc_time=0.05, units=units, **kw)


finish = finish_group  # run until idle, queue empty, axes still; the end time


def sampled_mm(ctl: Controller, g: Group, t0: float, t1: float, ppu: tuple[float, float]):
    t = np.linspace(t0, t1, 20001)
    sx, sy = (ctl.history.sample(a.index, t) for a in g.axes)
    return sx.p / ppu[0], sy.p / ppu[1], sx.v / ppu[0], sy.v / ppu[1]


def test_scales_come_from_the_machine_config():
    ctl, g = make()
    assert g.units
    assert g._k.tolist() == [1000.0, 2000.0]
    assert not Group(ctl, ["z"], units=False).units


def test_arc_in_mm_stays_on_the_circle_and_feed_is_the_tool_speed():
    ctl, g = make()
    t0 = ctl.time
    g.arc([0.0, 10.0], [10.0, 10.0], direction="CW")  # half circle, R 10 mm
    t1 = finish(ctl, g)
    assert g.position.tolist() == [10.0, 10.0]
    assert [a.position for a in g.axes] == [10_000.0, 20_000.0]  # exactly
    x, y, vx, vy = sampled_mm(ctl, g, t0, t1, (1000.0, 2000.0))
    r = np.hypot(x, y - 10.0)
    assert np.max(np.abs(r - 10.0)) < 1e-6  # mm: a true circle, not an ellipse
    speed = np.hypot(vx, vy)
    assert speed.max() <= FEED * (1 + 1e-6)
    assert speed.max() >= FEED * (1 - 1e-3)  # cruises at the feed in mm/s


def test_line_in_mm_ends_exactly_and_keeps_the_direction():
    ctl, g = make()
    t0 = ctl.time
    g.line([30.0, 12.0])
    t1 = finish(ctl, g)
    assert [a.position for a in g.axes] == [30_000.0, 24_000.0]
    _, _, vx, vy = sampled_mm(ctl, g, t0, t1, (1000.0, 2000.0))
    m = np.abs(vx) > 1e-6
    assert np.allclose(vy[m] / vx[m], 12.0 / 30.0, rtol=1e-9)
    assert np.hypot(vx, vy).max() == pytest.approx(FEED, rel=1e-9)


def test_reversed_axis_units_mirror_the_pulses():
    ctl = table_without_mel(safety=False)
    units = [AxisUnits("x", "mm", 1000.0, -1), AxisUnits("y", "mm", 500.0, 1)]
    g = Group(ctl, ["x", "y"], feed=FEED, acc_time=0.05, units=units)
    g.line([-5.0, 4.0])
    finish(ctl, g)
    assert [a.position for a in g.axes] == [5000.0, 2000.0]
    assert g.position.tolist() == [-5.0, 4.0]


def test_pulse_limits_are_converted_to_units():
    ctl, g = make()
    # y: 2000 pulses/mm; 30 000 pps = 15 mm/s; a pure-y line at 20 mm/s needs 40 000 pps
    g.set_max_pulse_speed([1e6, 30_000.0])
    with pytest.raises(GroupError) as err:
        g.line([0.0, 10.0])
    assert err.value.code == ERR_SPEED and "axis y" in str(err.value)
    g.line([10.0, 0.0])  # x needs 20 000 pps: fine
    g.set_axis_limit_policy("slow")
    t0 = ctl.time
    g.line([10.0, 10.0])
    t1 = finish(ctl, g)
    t = np.linspace(t0, t1, 20001)
    vy = ctl.history.sample(g.axes[1].index, t).v
    assert np.abs(vy).max() <= 30_000.0 * (1 + 1e-9)
    assert [a.position for a in g.axes] == [10_000.0, 20_000.0]


def test_dry_run_and_ptp_report_user_units():
    ctl, g = make()
    g.enable_dry_run()
    g.line([3.0, 4.0])
    finish(ctl, g)
    assert g.position.tolist() == [3.0, 4.0]
    assert [a.position for a in g.axes] == [0.0, 0.0]
    g.enable_dry_run(False)
    g.ptp([2.0, 1.5])
    finish(ctl, g)
    assert [a.position for a in g.axes] == [2000.0, 3000.0]
    assert g.position.tolist() == [2.0, 1.5]


def test_bad_units_refused():
    ctl = Controller(safety=False)
    with pytest.raises(MotionError, match="units"):
        Group(ctl, ["x", "y"], units=[AxisUnits("x", "mm", 1000.0)])
    with pytest.raises(MotionError, match="units"):
        Group(ctl, ["x"], units="mm")  # type: ignore[arg-type]
