"""Methods of the machine, interface, homing and status pages (see docs/remote.md)."""

from __future__ import annotations

import math
import platform
from importlib import metadata
from typing import Any

from .. import __version__
from ..config import dumps_machine
from ..control.core.states import AxisState
from ..errors import MotionError
from . import homeconf, interface
from .deadman import CONFIRM_MS, DEADMAN_S
from .methods import Context, method
from .protocol import MAX_MESSAGE_BYTES, Params
from .status import FIELDS, axis_status, snapshot

API_VERSION = 1
#: modules a machine runs with, shown on the machine page
MODULES = (
    ("control", "axes, cycle, safety (limits, SD, ALM, E-stop, ERC), jog, homing"),
    ("profile", "T / S / jerk-limited profiles, change of speed and position on the fly"),
    ("path", "groups: lines, arcs, look-ahead, blending"),
    ("program", "G-code interpreter and program runner"),
    ("hw.sim", "the simulated machine: drives, encoders, switches"),
    ("remote", "this server: JSON-RPC API, scope, deadman jog"),
)


def _version(pkg: str) -> str | None:
    try:
        return metadata.version(pkg)
    except metadata.PackageNotFoundError:
        return None


@method("server.info", command=False)
def server_info(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    svc = ctx.svc
    clients = ctx.conn.server.clients() if ctx.conn is not None else 0
    return {"name": "openmotion", "version": __version__, "api": API_VERSION,
            "period_s": svc.ctl.period, "speed": svc.speed, "realtime": svc.running,
            "clients": clients, "max_message_bytes": MAX_MESSAGE_BYTES,
            "deadman_ms": int(DEADMAN_S * 1e3), "confirm_ms": CONFIRM_MS,
            "hook_errors": list(svc.hook_errors)[-10:]}


def axis_info(ax: Any) -> dict[str, Any]:
    cfg = ax.config
    u = ax.units
    travel = None
    if cfg.mel is not None and cfg.pel is not None:
        ends = sorted(float(u.to_units(x)) for x in (cfg.mel.position, cfg.pel.position))
        travel = [round(ends[0], 6), round(ends[1], 6)]
    vmax = cfg.max_speed
    return {"name": ax.name, "index": ax.index, "unit": cfg.unit,
            "pulses_per_unit": u.pulses_per_unit, "max_speed": vmax, "travel": travel,
            "drive": cfg.drive.type, "encoder_counts_per_rev": cfg.encoder_counts_per_rev,
            "speed_limits": {"str_vel": [0.0, vmax], "max_vel": [0.0, vmax],
                             "tacc": [0.0, 100.0]}}


def machine_info(ctx: Context) -> dict[str, Any]:
    svc = ctx.svc
    ctl = svc.ctl
    return {"name": svc.config.name, "file": None if svc.file is None else str(svc.file),
            "config_version": svc.config_version, "period_s": ctl.period, "simulated": True,
            "axes": [axis_info(ax) for ax in ctl.axes],
            "digital_inputs": svc.config.digital_inputs,
            "digital_outputs": svc.config.digital_outputs,
            "modules": [{"name": n, "doc": d} for n, d in MODULES],
            "versions": {"openmotion": __version__, "python": platform.python_version(),
                         **{k: _version(k) for k in ("numpy", "starlette", "uvicorn",
                                                     "websockets")}}}


@method("machine.info", command=False)
def m_machine_info(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    return machine_info(ctx)


@method("machine.config", command=False)
def machine_config(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    return {"toml": dumps_machine(ctx.svc.config), "config_version": ctx.svc.config_version}


@method("machine.save")
def machine_save(ctx: Context, p: Params) -> dict[str, Any]:
    path = p.string("path", None)
    p.done()
    f = ctx.svc.save(None if path is None else ctx.svc.workdir.resolve("path", path))
    return {"file": str(f)}


@method("machine.load")
def machine_load(ctx: Context, p: Params) -> dict[str, Any]:
    path = p.string("path")
    if not p.has("config_version"):
        p.integer("config_version")   # required here: refused as missing
    p.done()
    ctx.svc.load(str(ctx.svc.workdir.resolve("path", path)))
    return machine_info(ctx)


@method("machine.estop", command=False)  # a stop never waits behind commands
def machine_estop(ctx: Context, p: Params) -> dict[str, Any]:
    reason = p.string("reason", "emergency stop", max_len=200)
    p.done()
    ctx.svc.estop(reason or "emergency stop")
    return {}


@method("machine.reset")
def machine_reset(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    ctl = ctx.svc.ctl
    if ctl.estop_active:
        raise MotionError("E-stop is active: release it before resetting the axes")
    with ctl.lock:
        for ax in ctl.axes:
            if ax.state is AxisState.ERROR_STOP:
                ax.reset()
        ctx.svc.estop_reason = None   # the software E-stop latch ends with the reset
        return {"axes": {ax.name: ax.state.value for ax in ctl.axes}}


@method("machine.events", command=False)
def machine_events(ctx: Context, p: Params) -> dict[str, Any]:
    since = p.integer("since", 0, lo=0)
    n = p.integer("max", 200, lo=1, hi=2000)
    p.done()
    evs = [e for e in list(ctx.svc.events) if e["seq"] >= since][:n]
    nxt = evs[-1]["seq"] + 1 if evs else since
    return {"events": evs, "next": nxt}


# -- interface I/O ------------------------------------------------------------------------
def _interface(ctx: Context, axis: Any) -> dict[str, Any]:
    ax = ctx.svc.ctl.axis(axis)
    return interface.interface_of(ctx.svc.config.axis(ax.name), ctx.svc.responses[ax.name])


@method("interface.get", command=False)
def interface_get(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p.done()
    return {**_interface(ctx, axis), "choices": interface.choices()}


@method("interface.set")
def interface_set(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    changes = p.obj("changes")
    if not p.has("config_version"):
        p.integer("config_version")
    p.done()
    saved = ctx.svc.set_interface(axis, changes)
    return {"interface": _interface(ctx, axis), "config_version": ctx.svc.config_version,
            "saved": None if saved is None else str(saved)}


# -- homing -------------------------------------------------------------------------------
def _home(ctx: Context, axis: Any, mode: Any = None) -> dict[str, Any]:
    """The saved homing settings, or with `mode` the saved ones in that mode (not applied:
    the page draws a mode's sequence before the user picks it)."""
    ax = ctx.svc.ctl.axis(axis)
    c = ctx.svc.homes[ax.name]
    if mode is not None:
        c = homeconf.home_from_user(ax, c, {"mode": mode})
    return {"config": homeconf.home_to_user(ax, c), "sequence": homeconf.sequence(ax, c)}


@method("home.get", command=False)
def home_get(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    mode = p.raw("mode", None)
    p.done()
    return {**_home(ctx, axis, mode), "choices": homeconf.choices()}


@method("home.set")
def home_set(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    changes = p.obj("changes")
    if not p.has("config_version"):
        p.integer("config_version")
    p.done()
    saved = ctx.svc.set_home(axis, changes)
    return {**_home(ctx, axis), "config_version": ctx.svc.config_version,
            "saved": None if saved is None else str(saved)}


@method("home.start")
def home_start(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p.done()
    ctx.svc.start_home(axis)
    return {}


@method("home.abort")
def home_abort(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis()
    p.done()
    ctx.svc.abort_home(axis)
    return {}


# -- status and subscriptions ---------------------------------------------------------------
def read_fields(p: Params) -> tuple[str, ...]:
    fields = p.raw("fields", None)
    if fields is None:
        return FIELDS
    if not isinstance(fields, list) or not fields or \
            any(not isinstance(f, str) or f not in FIELDS for f in fields):
        from .protocol import INVALID_PARAMS, RpcError

        raise RpcError(INVALID_PARAMS, f"params.fields must be a non-empty array of "
                       f"{', '.join(FIELDS)}; got {fields!r}", {"param": "fields"})
    return tuple(f for f in FIELDS if f in fields)


@method("status.get", command=False)
def status_get(ctx: Context, p: Params) -> dict[str, Any]:
    fields = read_fields(p)
    p.done()
    return snapshot(ctx.svc, fields)


@method("axis.status", command=False)
def axis_status_m(ctx: Context, p: Params) -> dict[str, Any]:
    axis = p.axis("axis", None)
    p.done()
    ctl = ctx.svc.ctl
    axes = ctl.axes if axis is None else (ctl.axis(axis),)
    with ctl.lock:
        return {ax.name: axis_status(ctx.svc, ax) for ax in axes}


def _rate(p: Params) -> float:
    r = p.number("rate_hz", 20.0, lo=1.0, hi=50.0)
    if not math.isfinite(r):
        raise MotionError("rate_hz must be finite")
    return r


@method("status.subscribe", command=False)
def status_subscribe(ctx: Context, p: Params) -> dict[str, Any]:
    rate = _rate(p)
    idle = p.number("idle_hz", rate, lo=1.0, hi=rate)
    if not math.isfinite(idle):
        raise MotionError("idle_hz must be finite")
    fields = read_fields(p)
    p.done()
    sub, snap = ctx.conn.subscribe_status(rate, fields, idle)
    return {"subscription": sub, "status": snap}


@method("scope.subscribe", command=False)
def scope_subscribe(ctx: Context, p: Params) -> dict[str, Any]:
    rate = _rate(p)
    p.done()
    sub, nxt = ctx.conn.subscribe_scope(rate)
    return {"subscription": sub, "next": nxt}


@method("unsubscribe", command=False)
def unsubscribe(ctx: Context, p: Params) -> dict[str, Any]:
    sub = p.string("subscription", max_len=64)
    p.done()
    ctx.conn.unsubscribe(sub)
    return {}
