"""The operator's feed and spindle-speed overrides, adaptive feed and the program's M48-M53
switches, as LinuxCNC's motion controller applies them.

The operator sets a percentage (ProgramRunner.set_feed_override / set_spindle_override,
1 .. 200 %, at any time). The program switches each override, adaptive feed (M52) and the
feed-stop switch (M53) on or off (overrides.py). LinuxCNC queues these "enables" with the
motion segments, so a switch takes effect where the next motion command starts, without
stopping a blended path: the runner binds a switch to the next command it queues (or, the
group at rest, applies it at once) and applies it in the cycle the group starts that
command (`step`; the cycle hook's `due` wakes at that command's exact start). The group's
feed override is then re-planned from where the path is, as LinuxCNC's planner changes its
feed scale at the segment: the path accelerates or decelerates in the new segment, within
every axis limit. Both overrides are on, adaptive feed off at the start of every pass.

The group's feed override for the command executing (`segment_percent`):
- spindle-synchronised motion (G33, G76, G33.1) runs at 100 %: LinuxCNC ignores the feed
  override, adaptive feed and feed hold there (tpGetFeedScale: position-synchronised
  segments scale 1.0). With a spindle axis the synchronised move sets the override itself
  (spindle.py, rigidtap_run.py); without one the commanded S x pitch is run as it is;
- otherwise the operator's percentage while the feed override is on (100 % off), times
  the adaptive factor while M52 P1 is in force. As in LinuxCNC 2.9 (control.c) adaptive
  feed scales every coordinated move, rapids included, and G95 moves (times the spindle
  follower's ratio, runfeed.py).

Adaptive feed (`RunOptions(adaptive_feed_input="ai<n>")`, LinuxCNC's motion.adaptive-feed):
the analog input is read every cycle while M52 P1 is in force and the factor is its value
clamped to 0 .. 1 (LinuxCNC 2.9 clamps to +-1), taken in 0.001 steps (finer changes would
only re-plan for nothing). 0 holds the path as a feed hold does (decelerating along it; it
goes on when the value rises again; a dwell is not held). A negative value means reverse
run in LinuxCNC 2.9 (the path run backwards): not supported here, so it holds the path the
same way and logs an `adaptive_feed` event naming the value, never runs forwards. M52 P1
without the option is refused when the program is bound (LinuxCNC's unconnected pin reads
1.0: a program asking for adaptive feed on a machine without the input would silently run
at full feed).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..errors import MotionError, check_finite
from . import canon
from .rigidtap import RigidTap

if TYPE_CHECKING:
    from ..control.groups.group import Group
    from .convert import Op
    from .overrides import OverrideSwitch
    from .runner import ProgramRunner

#: The adaptive factor's resolution (a change below it does not re-plan the path).
ADAPTIVE_STEP = 1e-3


@dataclass
class Pending:
    """A switch the feed has reached, waiting for the command it takes effect at (`index`,
    a group command index; None: the next command queued)."""

    sw: OverrideSwitch
    index: int | None = None


@dataclass
class SegmentState:
    """The runner's switch queue and what the command executing runs under."""

    pending: deque[Pending] = field(default_factory=deque)
    #: (group index, synchronised) where the next queued command changes between
    #: spindle-synchronised and ordinary motion
    marks: deque[tuple[int, bool]] = field(default_factory=deque)
    last_synced: bool = False   # the last command queued is spindle-synchronised
    synced: bool = False        # the command executing is (no override applies)
    adaptive: float = 1.0       # the adaptive factor in force (0 .. 1)
    held: bool = False          # the path is held by an adaptive factor of 0
    warned: bool = False        # the negative value of this excursion was logged


def check_percent(name: str, percent: float) -> float:
    """An override percentage: a number in [1, 200]."""
    if isinstance(percent, bool) or not isinstance(percent, int | float):
        raise MotionError(f"{name} must be a number in [1, 200] %, got {percent!r}")
    p = check_finite(name, float(percent))
    if not 1.0 <= p <= 200.0:
        raise MotionError(f"{name} must be in [1, 200] %, got {percent!r}")
    return p


def check_adaptive(run: ProgramRunner) -> None:
    """At bind time: the adaptive-feed input exists on the hardware, and a program with
    M52 P1 has one."""
    from .overrides import OverrideSwitch

    name = run.options.adaptive_feed_input
    if name is not None:
        try:
            run.analog_in.read(int(name[2:]))
        except MotionError as err:
            raise MotionError(f"adaptive_feed_input {name!r}: {err}") from None
        return
    on = next((c for c in run.commands if isinstance(c, OverrideSwitch) and c.adaptive), None)
    if on is not None:
        raise MotionError(f"line {on.line}: M52 P1 (adaptive feed) needs RunOptions("
                          "adaptive_feed_input='ai<n>'), the analog input that scales the "
                          "feed (openmotion run --adaptive-feed-input ai<n>)")


