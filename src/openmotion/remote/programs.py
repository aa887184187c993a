"""The program page's back end: one loaded G-code program, its decimated preview, its run
(program.runner.ProgramRunner) and the path the tool actually travelled.

Loading compiles the whole program at once (errors name the line before anything moves),
with the same G54 origin rule as `openmotion run`. The preview is the toolpath of the
compiled operations (arcs as chords) decimated to a point budget, so a 20 MB program
stays responsive in the browser. `PathRecorder` samples the running group's position inside
the control cycle into a bounded buffer (a program's run, or, outside programs, the axes a
PSO job watches while they move); `path()` adds the speed and the firings for the path
view: the program's synchronized outputs (M62/M63) and the compare engine's (PSO) firings.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import MotionError
from ..path.geometry import Direction
from ..program.runjob import sets_work_offset, work_origin
from ..program.runner import ProgramRunner, RunOptions, RunState

if TYPE_CHECKING:
    from ..control.core.controller import Controller

MAX_TEXT_BYTES = 1 << 20
MAX_FILE_BYTES = 64 << 20
PATH_CAPACITY = 200_000
PATH_EVERY_S = 0.005
_XYZ = "XYZ"


class ProgramSession:
    """The loaded program and its runner (one at a time)."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.text = ""
        self.file = ""
        self.lines: list[str] = []
        self.runner: ProgramRunner | None = None
        self.feed_override = 100.0
        self.single_block = False
        self._preview: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._compiled_at: tuple[float, ...] = ()
        self.path = PathRecorder(ctl)

    # ------------------------------------------------------------------ loading
    def load(self, text: str, name: str = "") -> dict[str, Any]:
        self._check_idle("load a program")
        runner = self._make_runner(text, name)
        if not runner.ops:
            raise MotionError(f"{name or 'program'}: the program holds no moves or actions")
        self.text, self.file, self.lines = text, name, text.splitlines()
        self.runner = runner
        self._preview = None
        pts = self._preview_points()[0]
        return {"file": name, "lines": len(self.lines), "moves": len(runner.ops),
                "letters": "".join(runner.letters), "bounds": _bounds(pts)}

    def load_path(self, path: str) -> dict[str, Any]:
        p = Path(path)
        if not p.is_file():
            raise MotionError(f"path {path!r}: no such file")
        if p.stat().st_size > MAX_FILE_BYTES:
            raise MotionError(f"path {path!r}: larger than {MAX_FILE_BYTES} bytes")
        return self.load(p.read_bytes().decode("utf-8", errors="replace"), os.fspath(p))

    def _make_runner(self, text: str, name: str) -> ProgramRunner:
        params = {} if sets_work_offset(text) else work_origin(self.ctl)
        opts = RunOptions(single_block=self.single_block)
        self._compiled_at = self._positions()
        return ProgramRunner(self.ctl, text, options=opts, file=name,
                             gcode={"parameters": params})

    def _positions(self) -> tuple[float, ...]:
        return tuple(ax.position for ax in self.ctl.axes)

    def _check_idle(self, what: str) -> None:
        r = self.runner
        if r is not None and r.state in (RunState.RUNNING, RunState.PAUSED):
            raise MotionError(f"cannot {what} while the program is {r.state.value}; "
                              "abort it first")

    @property
    def active(self) -> bool:
        """A program runs (or is paused)."""
        r = self.runner
        return r is not None and r.state in (RunState.RUNNING, RunState.PAUSED)

    # ------------------------------------------------------------------ running
    def run(self, *, feed_override: float, single_block: bool, optional_stop: bool,
            repeat: int, acc_time: float) -> None:
        """Start the loaded program. The compile (the costly part) runs outside the
        controller's lock; only the start holds it."""
        r = self.runner
        if r is None:
            raise MotionError("no program loaded: program.load first")
        self._check_idle("start the program")
        opts = RunOptions(single_block=single_block, optional_stop=optional_stop,
                          repeat=repeat, acc_time=acc_time)
        if not 1.0 <= feed_override <= 200.0:
            raise MotionError(f"feed_override must be in [1, 200] %, got {feed_override!r}")
        if r.state is not RunState.READY or self._compiled_at != self._positions():
            # ran before, or the axes moved since the compile: compile again here, outside
            # the lock (start() would do it under the lock, holding up the cycle)
            r = self._make_runner(self.text, self.file)
        r.options = opts   # run-time settings only: the compiled operations stay valid
        with self.ctl.lock:
            r.start()   # recompiles only if the axes moved since
            if r.group is not None:
                r.group.set_override(feed_override)
            self.runner = r
            self.feed_override = feed_override
            self.single_block = single_block
            self.path.start(r)

    def _running(self) -> ProgramRunner:
        if self.runner is None:
            raise MotionError("no program loaded")
        return self.runner

    def pause(self) -> None:
        self._running().pause()

    def resume(self) -> None:
        self._running().resume()

    def abort(self) -> None:
        self._running().abort()

    def set_single_block(self, on: bool) -> None:
        self.single_block = on
        r = self.runner
        if r is not None:
            r.options = dataclasses.replace(r.options, single_block=on)

    def set_feed_override(self, percent: float) -> None:
        if not 1.0 <= percent <= 200.0:
            raise MotionError(f"percent must be in [1, 200] %, got {percent!r}")
        r = self.runner
        if r is not None and r.group is not None and r.state in (RunState.RUNNING,
                                                                  RunState.PAUSED):
            r.group.set_override(percent)
        self.feed_override = percent

    def abort_if_running(self) -> None:
        r = self.runner
        if r is not None and r.state in (RunState.RUNNING, RunState.PAUSED):
            with contextlib.suppress(MotionError):
                r.abort()

    def status(self) -> dict[str, Any]:
        r = self.runner
        if r is None:
            return {"state": "none", "file": "", "line": 0, "progress": 0.0,
                    "feed_override": self.feed_override, "single_block": self.single_block,
                    "message": "", "elapsed_s": 0.0}
        msg = ""
        for ev in reversed(r.events[-20:]):
            if ev.kind not in ("sync_output", "output"):
                msg = f"line {ev.line}: {ev.text}" if ev.line else ev.text
                break
        running = r.state in (RunState.RUNNING, RunState.PAUSED)
        elapsed = (self.ctl.time if running else r.t_end) - r.t_start if r.t_start else 0.0
        return {"state": r.state.value, "file": self.file, "line": r.current_line,
                "progress": round(r.progress, 4), "feed_override": self.feed_override,
                "single_block": self.single_block, "message": msg,
                "elapsed_s": round(max(0.0, elapsed), 3)}

    def line_range(self, first: int, count: int) -> dict[str, Any]:
        return {"first": first, "total": len(self.lines),
                "lines": self.lines[first - 1:first - 1 + count]}

    # ------------------------------------------------------------------ preview
    def _preview_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self._preview is None:
            self._preview = _toolpath(self._running(), self.ctl)
        return self._preview

    def preview(self, max_points: int) -> dict[str, Any]:
        pts, lines, rapid = self._preview_points()
        n = len(pts)
        sel = _decimate_path(rapid, n, max_points)
        return {"points": np.round(pts[sel], 6).tolist(), "line": lines[sel].tolist(),
                "rapid": rapid[sel].tolist(), "decimated": len(sel) < n, "total": n,
                "bounds": _bounds(pts)}


