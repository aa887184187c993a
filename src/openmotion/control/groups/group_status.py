"""The status side of a `Group` (group.py): state, command index at a time, positions.

What a group reports without changing anything: its state and error, the queue, the
command the running (or held) chain executes at a time (`index_at`, vectorised
`indices_at`/`index_lookup` for a trace, `start_of`/`start_time`: the instant a command
starts), where the group is and where its queue ends, and the command being executed
(`CommandInfo`). The chain's arithmetic is the run's own (pathexec.py, pathrun.py).
"""

from __future__ import annotations

import bisect
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .group_settings import GroupSettings
from .groupdue import group_due
from .groupexec import GroupState

if TYPE_CHECKING:
    from ..core.controller import Controller


def _turn(basis: tuple[np.ndarray, np.ndarray]) -> str:
    """CW / CCW of a 3-D arc seen in the first of the planes xy, yz, zx it is not edge-on
    to (the plane of an MCC_ArcXY / YZ / ZX), "3D" when it is edge-on to all."""
    e1, e2 = basis
    n = len(e1)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        if i < n and j < n:
            z = float(e1[i] * e2[j] - e1[j] * e2[i])
            if abs(z) > 1e-9:
                return "CCW" if z > 0.0 else "CW"
    return "3D"


@dataclass(frozen=True)
class CommandInfo:
    """The command a group executes: index, kind (ptp, path, delay), element type (Line,
    Arc, Arc3D), arc direction ("CW", "CCW", "3D" or None), feed (PtP: the speed
    ratio %), target (logical units; None for a delay)."""

    index: int
    kind: str
    element: str
    direction: str | None
    feed: float
    target: np.ndarray | None


