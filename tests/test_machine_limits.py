"""Per-axis acceleration and jerk limits of the machine file (`max_accel`, `max_jerk`):
validated with the key's name, round-tripped, and kept by group paths and PtP moves."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import finish_group
from openmotion.config import AxisConfig, MachineConfig, dumps_machine, loads_machine
from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.errors import MotionError


def machine(**kw) -> MachineConfig:
    # 1000 pulses/mm, 500 mm/s, no switches
    return MachineConfig("t", tuple(AxisConfig(name=c, pulses_per_rev=1000, lead=1.0, **kw)
                                    for c in "xy"))


@pytest.mark.parametrize("key,bad", [("max_accel", -1.0), ("max_jerk", float("nan")),
                                     ("max_accel", "fast")])
def test_bad_limits_name_the_key(key, bad):
    with pytest.raises(MotionError, match=f"axes.x.{key}"):
        AxisConfig(name="x", **{key: bad})
    text = f'[axes.x]\n{key} = {bad!r}\n'.replace("nan", "nan").replace("'", '"')
    with pytest.raises(MotionError, match=f"axes.x.{key}"):
        loads_machine(text)


def test_limits_round_trip_and_default_off():
    cfg = machine(max_accel=2000.0, max_jerk=5e4)
    back = loads_machine(dumps_machine(cfg))
    assert back.axes[0].max_accel == 2000.0 and back.axes[0].max_jerk == 5e4
    assert AxisConfig(name="z").max_accel == 0.0 and AxisConfig(name="z").max_jerk == 0.0


def run_group(cfg, cmd):
    ctl = Controller(cfg, safety=False)
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=200_000.0, acc_time=0.02)
    g.set_axis_limit_policy("slow")
    g.set_ptp_speed(50.0)
    t0 = ctl.time
    cmd(g)
    t1 = finish_group(ctl, g)
    t = np.arange(t0, t1, 2e-5)
    return [ctl.history.sample(a.index, t) for a in g.axes]


@pytest.mark.parametrize("kind", ["line", "ptp"])
def test_axes_stay_within_the_machine_acceleration(kind):
    cfg = machine(max_accel=2000.0)          # mm/s^2 = 2e6 pps^2
    st = run_group(cfg, lambda g: getattr(g, kind)([60_000, 20_000]))
    for s in st:
        assert np.abs(np.diff(s.v)).max() / 2e-5 <= 2e6 * (1 + 1e-3)
    free = run_group(machine(), lambda g: getattr(g, kind)([60_000, 20_000]))
    assert max(np.abs(np.diff(s.v)).max() for s in free) / 2e-5 > 4e6  # the limit bites


def test_machine_jerk_makes_paths_jerk_limited():
    cfg = machine(max_jerk=1e5)              # mm/s^3 = 1e8 pps^3
    st = run_group(cfg, lambda g: g.line([60_000, 0]))
    assert np.abs(st[0].j).max() <= 1e8 * (1 + 1e-6)
    assert np.abs(st[0].j).max() > 1e7


def test_refusals_of_a_units_group_speak_the_users_units():
    from openmotion.control.groups.group import GroupError

    ctl = Controller(machine(max_accel=2000.0), safety=False)
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=100.0, acc_time=0.02, units=True)   # mm, mm/s
    with pytest.raises(GroupError, match=r"axis x would need 5000 mm/s\^2 \(5e\+06 pps\^2\), "
                                         r"above its maximum acceleration 2000 mm/s\^2"):
        g.line([10.0, 0.0])
    assert g.queue_length == 0
    with pytest.raises(GroupError, match=r"system maximum speed 500 mm/s, got 600"):
        g.set_feed(600.0)
    c2 = Controller(machine(), safety=False)
    c2.enable_all()
    p = Group(c2, ["x", "y"], feed=200_000.0)            # a group in pulses: as before
    p.set_max_pulse_speed([100_000.0, 100_000.0])
    with pytest.raises(GroupError, match=r"would need 200000 pps at feed 200000, above its "
                                         r"maximum speed 100000 pps"):
        p.line([10_000.0, 0.0])