def feed_percent(run: ProgramRunner) -> float:
    """The operator's feed override as the program has it now (100 under M50 P0 / M49)."""
    return run.feed_override if run.feed_override_on else 100.0


def segment_percent(run: ProgramRunner) -> float:
    """The feed override for the command executing (module doc); 0 while adaptive feed
    holds the path."""
    st = run._seg
    if st.synced:
        return 100.0
    pct = feed_percent(run)
    if run.adaptive_feed_on and run.options.adaptive_feed_input is not None:
        pct *= st.adaptive
    return pct


def spindle_factor(run: ProgramRunner) -> float:
    """The spindle-speed factor now (1 while M51 P0 / M49 is in force)."""
    return run.spindle_override / 100.0 if run.spindle_override_on else 1.0


def apply(run: ProgramRunner) -> None:
    """Bring the group's feed override and the spindle's factor up to date (with a
    spindle axis the G95 follower sets the feed override every cycle, runfeed.py)."""
    g = run.group
    if g is not None and run.spindle is None:
        pct = segment_percent(run)
        if pct > 0.0 and g.override != pct:
            g.set_override(pct)
    if run.spindle is not None:
        run.spindle.set_override(spindle_factor(run))


def switch(run: ProgramRunner, sw: OverrideSwitch) -> None:
    """An M48-M53 takes effect (its command starts, or the group is at rest)."""
    if sw.feed is not None:
        run.feed_override_on = sw.feed
    if sw.spindle is not None:
        run.spindle_override_on = sw.spindle
    if sw.feed_hold is not None:
        run.feed_hold_on = sw.feed_hold
        run._fh_check = True
    if sw.adaptive is not None:
        run.adaptive_feed_on = sw.adaptive
        run._seg.warned = False
    run._event("action", sw.line, sw.text)
    apply(run)


def queue_switch(run: ProgramRunner, op: Op) -> None:
    """The feed reached an M48-M53: at once with the group at rest, else at the start of
    the next command queued."""
    from .overrides import OverrideSwitch

    assert isinstance(op.source, OverrideSwitch)
    if run._idle():
        switch(run, op.source)
    else:
        run._seg.pending.append(Pending(op.source))


def is_synced(op: Op) -> bool:
    """A G33/G76/G33.1 move run as a plain line (no spindle axis)."""
    return op.kind != "delay" and isinstance(op.source, canon.SyncedFeed | RigidTap)


def starts_sync(run: ProgramRunner, op: Op) -> bool:
    """Queuing `op` starts spindle-synchronised motion after ordinary motion: LinuxCNC
    does not blend into it (handleModeChange: an exact stop), so it waits for rest."""
    return is_synced(op) and not run._seg.last_synced


def pushed(run: ProgramRunner, index: int, op: Op, at_rest: bool) -> None:
    """Command `index` (op) was queued; `at_rest`: the group was at rest with nothing
    queued before it. Binds the waiting switches to it."""
    st = run._seg
    synced = is_synced(op)
    if at_rest:  # everything before it has run: it starts under its own settings
        while st.pending:
            switch(run, st.pending.popleft().sw)
        st.marks.clear()
        if synced != st.synced:
            st.synced = synced
            apply(run)
    else:
        for p in st.pending:
            if p.index is None:
                p.index = index
        if synced != st.last_synced:
            st.marks.append((index, synced))
    st.last_synced = synced


def flush(run: ProgramRunner) -> None:
    """The pass ends: the switches still waiting take effect."""
    st = run._seg
    while st.pending:
        switch(run, st.pending.popleft().sw)
    st.marks.clear()


def reset(run: ProgramRunner) -> None:
    """A pass starts: both overrides and the feed-stop switch on, adaptive feed off
    (LinuxCNC's start-up state; its M2/M30 switch the overrides on again)."""
    run.feed_override_on = run.spindle_override_on = run.feed_hold_on = True
    run.adaptive_feed_on = False
    run._seg = SegmentState()
    run._fh_check = True
    apply(run)


def in_sync(run: ProgramRunner) -> bool:
    """The command executing is spindle-synchronised (no override, no hold applies)."""
    from .rigidtap_run import RigidTapMove
    from .spindle import SyncMove

    return run._seg.synced or isinstance(run._request, SyncMove | RigidTapMove)


