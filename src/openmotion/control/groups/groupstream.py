"""The streaming look-ahead of a group's running chain (a mixin of `GroupEngine`).

Klipper's lazy flush: a chain holds the queued commands up to twice the distance it needs
to brake from its feed (`_reach`, `_take`) and joins the next ones when it runs short
(`_join_queued`): the running chain re-planned from now over itself and the new commands
(pathrun.replan; the join's speed curve in one compiled pass, _chain.c), with the corner
between them blended when the path has not reached the blend's start yet
(`_join_options`). Every corner is rounded where that pays (`_blend_run`: each run of
lines in one compiled call, path/blend.py `_line_run`; other corners `_blend_new`,
`_blend_pays`); quiet cycles blend the queued corners ahead of the join (`_preblend`).
In real-time mode the re-plan runs on the join worker (groupjoin.py). The constants
(MAX_JOIN, PREBLEND_PER_CYCLE, PREBLEND_AHEAD) live in groupexec.py and are read there at
each use.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections import deque
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import InfeasibleError, MotionError
from ...path import blend_corner, speed_caps
from ...path.blend import _corner_max_dim, _line_run
from ...path.geometry import Line, PathElement
from ...path.lookahead import _element_limits as element_limits
from ...path.smoothing import jerk_window
from ...profile.segments import Profile
from . import pathexec as px
from . import pathrun
from .grouptypes import ERR_AXIS_STATE, GroupState, _Cmd, _Run

if TYPE_CHECKING:
    from ..core.controller import Controller


class ChainStream:
    """Mixin of `GroupEngine`: joining queued path commands to the running chain."""

    _ctl: Controller
    _queue: deque[_Cmd]
    _pre: dict[int, tuple[Any, ...]]
    _pre_tail: tuple[int, Any] | None
    _state: GroupState
    _run: _Run | None
    _job: Any
    _override: float
    _sys_max: float
    _wait_inpos: bool
    _blend: bool
    _blend_tol: float
    _corner_velocity: float
    sync_joins: int

    def _joins(self, tj: float, cmd: _Cmd, str_vel: float = 0.0) -> bool:
        """Whether `cmd` can join a chain smoothed with window tj (0: a T chain) that starts
        and ends at `str_vel`: a path command of the same shape and StrVel whose own window
        fits in tj (its jerk stays bounded)."""
        if cmd.kind != "path" or cmd.str_vel != str_vel or self._wait_inpos or \
                self._alone(cmd):
            return False
        if tj == 0.0 or not cmd.jerk:
            return tj == 0.0 and not cmd.jerk
        return jerk_window(cmd.window_accel, cmd.jerk) <= tj * (1.0 + 1e-12)

    def _reach(self, cmd: _Cmd, tj: float) -> float:
        """Path length a chain should keep ahead for `cmd`: twice what it takes to brake
        from its feed (override included), plus a few cycles and the smoothing window, so
        joining commands never makes the running motion brake for the chain's end."""
        f = min(cmd.feed * self._override, self._sys_max)
        ahead = 4.0 * self._ctl.period + tj
        if self._ctl.realtime:  # a join in flight (groupjoin.py) must not see the end
            ahead += (self._lead_cycles() + 2) * self._ctl.period
        return 2.0 * (f * f / (2.0 * cmd.dec) + f * ahead)

    def _take(self, tj: float, have: float, cmds: list[_Cmd]) -> list[_Cmd]:
        """Pop the queued commands that join a chain with `have` length ahead until it
        holds twice its reach (Klipper's lazy flush: the rest waits in the queue)."""
        max_join = _groupexec().MAX_JOIN  # (read at each use: see the module doc)
        out: list[_Cmd] = []
        reach = max(self._reach(c, tj) for c in cmds[-1:]) if cmds else 0.0
        sv = cmds[0].str_vel if cmds else 0.0
        while self._queue and len(out) < max_join and self._joins(tj, self._queue[0], sv):
            reach = max(reach, self._reach(self._queue[0], tj))
            if have >= 2.0 * reach:
                break
            c = self._queue.popleft()
            out.append(c)
            have += c.elements[0].length
        return out

    def _join_queued(self, t: float) -> None:
        """Streaming look-ahead: when the running chain has less than its reach ahead, join
        the next queued path commands and re-plan from now. The corner with the running
        chain is blended when the path has not yet reached the blend's start; otherwise the
        corner keeps its exact stop (or junction speed). A join that cannot be followed
        from the present speed leaves the commands queued (they start after the chain).
        In real-time mode the re-plan runs on the join worker (groupjoin.py)."""
        r = self._run
        if r is None or r.plan is None or self._state is not GroupState.MOVING or \
                self._job is not None:
            return
        plan = r.plan
        if plan.move is not None or r.overlay_end is not None:
            return  # a command run alone, or a time-overlap blend: no chain to join
        if t < plan.t0 or not self._joins(plan.tj, self._queue[0], plan.limits.str_vel):
            return  # (a plan starting later in this cycle joins from the next one)
        reach = max(self._reach(self._queue[0], plan.tj), self._reach(r.cmds[-1], plan.tj))
        memo = self.__dict__.get("_have_memo")
        if memo is not None and memo[0] is plan and t >= memo[1]:
            # a lower bound of the length ahead from the last evaluation and the plan's
            # peak raw speed: no join while it holds the reach (what the evaluation would
            # say), without evaluating s(t) every cycle
            dt = t - memo[1]
            low = memo[2] - memo[3] * dt * (1.0 + 1e-9) - 1e-9 * max(1.0, plan.chain.length)
            if low >= reach:
                return
        have = plan.remaining(t)
        self._have_memo = (plan, t, have, _peak_speed(plan.raw))
        if have >= reach:
            return
        new = self._take(plan.tj, have, [r.cmds[-1]])
        if not new:
            return
        if self._use_worker(plan):
            self._join_async(r, new)
            return
        if self._ctl.realtime:
            self.sync_joins += 1
        for chain in self._join_options(plan, have, new):
            try:
                p2 = pathrun.replan(plan, t, chain=chain,
                                    limits=self._limits(chain, plan.limits.str_vel))
            except InfeasibleError:
                continue
            try:
                self._launch(p2, [*r.cmds, *new], t)
            except MotionError as err:  # refused by an axis (safety): stop the group
                self._fault(getattr(err, "code", ERR_AXIS_STATE), f"join refused: {err}")
            return
        self._queue.extendleft(reversed(new))

    def _join_options(self, plan: pathrun.PathPlan, have: float, new: list[_Cmd],
                      pre: dict[int, tuple[Any, ...]] | None = None) -> Iterator[px.Chain]:
        """The running chain joined with `new`: first with the corner between them blended
        (when the path has not reached the blend's start yet), then with that corner kept
        as it is. Lazy: the second is built only when the first is missing or refused.
        `pre`: the pre-blend cache to use (the join worker's copy; default the group's)."""
        s_raw = plan.chain.length - have
        last = plan.chain.elements[-1]
        first, els, owners = self._elements(new, last, pre)
        if first is not last and s_raw < float(plan.chain.cum[-2]) + first.length:
            yield plan.chain.joined(els, owners, *self._per(owners, new), replace_last=first)
        if first is not last:  # without the blend the new elements differ: rebuild them
            _, els, owners = self._elements(new)
        yield plan.chain.joined(els, owners, *self._per(owners, new))

    @staticmethod
    def _per(owners: list[int], cmds: list[_Cmd]
             ) -> tuple[list[float], list[float], list[float] | None]:
        """Feed, acceleration and deceleration (None when no command sets one apart) of
        each element, from the command that owns it."""
        by = {c.index: c for c in cmds}
        dec = None if all(c.decel is None for c in cmds) else [by[o].dec for o in owners]
        return [by[o].feed for o in owners], [by[o].accel for o in owners], dec

    def _chain(self, cmds: list[_Cmd]) -> px.Chain:
        """The commands' elements end to end, corners blended where that pays."""
        _, els, owners = self._elements(cmds)
        return px.Chain(els, owners, *self._per(owners, cmds))

    def _elements(self, cmds: list[_Cmd], prev: PathElement | None = None,
                  pre: dict[int, tuple[Any, ...]] | None = None
                  ) -> tuple[PathElement | None, list[PathElement], list[int]]:
        """The commands' elements (and owners), each corner blended where that pays; with
        `prev` (the last element before them) the first corner too: `prev` comes back
        trimmed by that blend (or unchanged). A corner `_preblend` prepared goes through
        `_blend_pair`, each stretch of the others through one `_blend_run`."""
        cache = self._pre if pre is None else pre
        els: list[PathElement] = [prev] if prev is not None else []
        owners: list[int] = [-1] if prev is not None else []
        i, n = 0, len(cmds)
        if prev is None and cmds:
            els.append(cmds[0].elements[0])
            owners.append(cmds[0].index)
            i = 1
        while i < n:
            if cmds[i].index in cache:
                j = i + 1
                got = [self._blend_pair(els[-1], cmds[i].elements[0], cmds[i], pre)]
            else:  # (no prepared corner: what _blend_pair would compute, in one run)
                j = i + 1
                while j < n and cmds[j].index not in cache:
                    j += 1
                got = self._blend_run(els[-1], cmds[i:j])
            for c, b in zip(cmds[i:j], got, strict=True):
                if b is None:
                    els.append(c.elements[0])
                    owners.append(c.index)
                else:
                    els[-1] = b[0]
                    els += b[1:]
                    owners += (c.index, c.index)
            i = j
        if prev is None:
            return None, els, owners
        return els[0], els[1:], owners[1:]

    def _blend_key(self) -> tuple:
        """The settings a blend depends on besides its two elements and its command."""
        vmax, amax = self._caps()
        return (self._blend, self._blend_tol, self._corner_velocity, vmax.tobytes(),
                amax.tobytes())

    def _blend_pair(self, prev: PathElement, el: PathElement, cmd: _Cmd,
                    pre: dict[int, tuple[Any, ...]] | None = None
                    ) -> tuple[PathElement, PathElement, PathElement] | None:
        """`_blend_new`, or its result from `_preblend` when computed for the same
        elements and settings (the same objects: the chain is the same bit for bit)."""
        hit = (self._pre if pre is None else pre).pop(cmd.index, None)
        if hit is not None and hit[0] is prev and hit[1] is el and hit[2] == self._blend_key():
            return hit[3]
        return self._blend_run(prev, [cmd])[0]

    def _blend_run(self, prev: PathElement, cmds: list[_Cmd]
                   ) -> list[tuple[PathElement, PathElement, PathElement] | None]:
        """`_blend_new` corner after corner: prev -> cmds[0]'s element -> cmds[1]'s ...,
        each corner's first element the second of the corner before (trimmed when that one
        was blended); bit for bit the same. Each stretch of lines (that follow one another,
        no corner velocity) in one compiled call (path/blend.py `_line_run`)."""
        if not (self._blend and self._blend_tol > 0.0):
            return [None] * len(cmds)
        out: list[tuple[PathElement, PathElement, PathElement] | None] = []
        fast = self._corner_velocity == 0.0 and prev.start.size <= _corner_max_dim
        single = False  # the next corner by _blend_new (its line starts off the corner)
        i, n = 0, len(cmds)
        while i < n:
            j = i
            if fast and not single and type(prev) is Line:  # the stretch of lines from i
                while j < n and type(cmds[j].elements[0]) is Line:
                    j += 1
            if j > i:
                run = cmds[i:j]
                amin = self._amin(self._caps()[1])
                got = _line_run(prev, [c.elements[0] for c in run], self._blend_tol,
                                accel=[min(c.accel, c.dec, amin) for c in run],
                                feed=[c.feed for c in run])
                single = len(got) < len(run)
            else:
                got = [self._blend_new(prev, cmds[i].elements[0], cmds[i])]
                single = False
            if got:
                out += got
                i += len(got)
                prev = cmds[i - 1].elements[0] if got[-1] is None else got[-1][2]
        return out

    def _preblend(self) -> None:
        """A quiet cycle of a running chain: blend the next few queued corners ahead of the
        join that will take them, starting from the chain's last element, so the join's
        work (about 40 % of it was blending) is spread over the cycles before it."""
        gx = _groupexec()
        r = self._run
        q = self._queue
        pre = self._pre
        if r is None or r.plan is None or not q or not (self._blend and self._blend_tol > 0.0) \
                or self._state is not GroupState.MOVING:
            # (a hold or abort in progress: the queued commands start after it, from rest)
            pre.clear()
            return
        prev = r.plan.chain.elements[-1]
        head = pre.get(q[0].index)
        i = 0
        if head is not None and head[0] is prev and self._pre_tail is not None:
            # the prepared corners still follow the chain's end: continue after them
            tail, piece = self._pre_tail
            i = tail - q[0].index + 1
            if 0 < i <= len(q) and q[i - 1].index == tail:
                prev = piece
            else:
                i = 0
        if i == 0:
            pre.clear()  # nothing prepared, or stale: the chain's end changed
        key = self._blend_key()
        run: list[_Cmd] = []
        for c in itertools.islice(q, i, min(len(q), i + gx.PREBLEND_PER_CYCLE, gx.PREBLEND_AHEAD)):
            if not self._joins(r.plan.tj, c, r.plan.limits.str_vel):
                break
            run.append(c)
        for c, b in zip(run, self._blend_run(prev, run), strict=True):
            el = c.elements[0]
            pre[c.index] = (prev, el, key, b)
            if b is not None and r.plan.tj == 0.0:
                # the trimmed prev belongs to the command before c, the blend arc to c
                self._warm_limits(b[0], q[i - 1] if i > 0 else r.cmds[-1])
                self._warm_limits(b[1], c)
            prev = b[2] if b is not None else el
            self._pre_tail = (c.index, prev)
            i += 1

    def _warm_limits(self, el: PathElement, cmd: _Cmd) -> None:
        """Have the look-ahead's per-element memo (path/lookahead.py) hold the limits of a
        new piece with the values the join's plan will ask for (a T chain's feed x
        override capped by the system maximum, the command's acceleration, the axis caps):
        the join then computes only the junctions and the passes."""
        if el.length > 0.0:
            vmax, amax = self._caps()
            # what speed_caps([el], ...) stores, without validating the group's own values
            element_limits(el, min(cmd.feed * self._override, self._sys_max), cmd.accel,
                           vmax, amax, px.ARC_TANGENTIAL_RATIO)

    def _blend_new(self, prev: PathElement, el: PathElement,
                   cmd: _Cmd) -> tuple[PathElement, PathElement, PathElement] | None:
        """The corner prev -> el (any Line/Arc/Arc3D pair) rounded within the tolerance
        (trimmed prev, the blend, the trimmed el), or None: blending off, no corner, or
        taking the corner unrounded (an exact stop, or the corner velocity when one is set)
        is faster."""
        if not (self._blend and self._blend_tol > 0.0):
            return None
        b = blend_corner(prev, el, self._blend_tol)
        if b is None:
            return None
        vmax, amax = self._caps()
        accel = min(cmd.accel, cmd.dec, self._amin(amax))
        v_corner = 0.0
        if self._corner_velocity > 0.0 and prev.length > 0.0 and el.length > 0.0:
            corner = self._corner_limits()
            v_corner = speed_caps([prev, el], cmd.feed, cmd.accel, axis_vmax=vmax,
                                  axis_amax=amax,
                                  square_corner_velocity=corner["square_corner_velocity"],
                                  axis_vjump=corner["axis_vjump"])[1][1]
        trims = (float(prev.length - b.first.length), float(el.length - b.second.length))
        if not _blend_pays(b, accel, cmd.feed, v_corner, trims):
            return None
        return b.first, b.arc, b.second

    def _amin(self, amax: np.ndarray) -> float:
        """min(amax), kept while amax is the same object (settings replace it)."""
        memo = self.__dict__.get("_amin_memo")
        if memo is None or memo[0] is not amax:
            memo = self._amin_memo = (amax, float(np.min(amax)))
        return memo[1]