def _toolpath(r: ProgramRunner, ctl: Controller) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (machine units, X/Y/Z), their source lines and rapid flags of the
    compiled operations; arcs become chords of at most 10 degrees."""
    letters = r.letters
    cols = [letters.index(c) if c in letters else -1 for c in _XYZ]
    # where the program starts: the axes' positions now (machine units)
    cur = np.array([ctl.axes[i].position for i in r.axis_indices], dtype=float) / r.scales.ppu
    pts: list[np.ndarray] = [cur.copy()]
    lines: list[int] = [0]
    rapid: list[bool] = [True]
    for op in r.ops:
        if op.kind not in ("line", "arc") or op.end is None:
            continue
        end = np.asarray(op.end, dtype=float)
        if op.kind == "arc" and op.centre is not None:
            for p in _arc_points(cur, end, op):
                pts.append(p)
                lines.append(op.line)
                rapid.append(False)
        pts.append(end)
        lines.append(op.line)
        rapid.append(bool(op.rapid))
        cur = end
    arr = np.array(pts, dtype=float).reshape(len(pts), len(letters))
    xyz = np.zeros((len(arr), 3))
    for k, c in enumerate(cols):
        if c >= 0:
            xyz[:, k] = arr[:, c]
    return xyz, np.array(lines, dtype=int), np.array(rapid, dtype=bool)


def _arc_points(start: np.ndarray, end: np.ndarray, op: Any) -> list[np.ndarray]:
    i, j = op.plane
    cx, cy = op.centre
    a0 = math.atan2(start[j] - cy, start[i] - cx)
    a1 = math.atan2(end[j] - cy, end[i] - cx)
    r0 = math.hypot(start[i] - cx, start[j] - cy)
    r1 = math.hypot(end[i] - cx, end[j] - cy)
    if op.direction == Direction.CCW:
        sweep = (a1 - a0) % (2 * math.pi)
        sweep = sweep or 2 * math.pi
        sweep += 2 * math.pi * op.turns
    else:
        sweep = -((a0 - a1) % (2 * math.pi) or 2 * math.pi) - 2 * math.pi * op.turns
    n = max(2, int(abs(sweep) / math.radians(10)) + 1)
    out = []
    for k in range(1, n):
        f = k / n
        a = a0 + sweep * f
        rr = r0 + (r1 - r0) * f
        p = start + (end - start) * f
        p[i] = cx + rr * math.cos(a)
        p[j] = cy + rr * math.sin(a)
        out.append(p)
    return out


def _decimate_path(rapid: np.ndarray, n: int, max_points: int) -> np.ndarray:
    """Indices of at most ~max_points points: a uniform stride, plus every point where the
    move kind changes (rapid <-> feed) and the last point."""
    if n <= max_points:
        return np.arange(n)
    stride = math.ceil(n / max_points)
    keep = np.zeros(n, bool)
    keep[::stride] = True
    change = np.flatnonzero(np.diff(rapid.astype(np.int8))) + 1
    keep[change[: max_points // 4]] = True
    keep[-1] = True
    return np.flatnonzero(keep)


def _bounds(pts: np.ndarray) -> dict[str, list[float]]:
    if not len(pts):
        return {"min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.0]}
    return {"min": [float(x) for x in pts.min(axis=0)],
            "max": [float(x) for x in pts.max(axis=0)]}


class PathRecorder:
    """The tool position every PATH_EVERY_S of control time (bounded): a program's run
    (`start`), or the motion of some axes outside programs (`follow`)."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.runner: ProgramRunner | None = None
        self._every = max(1, round(PATH_EVERY_S / ctl.period))
        self._tick = 0
        self._t = np.zeros(PATH_CAPACITY)
        self._p = np.zeros((PATH_CAPACITY, 3))
        self.n = 0
        self._closed = True
        self._cols: list[tuple[int, int, float]] = []
        self._names: list[str] = []
        self._moving = False
        self._t_start = -math.inf   # firings before the path began are not its own
        #: more firings for the path: fn(t_lo, t_hi) -> [{"t", "output", "level",
        #: "pulses": every axis's Axis.position}] (the PSO session registers one)
        self.firing_sources: list[Callable[[float, float], list[dict[str, Any]]]] = []

    def start(self, runner: ProgramRunner) -> None:
        self.runner = runner
        self.n = 0
        self._tick = 0
        self._closed = False
        self._t_start = self.ctl.time
        axes = runner.axis_indices
        self._cols = [(k, axes[runner.letters.index(c)], float(runner.scales.ppu[
            runner.letters.index(c)])) for k, c in enumerate(_XYZ) if c in runner.letters]
        self._names = list(runner.letters)

    def follow(self, axes: list[int]) -> None:
        """Record `axes` (1..3: the view's X, Y, Z) whenever one of them moves, until a
        program starts. A new set of axes starts a new path; the same set goes on."""
        names = [self.ctl.axes[a].name for a in axes]
        if self.runner is None and not self._closed and names == self._names:
            return
        self.runner = None
        self.n = 0
        self._tick = 0
        self._closed = False
        self._moving = False
        self._t_start = self.ctl.time
        self._names = names
        self._cols = []
        for k, a in enumerate(axes[:3]):
            u = self.ctl.axes[a].units
            self._cols.append((k, a, float(u.sign * u.pulses_per_unit)))

    def sample(self, t: float) -> None:
        if self._closed:
            return
        r = self.runner
        moving = any(self.ctl.axes[i].is_moving for _k, i, _p in self._cols)
        if r is None:                  # following axes: record while they move
            if moving != self._moving or (self.n == 0 and not moving):
                self._moving = moving
                self._tick = 0
                self._record(t)        # where a motion starts and ends
                return
            if not moving:
                return
        elif r.state not in (RunState.RUNNING, RunState.PAUSED) and not moving:
            self._record(t)      # the end point (after an abort: at rest); every firing
            self._closed = True  # lies within the samples
            return
        self._tick += 1
        if self._tick < self._every:
            return
        self._tick = 0
        self._record(t)

    def _record(self, t: float) -> None:
        i = self.n % PATH_CAPACITY
        self._t[i] = t
        axes = self.ctl.axes
        for k, idx, ppu in self._cols:
            self._p[i, k] = axes[idx].position / ppu
        self.n += 1

    def _point_of(self, pulses: np.ndarray) -> list[float]:
        pt = [0.0, 0.0, 0.0]
        for k, idx, ppu in self._cols:
            pt[k] = round(float(pulses[idx]) / ppu, 6)
        return pt

    def path(self, since: int, max_points: int) -> dict[str, Any]:
        n = self.n
        first = max(0, n - PATH_CAPACITY)
        start = min(max(since, first), n)
        idx = np.arange(start, n) % PATH_CAPACITY
        t = self._t[idx].copy()
        p = self._p[idx].copy()
        if len(t) > 1:
            speed = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.maximum(np.diff(t), 1e-12)
            speed = np.concatenate([[speed[0]], speed])
        else:
            speed = np.zeros(len(t))
        sel = np.arange(len(t))
        if len(t) > max_points:
            sel = np.unique(np.linspace(0, len(t) - 1, max_points).astype(int))
        firings: list[dict[str, Any]] = []
        r = self.runner
        if n > first:
            # the firings after the point before `start` up to the last point returned (the
            # recorder takes a last point when the run ends), so reading on with since=next
            # gives each firing exactly once
            t_lo = self._t[(start - 1) % PATH_CAPACITY] if start > first else -np.inf
            t_lo = max(t_lo, self._t_start)
            t_hi = t[-1] if len(t) else t_lo
            all_idx = np.arange(first, n) % PATH_CAPACITY
            all_t = self._t[all_idx]
            for ev in r.events if r is not None else ():
                if ev.kind == "sync_output" and t_lo < ev.t <= t_hi:
                    k = int(np.clip(np.searchsorted(all_t, ev.t), 0, len(all_t) - 1))
                    firings.append({"t": ev.t, "kind": "M62/M63",
                                    "point": np.round(self._p[all_idx[k]], 6).tolist(),
                                    "output": ev.index, "level": ev.level})
            for src in self.firing_sources:   # PSO / CMP: exact positions of the firing
                for f in src(t_lo, t_hi):
                    firings.append({"t": f["t"], "kind": f.get("kind", "PSO"),
                                    "point": self._point_of(f["pulses"]),
                                    "output": f["output"], "level": f["level"]})
            firings.sort(key=lambda f: f["t"])
        vmax = float(speed.max()) if len(speed) else 0.0
        axes_out: Any = "".join(r.letters) if r is not None else list(self._names)
        return {"axes": axes_out, "first": first,
                "next": n, "t": np.round(t[sel], 6).tolist(),
                "points": np.round(p[sel], 6).tolist(),
                "speed": np.round(speed[sel], 6).tolist(), "firings": firings, "vmax": vmax}