def due(run: ProgramRunner) -> float:
    """When `step` must next run (Controller.add_cycle_hook): every cycle while adaptive
    feed is read or holds the path; at the start of the command a waiting switch or a
    synchronised change is bound to; at rest for the switches not bound yet."""
    st = run._seg
    g = run.group
    if g is None:
        return math.inf
    if st.held or (run.adaptive_feed_on and run.options.adaptive_feed_input is not None):
        return -math.inf
    if not st.pending and not st.marks:
        return math.inf
    if run._idle():
        return -math.inf
    firsts = [i for i in (st.pending[0].index if st.pending else None,
                          st.marks[0][0] if st.marks else None) if i is not None]
    if not firsts:
        return math.inf  # applied at rest: the motion's end lands the jump
    now = run._ctl.time
    t = g.start_time(min(firsts), now, now + 1e9)
    return math.inf if t is None else t


def step(run: ProgramRunner, g: Group) -> None:
    """Per cycle (see `due`): the switches and synchronised changes whose command has
    started take effect; adaptive feed follows its input."""
    st = run._seg
    if st.pending or st.marks:
        idx = g.current_index
        rest = run._idle()
        changed = False
        while st.pending and (rest or (st.pending[0].index is not None
                                       and idx >= st.pending[0].index)):
            switch(run, st.pending.popleft().sw)
        while st.marks and (rest or idx >= st.marks[0][0]):
            st.synced = st.marks.popleft()[1]
            changed = True
        if changed:
            apply(run)
    if run.adaptive_feed_on and run.options.adaptive_feed_input is not None:
        adaptive_step(run, g)
    elif st.held:
        release(run, g)


def adaptive_factor(value: float) -> float:
    """The factor of an adaptive-feed reading: clamped to 0 .. 1 in ADAPTIVE_STEP steps
    (a negative or non-finite value: 0)."""
    if not math.isfinite(value) or value <= 0.0:
        return 0.0
    return min(1.0, round(value / ADAPTIVE_STEP) * ADAPTIVE_STEP)


def adaptive_step(run: ProgramRunner, g: Group) -> None:
    """Read the adaptive-feed input: scale the feed, hold at 0, go on when it rises."""
    from ..control.groups.group import GroupState
    from .runtypes import RunState

    st = run._seg
    name = run.options.adaptive_feed_input
    assert name is not None
    value = run.analog_in.read(int(name[2:]))
    a = adaptive_factor(value)
    why = f"adaptive feed {name} = {value:g}: "
    if value < 0.0 or not math.isfinite(value):  # said once per excursion
        why += "reverse run is not supported; " if math.isfinite(value) else "not a number; "
        if not st.warned and st.held:
            run._event("adaptive_feed", run.current_line, why + "holding")
        st.warned = True
    else:
        st.warned = False
    if a != st.adaptive:
        st.adaptive = a
        if a > 0.0:
            apply(run)
    if a == 0.0:  # (again after an operator's resume while the input is still at 0)
        cur = run.op_of.get(g.current_index)
        if g.state is GroupState.MOVING and run.state is RunState.RUNNING \
                and not in_sync(run) and (cur is None or cur.kind != "delay"):
            g.hold()
            if not st.held:
                run._event("adaptive_feed", run.current_line, why + "holding")
            st.held = True
    elif st.held:
        release(run, g)


def release(run: ProgramRunner, g: Group) -> None:
    """Go on after an adaptive hold (once it rests; not while the operator or a feed-stop
    input holds the program)."""
    from ..control.groups.group import GroupState
    from .runtypes import RunState

    st = run._seg
    if g.state is GroupState.HOLDING:
        return  # still decelerating
    if g.state is GroupState.HELD:
        if run.state is not RunState.RUNNING:
            return  # paused by someone else: their resume continues
        g.cont()
        run._event("adaptive_feed", run.current_line, "adaptive feed: going on")
    st.held = False


def feed_hold_step(run: ProgramRunner, g: Group) -> None:
    """Per cycle after a feed-stop edge or an M53 (`run._fh_check`): hold the path while
    the input is active and the switch on; go on once it is released (only a hold it made
    itself: an operator's pause() or an M0 stays paused). A spindle-synchronised move runs
    to its end first (LinuxCNC does not hold position-synchronised segments)."""
    from ..control.groups.group import GroupState
    from .runtypes import RunState

    name = run.options.feed_hold_input
    if name is None:
        run._fh_check = False
        return
    active = run.feed_hold_on and bool(run._ctl.hardware.read_input(name))
    if active and run.state is RunState.RUNNING:
        if in_sync(run):
            return  # checked again next cycle
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
