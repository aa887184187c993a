"""The machine behind the remote API: a Controller on the simulator, paced in real time on a
background thread, plus what the pages need around it (jogs with a deadman, repeats, the
scope, the program, homing runs, the machine file with its responses and homing tables,
config_version).

Threads: the real-time pacer runs `Controller.step`; every change to the controller holds
`ctl.lock` (the lock every cycle runs under), and the server runs commands one at a time
(`command_lock`). The service's own per-cycle work (deadman check, repeats, scope and path
sampling) is one cycle hook that never raises: a failure there turns the part that failed
off and is reported in `hook_errors`, the cycle goes on.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..config import MachineConfig, default_machine, dumps_machine
from ..config_toml import load_machine_settings
from ..control.core.clock import RealtimePacer
from ..control.core.controller import Controller
from ..control.core.states import AxisState
from ..control.guard.responses import apply_machine_responses
from ..control.home.homing import Homing
from ..control.home.homing_modes import HomeConfig
from ..errors import MotionError
from ..program.runjob import load_machine_arg
from .deadman import JogRegistry
from .homeconf import home_configs, home_from_user, home_to_user
from .interface import (
    apply_responses,
    atomic_write,
    check_responses,
    default_responses,
    load_sidecar,
    sidecar_path,
    split_changes,
)
from .programs import ProgramSession
from .pso import PsoSession
from .repeat import RepeatRegistry
from .scope import Scope, Trigger
from .tuning import Tuning, check_loop_changes
from .workdir import WorkFolder

MAX_SPEED = 20.0
EVENT_KEEP = 2000

Listener = Callable[[str, dict[str, Any]], None]


class MachineService:
    """One simulated machine running in real time (see the module docstring)."""

    def __init__(self, config: MachineConfig | None = None, file: str | Path | None = None,
                 *, speed: float = 1.0, workdir: WorkFolder | None = None) -> None:
        self.file: Path | None = None
        self.workdir = WorkFolder() if workdir is None else workdir   # file-path methods
        if file is not None:
            self.file = Path(file)
            config = load_machine_arg(str(self.file), "--machine")
        self.config = config if config is not None else default_machine()
        self.config_version = 1
        self.command_lock = threading.Lock()
        self.speed = _check_speed(speed)
        self._listeners: list[Listener] = []
        self.events: deque[dict[str, Any]] = deque(maxlen=EVENT_KEEP)
        self.hook_errors: deque[str] = deque(maxlen=100)   # failures in the cycle hook
        self.responses, self._home_user = _settings_of(self.file, self.config)
        self._pacer: RealtimePacer | None = None
        self._build(self.config, scope=None)

    # ------------------------------------------------------------------ building
    def _build(self, config: MachineConfig, scope: dict[str, Any] | None) -> None:
        ctl = Controller(config)
        self.ctl = ctl
        self.config = config
        self.estop_reason: str | None = None   # software E-stop latched until machine.reset
        apply_machine_responses(ctl, self.responses)
        self.homes: dict[str, HomeConfig] = home_configs(ctl, self._home_user)
        self.homings: dict[int, Homing] = {}
        self.jogs = JogRegistry(ctl)
        self.repeats = RepeatRegistry(ctl)
        self.scope = Scope(ctl)
        if scope is not None:
            with contextlib.suppress(MotionError):
                self.scope.configure(scope["channels"], scope["divider"], scope["seconds"],
                                     Trigger(**scope["trigger"]))
        self.program = ProgramSession(ctl)
        self.pso = PsoSession(ctl)   # a rebuild sets the old jobs up again (rebuild)
        self.tuning = Tuning(ctl)
        self.program.path.firing_sources.append(self.pso.firings)
        self._cmp_firings: deque[dict[str, Any]] = deque(maxlen=EVENT_KEEP)
        self.program.path.firing_sources.append(self._comparator_firings)
        self._cmp_time = [-1.0] * len(ctl.axes)
        if ctl.safety is not None:
            ctl.safety.cmp.on_event(self._on_compare)
        ctl.events.on_event(self._on_event)
        self._parts: list[tuple[str, Callable[[float], None]]] = [
            ("deadman", lambda t: self.jogs.check()), ("repeat", self.repeats.step),
            ("scope", self.scope.sample), ("path", self.program.path.sample),
            ("tuning", self.tuning.sample)]
        ctl.add_cycle_hook(self._on_cycle)

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        for part in self._parts:
            name, fn = part
            try:
                fn(t)
            except Exception as exc:  # never out of the cycle: drop the part, tell why
                if name == "deadman":  # the deadman must not die: stop every jog instead
                    with contextlib.suppress(Exception):
                        self.jogs.stop_all(f"deadman check failed: {exc}")
                    continue
                self._parts = [p for p in self._parts if p is not part]
                self.hook_errors.append(f"{name}: {type(exc).__name__}: {exc}")

    def _on_compare(self, ev: Any) -> None:
        """Inside the cycle (comparator callback): never raises. Lights CMP and keeps the
        firing, with every axis's position at its exact time, for the path view."""
        with contextlib.suppress(Exception):
            axis = getattr(ev, "axis", None)
            if isinstance(axis, int) and 0 <= axis < len(self._cmp_time):
                self._cmp_time[axis] = self.ctl.time
            hist = self.ctl.history
            pulses = [float(hist.position_at(a, ev.time)) for a in range(len(self.ctl.axes))]
            self._cmp_firings.append({"t": float(ev.time), "output": -1, "level": True,
                                      "pulses": pulses, "kind": "CMP",
                                      "comparator": ev.comparator})

    def _comparator_firings(self, t_lo: float, t_hi: float) -> list[dict[str, Any]]:
        """The HSL comparators' (safety.cmp) firings with t_lo < t <= t_hi."""
        return [f for f in tuple(self._cmp_firings) if t_lo < f["t"] <= t_hi]

    def _on_event(self, ev: Any) -> None:
        """Inside the cycle (event-log callback): keep and push the event; never raises."""
        try:
            if ev.kind == "home_done" and ev.axis in self.homings:
                # Motion Creator's Home leaves every counter at the home, the target
                # recorder too: the HSL library does not clear it (manual 4.4: "users need
                # to manually maintain it ... after a home move completes") and the tool
                # is the application that does. Same cycle as `done`: one status push.
                cnt = self.ctl.axes[ev.axis].counters
                cnt.reset_target(float(cnt.command))
            name = None if ev.axis is None else self.ctl.axes[ev.axis].name
            pos = None
            if ev.position is not None and ev.axis is not None:
                pos = float(self.ctl.axes[ev.axis].units.to_units(ev.position))
            item = {"seq": ev.seq, "t": ev.time, "kind": ev.kind, "axis": name,
                    "position": pos, "detail": ev.detail}
            self.events.append(item)
            self._notify("event", item)
        except Exception as exc:
            self.hook_errors.append(f"event: {type(exc).__name__}: {exc}")

    def cmp_active(self, axis: int) -> bool:
        t = self._cmp_time[axis]
        return t >= 0.0 and self.ctl.time - t <= 0.1

    # ------------------------------------------------------------------ listeners
    def add_listener(self, fn: Listener) -> None:
        self._listeners.append(fn)

    def remove_listener(self, fn: Listener) -> None:
        if fn in self._listeners:
            self._listeners.remove(fn)

    def _notify(self, kind: str, payload: dict[str, Any]) -> None:
        for fn in tuple(self._listeners):
            with contextlib.suppress(Exception):
                fn(kind, payload)

    # ------------------------------------------------------------------ real time
    def start(self) -> None:
        if self._pacer is not None and self._pacer.running:
            return
        self._pacer = RealtimePacer(self.ctl.step, self.ctl.period / self.speed,
                                    self._overran)
        self._pacer.start()

    def stop(self) -> None:
        if self._pacer is not None:
            self._pacer.stop()
            self._pacer = None

    @property
    def running(self) -> bool:
        return self._pacer is not None and self._pacer.running

    def cycle_stats(self, max_age_s: float = 1.0) -> Any:
        """The pacer's CycleStats, recomputed at most every `max_age_s` (they cost a
        percentile over the 65536-cycle window)."""
        if self._pacer is None:
            return None
        now = time.monotonic()
        cached = getattr(self, "_stats_cache", None)
        if cached is None or now - cached[0] > max_age_s or cached[2] is not self._pacer:
            cached = (now, self._pacer.stats(), self._pacer)
            self._stats_cache = cached
        return cached[1]

    def _overran(self, count: int, behind: int) -> None:
        with contextlib.suppress(Exception):
            self.ctl.events.record("overrun", None, self.ctl.time, None,
                                   f"cycle overran its period (overrun {count}, {behind} "
                                   "slots behind)")

    def set_speed(self, factor: float) -> None:
        self.speed = _check_speed(factor)
        if self.running:
            self.stop()
            self.start()

    def shutdown(self) -> None:
        """Stop every axis (decelerating), let them come to rest, stop the thread."""
        with contextlib.suppress(Exception), self.ctl.lock:
            self.jogs.stop_all("server shutdown")
            self.repeats.stop_all("server shutdown")
            self.program.abort_if_running()
            for ax in self.ctl.axes:
                if ax.is_moving:
                    ax.stop()
        t_end = time.monotonic() + 5.0
        while self.running and time.monotonic() < t_end and \
                any(a.is_moving for a in self.ctl.axes):
            time.sleep(0.01)
        self.stop()

    # ------------------------------------------------------------------ configuration
    def check_version(self, version: Any) -> None:
        from .protocol import RELOAD, RpcError

        if version is None:
            return
        if isinstance(version, bool) or not isinstance(version, int):
            from .protocol import INVALID_PARAMS

            raise RpcError(INVALID_PARAMS, f"params.config_version must be an integer, "
                           f"got {version!r}", {"param": "config_version"})
        if version != self.config_version:
            raise RpcError(RELOAD, f"the configuration changed (version {version} -> "
                           f"{self.config_version}) since this client loaded it: reload",
                           {"config_version": self.config_version})

    def _bump(self) -> None:
        self.config_version += 1
        self._notify("config", {"config_version": self.config_version})

    def _check_at_rest(self, what: str) -> None:
        busy = [a.name for a in self.ctl.axes if a.is_moving or a.state in (
            AxisState.HOMING, AxisState.STOPPING)]
        if busy:
            raise MotionError(f"{what} needs every axis at rest; moving: {', '.join(busy)}")
        self.program._check_idle(what)

    def rebuild(self, config: MachineConfig, keep_pso: bool = True) -> None:
        """Run `config`: the simulated machine restarts (as a power cycle of the card:
        positions 0) with the servo state, responses, homing, scope settings and (unless
        `keep_pso` is False: another machine file was loaded) the PSO jobs kept."""
        self._check_at_rest("changing the machine")
        enabled = {a.name for a in self.ctl.axes if a.powered}
        info = self.scope.info()
        scope = {"channels": info["channels"], "divider": info["divider"],
                 "seconds": info["seconds"], "trigger": info["trigger"]}
        was_running = self.running
        self.stop()
        old, old_pso = self.ctl, self.pso
        try:
            for name in list(self.responses):
                if name not in config.axis_names:
                    del self.responses[name]
            for a in config.axes:
                self.responses.setdefault(a.name, default_responses())
            self._build(config, scope)
        except Exception:
            self.ctl, self.pso = old, old_pso
            raise
        finally:
            if was_running:
                self.start()
        for ax in self.ctl.axes:
            if ax.name in enabled:
                with contextlib.suppress(MotionError):
                    ax.enable()
        with self.ctl.lock:
            used = self.pso.restore(old_pso) if keep_pso else []
            if used:
                self.program.path.follow(used)   # as pso.set does

    def set_interface(self, axis: Any, changes: Any) -> Path | None:
        ax = self.ctl.axis(axis)
        cfg = self.config.axis(ax.name)
        new_cfg, new_resp = split_changes(cfg, self.responses[ax.name], changes)
        if new_cfg != cfg:
            old_resp = self.responses[ax.name]
            self.responses[ax.name] = new_resp
            try:
                self.rebuild(self.config.with_axis(new_cfg))
            except Exception:
                self.responses[ax.name] = old_resp
                raise
        else:
            with self.ctl.lock:
                apply_responses(self.ctl, ax.index, new_resp)
            self.responses[ax.name] = new_resp
        self._bump()
        return self.autosave()

    def set_loop(self, ax: Any, changes: Any) -> Path | None:
        """New servo loop gains for `ax`: applied to the running loop at once (no rebuild)
        and saved in the machine file's [axes.<name>.loop] table."""
        cfg = self.config.axis(ax.name)
        new = check_loop_changes(cfg.loop, ax.name, changes)
        live = self.ctl.servo_loops.get(ax.name)
        with self.ctl.lock:
            if live is None:
                raise MotionError(f"axis {ax.name}: no servo loop runs in the controller")
            if self.tuning.busy():
                raise MotionError("a tuning run is in progress: wait for it or stop it")
            live.retune(new)
            self.config = self.config.with_axis(dataclasses.replace(cfg, loop=new))
        self._bump()
        return self.autosave()

    def set_home(self, axis: Any, changes: Any) -> Path | None:
        ax = self.ctl.axis(axis)
        new = home_from_user(ax, self.homes[ax.name], changes)
        self.homes[ax.name] = new
        self._home_user[ax.name] = home_to_user(ax, new)
        self._bump()
        return self.autosave()

    def load(self, path: str) -> None:
        p = Path(path)
        cfg = load_machine_arg(path, "path")
        resp, home = _settings_of(p, cfg)
        self._check_at_rest("loading a machine")
        old = (self.responses, self._home_user)
        self.responses, self._home_user = resp, home
        try:
            self.rebuild(cfg, keep_pso=False)   # another machine: its jobs start anew
        except Exception:
            self.responses, self._home_user = old
            raise
        self.file = p
        self._bump()

    def autosave(self) -> Path | None:
        if self.file is None:
            return None
        self.save(self.file)
        return self.file

    def settings(self) -> dict[str, dict[str, Any]]:
        """The responses and homing settings of every axis, as the machine file keeps them."""
        return {a.name: {"responses": self.responses[a.name],
                         "home": self._home_user.get(a.name, {})} for a in self.config.axes}

    def save(self, path: str | Path | None = None) -> Path:
        p = Path(path) if path is not None else self.file
        if p is None:
            raise MotionError("path is required: the server has no machine file yet")
        if p.suffix != ".toml":
            raise MotionError(f"path must name a .toml file, got {str(p)!r}")
        if not p.parent.is_dir():
            raise MotionError(f"path {str(p)!r}: folder {str(p.parent)!r} does not exist")
        try:
            atomic_write(p, dumps_machine(self.config, self.settings()))
            # an old sidecar's settings are in the machine file now: it would only mislead
            sidecar_path(p).unlink(missing_ok=True)
        except OSError as exc:
            raise MotionError(f"path {str(p)!r}: cannot write ({exc.strerror or exc})") from None
        self.file = p
        return p

    # ------------------------------------------------------------------ homing
    def start_home(self, axis: Any) -> None:
        ax = self.ctl.axis(axis)
        with self.ctl.lock:
            h = Homing(self.ctl, ax.index, self.homes[ax.name])
            h.start()
            self.homings[ax.index] = h

    def abort_home(self, axis: Any) -> None:
        ax = self.ctl.axis(axis)
        with self.ctl.lock:
            h = self.homings.get(ax.index)
            if h is None or not h.running:
                raise MotionError(f"axis {ax.name} is not homing")
            h.abort()

    # ------------------------------------------------------------------ stops
    def estop(self, reason: str) -> None:
        """Software E-stop: jogs, repeats and the program end, every axis stops at once.
        Latched (status `estop`) until `machine.reset`, like a pressed EMG button."""
        with self.ctl.lock:
            self.jogs.stop_all("emergency stop")
            self.repeats.stop_all("emergency stop")
            self.tuning.abort("emergency stop")
            self.program.abort_if_running()
            for h in self.homings.values():
                if h.running:
                    with contextlib.suppress(MotionError):
                        h.abort()
            self.ctl.emergency_stop(reason)
            self.estop_reason = reason

    def stop_axis(self, axis: Any | None, immediate: bool, tdec: float | None) -> None:
        with self.ctl.lock:
            axes = self.ctl.axes if axis is None else (self.ctl.axis(axis),)
            for ax in axes:
                self.repeats.stop(ax.index, "stop command")
                run = self.tuning.run
                if run is not None and run.axis == ax.index:
                    self.tuning.abort("stop command")
                h = self.homings.get(ax.index)
                if h is not None and h.running:
                    h.abort()
                if immediate:
                    ax.stop_immediately()
                elif ax.is_moving:
                    ax.stop(tdec)
            if axis is None:
                self.jogs.stop_all("stop command")


