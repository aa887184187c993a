"""When a group's cycle hook may next act (Controller.add_cycle_hook(..., due=...)).

`GroupEngine._cycle_step` acts on a few instants only: a queued command becoming due (the
group idle or the running command ended), the end of a delay, the renewal of a path
window, the cycle in which the running chain has less than its reach ahead (a join), and
the pre-blending of queued corners, the cycle a command blends in over the running one and
the end of a blend's overlay when a hold or override waits for it. Between them a running
line or arc needs nothing from Python, so virtual time may jump (control/core/jump.py).
`group_due` returns the earliest of those instants (a join in flight, real time: its install
cycle); -inf ("every cycle") wherever the answer is not cheap and sure: pre-blending still
to do in real time, a group axis in ErrorStop or standing on a limit switch (the limit
check depends on the velocity's sign cycle by cycle). Pre-blending spreads a join's corner
work over the quiet cycles before it, which matters only where a cycle has a deadline: in
virtual time it is not due (the join blends the corners no quiet cycle prepared, the very
same corners: tests/test_group_preblend.py), so a streamed chain jumps from join to join.

The join instant is found on the very cycle grid the hook sees, by evaluating the plan's
`remaining(t)` at the cycle ends ahead (vectorised, blocks of JOIN_BLOCK cycles, the same
arithmetic as `Profile.state_at`; cached while the plan and the queue head stay the same),
so the cycle found is the one the cycle-by-cycle run joins in.
"""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.states import AxisState

if TYPE_CHECKING:
    from ..core.controller import Controller

#: How many cycle ends ahead one due call looks for the join cycle (then it asks again).
JOIN_HORIZON = 4096
#: Cycle ends evaluated per vectorised pass of that search.
JOIN_BLOCK = 256


def group_due(g: Any, ctl: Controller) -> float:
    """Earliest time the group's `_on_cycle` may act (see the module docstring)."""
    from .groupexec import PATH_WINDOW_S, GroupState

    state = g._state
    if state is GroupState.ERROR:
        return math.inf
    if g._job is not None:
        return _in_flight_due(g, ctl)
    r = g._run
    due = math.inf
    if r is not None:
        if not g._dry and _faults_pending(g, ctl):
            return -math.inf
        if r.window_end is not None:
            due = min(due, r.window_end - 0.5 * PATH_WINDOW_S)
        if r.kind == "delay" and g._queue:
            due = min(due, r.t_until - ctl.period)
        due = min(due, r.t_end - 1e-12)
        if r.blend_at is not None and g._queue:  # the cycle the next command blends in
            due = min(due, r.blend_at - ctl.period)
        if r.deferred is not None and r.overlay_end is not None:  # a hold/override waits
            due = min(due, r.overlay_end - 1e-12)
    elif state in (GroupState.MOVING, GroupState.IDLE):
        return -math.inf if g._queue or state is GroupState.MOVING else due
    if g._queue:
        if ctl.realtime and _preblend_pending(g):
            return -math.inf
        due = min(due, _join_due(g, ctl))
    return due


def _in_flight_due(g: Any, ctl: Controller) -> float:
    """A join in flight (real time, groupjoin.py): `_poll_join` acts at its install cycle,
    or when the plan or the settings changed (only a command or a hook changes them, and
    either lands a cycle); before that `_cycle_step` only checks faults and renews the
    path window."""
    from .groupexec import PATH_WINDOW_S, GroupState

    r = g._run
    if r is None or g._state is not GroupState.MOVING or (
            not g._dry and _faults_pending(g, ctl)):
        return -math.inf
    due = g._job.t_j - 0.5 * ctl.period
    if r.window_end is not None:
        due = min(due, r.window_end - 0.5 * PATH_WINDOW_S)
    return due


def _faults_pending(g: Any, ctl: Controller) -> bool:
    """A group axis in ErrorStop, or on an end limit (checked every cycle then)."""
    for a in g.axes:
        if a.state is AxisState.ERROR_STOP:
            return True
        if ctl.input_active(a.index, "pel") or ctl.input_active(a.index, "mel"):
            return True
    return False


def _preblend_pending(g: Any) -> bool:
    """Whether `_preblend` would change anything this cycle (see groupstream.py)."""
    from .groupexec import PREBLEND_AHEAD, PREBLEND_PER_CYCLE, GroupState

    r, q, pre = g._run, g._queue, g._pre
    if r is None or r.plan is None or not q or not (g._blend and g._blend_tol > 0.0) \
            or g._state is not GroupState.MOVING:
        return bool(pre)
    prev = r.plan.chain.elements[-1]
    head = pre.get(q[0].index)
    i = 0
    if head is not None and head[0] is prev and g._pre_tail is not None:
        tail, _ = g._pre_tail
        i = tail - q[0].index + 1
        if not (0 < i <= len(q) and q[i - 1].index == tail):
            i = 0
    if i == 0 and pre:
        return True
    end = min(len(q), i + PREBLEND_PER_CYCLE, PREBLEND_AHEAD)
    for c in itertools.islice(q, i, end):
        return bool(g._joins(r.plan.tj, c, r.plan.limits.str_vel))
    return False


def _join_due(g: Any, ctl: Controller) -> float:
    """The end time of the first cycle ahead in which `_join_queued` joins (or a later
    cycle end to ask again; inf when it cannot join the running chain)."""
    from .groupexec import GroupState

    r = g._run
    if r is None or r.plan is None or g._state is not GroupState.MOVING:
        return math.inf
    plan = r.plan
    q0 = g._queue[0]
    if not g._joins(plan.tj, q0, plan.limits.str_vel):
        return math.inf
    reach = max(g._reach(q0, plan.tj), g._reach(r.cmds[-1], plan.tj))
    origin, period, n = ctl._t_origin, ctl.period, ctl.cycles
    key = (q0.index, reach)
    cache = g.__dict__.get("_join_due_cache")
    k = n + 1
    if cache is not None and cache[0] is plan and cache[1] == key:
        k = max(k, cache[2])  # the cycles before it were checked: no join there
    last = n + JOIN_HORIZON
    raw = plan.raw
    while k <= last:  # the cycle ends ahead in blocks, each in one vectorised pass
        ks = np.arange(k, min(k + JOIN_BLOCK, last + 1))
        t = origin + ks * period
        if raw.n_segments:  # plan.remaining(t), as Profile.state_at computes it
            u = np.minimum(np.maximum(t - plan.raw_t0, 0.0), raw.duration)
            rem = plan.chain.length - raw.sample(u).p
        else:
            rem = np.array([plan.remaining(float(x)) for x in t])
        hit = np.flatnonzero((t >= plan.t0) & (rem < reach))
        if len(hit):
            k = int(ks[hit[0]])
            g._join_due_cache = (plan, key, k)
            return float(t[hit[0]])
        k = int(ks[-1]) + 1
    g._join_due_cache = (plan, key, k)
    return origin + last * period
