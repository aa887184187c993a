"""ZMotion BASIC commands in Python: `ZController` (seed zmotion-pso-2d-3d-and-hw-timer.txt).

The article's subroutines read almost word for word:

    c = ZController()                 # 3 free axes on the simulator, OUT0..3 PSO-capable
    c.BASE(0, 1, 2)
    c.ATYPE = 1, 1, 1
    c.UNITS = 100, 100, 100
    c.SPEED = 100, 100, 100
    c.MERGE = ON, ON, ON
    c.TABLE(0, 100, 150, 250, 300, 400, 450)
    c.HW_PSWITCH2(1, 0, 1, 0, 5, 1)
    c.TRIGGER()
    c.MOVE(500)
    c.WAIT_IDLE(0)

Mapping onto the core (the facade keeps the settings and forwards; every rule lives in the
core): TABLE / BASE / UNITS / ATYPE / VECTOR_MOVED / HW_PSWITCH2 / HW_TIMER go to
`control.trigger.pso.ZPso` on a `CompareEngine`; MOVE / MOVEABS are linear interpolations of a
`control.groups.group.Group` over the BASE axes (`pso.base_axes`: a BASE list shorter than the
move is extended by the following axes) in units of UNITS pulses, at the main axis's SPEED
(vector speed), ACCEL, DECEL, with SRAMP as an S-curve whose jerk is ACCEL / SRAMP and MERGE
as blending (corners rounded within one pulse of the main axis, so a PSO window around a
corner still sees the path); DPOS / MPOS are the command and feedback counters divided by
UNITS; OP drives an output (a PSO output through its exact compare waveform); TRIGGER starts
a `compare_scope.Scope`; WAIT_IDLE runs virtual time until the axis is idle; RAPIDSTOP(2)
aborts every interpolation along its path, RAPIDSTOP(3) stops at once.

A refused command raises `ZMotionError` (a MotionError) naming the command and the
parameter, with a code, and changes nothing. docs/porting-zmotion.md has the status table.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from functools import wraps
from typing import Any, TypeVar

from ..config import AxisConfig, MachineConfig
from ..control.core.controller import Controller
from ..control.groups.group import (
    ERR_AXIS_BUSY,
    ERR_GROUP,
    ERR_STATE,
    Group,
    GroupError,
    GroupState,
)
from ..control.trigger.compare import CompareEngine
from ..control.trigger.compare_scope import Scope
from ..control.trigger.pso import ZPso, base_axes
from ..errors import MotionError, check_finite, check_positive
from ..profile.sramp import ramp_spec
from ..units import AxisUnits
from .zmotion_params import (
    ZERR_PARAMETER,
    ZERR_STATE,
    ZERR_TIMEOUT,
    ZERR_UNSUPPORTED,
    AxisParam,
    TableView,
    ZMotionError,
    parameter_of,
)

__all__ = ["OFF", "ON", "ZController", "ZMotionError"]

ON, OFF = 1, 0
#: ATYPE values: 1 pulse axis (PSO compares DPOS), 4 pulse axis with encoder (MPOS).
ATYPES = {1: "dpos", 4: "mpos"}
F = TypeVar("F", bound=Callable[..., Any])


def _command(name: str) -> Callable[[F], F]:
    """Turn any core refusal into a ZMotionError naming the command and the parameter."""

    def deco(fn: F) -> F:
        @wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            try:
                return fn(*args, **kwargs)
            except ZMotionError:
                raise
            except GroupError as e:
                code = ZERR_STATE if e.code in (ERR_AXIS_BUSY, ERR_STATE, ERR_GROUP) \
                    else ZERR_PARAMETER
                raise ZMotionError(name, parameter_of(str(e)), str(e), code) from None
            except MotionError as e:
                raise ZMotionError(name, parameter_of(str(e)), str(e)) from None

        return wrapper  # type: ignore[return-value]

    return deco


def _machine(n_axes: int) -> Controller:
    """n free axes (no switches), 16 outputs, 1 ms cycle: a ZMC-like simulated card."""
    if isinstance(n_axes, bool) or not isinstance(n_axes, int) or not 1 <= n_axes <= 4:
        raise MotionError(f"n_axes must be an integer in [1, 4], got {n_axes!r}")
    cfg = MachineConfig("zmotion", tuple(AxisConfig(name=k) for k in "xyzu"[:n_axes]))
    c = Controller(cfg)
    c.enable_all()
    return c


class ZController:
    """A ZMotion controller on an openmotion Controller (default: `n_axes` free simulated
    axes). outputs: the PSO-capable outputs (default OUT0..3, as a ZMC406)."""

    def __init__(self, controller: Controller | None = None, *, n_axes: int = 3,
                 outputs: Sequence[int] = (0, 1, 2, 3), table_size: int = 100_000) -> None:
        self.ctl = _machine(n_axes) if controller is None else controller
        if not isinstance(self.ctl, Controller):
            raise MotionError(f"controller must be a Controller, got {type(controller).__name__}")
        n = len(self.ctl.axes)
        self.engine = CompareEngine(self.ctl)
        self.pso = ZPso(self.engine, table_size=table_size, outputs=outputs)
        self.pso.base(*range(n))
        self._n = n
        self._atype = [1] * n
        self._speed = [100.0] * n  # units/s
        self._accel = [1000.0] * n
        self._decel = [1000.0] * n
        self._merge = [0] * n
        self._sramp = [0.0] * n
        self._groups: dict[tuple[int, ...], Group] = {}
        self._group_units: dict[tuple[int, ...], tuple[float, ...]] = {}
        self.scope: Scope | None = None
        self._params = {
            "ATYPE": AxisParam("ATYPE", n, lambda: self.pso.base_list,
                               lambda a: self._atype[a], self._put_atype),
            "UNITS": AxisParam("UNITS", n, lambda: self.pso.base_list, self.pso.units,
                               self._put_units),
            "SPEED": self._setting("SPEED", self._speed, check_positive),
            "ACCEL": self._setting("ACCEL", self._accel, check_positive),
            "DECEL": self._setting("DECEL", self._decel, check_positive),
            "MERGE": self._setting("MERGE", self._merge, _on_off),
            "SRAMP": self._setting("SRAMP", self._sramp, _sramp),
            "DPOS": AxisParam("DPOS", n, lambda: self.pso.base_list, self._dpos,
                              lambda v: self._put_counter("DPOS", v)),
            "MPOS": AxisParam("MPOS", n, lambda: self.pso.base_list, self._mpos,
                              lambda v: self._put_counter("MPOS", v)),
            "VECTOR_MOVED": AxisParam("VECTOR_MOVED", n, lambda: self.pso.base_list,
                                      lambda a: self.pso.vector_moved(a),
                                      self._put_vector),
        }
        self.TABLE = TableView(lambda: int(self.pso.table_data.size),
                               lambda i: float(self.pso.table_data[i]), self._put_table)

    # ------------------------------------------------------------------ axis parameters
    def _setting(self, name: str, store: list[Any], check: Callable[[str, Any], Any]
                 ) -> AxisParam:
        def put(values: dict[int, Any]) -> None:
            ok = {a: check(f"{name}({a})", v) for a, v in values.items()}  # all, then set
            for a, v in ok.items():
                store[a] = v

        return AxisParam(name, self._n, lambda: self.pso.base_list, lambda a: store[a],
                         _command(name)(put))

    def _param(name: str) -> property:  # noqa: N805 - a property factory in the class body
        def fget(self: ZController) -> AxisParam:
            return self._params[name]

        def fset(self: ZController, values: Any) -> None:
            self._params[name].assign(values)

        return property(fget, fset, doc=f"{name}: per-axis parameter (see zmotion_params)")

    ATYPE = _param("ATYPE")
    UNITS = _param("UNITS")
    SPEED = _param("SPEED")
    ACCEL = _param("ACCEL")
    DECEL = _param("DECEL")
    MERGE = _param("MERGE")
    SRAMP = _param("SRAMP")
    DPOS = _param("DPOS")
    MPOS = _param("MPOS")
    VECTOR_MOVED = _param("VECTOR_MOVED")
    del _param

    @_command("ATYPE")
    def _put_atype(self, values: dict[int, Any]) -> None:
        for a, v in values.items():
            if isinstance(v, bool) or not isinstance(v, int) or v not in ATYPES:
                raise ZMotionError("ATYPE", f"ATYPE({a})", f"ATYPE({a}) must be 1 (pulse "
                                   f"axis, compares DPOS) or 4 (pulse axis with encoder, "
                                   f"compares MPOS), got {v!r}", ZERR_UNSUPPORTED)
        for a, v in values.items():
            self.pso.source(a, ATYPES[v])
            self._atype[a] = int(v)

    @_command("UNITS")
    def _put_units(self, values: dict[int, Any]) -> None:
        ok = {a: check_positive(f"UNITS({a})", v) for a, v in values.items()}
        for a in ok:
            if self.ctl.axes[a].is_moving:
                raise ZMotionError("UNITS", f"UNITS({a})", f"axis {a} is moving",
                                   ZERR_STATE)
        for a, v in ok.items():
            self.pso.set_units(a, v)

    def _dpos(self, axis: int) -> float:
        return self.ctl.axes[axis].position / self.pso.units(axis)

    def _mpos(self, axis: int) -> float:
        return self.ctl.axes[axis].counters.feedback_unwrapped() / self.pso.units(axis)

    def _put_counter(self, name: str, values: dict[int, Any]) -> None:
        @_command(name)
        def put() -> None:
            counts = {a: round(check_finite(f"{name}({a})", v) * self.pso.units(a))
                      for a, v in values.items()}
            for a in counts:
                if self.ctl.axes[a].is_moving:
                    raise ZMotionError(name, f"{name}({a})", f"axis {a} is moving; "
                                       "WAIT IDLE first", ZERR_STATE)
            for a, k in counts.items():
                ctr = self.ctl.axes[a].counters
                ctr.set_command(k) if name == "DPOS" else ctr.set_feedback(k)

        put()

    @_command("VECTOR_MOVED")
    def _put_vector(self, values: dict[int, Any]) -> None:
        ok = {a: check_finite(f"VECTOR_MOVED({a})", v) for a, v in values.items()}
        for a, v in ok.items():
            self.pso.set_vector_moved(v, a)

    @_command("TABLE")
    def _put_table(self, start: int, values: Sequence[float]) -> None:
        self.pso.table(start, *values)

    # ------------------------------------------------------------------ BASE
    @_command("BASE")
    def BASE(self, *axes: int) -> None:  # noqa: N802 - the ZMotion command name
        """BASE(a0, a1, ...): the axes the following commands act on."""
        self.pso.base(*axes)

    @property
    def base(self) -> tuple[int, ...]:
        return self.pso.base_list

    # ------------------------------------------------------------------ I/O
    @_command("OP")
    def OP(self, number: int, state: int | bool | None = None) -> bool | None:  # noqa: N802
        """OP(n, ON/OFF) drives output n; OP(n) reads it."""
        n_do = self.ctl.config.digital_outputs
        if isinstance(number, bool) or not isinstance(number, int) or not 0 <= number < n_do:
            raise ZMotionError("OP", "number", f"number must be an output in [0, {n_do - 1}], "
                               f"got {number!r}")
        pso_line = number in self.pso.outputs
        if state is None:
            if pso_line:
                return self.engine.output(number).level_at(self.ctl.time)
            return bool(self.ctl.hardware.read_output(None, f"do{number}"))
        level = bool(_on_off("state", state))
        if pso_line:
            self.engine.output(number).set(self.ctl.time, level)
        else:
            self.ctl.hardware.write_output(None, f"do{number}", level)
        return None

    # ------------------------------------------------------------------ PSO
    @_command("HW_PSWITCH2")
    def HW_PSWITCH2(self, mode: int, *params: float) -> int | None:  # noqa: N802
        """HW_PSWITCH2(mode, ...) on the BASE axes (control.trigger.pso.ZPso.hw_pswitch2)."""
        return self.pso.hw_pswitch2(mode, *params)

    @_command("HW_PSWITCH2")
    def HW_PSWITCH2_FREE(self, axis: int | None = None) -> int:  # noqa: N802
        """?HW_PSWITCH2(axis): the compare buffer space left."""
        return self.pso.remaining(axis)

    @_command("HW_TIMER")
    def HW_TIMER(self, mode: int, cycle_us: float, on_us: float, reptimes: int,  # noqa: N802
                 opstate: int | bool, opnum: int) -> None:
        """HW_TIMER(mode, cyclonetime, optime, reptimes, opstate, opnum)."""
        self.pso.hw_timer(mode, cycle_us, on_us, reptimes, _on_off("opstate", opstate), opnum)

    @_command("TRIGGER")
    def TRIGGER(self) -> Scope:  # noqa: N802
        """Start the oscilloscope: every axis's DPOS/MPOS and the PSO outputs from now."""
        if self.scope is None:
            self.scope = Scope(self.engine, range(self._n), sorted(self.pso.outputs),
                               scale=[self.pso.units(a) for a in range(self._n)])
        else:
            self.scope.scale = tuple(self.pso.units(a) for a in range(self._n))
        self.scope.trigger()
        return self.scope

    # ------------------------------------------------------------------ motion
    def _group(self, axes: tuple[int, ...], command: str) -> Group:
        units = tuple(self.pso.units(a) for a in axes)
        key = axes
        g = self._groups.get(key)
        if g is not None and self._group_units[key] == units:
            return g
        for k, other in list(self._groups.items()):
            if set(k) & set(axes) and (other.state is not GroupState.IDLE
                                       or other.queue_length):
                raise ZMotionError(command, "axes", f"axes {k!r} are still moving in "
                                       "another interpolation; WAIT IDLE first", ZERR_STATE)
        for k, other in list(self._groups.items()):
            if set(k) & set(axes):
                other.close()
                del self._groups[k]
        au = [AxisUnits(self.ctl.axes[a].name, "unit", u, 1,
                        self.ctl.axes[a].max_speed / u) for a, u in zip(axes, units, strict=True)]
        g = Group(self.ctl, list(axes), units=au, feed=min(self._speed[axes[0]],
                                                           au[0].max_speed))
        self._groups[key] = g
        self._group_units[key] = units
        return g

    def _move(self, command: str, values: Sequence[float], relative: bool) -> int:
        if not values:
            raise ZMotionError(command, "distance", "needs at least one value")
        vals = [check_finite(f"value[{i}]", v) for i, v in enumerate(values)]
        try:
            axes = base_axes(self.pso.base_list, len(vals), self._n)
        except MotionError as e:
            raise ZMotionError(command, "axes", str(e)) from None
        main = axes[0]
        if len(axes) == 1:
            return self._move_axis(command, main, vals[0], relative)
        g = self._group(axes, command)
        feed, acc = self._speed[main], self._accel[main]
        g.set_feed(feed)
        g.set_acc_time(feed / acc)
        g.set_dec_time(feed / self._decel[main])
        ramp = self._sramp[main] / 1000.0
        g.set_path_shape("S", acc / ramp) if ramp > 0 else g.set_path_shape("T")
        if self._merge[main]:
            g.enable_blend(1.0 / self.pso.units(main))
        else:
            g.disable_blend()
        return g.line(vals, relative=relative)

    def _move_axis(self, command: str, axis: int, value: float, relative: bool) -> int:
        """One axis: a PCL-style T/S move at SPEED with ACCEL / DECEL smoothed by SRAMP."""
        ax = self.ctl.axes[axis]
        for k in self._groups:
            if axis in k and not self._idle(axis):
                raise ZMotionError(command, "axes", f"axis {axis} is moving in an "
                                   "interpolation; WAIT IDLE first", ZERR_STATE)
        if ax.is_moving:
            raise ZMotionError(command, "axes", f"axis {axis} is moving (single-axis moves "
                               "are not buffered here); WAIT IDLE first", ZERR_STATE)
        u = self.pso.units(axis)
        dist = value if relative else value - self._dpos(axis)
        v, ts = self._speed[axis], self._sramp[axis] / 1000.0
        shape, tacc, vs_acc = ramp_spec(v * u, self._accel[axis] * u, ts)
        _, tdec, vs_dec = ramp_spec(v * u, self._decel[axis] * u, ts)
        for k, g in list(self._groups.items()):  # the axis leaves its idle interpolation
            if axis in k:
                g.close()
                del self._groups[k]
        ax.move_relative(dist * u, max_vel=v * u, tacc=tacc, tdec=tdec, shape=shape,
                         vs_acc=vs_acc, vs_dec=vs_dec)
        return 0

    @_command("MOVE")
    def MOVE(self, *distances: float) -> int:  # noqa: N802
        """MOVE(d0, d1, ...): relative linear interpolation of the BASE axes (units)."""
        return self._move("MOVE", distances, True)

    @_command("MOVEABS")
    def MOVEABS(self, *positions: float) -> int:  # noqa: N802
        """MOVEABS(p0, p1, ...): absolute linear interpolation of the BASE axes (units)."""
        return self._move("MOVEABS", positions, False)

    def _idle(self, axis: int) -> bool:
        for k, g in self._groups.items():
            if axis in k and (g.state is not GroupState.IDLE or g.queue_length):
                return False
        return not self.ctl.axes[axis].is_moving

    @_command("WAIT IDLE")
    def WAIT_IDLE(self, axis: int | None = None, timeout: float = 3600.0) -> float:  # noqa: N802
        """WAIT IDLE(axis) (default the first BASE axis): run virtual time until the axis
        and its interpolation are idle; returns the controller time then."""
        a = self.pso.base_list[0] if axis is None else axis
        if isinstance(a, bool) or not isinstance(a, int) or not 0 <= a < self._n:
            raise ZMotionError("WAIT IDLE", "axis", f"axis must be an integer in "
                               f"[0, {self._n - 1}], got {axis!r}")
        check_positive("timeout", timeout)
        if not self.ctl.run_until(lambda: self._idle(a), timeout):
            raise ZMotionError("WAIT IDLE", "axis", f"axis {a} still moving after "
                               f"{timeout:g} s", ZERR_TIMEOUT)
        return self.ctl.time

    @_command("IDLE")
    def IDLE(self, axis: int) -> bool:  # noqa: N802
        """IDLE(axis): True when the axis and its interpolation are idle."""
        if isinstance(axis, bool) or not isinstance(axis, int) or not 0 <= axis < self._n:
            raise ZMotionError("IDLE", "axis", f"axis must be an integer in "
                               f"[0, {self._n - 1}], got {axis!r}")
        return self._idle(axis)

    @_command("RAPIDSTOP")
    def RAPIDSTOP(self, mode: int = 2) -> None:  # noqa: N802
        """RAPIDSTOP(2): every interpolation decelerates along its path at its deceleration
        and the buffered moves are dropped; RAPIDSTOP(3): every axis stops at once."""
        if isinstance(mode, bool) or not isinstance(mode, int) or mode not in (0, 1, 2, 3):
            raise ZMotionError("RAPIDSTOP", "mode", f"mode must be 2 or 3, got {mode!r}")
        if mode in (0, 1):
            raise ZMotionError("RAPIDSTOP", "mode", f"mode {mode} (cancel only the current "
                               "or only the buffered move) is not provided; use 2 or 3",
                               ZERR_UNSUPPORTED)
        if mode not in (2, 3):
            raise ZMotionError("RAPIDSTOP", "mode", f"mode must be 2 or 3, got {mode!r}")
        in_groups: set[int] = set()
        for k, g in list(self._groups.items()):
            if mode == 3:
                g.close()
                del self._groups[k]
            else:
                in_groups.update(k)
                if g.state is not GroupState.IDLE or g.queue_length:
                    g.abort()  # the group decelerates its own axes along the path
        for ax in self.ctl.axes:  # single axes (a direct stop of a group axis would fault it)
            if ax.index not in in_groups:
                if mode == 3:
                    ax.stop_immediately()
                else:
                    ax.stop()

    @_command("WAIT UNTIL")
    def WAIT_UNTIL(self, condition: Callable[[], bool], timeout: float = 3600.0  # noqa: N802
                   ) -> float:
        """WAIT UNTIL condition: run virtual time until `condition()` is true."""
        if not callable(condition):
            raise ZMotionError("WAIT UNTIL", "condition", f"condition must be callable, "
                               f"got {condition!r}")
        if not self.ctl.run_until(condition, check_positive("timeout", timeout)):
            raise ZMotionError("WAIT UNTIL", "condition", f"still false after {timeout:g} s",
                               ZERR_TIMEOUT)
        return self.ctl.time

    # ------------------------------------------------------------------ convenience
    def run(self, seconds: float) -> None:
        """Let `seconds` of virtual time pass (ZMotion: the program waits, e.g. DELAY)."""
        self.ctl.advance(check_finite("seconds", seconds))


def _on_off(name: str, v: Any) -> int:
    if isinstance(v, bool):
        return int(v)
    if isinstance(v, int | float) and v in (0, 1):
        return int(v)
    raise MotionError(f"{name} must be ON (1) or OFF (0), got {v!r}")


def _sramp(name: str, v: Any) -> float:
    x = check_finite(name, v)
    if not 0.0 <= x <= 250.0 or math.isnan(x):
        raise MotionError(f"{name} must be in [0, 250] ms, got {v!r}")
    return x
