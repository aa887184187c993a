"""The join instant of a streaming group (groupdue._join_due), found in vectorised blocks of
cycle ends, is the cycle the scalar scan of `PathPlan.remaining` finds (the oracle here),
for every plan and queue head a streamed program passes through."""

from __future__ import annotations

import math

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups import groupdue
from openmotion.control.groups.group import Group, GroupState


def _scalar_join_due(g, ctl: Controller) -> float:  # noqa: ANN001
    """The cycle-by-cycle scan (the code before the vectorised one), no cache."""
    r = g._run
    if r is None or r.plan is None or g._state is not GroupState.MOVING:
        return math.inf
    plan = r.plan
    q0 = g._queue[0]
    if not g._joins(plan.tj, q0, plan.limits.str_vel):
        return math.inf
    reach = max(g._reach(q0, plan.tj), g._reach(r.cmds[-1], plan.tj))
    origin, period, n = ctl._t_origin, ctl.period, ctl.cycles
    for k in range(n + 1, n + groupdue.JOIN_HORIZON + 1):
        t = origin + k * period
        if t >= plan.t0 and plan.remaining(t) < reach:
            return t
    return origin + (n + groupdue.JOIN_HORIZON) * period


def test_vectorised_join_due_equals_the_scalar_scan(monkeypatch):
    monkeypatch.setattr(groupdue, "JOIN_BLOCK", 16)  # answers inside and beyond a block
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xy")
    ctl = Controller(MachineConfig(name="due", axes=axes))
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], units=True, feed=40.0, acc_time=0.05, queue_size=1024)
    g.enable_blend(0.005)
    pts = iter([(0.05 * k, 0.5 * math.sin(k / 15.0)) for k in range(1, 251)])
    checked = []

    def feed(c: Controller, t: float) -> None:
        for _ in range(3):
            p = next(pts, None) if g.queue_length < 200 else None
            if p is None:
                break
            g.line(p)
        if g.queue_length and g._run is not None and c.cycles % 3 == 0:
            g.__dict__.pop("_join_due_cache", None)  # the scan from the next cycle on
            want = _scalar_join_due(g, c)
            assert groupdue._join_due(g, c) == want
            if math.isfinite(want):
                checked.append(round((want - c.time) / c.period))

    ctl.add_cycle_hook(feed)
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                         and next(pts, None) is None, 60.0)
    # answers near and far (beyond one block)
    assert min(checked) <= 2 and max(checked) > groupdue.JOIN_BLOCK
