"""Methods of the program, path and scope pages (see docs/remote.md)."""

from __future__ import annotations

from typing import Any

from ..errors import MotionError
from .methods import Context, method
from .programs import MAX_TEXT_BYTES
from .protocol import Params
from .scope import Trigger, channel_names


# -- program --------------------------------------------------------------------------------
@method("program.load")
def program_load(ctx: Context, p: Params) -> dict[str, Any]:
    text = p.string("text", None, max_len=MAX_TEXT_BYTES)
    path = p.string("path", None)
    name = p.string("name", "", max_len=255)
    p.done()
    if (text is None) == (path is None):
        raise MotionError("give exactly one of text and path")
    prog = ctx.svc.program   # compiled outside the controller's lock (a big program
    if path is not None:     # takes seconds; the cycle must not wait for it)
        return prog.load_path(str(ctx.svc.workdir.resolve("path", path)))
    return prog.load(text, name or "program.ngc")


@method("program.preview", command=False)
def program_preview(ctx: Context, p: Params) -> dict[str, Any]:
    n = p.integer("max_points", 20000, lo=100, hi=200_000)
    p.done()
    return ctx.svc.program.preview(n)


@method("program.lines", command=False)
def program_lines(ctx: Context, p: Params) -> dict[str, Any]:
    first = p.integer("first", 1, lo=1)
    count = p.integer("count", 200, lo=1, hi=2000)
    p.done()
    return ctx.svc.program.line_range(first, count)


@method("program.run")
def program_run(ctx: Context, p: Params) -> dict[str, Any]:
    kw = {"feed_override": p.number("feed_override", 100.0, lo=1.0, hi=200.0),
          "single_block": p.boolean("single_block", False),
          "optional_stop": p.boolean("optional_stop", False),
          "repeat": p.integer("repeat", 1, lo=1, hi=10_000),
          "acc_time": p.number("acc_time", 0.05, lo=0.0, hi=1000.0, lo_open=True)}
    p.done()
    ctx.svc.program.run(**kw)
    return {}


def _simple(name: str, action: str, urgent: bool = False) -> None:
    def handler(ctx: Context, p: Params) -> dict[str, Any]:
        p.done()
        with ctx.svc.ctl.lock:
            getattr(ctx.svc.program, action)()
        return {}
    handler.__name__ = f"program_{action}"
    method(name, command=not urgent)(handler)


_simple("program.pause", "pause", urgent=True)   # stops never wait behind commands
_simple("program.resume", "resume")
_simple("program.abort", "abort", urgent=True)


@method("program.single_block")
def program_single_block(ctx: Context, p: Params) -> dict[str, Any]:
    on = p.boolean("on")
    p.done()
    with ctx.svc.ctl.lock:
        ctx.svc.program.set_single_block(on)
    return {}


@method("program.feed_override")
def program_feed_override(ctx: Context, p: Params) -> dict[str, Any]:
    pct = p.number("percent", lo=1.0, hi=200.0)
    p.done()
    with ctx.svc.ctl.lock:
        ctx.svc.program.set_feed_override(pct)
    return {}


@method("program.status", command=False)
def program_status(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    with ctx.svc.ctl.lock:
        return ctx.svc.program.status()


@method("path.get", command=False)
def path_get(ctx: Context, p: Params) -> dict[str, Any]:
    since = p.integer("since", 0, lo=0)
    n = p.integer("max_points", 20000, lo=10, hi=200_000)
    p.done()
    with ctx.svc.ctl.lock:
        return ctx.svc.program.path.path(since, n)


# -- PSO / compare jobs (their firings are drawn on the path) -------------------------------
@method("pso.set")
def pso_set(ctx: Context, p: Params) -> dict[str, Any]:
    kind = p.choice("kind", ("distance", "points"))
    axes = p.list("axes")
    output = p.integer("output", lo=0)
    pulse_s = p.number("pulse_s", 0.001)
    every = p.number("every", None) if kind == "distance" else None
    start = p.number("start", None) if kind == "distance" else None
    points = p.list("points") if kind == "points" else None
    window = p.number("window", None) if kind == "points" else None
    p.done()
    svc = ctx.svc
    if not all(isinstance(a, (str, int)) and not isinstance(a, bool) for a in axes):
        raise MotionError(f"axes must be a list of axis names, got {axes!r}")
    idx = [svc.ctl.axis(a).index for a in axes]
    with svc.ctl.lock:
        job = svc.pso.add(kind, idx, output, pulse_s, every=every, start=start,
                          points=points, window=window)
        if not svc.program.active:
            svc.program.path.follow(idx)   # the path view follows these axes
    return {"job": job, **svc.pso.info()}


@method("pso.clear")
def pso_clear(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    with ctx.svc.ctl.lock:
        ctx.svc.pso.clear()
    return ctx.svc.pso.info()


@method("pso.get", command=False)
def pso_get(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    with ctx.svc.ctl.lock:
        return ctx.svc.pso.info()


# -- scope ----------------------------------------------------------------------------------
@method("scope.channels", command=False)
def scope_channels(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    return {"channels": channel_names(ctx.svc.ctl)}


def _trigger(p: Params) -> Trigger:
    t = p.obj("trigger", None)
    if t is None:
        return Trigger()
    allowed = ("channel", "mode", "level", "pre_s")
    for k in t:
        if k not in allowed:
            raise MotionError(f"trigger.{k}: unknown key; valid keys: {', '.join(allowed)}")
    sub = Params({k: v for k, v in t.items()})
    tr = Trigger(channel=sub.string("channel", ""), mode=sub.string("mode", "none"),
                 level=sub.number("level", 0.0), pre_s=sub.number("pre_s", 0.0, lo=0.0))
    return tr


@method("scope.configure")
def scope_configure(ctx: Context, p: Params) -> dict[str, Any]:
    chans = p.list("channels")
    divider = p.integer("divider", 1, lo=1, hi=1000)
    seconds = p.number("seconds", 30.0, lo=1.0, hi=600.0)
    trig = _trigger(p)
    p.done()
    sc = ctx.svc.scope
    sc.configure(chans, divider, seconds, trig)
    return {"scope_version": sc.version, "rate_hz": 1.0 / sc.dt}


@method("scope.get", command=False)
def scope_get(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    return ctx.svc.scope.info()


@method("scope.data", command=False)
def scope_data(ctx: Context, p: Params) -> dict[str, Any]:
    since = p.integer("since", -1, lo=-1)
    n = p.integer("max_points", 5000, lo=10, hi=200_000)
    p.done()
    return ctx.svc.scope.data(since, n)


@method("scope.run")
def scope_run(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    ctx.svc.scope.set_running(True)
    return {"running": True}


@method("scope.pause")
def scope_pause(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    ctx.svc.scope.set_running(False)
    return {"running": False}


@method("scope.arm")
def scope_arm(ctx: Context, p: Params) -> dict[str, Any]:
    p.done()
    ctx.svc.scope.arm()
    return {}


@method("scope.csv", command=False)
def scope_csv(ctx: Context, p: Params) -> dict[str, Any]:
    start = p.number("start", None)
    end = p.number("end", None)
    p.done()
    return {"csv": ctx.svc.scope.csv(start, end)}
