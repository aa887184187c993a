"""The runner's spindle-speed followers: G95 feed per revolution on the measured speed,
and the G96 X reader.

A G95 move is planned for the fastest the spindle may turn during it (`ceiling_rps`: the
planned rpm, or in G96 the D limit / spindle maximum), and while it runs the group's feed
override is measured / ceiling speed (1 .. 200 %, re-planned on a 1 % change at most every
10 cycles, or at once on a 5 % change): the tool advances F per measured revolution, as
LinuxCNC's G95 follows spindle.N.speed-in. G33/G76/G33.1 have their own followers
(spindle.py, rigidtap_run.py).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .runoverride import segment_percent

if TYPE_CHECKING:
    from ..control.groups.group import Group
    from .convert import Op
    from .runner import ProgramRunner


def follow_per_rev(run: ProgramRunner, g: Group) -> None:
    """G95 on a spindle axis: the moves run at F x the measured speed (the group's feed
    override = the operator's override x the adaptive factor x measured / planned spindle
    speed, 1 .. 200 %); outside G95 the first two (runoverride.segment_percent)."""
    assert run.spindle is not None
    planned = run._per_rev_ops.get(g.current_index)
    run._feed_tick += 1
    base = segment_percent(run)  # the operator's override (100 under M50 P0 / M49), x
    if base <= 0.0:              # the adaptive factor; 0: adaptive feed holds the path
        return
    if planned is None:
        pct = base
    else:  # the speed averaged over the measuring window (a re-plan costs)
        pct = min(200.0, max(min(1.0, base), base * abs(run.spindle.revs_per_s()) / planned))
    step = abs(pct - g.override)
    if (planned is None and step > 0.0) or step >= 5.0 or (
            step >= 1.0 and run._feed_tick >= 10):
        g.set_override(pct)
        run._feed_tick = 0


def planned_rps(run: ProgramRunner, op: Op) -> float:
    """Spindle speed (rev/s) a G95 move was planned with (compile: S, or G96 at its
    start X)."""
    assert run.spindle is not None
    cmd = run.spindle._cmd
    if cmd is None or not cmd.on:
        return 0.0
    mode = run.spindle.css
    if mode is None:
        return cmd.speed / 60.0
    k = mode.x_axis
    x = float(run._cursor[k]) / float(run.scales.ppu[k])
    return mode.rpm(cmd.speed, x) / 60.0


def ceiling_rps(run: ProgramRunner, planned: float) -> float:
    """The fastest the spindle may turn during a G95 move (G96: D or the spindle's
    maximum; rpm mode: the planned speed): its feed is planned for it so that the
    follower's override stays at or below 100 %."""
    assert run.spindle is not None
    mode = run.spindle.css
    if mode is None:
        return planned
    return max(planned, min(mode.max_rpm, run.spindle.max_rpm) / 60.0)


def x_reader(run: ProgramRunner, k: int):
    ax = run._ctl.axes[run.axis_indices[k]]
    ppu = float(run.scales.ppu[k])
    return lambda: ax.position / ppu