class GroupStatus(GroupSettings):
    """Base of `Group`: what it reports (state, indices, positions, the command)."""

    # ------------------------------------------------------------------ status
    @property
    def state(self) -> GroupState:
        return self._state

    @property
    def error_code(self) -> int:
        """0, or the negative code of the run-time error that stopped the group."""
        return self._error

    @property
    def error_message(self) -> str:
        return self._error_msg

    @property
    def queue_length(self) -> int:
        return len(self._queue)

    @property
    def current_index(self) -> int:
        """Index of the command being executed (-1 when none)."""
        return self.index_at(self._ctl.time)

    def index_at(self, t: float) -> int:
        """Index of the command the running (or held) chain executes at time t (-1 when
        none); for times the present run covers."""
        r = self._run or self._held
        if r is None:
            return -1
        memo = self._index_memo  # asked several times a cycle (runner, outputs, progress)
        if memo is not None and memo[0] == t and memo[1] is r and memo[2] is r.plan:
            return memo[3]
        if r.plan is not None:
            chain = r.plan.chain
            idx = chain.owners[chain.locate(r.plan.s_at(t))]
        else:
            idx = r.cmds[0].index
        self._index_memo = (t, r, r.plan, idx)
        return idx

    def indices_at(self, ts: np.ndarray) -> np.ndarray:
        """`index_at` at each of the times `ts` (float64 array) in one vectorised pass,
        the same values (the same arithmetic as `Profile.state_at`, `Chain.locate`)."""
        return self.index_lookup()(ts)

    def index_lookup(self) -> Callable[[np.ndarray], np.ndarray]:
        """`indices_at` for the present run, kept: it gives the same values later, when
        the group runs something else (plans never change once made), so a trace of the
        cycles a jump crossed can look them up when it is read (program/trace.py)."""
        r = self._run or self._held
        plan = r.plan if r is not None else None
        memo = self._lookup_memo  # one object per run and plan (program/trace.py groups by it)
        if memo is not None and memo[0] is r and memo[1] is plan:
            return memo[2]
        fn = self._make_lookup(r)
        self._lookup_memo = (r, plan, fn)
        return fn

    def _make_lookup(self, r: Any) -> Callable[[np.ndarray], np.ndarray]:
        if r is None or r.plan is None:
            idx = -1 if r is None else r.cmds[0].index
            return lambda ts: np.full(len(ts), idx, dtype=np.int64)
        plan = r.plan
        sprof, chain = plan.sprof, plan.chain
        if not sprof.n_segments:  # (Profile.sample needs segments): as index_at does
            return lambda ts: np.array([chain.owners[chain.locate(plan.s_at(float(t)))]
                                        for t in ts], dtype=np.int64)
        owners = self._owners_memo
        if owners is None or owners[0] is not chain:  # chains never change once made
            owners = self._owners_memo = (chain, np.asarray(chain.owners, dtype=np.int64))
        table, t0, last = owners[1], plan.t0, len(chain.elements) - 1

        def lookup(ts: np.ndarray) -> np.ndarray:
            u = np.minimum(np.maximum(ts - t0, 0.0), sprof.duration)
            k = np.searchsorted(chain.cum, sprof.sample(u).p, side="right") - 1
            np.clip(k, 0, last, out=k)
            return table[k]

        return lookup

    def start_of(self, index: int) -> float | None:
        """The exact instant the present run starts command `index` or a later one
        (`start_time` over the whole run: the first instant `index_at` reports one of
        them), or None when the present run does not hold it (a later plan will: it is
        made in a cycle the group's hook runs). Kept per run, plan and index (plans never
        change once made), so a due function may ask it at every landing."""
        r = self._run
        if r is None:
            return None
        memo = self.__dict__.get("_start_memo")
        if memo is not None and memo[0] is r and memo[1] is r.plan and memo[2] == index:
            return memo[3]
        if r.plan is None:
            t = r.t0 if r.cmds[0].index >= index else None
        else:
            t = self.start_time(index, r.plan.t0, r.plan.t_end)
        self._start_memo = (r, r.plan, index, t)
        return t

    def start_time(self, index: int, t0: float, t1: float) -> float | None:
        """The exact time in [t0, t1] at which the running (or held) chain starts command
        `index` or a later one: the first instant `index_at` reports one of them (t0 when
        it already does at t0); None when it does not by t1 or nothing runs. Found on the
        chain position (where the command's first element starts), so a command that ends
        where it began (a full circle) or a blend arc it owns count from their start. For
        times the present run covers (e.g. the coming cycle, before the hardware runs)."""
        r = self._run or self._held
        if r is None or t1 < t0:
            return None
        if r.plan is None:
            return max(r.t0, t0) if r.cmds[0].index >= index and r.t0 <= t1 else None
        plan = r.plan
        k = bisect.bisect_left(plan.chain.owners, index)  # owners follow the queue order
        if k >= len(plan.chain.owners):
            return None
        s_b = float(plan.chain.cum[k])
        if plan.s_at(t0) >= s_b:
            return t0
        if plan.s_at(t1) < s_b:
            return None
        lo, hi = t0, t1  # s(lo) < s_b <= s(hi); s(t) never decreases
        while True:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                return hi
            if plan.s_at(mid) >= s_b:
                hi = mid
            else:
                lo = mid

    def _due(self, ctl: Controller) -> float:
        """When the cycle hook may next act (control/groups/groupdue.py)."""
        return group_due(self, ctl)

    @property
    def position(self) -> np.ndarray:
        """Logical positions (pulses, or user units): the axes' command positions, or in
        dry run the planned positions the pulses would have reached."""
        if not self._dry:
            return self._units_of(np.array([a.position for a in self.axes]))
        r = self._run
        if r is not None and r.profiles:
            u = self._ctl.time - r.t0
            return self._units_of(np.array([p.state_at(min(max(u, 0.0), p.duration)).p
                                            for p in r.profiles]))
        return self._units_of(self._dry_pos)

    @property
    def end_point(self) -> np.ndarray:
        """Where the last queued command ends (logical units): the start point of a
        relative command; the position when nothing is queued or running."""
        if self._tail is None or (self._run is None and not self._queue
                                  and self._held is None):
            return self.position
        return self._tail.copy()

    @property
    def current_command(self) -> CommandInfo | None:
        """The command being executed (MCC_GetCurCommand), None when none is."""
        r = self._run or self._held
        if r is None:
            return None
        idx = self.current_index
        cmd = next((c for c in r.cmds if c.index == idx), r.cmds[0])
        el = cmd.elements[0] if cmd.elements else None
        target = cmd.target if cmd.kind == "ptp" else (
            None if el is None else np.array(el.end, dtype=float))
        direction = str(getattr(getattr(el, "direction", None), "name", "")) or None
        if el is not None and getattr(el, "via", None) is not None:
            direction = _turn(el.basis)
        feed = self._ptp_ratio if cmd.kind == "ptp" else cmd.feed
        return CommandInfo(cmd.index, cmd.kind, type(el).__name__ if el is not None
                           else cmd.kind, direction, feed,
                           None if target is None else np.asarray(target, float).copy())

    @property
    def commands_pending(self) -> int:
        """Commands accepted and not yet started (MCC_GetCommandCount): the queue and the
        commands a running chain has taken in ahead of the one it executes."""
        r = self._run or self._held
        ahead = 0
        if r is not None:
            cur = self.current_index
            ahead = sum(1 for c in r.cmds if c.index > cur)
        return len(self._queue) + ahead

    @property
    def units(self) -> bool:
        """Whether logical coordinates are user units (False: command pulses)."""
        return bool(np.any(self._k != 1.0))

    @property
    def str_vel(self) -> float:
        """StrVel of the following path commands (pps, or user units/s)."""
        return self._str_vel

    @property
    def override(self) -> float:
        return self._override * 100.0

    @property
    def dry_run(self) -> bool:
        return self._dry
