"""Methods of the operation, jog and simulation pages (see docs/remote.md).

Positions and speeds are in the axis's user unit; the axis methods are called with
`units=True`, so every range rule and message is the library's own.
"""

from __future__ import annotations

from typing import Any

from ..control.core.states import AxisState
from ..control.manual.jog import jog_space
from ..errors import MotionError
from .methods import Context, method, renamed
from .protocol import Params
from .status import axis_status

SHAPES = ("T", "S")
TIME_MAX = 100.0


def _speed(p: Params, ax: Any, name: str, default: Any = None, *, positive: bool = False
           ) -> Any:
    """A speed parameter in the axis's user unit, checked against its maximum safe speed
    (the message in user units; the library checks the rest in pulses)."""
    v = p.number(name) if default is None else p.number(name, default)
    vmax = ax.config.max_speed
    if not (v > 0.0 if positive else v >= 0.0) or v > vmax * (1 + 1e-12):
        raise MotionError(f"{name} on axis {ax.name} must be in {'(' if positive else '['}0, "
                          f"{vmax:g}] {ax.config.unit}/s (maximum safe speed), got {v!r}")
    return v


def _move_params(p: Params, ax: Any, *, max_vel: bool = True) -> dict[str, Any]:
    kw: dict[str, Any] = {}
    if max_vel:
        kw["max_vel"] = _speed(p, ax, "max_vel", positive=True)
    kw["str_vel"] = _speed(p, ax, "str_vel", 0.0)
    kw["tacc"] = p.number("tacc", 0.1, lo=0.0, hi=TIME_MAX, lo_open=True)
    tdec = p.number("tdec", None, lo=0.0, hi=TIME_MAX, lo_open=True)
    if max_vel:
        kw["tdec"] = tdec
    kw["shape"] = p.choice("shape", SHAPES, "T")
    kw["vs_acc"] = _speed(p, ax, "vs_acc", 0.0)
    if max_vel:
        kw["vs_dec"] = _speed(p, ax, "vs_dec", 0.0)
    return kw


def _status(ctx: Context, ax: Any) -> dict[str, Any]:
    with ctx.svc.ctl.lock:
        return axis_status(ctx.svc, ax)


