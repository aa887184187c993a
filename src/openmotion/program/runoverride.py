"""The operator's feed and spindle-speed overrides and the program's M48-M51 switches.

The operator sets a percentage (ProgramRunner.set_feed_override / set_spindle_override,
1 .. 200 %, at any time); the program switches each override on or off (M48/M49, M50,
M51: overrides.py), after the motion before the switch has ended. While a switch is off
the program runs at 100 %; both are on at the start of every pass. The group's feed
override is the operator's feed percentage while it is on (times the G95 follower's ratio
on a spindle axis, runfeed.py); spindle-synchronised motion (G33, G76, G33.1) owns the
group's override while it runs, as in LinuxCNC. The spindle's speed is S x the spindle
percentage while it is on (SpindleDrive.set_override).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import MotionError, check_finite

if TYPE_CHECKING:
    from ..control.groups.group import Group
    from .overrides import OverrideSwitch
    from .runner import ProgramRunner


def check_percent(name: str, percent: float) -> float:
    """An override percentage: a number in [1, 200]."""
    if isinstance(percent, bool) or not isinstance(percent, int | float):
        raise MotionError(f"{name} must be a number in [1, 200] %, got {percent!r}")
    p = check_finite(name, float(percent))
    if not 1.0 <= p <= 200.0:
        raise MotionError(f"{name} must be in [1, 200] %, got {percent!r}")
    return p


def feed_percent(run: ProgramRunner) -> float:
    """The feed override the program runs at now (100 while M50 P0 / M49 is in force)."""
    return run.feed_override if run.feed_override_on else 100.0


def spindle_factor(run: ProgramRunner) -> float:
    """The spindle-speed factor now (1 while M51 P0 / M49 is in force)."""
    return run.spindle_override / 100.0 if run.spindle_override_on else 1.0


def apply(run: ProgramRunner) -> None:
    """Bring the group's feed override and the spindle's factor up to date (with a
    spindle axis the G95 follower sets the feed override every cycle, runfeed.py)."""
    g = run.group
    if g is not None and run.spindle is None:
        pct = feed_percent(run)
        if g.override != pct:
            g.set_override(pct)
    if run.spindle is not None:
        run.spindle.set_override(spindle_factor(run))


def switch(run: ProgramRunner, sw: OverrideSwitch) -> None:
    """M48-M53 reached (the motion before it has ended)."""
    if sw.feed is not None:
        run.feed_override_on = sw.feed
    if sw.spindle is not None:
        run.spindle_override_on = sw.spindle
    if sw.feed_hold is not None:
        run.feed_hold_on = sw.feed_hold
        run._fh_check = True
    apply(run)


def reset(run: ProgramRunner) -> None:
    """A pass starts: both overrides and the feed-stop switch on (LinuxCNC's M2/M30 switch
    them on again)."""
    run.feed_override_on = run.spindle_override_on = run.feed_hold_on = True
    run._fh_check = True
    apply(run)


def feed_hold_step(run: ProgramRunner, g: Group) -> None:
    """Per cycle after a feed-stop edge or an M53 (`run._fh_check`): hold the path while
    the input is active and the switch on; go on once it is released (only a hold it made
    itself: an operator's pause() or an M0 stays paused)."""
    from ..control.groups.group import GroupState
    from .runtypes import RunState

    name = run.options.feed_hold_input
    if name is None:
        run._fh_check = False
        return
    active = run.feed_hold_on and bool(run._ctl.hardware.read_input(name))
    if active and run.state is RunState.RUNNING:
        run._hold()
        run.state = RunState.PAUSED
        run._fh_paused = True
        run._event("feed_hold", run.current_line, f"feed stop {name} active: holding")
    elif not active and run._fh_paused and run.state is RunState.PAUSED:
        if g.state is GroupState.HOLDING:
            return  # still decelerating: check again next cycle
        if g.state is GroupState.HELD:
            g.cont()
        run.state = RunState.RUNNING
        run._fh_paused = False
        run._event("feed_hold", run.current_line, f"feed stop {name} released")
    run._fh_check = False
