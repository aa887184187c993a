"""Corners blended ahead of a join (groupexec._preblend): a streamed, blended chain moves
bit for bit as without them, and its joins find their corners already blended."""

from __future__ import annotations

import math

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups import groupexec as gx
from openmotion.control.groups.group import Group, GroupState


def _stream(n: int) -> tuple[Controller, Group, dict[str, int]]:
    """n short segments on a wavy line, pushed one per cycle while the chain runs."""
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xy")
    ctl = Controller(MachineConfig(name="pre", axes=axes))
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], units=True, feed=40.0, acc_time=0.05)
    g.enable_blend(0.005)
    pts = iter([(0.05 * k, 0.5 * math.sin(k / 15.0)) for k in range(1, n + 1)])
    count = {"new": 0, "join_new": 0}
    run = g._blend_run  # every corner the group blends goes through it
    join = g._join_queued

    def blend_run(prev, cmds):  # noqa: ANN001, ANN202
        count["new"] += len(cmds)
        return run(prev, cmds)

    def join_queued(t: float) -> None:
        before = count["new"]
        join(t)
        count["join_new"] += count["new"] - before

    g._blend_run = blend_run  # type: ignore[method-assign]
    g._join_queued = join_queued  # type: ignore[method-assign]

    def feed(c: Controller, t: float) -> None:
        while g.queue_length < 64:
            p = next(pts, None)
            if p is None:
                return
            g.line(p)

    ctl.add_cycle_hook(feed)
    ctl.run_until(lambda: ctl.time > 0.01 and g.state is GroupState.IDLE
                  and g.queue_length == 0, 30.0)
    return ctl, g, count


@pytest.mark.parametrize("per_cycle", [0, gx.PREBLEND_PER_CYCLE])
def test_preblended_stream_moves_bit_for_bit_as_without(monkeypatch, per_cycle):
    ctl0, g0, c0 = _stream(600)
    monkeypatch.setattr(gx, "PREBLEND_PER_CYCLE", per_cycle)
    ctl1, g1, c1 = _stream(600)
    t = np.arange(0.0, ctl0.time, 0.00037)
    for i in (0, 1):
        a = [ctl0.history.state_at(i, x) for x in t]
        b = [ctl1.history.state_at(i, x) for x in t]
        assert [s.p for s in a] == [s.p for s in b]
        assert [s.v for s in a] == [s.v for s in b]
    assert ctl0.time == ctl1.time
    assert np.allclose([a.position for a in ctl1.axes], [30000.0, 500.0 * math.sin(40.0)],
                       rtol=0.0, atol=1e-9)
    if per_cycle == 0:  # every corner was blended inside a join
        assert c1["join_new"] > 500
    else:  # the joins found (almost) every corner done in the quiet cycles before them
        assert c1["join_new"] < 0.1 * c1["new"]
    assert not g1._pre  # nothing left behind