@method("axis.servo")
def axis_servo(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    on = p.boolean("on")
    p.done()
    ctl = ctx.svc.ctl
    ax = ctl.axis(axis)
    with ctl.lock:
        if ctl.safety is not None:
            ctl.safety.set_servo(ax.index, on)
        elif on:
            ax.enable()
        else:
            ax.disable()
    return _status(ctx, ax)


@method("axis.reset")
def axis_reset(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p.done()
    ax = ctx.svc.ctl.axis(axis)
    if ctx.svc.estop_reason is not None:   # one axis must not leave a latched E-stop
        raise MotionError(f"axis {ax.name}: the software E-stop is latched; machine.reset "
                          "releases it and resets every axis")
    ax.reset()
    return _status(ctx, ax)


@method("axis.move")
def axis_move(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    kind = p.choice("kind", ("absolute", "relative", "velocity"))
    ctl = ctx.svc.ctl
    ax = ctl.axis(axis)
    srange = _speed(p, ax, "speed_range", -1.0) if p.has("speed_range") else None
    if kind == "velocity":
        v = p.number("velocity")
        kw = _move_params(p, ax, max_vel=False)
        p.done()
        with ctl.lock:
            _no_repeat(ctx, ax)
            _fix_range(ax, srange)
            ax.move_velocity(v, units=True, **kw)
        return {"duration": None}
    target = p.number("position" if kind == "absolute" else "distance")
    kw = _move_params(p, ax)
    p.done()
    with ctl.lock:
        _no_repeat(ctx, ax)
        _fix_range(ax, srange)
        if kind == "absolute":
            ax.move_absolute(target, units=True, **kw)
        else:
            ax.move_relative(target, units=True, **kw)
        m = ax.motion
        return {"duration": None if m is None else float(m.profile.duration)}


def _fix_range(ax: Any, srange: float | None) -> None:
    """HSL fix_speed_range: the highest speed a later change of speed may reach (a move
    without it may only change up to its own MaxVel); 0 unfixes it."""
    if srange is None:
        return
    if srange == 0.0:
        ax.unfix_speed_range()
    else:
        ax.fix_speed_range(srange, units=True)


def _no_repeat(ctx: Context, ax: Any) -> None:
    if ctx.svc.repeats.active(ax.index):
        raise MotionError(f"axis {ax.name} is repeating; axis.stop ends the repeat first")


@method("axis.repeat")
def axis_repeat(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p1 = p.number("p1")
    p2 = p.number("p2")
    delay = p.number("delay_s", 0.5, lo=0.0, hi=60.0)
    count = p.integer("count", 0, lo=0, hi=1_000_000)
    kw = _move_params(p, ctx.svc.ctl.axis(axis))
    p.done()
    ctx.svc.repeats.start(axis, p1, p2, delay, count, kw)
    return {}


@method("axis.change_speed")
def axis_change_speed(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    v = p.number("velocity")
    tacc = p.number("tacc", 0.1, lo=0.0, hi=TIME_MAX, lo_open=True)
    p.done()
    ax = ctx.svc.ctl.axis(axis)
    try:
        ax.change_speed(v, tacc, units=True)
    except MotionError as exc:
        raise renamed(exc, {"new_vel": "velocity"}) from None
    return {}


@method("axis.change_position")
def axis_change_position(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    pos = p.number("position")
    p.done()
    ax = ctx.svc.ctl.axis(axis)
    try:
        ax.change_position(pos, units=True)
    except MotionError as exc:
        raise renamed(exc, {"new_position": "position"}) from None
    return {}


@method("axis.stop", command=False)  # a stop never waits behind commands
def axis_stop(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis("axis", None)
    mode = p.choice("mode", ("decel", "immediate"), "decel")
    tdec = p.number("tdec", None, lo=0.0, hi=TIME_MAX, lo_open=True)
    p.done()
    ctx.svc.stop_axis(axis, mode == "immediate", tdec)
    return {}


def _at_rest(ax: Any) -> None:
    if ax.is_moving or ax.state not in (AxisState.STANDSTILL, AxisState.DISABLED,
                                        AxisState.ERROR_STOP):
        raise MotionError(f"axis {ax.name}: positions can be set at rest only "
                          f"(state {ax.state.value})")


@method("axis.set_position")
def axis_set_position(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    pos = p.number("position", None)
    command = p.integer("command", None)
    feedback = p.integer("feedback", None)
    target = p.integer("target", None)
    p.done()
    if pos is None and command is None and feedback is None and target is None:
        raise MotionError("give at least one of position, command, feedback, target")
    ctl = ctx.svc.ctl
    ax = ctl.axis(axis)
    with ctl.lock:
        _at_rest(ax)
        c = ax.counters
        if pos is not None:
            pulses = round(float(ax.units.to_pulses(pos)))
            c.set_command(pulses)
            c.set_feedback(round(pulses * c.move_ratio))
            c.reset_target(float(pulses))
        if command is not None:
            c.set_command(command)
        if feedback is not None:
            c.set_feedback(feedback)
        if target is not None:
            c.reset_target(float(target))
    return _status(ctx, ax)


@method("axis.reset_position")
def axis_reset_position(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p.done()
    ctl = ctx.svc.ctl
    ax = ctl.axis(axis)
    with ctl.lock:
        _at_rest(ax)
        ax.counters.reset_all()
    return _status(ctx, ax)


# -- jog ----------------------------------------------------------------------------------
@method("jog.start")
def jog_start(ctx: Context, p: Params) -> dict[str, Any]:
    from .deadman import CONFIRM_MS, DEADMAN_S

    axis = p.axis()
    direction = p.choice("direction", (1, -1))
    speed = p.number("speed", None, lo=0.0, lo_open=True)
    ratio = p.number("ratio", None, lo=0.0, hi=100.0, lo_open=True)
    tacc = p.number("tacc", 0.05, lo=0.0, hi=10.0, lo_open=True)
    p.done()
    if speed is not None and ratio is not None:
        raise MotionError("give speed or ratio, not both")
    ax = ctx.svc.ctl.axis(axis)
    if speed is not None:
        vmax = ax.config.max_speed
        if speed > vmax:
            raise MotionError(f"speed on axis {ax.name} must be <= {vmax:g} "
                              f"{ax.config.unit}/s (maximum safe speed), got {speed!r}")
        ratio = 100.0 * speed / vmax
    jog = ctx.svc.jogs.start(ax.index, direction, 10.0 if ratio is None else ratio, tacc,
                             ctx.conn)
    return {"jog": jog.id, "confirm_ms": CONFIRM_MS, "deadman_ms": int(DEADMAN_S * 1e3)}


@method("jog.confirm", command=False)
def jog_confirm(ctx: Context, p: Params) -> dict[str, Any]:
    jog = p.string("jog", max_len=64)
    p.done()
    active, reason = ctx.svc.jogs.confirm(jog)
    return {"active": active, "reason": reason}


@method("jog.stop", command=False)
def jog_stop(ctx: Context, p: Params) -> dict[str, Any]:
    jog = p.string("jog", max_len=64)
    p.done()
    ctx.svc.jogs.stop(jog)
    return {}


@method("jog.step")
def jog_step(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    distance = p.number("distance")
    speed = p.number("speed", None, lo=0.0, lo_open=True)
    p.done()
    ax = ctx.svc.ctl.axis(axis)
    vmax = ax.config.max_speed
    ratio = 10.0 if speed is None else 100.0 * speed / vmax
    if ratio > 100.0:
        raise MotionError(f"speed on axis {ax.name} must be <= {vmax:g} {ax.config.unit}/s "
                          f"(maximum safe speed), got {speed!r}")
    jog_space(ctx.svc.ctl, ax.index, distance, ratio)
    return {}


# -- simulation -----------------------------------------------------------------------------
def _scenario(ctx: Context) -> Any:
    sc = getattr(ctx.svc.ctl.hardware, "scenario", None)
    if sc is None:
        raise MotionError("the back end is not the simulator: no simulation controls")
    return sc


@method("sim.trip_limit")
def sim_trip_limit(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    signal = p.choice("signal", ("pel", "mel", "org", "sd"))
    active = p.boolean("active")
    p.done()
    ctl = ctx.svc.ctl
    ax = ctl.axis(axis)
    sc = _scenario(ctx)
    with ctl.lock:
        if active:
            # a switch under the carriage now: the motor position (where switches act)
            here = float(ctl.hardware.load_position(ax.index))
            span = max(100.0, ax.units.pulses_per_unit)
            sc.place_switch(ax.index, signal, here - span, 2 * span)
        else:
            sw = getattr(ax.config, signal)
            if sw is None:
                sc.remove_switch(ax.index, signal)
            else:
                sc.place_switch(ax.index, signal, sw.position, sw.width, sw.hysteresis)
    return {}


@method("sim.alarm")
def sim_alarm(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    active = p.boolean("active")
    p.done()
    ax = ctx.svc.ctl.axis(axis)
    sc = _scenario(ctx)
    with ctx.svc.ctl.lock:
        if active:
            sc.trip_alarm(ax.index)
        else:
            sc.clear_alarm(ax.index)
    return {}


@method("sim.estop", command=False)  # a stop never waits behind commands
def sim_estop(ctx: Context, p: Params) -> dict[str, Any]:
    pressed = p.boolean("pressed")
    p.done()
    sc = _scenario(ctx)
    svc = ctx.svc
    with svc.ctl.lock:
        if pressed:
            svc.jogs.stop_all("emergency stop")
            svc.repeats.stop_all("emergency stop")
            svc.program.abort_if_running()
            sc.press_estop()
        else:
            sc.release_estop()
    return {}


@method("sim.input")
def sim_input(ctx: Context, p: Params) -> dict[str, Any]:
    index = p.integer("index", lo=0)
    level = p.boolean("level")
    p.done()
    n = ctx.svc.config.digital_inputs
    if index >= n:
        raise MotionError(f"index must be in [0, {n - 1}] (the machine's digital inputs), "
                          f"got {index}")
    sc = _scenario(ctx)
    with ctx.svc.ctl.lock:
        sc.set_input(f"di{index}", level)
    return {}


@method("sim.speed")
def sim_speed(ctx: Context, p: Params) -> dict[str, Any]:
    factor = p.number("factor", lo=1.0, hi=20.0)
    p.done()
    ctx.svc.set_speed(factor)
    return {"speed": ctx.svc.speed}
