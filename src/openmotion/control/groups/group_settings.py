"""The settings of a `Group` (MCCL 2.6.2-2.6.4): feed, acceleration and deceleration
times, the per-axis speed and acceleration caps (in pps and per interpolation period),
blending, in-position waits, path shape, StrVel and the point-to-point speed, shapes and
times. They apply to the commands queued after them (an override or a hold acts on the
running motion: group.py)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...errors import MotionError, check_finite, check_nonnegative
from ...limits import check_quantity
from .group_checks import GroupChecks
from .groupexec import ERR_ARGUMENT, ERR_SPEED, GroupError

#: MCCL 2.6.4: an axis sends at most 32768 pulses per interpolation period (max pulse speed
#: = 32768 / T); MCC_SetMaxPulseSpeed / MCC_SetMaxPulseAcc default to 30000.
PERIOD_PULSES_MAX = 32768
PERIOD_PULSES_DEFAULT = 30000.0


class GroupSettings(GroupChecks):
    """Base of `Group`: its settings (see the module doc)."""

    def set_limit_mode(self, mode: str) -> None:
        """Which limit switches stop the moving group (MCC_EnableLimitSwitchCheck):
        "direction" (default, mode 0: the switch ahead of an axis) or "any" (mode 1: any
        engaged switch of a moving axis)."""
        if not isinstance(mode, str) or mode not in ("direction", "any"):
            raise MotionError(f"mode must be 'direction' or 'any', got {mode!r}")
        self._limit_any = mode == "any"

    _vmax_pps: np.ndarray
    _amax_pps: np.ndarray
    _period_pulses: np.ndarray
    _period_pulse_acc: np.ndarray
    _ptp_ratio: float
    _ptp_shapes: tuple[str, ...]
    _ptp_dec_shapes: tuple[str, ...]
    _ptp_acc_time: float | None
    _ptp_dec_time: float | None
    _path_sfactor: float
    _path_jerk: float
    _path_dec_shape: str | None = None  # None: as the acceleration (set_path_dec_shape)
    _overlap: bool = False              # time-overlap blending (enable_overlap_blend)

    def set_feed(self, feed: float) -> None:
        """MCC_SetFeedSpeed: vector speed (pps, or user units/s) of the following path
        commands."""
        try:
            f = check_quantity("feed", feed, "pps")
        except MotionError as e:
            raise GroupError(ERR_SPEED, str(e)) from None
        if hasattr(self, "_sys_max") and f > self._sys_max * (1 + 1e-12):
            names = set(getattr(self, "_unit_names", ("pulse",)))
            unit = "pps" if names == {"pulse"} else \
                (f"{names.pop()}/s" if len(names) == 1 else "units/s")
            raise GroupError(ERR_SPEED, f"feed must be <= the system maximum speed "
                                        f"{self._sys_max:g} {unit}, got {feed!r}")
        self._feed = f

    def set_sys_max_speed(self, speed: float) -> None:
        """MCC_SetSysMaxSpeed: the largest feed accepted (pps, or user units/s)."""
        self._sys_max = check_quantity("speed", speed, "pps")

    def set_acc_time(self, seconds: float) -> None:
        """Time to accelerate from rest to the feed (MCC_SetAccStep x interpolation time)
        of the following commands; the deceleration follows it until set_dec_time."""
        t = check_quantity("seconds", seconds, "seconds")
        self._acc_time = t

    def set_dec_time(self, seconds: float) -> None:
        """Time to decelerate from the feed to rest (MCC_SetDecStep x interpolation time)
        of the following commands: path commands brake at feed / seconds (the look-ahead's
        backward pass, holds, aborts, a lower override), point-to-point axes with this
        Tdec. Until it is called the deceleration follows set_acc_time."""
        t = check_quantity("seconds", seconds, "seconds")
        self._dec_time = t

    @property
    def acc_time(self) -> float:
        """Acceleration time of the following commands (s)."""
        return self._acc_time

    @property
    def dec_time(self) -> float:
        """Deceleration time of the following commands (s): set_dec_time's, or the
        acceleration time."""
        return self._acc_time if self._dec_time is None else self._dec_time

    def set_max_pulse_speed(self, pps: Sequence[float]) -> None:
        """Speed cap per logical axis (pps); default the axes' maximum speed. The
        per-period cap (set_period_pulse_caps) applies on top of it."""
        self._vmax_pps = self._axis_values("pps", pps)
        self._update_caps()

    def set_period_pulse_caps(self, speed: Sequence[float] | None = None,
                              acc: Sequence[float] | None = None) -> None:
        """MCC_SetMaxPulseSpeed / MCC_SetMaxPulseAcc (MCCL 2.6.4): per logical axis, the
        most pulses an axis may send in one interpolation period (`speed`) and the largest
        change of that count between two neighbouring periods (`acc`), each a whole
        number 1..32768 (default 30000). They cap the axis at speed/T pps and acc/T**2
        pps^2 (T the period) for every group command: refused above them (policy
        "refuse"), or planned below them ("slow"). All checked before either changes."""
        new = []
        for name, val in (("speed", speed), ("acc", acc)):
            if val is None:
                new.append(None)
                continue
            arr = self._axis_values(name, val)
            if np.any(arr != np.round(arr)) or np.any(arr > PERIOD_PULSES_MAX):
                raise MotionError(f"{name} must be {len(self.axes)} whole numbers of pulses "
                                  f"in 1..{PERIOD_PULSES_MAX}, got {val!r}")
            new.append(arr)
        if new[0] is not None:
            self._period_pulses = new[0]
        if new[1] is not None:
            self._period_pulse_acc = new[1]
        self._update_caps()

    @property
    def period_pulse_caps(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(pulses per period, change of pulses per period) of each logical axis."""
        return tuple(self._period_pulses.tolist()), tuple(self._period_pulse_acc.tolist())

    def _update_caps(self) -> None:
        """The effective per-axis caps: the pps caps and the per-period pulse caps."""
        T = self._ctl.period
        self._vmax = np.minimum(self._vmax_pps, self._period_pulses / T)
        self._amax = np.minimum(self._amax_pps, self._period_pulse_acc / (T * T))

    def set_axis_limit_policy(self, policy: str) -> None:
        """"refuse" (default, MCCL): a path command whose feed or acceleration would take an
        axis past its maximum pulse speed/acceleration is refused (ERR_SPEED / ERR_ACCEL);
        "slow": it is accepted and the look-ahead slows the path down to the axis limits."""
        if not isinstance(policy, str) or policy not in ("refuse", "slow"):
            raise MotionError(f"policy must be 'refuse' or 'slow', got {policy!r}")
        self._refuse = policy == "refuse"

    def set_max_pulse_acc(self, pps2: Sequence[float]) -> None:
        """Acceleration cap per logical axis (pps^2, inf = unlimited, the default); the
        per-period cap (set_period_pulse_caps) applies on top of it."""
        self._amax_pps = self._axis_values("pps2", pps2)
        self._update_caps()

    def enable_blend(self, tolerance: float) -> None:
        """Blend consecutive path commands: corners between lines and arcs are rounded so
        that the path passes within `tolerance` (pulses, or user units with `units=`) of
        the programmed corner point (0: exact stop). Helices and elements in different
        planes still stop exactly at their corners."""
        self._blend_tol = check_nonnegative("tolerance", tolerance)
        self._blend = True

    def disable_blend(self) -> None:
        """No blending: neither corner rounding nor the time-overlap blend."""
        self._blend = False
        self._overlap = False

    def enable_overlap_blend(self) -> None:
        """MCCL's velocity blending (2.6.3 II): every command is planned on its own, from
        rest to rest, and the next one starts when it begins its final deceleration; each
        axis then follows the sum of both motions, so the deceleration of one and the
        acceleration of the next overlap in time and their speeds add (line-line,
        line-arc, arc-arc and point-to-point alike; control/groups/overlap.py). A blend that
        would take an axis above its speed or acceleration cap is not made: those two
        commands run one after the other. Replaces corner rounding (enable_blend)."""
        self._blend = False
        self._overlap = True

    @property
    def blend_mode(self) -> str:
        """"off", "corner" (enable_blend: rounded within a tolerance) or "overlap"."""
        return "overlap" if self._overlap else ("corner" if self._blend else "off")

    def set_path_dec_shape(self, shape: str | None) -> None:
        """MCC_SetDecType: the deceleration shape of the following path commands, "T" or
        "S" (S with ramp times: a triangular deceleration lasting the deceleration time),
        None = the path shape (set_path_shape). A command whose deceleration shape differs
        from its acceleration shape runs alone as one move along its length
        (control/groups/pathmove.py): it ends at rest (or blends in time into the next with
        enable_overlap_blend), it joins no chain."""
        if shape is not None and (not isinstance(shape, str) or shape not in ("T", "S")):
            raise MotionError(f"shape must be 'T', 'S' or None, got {shape!r}")
        self._path_dec_shape = shape

    @property
    def path_shapes(self) -> tuple[str, str]:
        """(acceleration, deceleration) shape of the following path commands."""
        acc = "S" if (self._path_sfactor or self._path_jerk) else "T"
        return acc, (self._path_dec_shape or acc)

    def set_wait_in_position(self, on: bool) -> None:
        """MCCL 2.10.2: with in-position checks on (control.guard.inposition), each command
        ends on its own (no join or blend with the next), so the next starts only once
        the axes are within their tolerance. Applies to the commands not started yet."""
        if not isinstance(on, bool):
            raise MotionError(f"on must be a bool, got {on!r}")
        self._wait_inpos = on

    def set_path_shape(self, shape: str, jerk: float | None = None, *,
                       s_factor: float | None = None) -> None:
        """Speed profile of the following path commands: "T" (constant path acceleration)
        or "S" (jerk-limited: the jerk of the path position stays within `jerk`, pps^3 or
        user units/s^3). S paths blend, stream, hold and take overrides like T paths: the
        T plan is smoothed by a moving average of window 2*accel/jerk, its speed caps held
        that much further along the path, exact-stop corners passed at rest.

        Instead of `jerk`, `s_factor` in (0, 1] sizes the S from the ramp times (MCCL's
        S-curve, s-factor 1 = a triangular acceleration): a ramp from rest to the feed then
        lasts exactly the acceleration time and one to rest the deceleration time, as with
        "T"; the jerk phases take `s_factor` of the shorter ramp (the window is
        s_factor * min(Tacc, Tdec) / 2), so with equal times every ramp's acceleration
        rises and falls over s_factor of it (peak feed / (Tacc * (1 - s_factor/2)))."""
        if not isinstance(shape, str) or shape not in ("T", "S"):
            raise MotionError(f"shape must be 'T' or 'S', got {shape!r}")
        if shape == "T":
            if s_factor is not None:
                raise MotionError("s_factor is only for shape 'S'")
            self._path_jerk = 0.0
            self._path_sfactor = 0.0
            return
        if s_factor is not None:
            if jerk is not None:
                raise MotionError("give either jerk or s_factor for shape 'S', not both")
            s = check_finite("s_factor", s_factor)
            if not 0.0 < s <= 1.0:
                raise MotionError(f"s_factor must be in (0, 1], got {s_factor!r}")
            self._path_jerk = 0.0
            self._path_sfactor = s
            return
        if jerk is None:
            raise MotionError("jerk must be a number > 0 (pps^3) for shape 'S', got None")
        j = check_quantity("jerk", jerk, "pps3")
        self._path_jerk = j
        self._path_sfactor = 0.0

    def set_str_vel(self, speed: float) -> None:
        """Start velocity (PCL6045 StrVel, HSL-4XMO 4.6) of the following path commands, in
        pps or user units/s (default 0, as MCCL): a chain starts at rest with a jump to this
        vector speed, and ends at it with a jump to rest. Checked when a command is queued:
        <= its feed and StrVel*|u_i| <= each axis's maximum speed (GroupError ERR_SPEED).
        T and S paths (an S path: jump to StrVel, then an S acceleration from a = 0)."""
        try:
            v = check_quantity("speed", speed, "pps", zero=True)
        except MotionError as e:
            raise GroupError(ERR_ARGUMENT, f"StrVel: {e}") from None
        self._str_vel = v

    def set_ptp_speed(self, ratio: float, *, shape: str | None = None) -> None:
        """MCC_SetPtPSpeed: each axis runs at ratio % of its maximum speed (default 10);
        `shape` 'T'/'S' also sets every axis's PtP shape (None keeps set_ptp_shapes')."""
        r = check_finite("ratio", ratio)
        if not 0.0 < r <= 100.0:
            raise MotionError(f"ratio must be in (0, 100] percent, got {ratio!r}")
        if shape is not None and (not isinstance(shape, str) or shape not in ("T", "S")):
            raise MotionError(f"shape must be 'T' or 'S', got {shape!r}")
        self._ptp_ratio = r
        if shape is not None:
            self._ptp_shapes = self._ptp_dec_shapes = (shape,) * len(self.axes)

    def set_ptp_shapes(self, shapes: Sequence[str],
                       dec_shapes: Sequence[str] | None = None) -> None:
        """MCC_SetPtPAccType / MCC_SetPtPDecType per axis: "T" or "S" for each logical
        axis's PtP acceleration and deceleration (`dec_shapes` None: as `shapes`)."""
        def check(name: str, v: object) -> tuple[str, ...]:
            if isinstance(v, str) or not isinstance(v, Sequence) or \
                    len(v) != len(self.axes) or \
                    any(not isinstance(x, str) or x not in ("T", "S") for x in v):
                raise MotionError(f"{name} must be {len(self.axes)} of 'T'/'S', got {v!r}")
            return tuple(v)
        acc = check("shapes", shapes)
        dec = acc if dec_shapes is None else check("dec_shapes", dec_shapes)
        self._ptp_shapes, self._ptp_dec_shapes = acc, dec

    def set_ptp_acc_time(self, seconds: float) -> None:
        """MCC_SetPtPAccStep x T: acceleration time of point-to-point axes (default: the
        path commands' set_acc_time)."""
        t = check_quantity("seconds", seconds, "seconds")
        self._ptp_acc_time = t

    def set_ptp_dec_time(self, seconds: float) -> None:
        """MCC_SetPtPDecStep x T: deceleration time of point-to-point axes (default: the
        PtP acceleration time)."""
        t = check_quantity("seconds", seconds, "seconds")
        self._ptp_dec_time = t

    @property
    def ptp_times(self) -> tuple[float, float]:
        """(acceleration, deceleration) time of point-to-point axes (s)."""
        acc = self._acc_time if self._ptp_acc_time is None else self._ptp_acc_time
        if self._ptp_dec_time is not None:
            return acc, self._ptp_dec_time
        return acc, (self.dec_time if self._ptp_acc_time is None else acc)

    @property
    def ptp_settings(self) -> tuple[float, tuple[str, ...]]:
        """(speed ratio %, the shape of each axis) of point-to-point commands."""
        return self._ptp_ratio, self._ptp_shapes
