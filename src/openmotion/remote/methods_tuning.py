"""Methods of the tuning page: test moves and step responses, servo loop gains (see
docs/remote.md "Tuning")."""

from __future__ import annotations

import dataclasses
from typing import Any

from ..errors import MotionError
from .methods import Context, method
from .methods_motion import _move_params
from .protocol import Params


def loop_info(ctx: Context, ax: Any) -> dict[str, Any]:
    cfg = ctx.svc.config.axis(ax.name)
    loop = cfg.loop
    live = ctx.svc.ctl.servo_loops.get(ax.name)
    return {"axis": ax.name, "unit": cfg.unit, "drive": cfg.drive.type,
            "servo_loop": live is not None,
            "loop": None if loop is None else dataclasses.asdict(loop),
            "inp_band": float(cfg.drive.inp_band) / abs(ax.units.pulses_per_unit),
            "max_speed": cfg.max_speed}


@method("tune.get", command=False)
def tune_get(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p.done()
    return loop_info(ctx, ctx.svc.ctl.axis(axis))


@method("tune.run")
def tune_run(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    kind = p.choice("kind", ("move", "step"))
    svc = ctx.svc
    ax = svc.ctl.axis(axis)
    band = p.number("band", None)
    if kind == "move":
        distance = p.number("distance")
        move = _move_params(p, ax)
        back = p.boolean("back", True)
        settle_s = p.number("settle_s", 0.5)
    else:
        amplitude = p.number("amplitude")
        duration_s = p.number("duration_s", 0.3)
    p.done()
    with svc.ctl.lock:
        if svc.program.active:
            raise MotionError("a program is running: abort it before a tuning run")
        if svc.repeats.active(ax.index) or svc.jogs.jog_of(ax.index) is not None:
            raise MotionError(f"axis {ax.name} is repeating or jogging; stop it first")
        if kind == "move":
            run = svc.tuning.start_move(ax, distance, move, back=back, settle_s=settle_s,
                                        band=band)
        else:
            run = svc.tuning.start_step(ax, amplitude, duration_s, band)
    return {"id": run.id, "state": run.state}


@method("tune.result", command=False)
def tune_result(ctx: Context, p: Params) -> dict[str, Any]:
    n = p.integer("max_points", 4000, lo=10, hi=100_000)
    p.done()
    with ctx.svc.ctl.lock:
        return ctx.svc.tuning.result(n)


@method("tune.gains")
def tune_gains(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    changes = p.obj("changes")
    p.done()
    svc = ctx.svc
    ax = svc.ctl.axis(axis)
    saved = svc.set_loop(ax, changes)
    return {**loop_info(ctx, ax), "saved": None if saved is None else str(saved),
            "config_version": svc.config_version}