@functools.cache
def _groupexec() -> Any:
    """The groupexec module (which imports this one), for its constants: imported once at
    the first use (an import statement in a method costs microseconds at every call)."""
    from . import groupexec

    return groupexec


def _peak_speed(p: Profile) -> float:
    """The largest |speed| a profile reaches (at a segment's ends: its pieces have constant
    jerk at most, so also at a zero of the acceleration inside one, bounded here by
    |v0| + |a0|*dt + |j|*dt**2/2), and its end speed."""
    if not p.n_segments:
        return abs(p.end.v)
    dts = p.dt if p.dt is not None else np.diff(np.append(p.t0, p.duration))
    top = np.abs(p.v0) + np.abs(p.a0) * dts + 0.5 * np.abs(p.j) * dts * dts
    return max(float(np.max(top)), abs(p.end.v), abs(p.start.v))


def _blend_pays(b: Any, accel: float, feed: float, v_corner: float = 0.0,
                trims: tuple[float, float] | None = None) -> bool:
    """Whether rounding a corner is faster than taking it unrounded: stopping exactly at it
    or, with a corner velocity, passing it at `v_corner` (an estimate).

    The blend arc (radius R = 1/kappa, sweep phi = L/R) starts d = R*tan(phi/2) before the
    corner and is crossed at v_c = min(F, sqrt(a_n*R)), a_n = sqrt(3)/2*A (the look-ahead's
    split of A on arcs). On each side, over the distance D from the corner in which the
    exact stop accelerates to the feed (or the shorter line ends), the exact stop takes
    time(D from rest) and the blend time(D - d from v_c); the blend pays when
    L/v_c + 2*time(D - d, v_c) < 2*time(D, 0); F is capped by the centripetal speed of
    an arc next to the corner. A sharp corner with a small tolerance gets an
    arc so tight that it would crawl: it stops exactly instead. A blend that turns half a
    circle or more (a line into an arc that starts back along it) has no finite
    R*tan(phi/2): d is then the mean of what the blend trimmed off the two elements
    (`trims`), never negative (a negative d made a square root of a negative number).
    """
    length = float(b.arc.length)
    kappa = float(b.arc.max_curvature)
    if kappa <= 0.0 or length <= 0.0:
        return True
    for el in (b.first, b.second):  # an arc next to the corner caps the speed there too
        k_el = float(el.max_curvature)
        if k_el > 0.0:
            feed = min(feed, math.sqrt(math.sqrt(0.75) * accel / k_el))
    radius = 1.0 / kappa
    phi = length / radius
    d = radius * math.tan(0.5 * phi) if phi < math.pi * (1.0 - 1e-9) else math.nan
    if not (math.isfinite(d) and d >= 0.0):
        d = max(0.0, 0.5 * (trims[0] + trims[1])) if trims is not None else 0.0
    v_c = min(feed, math.sqrt(math.sqrt(0.75) * accel * radius))
    reach = min(float(b.first.length), float(b.second.length)) + d
    span = min(d + feed * feed / (2.0 * accel), reach)

    def time(dist: float, v0: float) -> float:
        dist = max(0.0, dist)
        d_acc = (feed * feed - v0 * v0) / (2.0 * accel)
        if dist <= d_acc:
            return (math.sqrt(v0 * v0 + 2.0 * accel * dist) - v0) / accel
        return (feed - v0) / accel + (dist - d_acc) / feed

    v_corner = min(v_corner, feed)
    return length / v_c + 2.0 * time(max(0.0, span - d), v_c) < 2.0 * time(span, v_corner)
