"""HomeConfig checks types; Homing.start() is atomic (issue #12 defect 8).

HomeConfig(max_vel="5000") or a Decimal was accepted, then Homing.start() raised
TypeError and left the axis in Homing with its hooks attached.
"""

from __future__ import annotations

from decimal import Decimal

import numpy as np
import pytest

from openmotion.control import AxisState, Controller
from openmotion.control.guard.safety import Safety
from openmotion.control.home.homing import HomeConfig, Homing
from openmotion.errors import MotionError


@pytest.mark.parametrize("name", ["str_vel", "max_vel", "tacc", "jerk", "org_offset",
                                  "home_offset", "search_range", "max_overrun", "settle_s",
                                  "timeout_s"])
@pytest.mark.parametrize("bad", ["5000", Decimal("5000"), True, np.array([5000.0]),
                                 float("nan"), 10**400, 1e300, -1.0])
def test_home_config_refuses_non_numbers_and_out_of_range(name, bad):
    if bad == -1.0 and name == "home_offset":
        pytest.skip("a negative home offset is valid")
    with pytest.raises(MotionError, match=name):
        HomeConfig(**{name: bad})


@pytest.mark.parametrize("name, bad", [("direction", True), ("direction", 1.0),
                                       ("auto_search", 1), ("phase1_same_direction", "yes"),
                                       ("final", ["mark"]), ("el_stop", None),
                                       ("ez_count", 1.0), ("mode", True)])
def test_home_config_refuses_wrong_types(name, bad):
    with pytest.raises(MotionError, match=name):
        HomeConfig(**{name: bad})


def test_home_config_stores_floats():
    c = HomeConfig(str_vel=np.float32(500), max_vel=np.int64(5000), tacc=1)
    assert type(c.max_vel) is float and type(c.str_vel) is float and type(c.tacc) is float


def _machine():
    ctl = Controller(safety=False)
    safety = Safety(ctl)
    ctl.enable_all()
    ctl.hardware.scenario.place_switch(0, "org", 2000.0, 3000.0, 50.0)
    return ctl, safety


def _attached(ctl, safety, ax):
    return (ax.state, len(ctl._edge_hooks), len(ctl._cycle_hooks),
            [sorted(c.suspended) for c in safety._cfg])


def test_start_that_fails_midway_leaves_nothing_behind(monkeypatch):
    ctl, safety = _machine()
    ax = ctl.axis("x")
    h = Homing(ctl, "x", HomeConfig(mode=0, str_vel=2000.0, max_vel=20000.0, tacc=0.05),
               safety=safety)
    before = _attached(ctl, safety, ax)
    status = h.status
    suspended_during = []

    def broken(*args, **kw):
        suspended_during.append(_attached(ctl, safety, ax))
        raise TypeError("a planner failed")


    monkeypatch.setattr(h, "_begin_phase", broken)
    with pytest.raises(TypeError):
        h.start()
    assert suspended_during and suspended_during[0] != before  # it had attached things
    assert _attached(ctl, safety, ax) == before
    assert ax.state is AxisState.STANDSTILL
    assert h.status is status and not h.running
    monkeypatch.undo()
    h.start()  # the same object starts cleanly afterwards
    assert h.running
    assert ctl.run_until(lambda: not h.running, 120.0, event_driven=True)
    assert h.done