def _settings_of(file: Path | None, cfg: MachineConfig
                 ) -> tuple[dict[str, dict[str, Any]], dict[str, dict[str, Any]]]:
    """(responses, homing settings) per axis from the machine file's [axes.<n>.responses]
    and [axes.<n>.home] tables; an axis without them takes an old `<stem>.ui.toml` sidecar's
    tables if there is one (read once: the next save folds them into the machine file)."""
    saved = load_machine_settings(file) if file is not None else {}
    side = load_sidecar(sidecar_path(file)) if file is not None else \
        {"interface": {}, "home": {}}
    responses, homes = {}, {}
    for a in cfg.axes:
        mine = saved.get(a.name, {"responses": default_responses(), "home": {}})
        if mine["responses"] == default_responses() and a.name in side["interface"]:
            mine = {**mine, "responses": check_responses(
                f"interface.{a.name}", side["interface"][a.name], default_responses())}
        responses[a.name] = mine["responses"]
        home = mine["home"] or dict(side["home"].get(a.name, {}))
        if home:
            homes[a.name] = home
    return responses, homes


def _check_speed(factor: Any) -> float:
    if isinstance(factor, bool) or not isinstance(factor, (int, float)) or \
            not 1.0 <= factor <= MAX_SPEED:
        raise MotionError(f"speed must be a number in [1, {MAX_SPEED:g}] (1 = real time), "
                          f"got {factor!r}")
    return float(factor)
