"""HSL motion functions: single-axis moves, speed and position changes, interpolation.

Single-axis functions map one to one onto `Axis` (control.core.axis); the PCL6045 speed range
(control.cards.speed_range) is attached to every axis of a network built from a config.
Interpolation runs on a `Group` (control.groups.group) of the named axes of one module: vector
StrVel / MaxVel, acceleration (MaxVel - StrVel) / Tacc and deceleration (MaxVel - StrVel) /
Tdec, S-curve jerk from VSacc as the PCL6045 defines it (profile.pcl). Circular moves
without Tacc run at MaxVel from start to end (StrVel = MaxVel): the seed's
"no T or S curve speed profile".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import Any

from ...control.cards.network import GET_U16, GET_U32, ONE_AXIS, SET_U16, SET_U32, SHORT, TWO_AXIS
from ...control.cards.speed_range import on_range, verify_speed
from ...control.groups.group import Group, GroupState
from ...errors import check_distance, check_finite
from ...profile.pcl import MoveSpec
from .base import HslBase, Module, hsl_call
from .errors import ERR_AxisBusy, ERR_InvalidParameter, Refusal

#: Arc direction codes (DIR): our assumption, the seed gives none.
DIR_CW, DIR_CCW = 0, 1


def _dir(code: Any) -> str:
    if isinstance(code, int) and not isinstance(code, bool) and code in (DIR_CW, DIR_CCW):
        return "CW" if code == DIR_CW else "CCW"
    raise Refusal(ERR_InvalidParameter, f"DIR must be 0 (CW) or 1 (CCW), got {code!r}")


def _push_arc(g: Group, *, centre: list[float], end: list[float], direction: str,
              absolute: bool) -> None:
    g.arc(centre, end, plane=(0, 1), direction=direction, relative=not absolute)


class MotionFunctions(HslBase):
    """Velocity mode, T/S point-to-point, on-the-fly changes, stops, interpolation."""

    # ------------------------------------------------------------------ velocity mode
    @hsl_call(ONE_AXIS)
    def HSL_M_tv_move(self, axis: int, StrVel: float, MaxVel: float, Tacc: float) -> None:
        """Velocity mode, T-curve: StrVel -> MaxVel (signed: the direction) in Tacc."""
        _, ax = self._axis(axis)
        ax.move_velocity(MaxVel, str_vel=abs(check_finite("StrVel", StrVel)), tacc=Tacc)

    @hsl_call(ONE_AXIS)
    def HSL_M_sv_move(self, axis: int, StrVel: float, MaxVel: float, Tacc: float,
                      SVacc: float) -> None:
        """Velocity mode, S-curve with an SVacc jerk region (0: pure S)."""
        _, ax = self._axis(axis)
        ax.move_velocity(MaxVel, str_vel=abs(check_finite("StrVel", StrVel)), tacc=Tacc,
                         shape="S", vs_acc=SVacc)

    HSL_M_start_tv_move = HSL_M_tv_move   # the spelling of the manual's 4.10 example
    HSL_M_start_sv_move = HSL_M_sv_move   # the spelling of 5.3 "Cont. Move"

    # ------------------------------------------------------------------ point to point
    def _ptp(self, axis: int, value: float, absolute: bool, shape: str, StrVel: float,
             MaxVel: float, Tacc: float, Tdec: float, SVacc: float = 0.0,
             SVdec: float = 0.0) -> None:
        _, ax = self._axis(axis)
        kw = {"str_vel": abs(check_finite("StrVel", StrVel)),
              "max_vel": abs(check_finite("MaxVel", MaxVel)), "tacc": Tacc, "tdec": Tdec,
              "shape": shape, "vs_acc": SVacc, "vs_dec": SVdec}
        if absolute:
            ax.move_absolute(value, **kw)
        else:
            ax.move_relative(value, **kw)

    @hsl_call(ONE_AXIS)
    def HSL_M_start_tr_move(self, axis: int, Dist: float, StrVel: float, MaxVel: float,
                            Tacc: float, Tdec: float) -> None:
        """Relative T-curve move of Dist pulses (Tacc may differ from Tdec)."""
        self._ptp(axis, Dist, False, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(ONE_AXIS)
    def HSL_M_start_ta_move(self, axis: int, Pos: float, StrVel: float, MaxVel: float,
                            Tacc: float, Tdec: float) -> None:
        """Absolute T-curve move to Pos (distance from the feedback / move ratio)."""
        self._ptp(axis, Pos, True, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(ONE_AXIS)
    def HSL_M_start_sr_move(self, axis: int, Dist: float, StrVel: float, MaxVel: float,
                            Tacc: float, Tdec: float, SVacc: float, SVdec: float) -> None:
        """Relative S-curve move."""
        self._ptp(axis, Dist, False, "S", StrVel, MaxVel, Tacc, Tdec, SVacc, SVdec)

    @hsl_call(ONE_AXIS)
    def HSL_M_start_sa_move(self, axis: int, Pos: float, StrVel: float, MaxVel: float,
                            Tacc: float, Tdec: float, SVacc: float, SVdec: float) -> None:
        """Absolute S-curve move."""
        self._ptp(axis, Pos, True, "S", StrVel, MaxVel, Tacc, Tdec, SVacc, SVdec)

    # ------------------------------------------------------------------ on the fly, stops
    @hsl_call(SHORT)
    def HSL_M_v_change(self, axis: int, NewVel: float, Tacc: float) -> None:
        """Change MaxVel on the fly (within the fixed speed range; enough pulses left)."""
        _, ax = self._axis(axis)
        ax.change_speed(NewVel, Tacc)

    @hsl_call(SHORT)
    def HSL_M_p_change(self, axis: int, NewPos: float) -> None:
        """Change the target of a running absolute move (Table 4-7 constraints)."""
        _, ax = self._axis(axis)
        ax.change_position(NewPos)

    @hsl_call(SHORT)
    def HSL_M_sd_stop(self, axis: int, Tdec: float) -> None:
        """Decelerate to a stop in Tdec (a group the axis interpolates in stops along the
        path)."""
        mod, ax = self._axis(axis)
        g = self._busy_group(mod, ax.index)
        if g is not None:
            g.abort()
        else:
            ax.stop(Tdec)

    @hsl_call(SHORT)
    def HSL_M_emg_stop(self, axis: int) -> None:
        """Stop at once (every axis of a running interpolation with it)."""
        mod, ax = self._axis(axis)
        g = self._busy_group(mod, ax.index)
        for a in (g.axes if g is not None else (ax,)):
            a.stop_immediately()
        if g is not None:
            g.abort()

    @hsl_call(GET_U16)
    def HSL_M_motion_done(self, axis: int) -> int:
        """0 when stopped, else the PCL6045 main status (9 homing, 10..13 moving, 14 INP)."""
        _, ax = self._axis(axis)
        return int(ax.motion_done)

    @hsl_call(GET_U32)
    def HSL_M_get_current_speed(self, axis: int) -> float:
        """The commanded speed now (pps, >= 0)."""
        _, ax = self._axis(axis)
        return float(ax.speed)

    HSL_M_get_currebt_speed = HSL_M_get_current_speed  # the manual's spelling (4.11)

    # ------------------------------------------------------------------ speed range
    @hsl_call(SET_U16)
    def HSL_M_fix_speed_range(self, axis: int, MaxVel: float) -> None:
        """Fix the speed range (the OverVelocity) for v_change and the acceleration grid."""
        _, ax = self._axis(axis)
        ax.fix_speed_range(MaxVel)

    @hsl_call(SET_U16)
    def HSL_M_unfix_speed_range(self, axis: int) -> None:
        """Each move's own MaxVel is again the range."""
        _, ax = self._axis(axis)
        ax.unfix_speed_range()

    @hsl_call(0)
    def HSL_M_verify_speed(self, M_No: int, StrVel: float, MaxVel: float,
                           MaxSpeed: float = 0.0) -> tuple[float, float, float]:
        """(minimum velocity, minAccT, maxAccT) of StrVel -> MaxVel on the range MaxSpeed
        (0: MaxVel itself). The C return value (minimum velocity) comes first."""
        self._module(M_No)
        return verify_speed(StrVel, MaxVel, MaxSpeed)

    @hsl_call(SET_U16)
    def HSL_M_set_move_ratio(self, axis: int, ratio: float) -> None:
        """Feedback counts per command pulse (e.g. 200/80 = 2.5, 4.6)."""
        _, ax = self._axis(axis)
        ax.set_move_ratio(ratio)

    # ------------------------------------------------------------------ simplified API
    def _simple(self, axis: int, name: str, value: float) -> None:
        mod, ax = self._axis(axis)
        v = check_finite(name, value)
        if v < 0.0:
            raise Refusal(ERR_InvalidParameter, f"{name} must be >= 0, got {value!r}")
        mod.simple.setdefault(ax.index, {})[name] = v

    @hsl_call(SET_U32)
    def HSL_M_set_str_velocity(self, axis: int, StrVel: float) -> None:
        """Simplified API: StrVel of the following move_*_distance/position calls."""
        self._simple(axis, "StrVel", StrVel)

    @hsl_call(SET_U32)
    def HSL_M_set_max_velocity(self, axis: int, MaxVel: float) -> None:
        self._simple(axis, "MaxVel", MaxVel)

    @hsl_call(SET_U32)
    def HSL_M_set_Tacc(self, axis: int, Tacc: float) -> None:
        self._simple(axis, "Tacc", Tacc)

    @hsl_call(SET_U32)
    def HSL_M_set_Tdec(self, axis: int, Tdec: float) -> None:
        self._simple(axis, "Tdec", Tdec)

    @hsl_call(SET_U32)
    def HSL_M_set_SVacc(self, axis: int, SVacc: float) -> None:
        self._simple(axis, "SVacc", SVacc)

    @hsl_call(SET_U32)
    def HSL_M_set_SVdec(self, axis: int, SVdec: float) -> None:
        self._simple(axis, "SVdec", SVdec)

    def _simple_move(self, axis: int, value: float, absolute: bool, shape: str) -> None:
        mod, ax = self._axis(axis)
        p = {"StrVel": 0.0, "MaxVel": 5000.0, "Tacc": 0.1, "Tdec": 0.1, "SVacc": 0.0,
             "SVdec": 0.0, **mod.simple.get(ax.index, {})}
        self._ptp(axis, value, absolute, shape, p["StrVel"], p["MaxVel"], p["Tacc"],
                  p["Tdec"], p["SVacc"] if shape == "S" else 0.0,
                  p["SVdec"] if shape == "S" else 0.0)

    @hsl_call(SHORT)
    def HSL_M_move_t_distance(self, axis: int, Dist: float) -> None:
        """Relative T move with the simplified API's parameters (defaults: 0, 5000 pps,
        0.1 s, 0.1 s - ours)."""
        self._simple_move(axis, Dist, False, "T")

    @hsl_call(SHORT)
    def HSL_M_move_t_position(self, axis: int, Pos: float) -> None:
        self._simple_move(axis, Pos, True, "T")

    @hsl_call(SHORT)
    def HSL_M_move_s_distance(self, axis: int, Dist: float) -> None:
        self._simple_move(axis, Dist, False, "S")

    @hsl_call(SHORT)
    def HSL_M_move_s_position(self, axis: int, Pos: float) -> None:
        self._simple_move(axis, Pos, True, "S")

    # ------------------------------------------------------------------ interpolation
    def _busy_group(self, mod: Module, local: int) -> Group | None:
        for axes, g in mod.groups.items():
            if local in axes and (g.state is not GroupState.IDLE or g.queue_length):
                return g
        return None

    def _group(self, mod: Module, local: tuple[int, ...]) -> Group:
        """The module's group over exactly these axes. Another group sharing an axis is
        closed first (closing stops its axes, so only when none of them moves)."""
        for i in local:
            if mod.ctl.axes[i].is_moving:
                raise Refusal(ERR_AxisBusy, f"axis {mod.index * 4 + i} is moving")
        g = mod.groups.get(local)
        if g is not None:
            if g.state is not GroupState.IDLE or g.queue_length:
                raise Refusal(ERR_AxisBusy, f"axes {list(local)} are still interpolating")
            return g
        for axes, other in list(mod.groups.items()):
            if set(axes) & set(local):
                if other.state is not GroupState.IDLE or other.queue_length or \
                        any(a.is_moving for a in other.axes):
                    raise Refusal(ERR_AxisBusy, f"axes {list(axes)} of module {mod.index} "
                                  "are moving")
                other.close()
                del mod.groups[axes]
        g = Group(mod.ctl, list(local))
        mod.groups[local] = g
        return g

    def _path(self, mod: Module, local: tuple[int, ...], shape: str, StrVel: float,
              MaxVel: float, Tacc: float, Tdec: float, SVacc: float = 0.0,
              SVdec: float = 0.0, *, push: Callable[[Group], object]) -> None:
        """Set a group up for one PCL6045 vector profile and `push` its command; a refusal
        anywhere leaves no trace (a group created for this call is closed again)."""
        spec = on_range(MoveSpec(shape, abs(check_finite("StrVel", StrVel)),
                                 abs(check_finite("MaxVel", MaxVel)), Tacc, Tdec, SVacc,
                                 SVdec))     # the vector speed registers' range
        new = local not in mod.groups
        g = self._group(mod, local)
        try:
            r = spec.rates
            mv = spec.max_vel
            g.set_feed(mv)
            g.set_str_vel(spec.str_vel)
            g.set_acc_time(mv / r.accel if r.accel > 0.0 else spec.tacc)
            g.set_dec_time(mv / r.decel if r.decel > 0.0 else spec.tdec)
            if shape == "S" and math.isfinite(r.jerk_acc):
                g.set_path_shape("S", min(r.jerk_acc, r.jerk_dec))
            else:
                g.set_path_shape("T")
            push(g)
        except BaseException:
            if new:
                g.close()
                del mod.groups[local]
            raise

    def _line(self, mod: Module, local: tuple[int, ...], target: tuple[float, ...],
              absolute: bool, shape: str, *profile: float) -> None:
        p = [check_distance("position", v) for v in target]   # 28-bit counters
        self._path(mod, local, shape, *profile,
                   push=lambda g: g.line(p, relative=not absolute))

    def _xy(self, M_No: int, first: int, target: tuple[float, ...], absolute: bool,
            shape: str, *profile: float) -> None:
        mod = self._module(M_No)
        local = tuple(range(first, first + len(target)))
        if local[-1] >= len(mod.ctl.axes):
            raise Refusal(ERR_InvalidParameter, f"module {M_No} has no axes {list(local)}")
        self._line(mod, local, target, absolute, shape, *profile)

    # the XY (axes 0, 1) and ZU (axes 2, 3) pairs of a module
    @hsl_call(TWO_AXIS)
    def HSL_M_start_tr_move_xy(self, M_No: int, X: float, Y: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float) -> None:
        """Relative 2-axis line on axes 0, 1 of module M_No (vector speeds)."""
        self._xy(M_No, 0, (X, Y), False, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_ta_move_xy(self, M_No: int, X: float, Y: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float) -> None:
        self._xy(M_No, 0, (X, Y), True, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sr_move_xy(self, M_No: int, X: float, Y: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float, SVacc: float,
                               SVdec: float) -> None:
        self._xy(M_No, 0, (X, Y), False, "S", StrVel, MaxVel, Tacc, Tdec, SVacc, SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sa_move_xy(self, M_No: int, X: float, Y: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float, SVacc: float,
                               SVdec: float) -> None:
        self._xy(M_No, 0, (X, Y), True, "S", StrVel, MaxVel, Tacc, Tdec, SVacc, SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_tr_move_zu(self, M_No: int, Z: float, U: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float) -> None:
        self._xy(M_No, 2, (Z, U), False, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_ta_move_zu(self, M_No: int, Z: float, U: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float) -> None:
        self._xy(M_No, 2, (Z, U), True, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sr_move_zu(self, M_No: int, Z: float, U: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float, SVacc: float,
                               SVdec: float) -> None:
        self._xy(M_No, 2, (Z, U), False, "S", StrVel, MaxVel, Tacc, Tdec, SVacc, SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sa_move_zu(self, M_No: int, Z: float, U: float, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float, SVacc: float,
                               SVdec: float) -> None:
        self._xy(M_No, 2, (Z, U), True, "S", StrVel, MaxVel, Tacc, Tdec, SVacc, SVdec)

    # any 2 / 3 axes of a module, all 4
    def _lineN(self, axes: Any, n: int, target: tuple[float, ...], absolute: bool,
               shape: str, *profile: float) -> None:
        mod, local = self._axes(axes, n)
        self._line(mod, local, target, absolute, shape, *profile)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_tr_line2(self, AxisArray: Any, X: float, Y: float, StrVel: float,
                             MaxVel: float, Tacc: float, Tdec: float) -> None:
        """Relative line on any 2 axes of one module (AxisArray of global numbers)."""
        self._lineN(AxisArray, 2, (X, Y), False, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_ta_line2(self, AxisArray: Any, X: float, Y: float, StrVel: float,
                             MaxVel: float, Tacc: float, Tdec: float) -> None:
        self._lineN(AxisArray, 2, (X, Y), True, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sr_line2(self, AxisArray: Any, X: float, Y: float, StrVel: float,
                             MaxVel: float, Tacc: float, Tdec: float, SVacc: float,
                             SVdec: float) -> None:
        self._lineN(AxisArray, 2, (X, Y), False, "S", StrVel, MaxVel, Tacc, Tdec, SVacc,
                    SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sa_line2(self, AxisArray: Any, X: float, Y: float, StrVel: float,
                             MaxVel: float, Tacc: float, Tdec: float, SVacc: float,
                             SVdec: float) -> None:
        self._lineN(AxisArray, 2, (X, Y), True, "S", StrVel, MaxVel, Tacc, Tdec, SVacc,
                    SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_tr_line3(self, AxisArray: Any, X: float, Y: float, Z: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float) -> None:
        """Relative line on any 3 axes of one module."""
        self._lineN(AxisArray, 3, (X, Y, Z), False, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_ta_line3(self, AxisArray: Any, X: float, Y: float, Z: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float) -> None:
        self._lineN(AxisArray, 3, (X, Y, Z), True, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sr_line3(self, AxisArray: Any, X: float, Y: float, Z: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float,
                             SVacc: float, SVdec: float) -> None:
        self._lineN(AxisArray, 3, (X, Y, Z), False, "S", StrVel, MaxVel, Tacc, Tdec, SVacc,
                    SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sa_line3(self, AxisArray: Any, X: float, Y: float, Z: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float,
                             SVacc: float, SVdec: float) -> None:
        self._lineN(AxisArray, 3, (X, Y, Z), True, "S", StrVel, MaxVel, Tacc, Tdec, SVacc,
                    SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_tr_line4(self, M_No: int, X: float, Y: float, Z: float, U: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float) -> None:
        """Relative line on all 4 axes of module M_No."""
        self._xy(M_No, 0, (X, Y, Z, U), False, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_ta_line4(self, M_No: int, X: float, Y: float, Z: float, U: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float) -> None:
        self._xy(M_No, 0, (X, Y, Z, U), True, "T", StrVel, MaxVel, Tacc, Tdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sr_line4(self, M_No: int, X: float, Y: float, Z: float, U: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float,
                             SVacc: float, SVdec: float) -> None:
        self._xy(M_No, 0, (X, Y, Z, U), False, "S", StrVel, MaxVel, Tacc, Tdec, SVacc,
                 SVdec)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_sa_line4(self, M_No: int, X: float, Y: float, Z: float, U: float,
                             StrVel: float, MaxVel: float, Tacc: float, Tdec: float,
                             SVacc: float, SVdec: float) -> None:
        self._xy(M_No, 0, (X, Y, Z, U), True, "S", StrVel, MaxVel, Tacc, Tdec, SVacc,
                 SVdec)

    # ------------------------------------------------------------------ arcs
    def _arc(self, mod: Module, local: tuple[int, ...], c: tuple[float, float],
             e: tuple[float, float], direction: Any, absolute: bool,
             profile: tuple[float, ...] | None, max_vel: float) -> None:
        d = _dir(direction)
        centre = [check_distance("center", v) for v in c]
        end = [check_distance("end", v) for v in e]
        push = partial(_push_arc, centre=centre, end=end, direction=d, absolute=absolute)
        if profile is None:  # constant tangential speed MaxVel, no ramps: StrVel = MaxVel,
            # and a path acceleration (1 us ramps) that never caps the arc's speed
            v = abs(check_finite("MaxVel", max_vel))
            self._path(mod, local, "T", v, v, 1e-6, 1e-6, push=push)
        else:
            self._path(mod, local, "T", *profile, push=push)

    def _arc_args(self, rest: tuple[Any, ...]) -> tuple[Any, float]:
        """(DIR, MaxVel) from `MaxVel` (the manual's example, DIR = CW) or `DIR, MaxVel`."""
        if len(rest) == 1:
            return DIR_CW, rest[0]
        if len(rest) == 2:
            return rest[0], rest[1]
        raise Refusal(ERR_InvalidParameter, "expected MaxVel or DIR, MaxVel after the end "
                      f"point, got {len(rest)} values")

    def _arc_pair(self, M_No: int, first: int) -> tuple[Module, tuple[int, int]]:
        mod = self._module(M_No)
        if first + 1 >= len(mod.ctl.axes):
            raise Refusal(ERR_InvalidParameter, f"module {M_No} has no axes "
                          f"{[first, first + 1]}")
        return mod, (first, first + 1)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_a_arc_xy(self, M_No: int, Cx: float, Cy: float, Ex: float, Ey: float,
                             *DIR_MaxVel: Any) -> None:
        """Absolute arc on axes 0, 1: centre (Cx, Cy), end (Ex, Ey), [DIR,] MaxVel."""
        mod, local = self._arc_pair(M_No, 0)
        d, v = self._arc_args(DIR_MaxVel)
        self._arc(mod, local, (Cx, Cy), (Ex, Ey), d, True, None, v)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_r_arc_xy(self, M_No: int, OffsetCx: float, OffsetCy: float,
                             OffsetEx: float, OffsetEy: float, *DIR_MaxVel: Any) -> None:
        """Relative arc on axes 0, 1: centre and end as offsets from the start."""
        mod, local = self._arc_pair(M_No, 0)
        d, v = self._arc_args(DIR_MaxVel)
        self._arc(mod, local, (OffsetCx, OffsetCy), (OffsetEx, OffsetEy), d, False, None, v)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_a_arc_zu(self, M_No: int, Cx: float, Cy: float, Ex: float, Ey: float,
                             *DIR_MaxVel: Any) -> None:
        mod, local = self._arc_pair(M_No, 2)
        d, v = self._arc_args(DIR_MaxVel)
        self._arc(mod, local, (Cx, Cy), (Ex, Ey), d, True, None, v)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_r_arc_zu(self, M_No: int, OffsetCx: float, OffsetCy: float,
                             OffsetEx: float, OffsetEy: float, *DIR_MaxVel: Any) -> None:
        mod, local = self._arc_pair(M_No, 2)
        d, v = self._arc_args(DIR_MaxVel)
        self._arc(mod, local, (OffsetCx, OffsetCy), (OffsetEx, OffsetEy), d, False, None, v)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_a_arc2(self, AxisArray: Any, Cx: float, Cy: float, Ex: float,
                           Ey: float, *DIR_MaxVel: Any) -> None:
        """Absolute arc on any 2 axes of one module."""
        mod, local = self._axes(AxisArray, 2)
        d, v = self._arc_args(DIR_MaxVel)
        self._arc(mod, local, (Cx, Cy), (Ex, Ey), d, True, None, v)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_r_arc2(self, AxisArray: Any, OffsetCx: float, OffsetCy: float,
                           OffsetEx: float, OffsetEy: float, *DIR_MaxVel: Any) -> None:
        mod, local = self._axes(AxisArray, 2)
        d, v = self._arc_args(DIR_MaxVel)
        self._arc(mod, local, (OffsetCx, OffsetCy), (OffsetEx, OffsetEy), d, False, None, v)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_tr_arc_xyu(self, M_No: int, OffsetCx: float, OffsetCy: float,
                               OffsetEx: float, OffsetEy: float, DIR: int, StrVel: float,
                               MaxVel: float, Tacc: float, Tdec: float) -> None:
        """Relative arc on axes 0, 1 with a T-curve tangential profile (4.6 "Circular
        Interpolation with Acc/dec Time"). The card borrows axis 3 as an aid; here axis 3
        must be idle and is left where it is."""
        mod, local = self._arc_pair(M_No, 0)
        if len(mod.ctl.axes) > 3 and mod.ctl.axes[3].is_moving:
            raise Refusal(ERR_AxisBusy, "axis 3 (the aided axis) is moving")
        self._arc(mod, local, (OffsetCx, OffsetCy), (OffsetEx, OffsetEy), DIR, False,
                  (StrVel, MaxVel, Tacc, Tdec), MaxVel)

    @hsl_call(TWO_AXIS)
    def HSL_M_start_ta_arc_xyu(self, M_No: int, Cx: float, Cy: float, Ex: float, Ey: float,
                               DIR: int, StrVel: float, MaxVel: float, Tacc: float,
                               Tdec: float) -> None:
        """Absolute arc on axes 0, 1 with a T-curve tangential profile."""
        mod, local = self._arc_pair(M_No, 0)
        if len(mod.ctl.axes) > 3 and mod.ctl.axes[3].is_moving:
            raise Refusal(ERR_AxisBusy, "axis 3 (the aided axis) is moving")
        self._arc(mod, local, (Cx, Cy), (Ex, Ey), DIR, True, (StrVel, MaxVel, Tacc, Tdec),
                  MaxVel)

