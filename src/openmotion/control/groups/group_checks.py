"""Accepting a group command: everything checked before it is queued, and the push.

A `Group` command is validated completely before anything changes: the group and its axes
can accept it, its points have the right shape, the path stays inside the enabled soft
limits, its StrVel and the axes' maximum pulse speed/acceleration allow its feed (policy
"refuse"). Only then is it pushed (next command index) and the tail moved; a refusal is a
`GroupError` with its negative code, leaving the queue, the tail and the running motion as
they were. `unit_scales` resolves the group's `units=` argument.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ...errors import MotionError, show
from ...limits import PATH_LENGTH_MAX, PPS_MAX, PPS_MIN, PULSES_MAX, as_array
from ...path.extent import element_extent
from ...path.geometry import Line, PathElement
from ...profile.pcl import MoveSpec
from ...units import AxisUnits
from ..core.states import AxisState
from .groupexec import (
    ERR_ACCEL,
    ERR_ARGUMENT,
    ERR_AXIS_BUSY,
    ERR_AXIS_STATE,
    ERR_GROUP,
    ERR_LIMIT,
    ERR_QUEUE_FULL,
    ERR_SPEED,
    GroupEngine,
    GroupError,
    GroupState,
    _Cmd,
)

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller
    from ..guard.safety import Safety


class GroupChecks(GroupEngine):
    """Base of `Group`: command validation and the queue push (on top of the engine)."""

    _queue: deque[_Cmd]
    _queue_size: int
    _next_index: int
    _feed: float
    _acc_time: float
    _dec_time: float | None
    _str_vel: float
    _path_jerk: float
    _path_sfactor: float
    _refuse: bool

    def _axis_values(self, name: str, values: Sequence[float]) -> np.ndarray:
        arr = as_array(name, values, None).reshape(-1)
        if arr.size != len(self.axes) or np.any(np.isnan(arr)) or np.any(arr <= 0.0):
            raise MotionError(f"{name} must be {len(self.axes)} numbers > 0, got {values!r}")
        return arr

    def _check_accepting(self) -> None:
        if self._state is GroupState.ERROR:
            raise GroupError(ERR_GROUP, f"group in error {self._error} ({self._error_msg}); "
                                        "clear_error() first")
        if len(self._queue) >= self._queue_size:
            raise GroupError(ERR_QUEUE_FULL, f"queue full ({self._queue_size} commands)")
        for a in self.axes:
            if a.state is AxisState.ERROR_STOP:
                raise GroupError(ERR_AXIS_STATE, f"axis {a.name} is in ErrorStop ({a.fault})")
            if a.state is AxisState.DISABLED and not self._dry:
                raise GroupError(ERR_AXIS_STATE, f"axis {a.name} is disabled; enable() first")
            if self._run is None and not self._dry and a.is_moving:
                raise GroupError(ERR_AXIS_BUSY, f"axis {a.name} is moving outside the group")

    def _start_point(self) -> np.ndarray:
        """Where the next command starts: the queue's tail, or where the axes are (while
        abort() is still stopping: where it stops). Read only: a refused command leaves
        the tail as it was; `_push` moves it."""
        self._check_accepting()
        if self._tail is None or (self._run is None and not self._queue
                                  and self._held is None):
            return self._rest_point()
        return self._tail.copy()

    def _rest_point(self) -> np.ndarray:
        """Where a command starts when nothing is queued: where the axes are (while abort()
        is still stopping: where it stops)."""
        return self._units_of(self._stop_point()) if self._aborting \
            and self._run is not None else self.position  # type: ignore[attr-defined]

    def _point(self, name: str, value: Sequence[float], base: np.ndarray | None) -> np.ndarray:
        try:
            arr = as_array(name, value).reshape(-1)
        except MotionError as e:
            raise GroupError(ERR_ARGUMENT, str(e)) from None
        if arr.size != len(self.axes):
            raise GroupError(ERR_ARGUMENT, f"{name} must be {len(self.axes)} finite numbers, "
                                           f"got {show(value)}")
        out = arr + base if base is not None else arr
        if np.any(np.abs(out) > PULSES_MAX):
            raise GroupError(ERR_ARGUMENT, f"{name} must lie within |x| <= {PULSES_MAX:g} "
                                           f"pulses, got {show(value)}")
        return out

    def _point2(self, name: str, value: Sequence[float], base: np.ndarray | None,
                plane: tuple[int, int]) -> np.ndarray:
        try:
            arr = as_array(name, value).reshape(-1)
        except MotionError as e:
            raise GroupError(ERR_ARGUMENT, str(e)) from None
        if not isinstance(plane, (tuple, list)) or len(plane) != 2 \
                or not all(isinstance(k, int) and not isinstance(k, bool) for k in plane) \
                or not all(0 <= k < len(self.axes) for k in plane) or plane[0] == plane[1]:
            raise GroupError(ERR_ARGUMENT, f"plane must be two different axis indices in "
                                           f"[0, {len(self.axes)}), got {show(plane)}")
        i, j = plane
        if arr.size != 2:
            raise GroupError(ERR_ARGUMENT, f"{name} must be 2 finite numbers, "
                                           f"got {show(value)}")
        out = arr + base[[i, j]] if base is not None else arr
        if np.any(np.abs(out) > PULSES_MAX):
            raise GroupError(ERR_ARGUMENT, f"{name} must lie within |x| <= {PULSES_MAX:g} "
                                           f"pulses, got {show(value)}")
        return out

    def _queue_line(self, end: np.ndarray, feed: float, line: Line | None = None) -> int:
        """The program runner's push (its cycle hook: the controller's lock is held):
        `set_feed(feed)` then `line(end)` for an `end` the program's compiler made (a 1-D
        float64 array of one value per axis, logical units; taken as it is when read
        only). `line`: the line to `end` the runner prepared (program/runahead.py), used
        when it starts at the queue's tail (that very array). The same command, made by
        the same checks at the same values (plain float comparisons, no re-validation of
        what cannot fail) and leaving the same state; when one of them fails, or the group
        is set up in a way this path does not cover, the public calls run instead and
        raise their own errors (or accept)."""
        f = float(feed)
        if not PPS_MIN <= f <= PPS_MAX or f > self._sys_max * (1 + 1e-12) or self._refuse \
                or self._str_vel != 0.0 or not self._accepting():
            return self._queue_line_public(end, feed)
        n = len(self.axes)
        b = end if not end.flags.writeable and end.dtype == np.float64 \
            else np.array(end, dtype=np.float64)
        if b.shape != (n,) or n < 2:
            return self._queue_line_public(end, feed)
        e_l = b.tolist()
        for x in e_l:
            if not -PULSES_MAX <= x <= PULSES_MAX:  # (NaN, inf: the public call refuses)
                return self._queue_line_public(end, feed)
        tail = self._tail
        if tail is None or (self._run is None and not self._queue and self._held is None):
            a = np.array(self._rest_point(), dtype=np.float64)
            line = None
        elif line is not None and line.start is tail and line.end is b:
            a = tail
        else:
            line = None  # (a tail the public _push copied is writeable: copied again)
            a = tail.copy() if tail.flags.writeable else tail
        if line is None:
            a.flags.writeable = b.flags.writeable = False
            el = Line.between(a, b)  # the same line as line(end) makes, bit for bit
        else:
            el = line
        length = el.length
        memo = self.__dict__.get("_push_memo")
        if memo is None or memo[0] is not self._k or memo[1] is not self._ppu:
            memo = self._push_memo = (self._k, self._ppu, self._k.tolist(),
                                      float(np.max(np.abs(self._ppu))),
                                      tuple(ax.index for ax in self.axes))
        if length == 0.0 or not length * memo[3] <= PATH_LENGTH_MAX:
            return self._queue_line_public(end, feed)
        if not self._dry and not self._soft_ok(a.tolist(), e_l, memo[2], memo[4]):
            return self._queue_line_public(end, feed)
        self._feed = f
        accel, decel, jerk = self._path_ramps(f)
        cmd = _Cmd(self._next_index, "path", elements=(el,), feed=f, accel=accel,
                   decel=decel, jerk=jerk, str_vel=0.0, move=self._path_move(f, 0.0))
        self._queue.append(cmd)
        self._next_index += 1
        if self._run is not None and self._run.plan is not None:
            self._join_queued(self._ctl.time)  # joins now if the running chain needs it
        self._tail = b
        return cmd.index

    def _queue_line_public(self, end: np.ndarray, feed: float) -> int:
        self.set_feed(feed)  # type: ignore[attr-defined]
        return self.line(end)  # type: ignore[attr-defined]

    def _accepting(self) -> bool:
        """Whether `_check_accepting` passes (it raises the refusal)."""
        if self._state is _G_ERROR or len(self._queue) >= self._queue_size:
            return False
        dry = self._dry
        free = self._run is None and not dry
        for a in self.axes:
            st = a.state
            if st is _A_ESTOP or (st is _A_DISABLED and not dry) or (free and a.is_moving):
                return False
        return True

    def _soft_ok(self, start: list[float], end: list[float], k: list[float],
                 indices: tuple[int, ...]) -> bool:
        """Whether `_check_soft_limits` passes for the line start -> end (plain floats; the
        same products and comparisons as `_check_soft_span`)."""
        safety = _safety_of(self._ctl)
        if safety is None:
            return True
        for i, pl, nl in safety.soft.enabled_of(indices):
            s, e, ki = start[i], end[i], k[i]
            lo, hi = (e, s) if e < s else (s, e)
            x, y = lo * ki, hi * ki
            plo, phi = (y, x) if y < x else (x, y)
            s *= ki
            if phi > max(pl, s) + 1e-9 * max(1.0, abs(pl)) or \
                    plo < min(nl, s) - 1e-9 * max(1.0, abs(nl)):
                return False
        return True

    def _check_soft_limits(self, el: PathElement) -> None:
        """Refuse (ERR_LIMIT) a path element that would take an axis past an enabled soft
        limit (further than where it starts), before it is queued."""
        lo, hi = element_extent(el)
        self._check_soft_span(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float),
                              np.asarray(el.start, dtype=float), "path")

    def _check_soft_span(self, lo: np.ndarray, hi: np.ndarray, start: np.ndarray,
                         what: str) -> None:
        """Refuse (ERR_LIMIT) a command whose axes sweep [lo, hi] (logical units) from
        `start` when an axis would pass an enabled soft limit further than it starts."""
        from ..guard.safety import Safety

        safety = Safety.of(self._ctl)
        if safety is None or self._dry:
            return
        a_, b_ = lo * self._k, hi * self._k
        plo, phi = np.minimum(a_, b_), np.maximum(a_, b_)
        start = start * self._k
        for i, ax in enumerate(self.axes):
            lim = safety.soft.get(ax.index)
            if not lim.enabled:
                continue
            if phi[i] > max(lim.plimit, start[i]) + 1e-9 * max(1.0, abs(lim.plimit)):
                raise GroupError(ERR_LIMIT, f"axis {self.names[i]}: the {what} passes the + "
                                            f"soft limit {lim.plimit!r} (reaches {phi[i]:.6g})")
            if plo[i] < min(lim.nlimit, start[i]) - 1e-9 * max(1.0, abs(lim.nlimit)):
                raise GroupError(ERR_LIMIT, f"axis {self.names[i]}: the {what} passes the - "
                                            f"soft limit {lim.nlimit!r} (reaches {plo[i]:.6g})")

    def _check_length(self, el: PathElement) -> None:
        """Refuse a path element longer than PATH_LENGTH_MAX pulses (docs/ranges.md): its
        path coordinate would lose pulse resolution, and its run would never end."""
        length = float(el.length) * float(np.max(np.abs(self._ppu)))
        if not length <= PATH_LENGTH_MAX:
            turns = getattr(el, "turns", None)
            what = f"arc of radius {el.radius:.6g} with turns={turns}" \
                if turns is not None and hasattr(el, "radius") else type(el).__name__.lower()
            raise GroupError(ERR_ARGUMENT, f"path length must be <= 2^45 = "
                                           f"{PATH_LENGTH_MAX:.6g} pulses, got {length:.6g} "
                                           f"(the {what})")

    def _push_path(self, el: PathElement, end: np.ndarray) -> int:
        self._check_length(el)
        self._check_soft_limits(el)
        feed, sv = self._feed, self._str_vel
        tan = el.max_abs_tangent
        accel, decel, jerk = self._path_ramps(feed)
        self._check_str_vel(sv, feed, tan)
        if self._refuse:  # MCCL: refused; "slow": the planner slows down to the axis limits
            vmax, amax = self._caps()
            need = feed * tan * self._ppu
            k = _first_over(need, vmax * self._ppu)
            if k is not None:
                raise GroupError(ERR_SPEED, f"axis {self.names[k]} would need "
                                            f"{self._in_units(k, need[k], '/s')} at feed "
                                            f"{feed:g}, above its maximum speed "
                                            f"{self._in_units(k, self._vmax[k], '/s')}")
            needa = max(accel, decel or 0.0) * tan * self._ppu
            k = _first_over(needa, amax * self._ppu)
            if k is not None:
                raise GroupError(ERR_ACCEL, f"axis {self.names[k]} would need "
                                            f"{self._in_units(k, needa[k], '/s^2')}, above "
                                            f"its maximum acceleration "
                                            f"{self._in_units(k, self._amax[k], '/s^2')}")
        return self._push(_Cmd(-1, "path", elements=(el,), feed=feed, accel=accel,
                               decel=decel, jerk=jerk, str_vel=sv,
                               move=self._path_move(feed, sv)), end)

    def _path_move(self, feed: float, str_vel: float) -> MoveSpec | None:
        """The 1-D move a path command runs as when its deceleration shape differs from
        its acceleration shape (pathmove.py), else None (it chains)."""
        acc, dec = self.path_shapes  # type: ignore[attr-defined]
        if acc == dec:
            return None
        if str_vel:
            raise GroupError(ERR_ARGUMENT, "a path deceleration shape apart needs StrVel 0")
        return MoveSpec(acc, 0.0, feed, self._acc_time, self.dec_time,
                        dec_shape=dec)  # type: ignore[attr-defined]

    def _path_ramps(self, feed: float) -> tuple[float, float | None, float]:
        """(acceleration, deceleration or None = the same, jerk or 0 = T) of a path command
        at `feed`. With an s-factor the T plan's ramps are shortened by the smoothing window
        tj so that the smoothed ramps last the acceleration / deceleration times exactly
        (moving average over tj: ramp + tj), and the jerk is the one giving that window."""
        s = self._path_sfactor
        if not s:
            decel = None if self._dec_time is None else feed / self._dec_time
            return feed / self._acc_time, decel, self._path_jerk
        ta = self._acc_time
        td = ta if self._dec_time is None else self._dec_time
        tj = 0.5 * s * min(ta, td)
        accel, dec = feed / (ta - tj), feed / (td - tj)
        return accel, (None if self._dec_time is None else dec), 2.0 * max(accel, dec) / tj

    def _in_units(self, k: int, pulses: float, per: str) -> str:
        """A pulse figure of axis k in the group's unit ("12.5 mm/s (25000 pps)"), or in
        pulses for a group that works in pulses."""
        unit = getattr(self, "_unit_names", None)
        p_unit = "pps" if per == "/s" else "pps^2"
        if not unit or unit[k] == "pulse":
            return f"{pulses:g} {p_unit}"
        return f"{pulses / self._ppu[k]:g} {unit[k]}{per} ({pulses:g} {p_unit})"

    def _check_str_vel(self, sv: float, feed: float, tan: np.ndarray) -> None:
        """StrVel of a path command: <= its feed, within every axis's maximum speed along
        the move (a jump cannot be slowed down); T and S paths."""
        if sv == 0.0:
            return
        if sv > feed * (1 + 1e-12):
            raise GroupError(ERR_SPEED, f"StrVel {sv:g} must be <= the feed {feed:g}")
        caps = np.minimum(self._vmax, [a.max_speed for a in self.axes])
        need = sv * tan * self._ppu
        k = _first_over(need, caps)
        if k is not None:
            raise GroupError(ERR_SPEED, f"axis {self.names[k]} would jump to {need[k]:g} pps "
                                        f"at StrVel {sv:g}, above its maximum speed "
                                        f"{caps[k]:g} pps")

    def _push(self, cmd: _Cmd, end: np.ndarray | None) -> int:
        self._check_accepting()
        cmd.index = self._next_index
        self._queue.append(cmd)
        self._next_index += 1
        if self._run is not None and self._run.plan is not None:
            self._join_queued(self._ctl.time)  # joins now if the running chain needs it
        if end is not None:
            self._tail = end.copy()
        return cmd.index


def unit_scales(controller: Controller, axes: Sequence[Axis],
                units: bool | Sequence[AxisUnits]) -> np.ndarray:
    """Signed pulses per logical unit of each axis (all 1.0 when units is False)."""
    if units is False:
        return np.ones(len(axes))
    if units is True:
        try:
            au = [AxisUnits.from_axis(controller.config.axes[a.index]) for a in axes]
        except (AttributeError, IndexError):
            raise MotionError("units=True needs the controller's machine config") from None
    elif isinstance(units, Sequence) and not isinstance(units, (str, bytes)) \
            and len(units) == len(axes) and all(isinstance(u, AxisUnits) for u in units):
        au = list(units)
    else:
        raise MotionError(f"units must be a bool or {len(axes)} AxisUnits, got {units!r}")
    return np.array([u.sign * u.pulses_per_unit for u in au], dtype=float)


def unit_names(controller: Controller, axes: Sequence[Axis],
               units: bool | Sequence[AxisUnits]) -> tuple[str, ...]:
    """The logical unit of each axis ("pulse" when the group works in pulses), for
    messages in the user's units."""
    if units is False:
        return ("pulse",) * len(axes)
    if units is True:
        return tuple(controller.config.axes[a.index].unit for a in axes)
    return tuple(u.unit for u in units)  # type: ignore[union-attr]


_G_ERROR = GroupState.ERROR
_A_ESTOP, _A_DISABLED = AxisState.ERROR_STOP, AxisState.DISABLED


def _safety_of(ctl: Controller) -> Safety | None:
    """Safety.of (the guard is built on the groups' core: imported on first use)."""
    if not _SAFETY:
        from ..guard.safety import Safety

        _SAFETY.append(Safety.of)
    return _SAFETY[0](ctl)


_SAFETY: list[Callable[[Controller], Safety | None]] = []


def _first_over(need: np.ndarray, cap: np.ndarray) -> int | None:
    """Index of the first axis whose need exceeds its cap (beyond rounding), or None."""
    bad = np.nonzero(need > cap * (1 + 1e-12))[0]
    return int(bad[0]) if len(bad) else None
