"""The tuning page's back end: test moves and loop step responses recorded every cycle,
with the figures a servo tuning tool shows (following error, overshoot, settling time).

A run is one of
- `move`: a relative move of `distance` with the given speed, ramps and S-curve and, with
  `back`, the move back after `settle_s`; every control cycle records the commanded and the
  actual (encoder) position, the commanded velocity and the following error;
- `step`: a set-point step of `amplitude` counts injected into the axis's servo loop
  (control.loops.servoloop.ServoLoop.inject_step, as the HCTL-1100 tools do), recorded for
  `duration_s` at the loop's sample rate, then undone.

Per move segment (or the step) `figures` gives: peak and RMS following error, overshoot
past the target (user units and % of the distance), settling time (from the end of the
commanded motion, or from the step, until the actual position stays within `band` of the
target), the error at the end of the record, and for a step the 10-90 % rise time.
The run is a cycle-hook state machine (`sample`): it never raises out of the cycle; a stop,
a fault or E-stop ends it as `aborted` with the reason.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..config import LoopConfig
from ..control.core.states import AxisState
from ..errors import MotionError
from .scope import _decimate, _round

if TYPE_CHECKING:
    from ..control.core.axis import Axis
    from ..control.core.controller import Controller

LOOP_KEYS = tuple(LoopConfig.__dataclass_fields__)
MAX_RECORD_S = 120.0
MAX_SETTLE_S = 10.0
KINDS = ("move", "step")


@dataclass
class TuneRun:
    """One test run and its record: rows of (t, command counter, feedback / move ratio,
    commanded velocity, following error), pulses / counts; converted when read."""

    id: int
    axis: int
    kind: str
    params: dict[str, Any]
    state: str = "running"        # running, done, aborted
    message: str = ""
    t0: float = 0.0
    rows: list[tuple[float, float, float, float, float]] = field(default_factory=list)
    segments: list[dict[str, Any]] = field(default_factory=list)   # per move: times, target
    phase: str = "moving"         # moving, settling (move); stepping (step)
    phase_t: float = 0.0
    leg: int = 0
    trace_from: int = 0


class Tuning:
    """Test runs on one controller (one at a time), sampled in the control cycle."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.run: TuneRun | None = None
        self._next_id = 1

    # ------------------------------------------------------------------ starting
    def busy(self) -> bool:
        return self.run is not None and self.run.state == "running"

    def start_move(self, ax: Axis, distance: float, move: dict[str, Any], *, back: bool,
                   settle_s: float, band: float | None) -> TuneRun:
        """Start a test move (caller holds the controller's lock; `move` as axis.move's
        keyword arguments in user units). MotionError, with nothing started, if refused."""
        self._check_free(ax)
        _check_settle(settle_s)
        if not math.isfinite(distance) or distance == 0.0:
            raise MotionError(f"distance must be a non-zero number of {ax.config.unit}, "
                              f"got {distance!r}")
        band_p = self._band(ax, band)
        run = TuneRun(self._next_id, ax.index, "move",
                      {"distance": distance, "back": back, "settle_s": settle_s,
                       "band": band_p / abs(ax.units.pulses_per_unit), **move},
                      t0=self.ctl.time, phase_t=self.ctl.time)
        run.segments.append(_segment(ax, self.ctl.time, lambda: ax.move_relative(
            distance, units=True, **move), band_p))      # refused: nothing changed
        run.params["_move"] = dict(move)
        self._begin(run)
        return run

    def start_step(self, ax: Axis, amplitude: float, duration_s: float,
                   band: float | None) -> TuneRun:
        """Inject a set-point step of `amplitude` counts into the axis's servo loop."""
        self._check_free(ax)
        loop = self.ctl.servo_loops.get(ax.name)
        if loop is None:
            raise MotionError(f"axis {ax.name}: a step response needs a servo loop in the "
                              f"controller (drive type {ax.config.drive.type!r} has none: "
                              "[axes.<name>.loop] in the machine file)")
        if not math.isfinite(amplitude) or amplitude == 0.0 or abs(amplitude) > 1e5:
            raise MotionError(f"amplitude must be a non-zero number of counts within "
                              f"+-100000, got {amplitude!r}")
        if not 0.01 <= duration_s <= MAX_SETTLE_S:
            raise MotionError(f"duration_s must be in [0.01, {MAX_SETTLE_S:g}] s, "
                              f"got {duration_s!r}")
        if band is not None and not band > 0.0:
            raise MotionError(f"band must be > 0 counts, got {band!r}")
        band_c = max(1.0, 0.02 * abs(amplitude)) if band is None else float(band)
        loop.inject_step(amplitude)          # refused while the loop is open
        loop.start_trace()
        run = TuneRun(self._next_id, ax.index, "step",
                      {"amplitude": amplitude, "duration_s": duration_s, "band": band_c},
                      t0=self.ctl.time, phase="stepping", phase_t=self.ctl.time)
        self._begin(run)
        return run

    def _begin(self, run: TuneRun) -> None:
        self._next_id += 1
        self.run = run
        self._record(run, self.ctl.time)

    def _check_free(self, ax: Axis) -> None:
        if self.busy():
            raise MotionError("a tuning run is in progress; axis.stop ends it")
        if ax.is_moving or ax.motion_done != 0 or ax.state is not AxisState.STANDSTILL:
            raise MotionError(f"axis {ax.name} must be at rest and enabled (state "
                              f"{ax.state.value}) for a tuning run")

    def _band(self, ax: Axis, band: float | None) -> float:
        """The settling band in pulses: `band` user units, or the drive's INP band."""
        ppu = abs(ax.units.pulses_per_unit)
        if band is None:
            return max(1.0, float(ax.config.drive.inp_band))
        if not band > 0.0 or not math.isfinite(band):
            raise MotionError(f"band must be > 0 {ax.config.unit}, got {band!r}")
        return float(band) * ppu

    def abort(self, reason: str) -> None:
        run = self.run
        if run is not None and run.state == "running":
            self._finish(run, "aborted", reason)

    # ------------------------------------------------------------------ the cycle
    def sample(self, t: float) -> None:
        run = self.run
        if run is None or run.state != "running":
            return
        ax = self.ctl.axes[run.axis]
        self._record(run, t)
        if ax.state in (AxisState.ERROR_STOP, AxisState.DISABLED):
            self._finish(run, "aborted", f"axis {ax.name}: {ax.fault or ax.state.value}")
            return
        if t - run.t0 > MAX_RECORD_S:
            self._finish(run, "aborted", f"longer than {MAX_RECORD_S:g} s")
            return
        if run.kind == "step":
            if t - run.phase_t >= run.params["duration_s"] - 1e-12:
                self._finish(run, "done", "")
            return
        seg = run.segments[-1]
        if run.phase == "moving":
            if ax.is_moving or ax.motion_done != 0:
                return
            if abs(ax.counters.command - seg["target"]) > 0.5:   # stopped before the end
                self._finish(run, "aborted", f"the move was stopped at "
                             f"{float(ax.units.to_units(ax.position)):g} {ax.config.unit}")
                return
            seg["t_end"] = t
            run.phase, run.phase_t = "settling", t
        elif t - run.phase_t >= run.params["settle_s"] - 1e-12:
            seg["t_done"] = t
            if run.params["back"] and run.leg == 0:
                run.leg = 1
                try:
                    run.segments.append(_segment(ax, t, lambda: ax.move_relative(
                        -run.params["distance"], units=True, **run.params["_move"]),
                        seg["band"]))
                except MotionError as exc:
                    self._finish(run, "aborted", f"the move back was refused: {exc}")
                    return
                run.phase, run.phase_t = "moving", t
            else:
                self._finish(run, "done", "")

    def _record(self, run: TuneRun, t: float) -> None:
        ax = self.ctl.axes[run.axis]
        c = ax.counters
        run.rows.append((t, float(c.command), float(c.feedback) / c.move_ratio,
                         float(ax.velocity), float(c.error)))

    def _finish(self, run: TuneRun, state: str, message: str) -> None:
        run.state, run.message = state, message
        if run.kind == "step":
            loop = self.ctl.servo_loops.get(self.ctl.axes[run.axis].name)
            if loop is not None:
                run.params["_trace"] = loop.trace()
                loop.stop_trace()
                if loop.closed:
                    loop.inject_step(-run.params["amplitude"])   # back to the set-point

    # ------------------------------------------------------------------ reading
    def result(self, max_points: int = 4000) -> dict[str, Any]:
        run = self.run
        if run is None:
            return {"id": None, "state": "idle"}
        ax = self.ctl.axes[run.axis]
        scale = ax.units.sign * ax.units.pulses_per_unit
        rows = np.array(run.rows, dtype=float).reshape(-1, 5)
        t = rows[:, 0] - run.t0
        cmd, act = rows[:, 1] / scale, rows[:, 2] / scale
        vel_cmd = rows[:, 3] / scale
        vel_act = _velocity(t, act)
        cols = {"command": cmd, "actual": act, "velocity_command": vel_cmd,
                "velocity_actual": vel_act, "error": rows[:, 4]}
        out: dict[str, Any] = {"id": run.id, "state": run.state, "message": run.message,
                               "axis": ax.name, "kind": run.kind, "unit": ax.config.unit,
                               "params": {k: v for k, v in run.params.items()
                                          if not k.startswith("_")}}
        if run.kind == "move":
            out["figures"] = [_move_figures(run, s, rows, scale) for s in run.segments
                              if "t_end" in s]
        else:
            tr = run.params.get("_trace")
            if tr is not None and len(tr["t"]):
                cols = {"command": tr["command"], "actual": tr["feedback"],
                        "duty": tr["duty"], "error": tr["command"] - tr["feedback"]}
                t = tr["t"] - run.t0
                out["unit"] = "counts"
                out["figures"] = [_step_figures(t, tr["command"], tr["feedback"],
                                                run.params["amplitude"],
                                                run.params["band"])]
            else:
                out["figures"] = []
        t_out, cols = _decimate(t, cols, max_points)
        out["t"] = _round(t_out, 9)
        out["columns"] = {k: _round(v, 9) for k, v in cols.items()}
        return out


def _segment(ax: Axis, t: float, start_move: Any, band: float) -> dict[str, Any]:
    """Start one test move; its record in the counters' frame (command counter, pulses):
    the target is where the target recorder says the move ends."""
    c = ax.counters
    before, tgt_before = float(c.command), float(c.target)
    start_move()
    return {"t_start": t, "from": before, "target": before + float(c.target) - tgt_before,
            "band": band}


def _check_settle(settle_s: float) -> None:
    if not 0.0 <= settle_s <= MAX_SETTLE_S:
        raise MotionError(f"settle_s must be in [0, {MAX_SETTLE_S:g}] s, got {settle_s!r}")


def _velocity(t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Actual velocity: the difference of the encoder position, averaged over 5 samples
    (one count per cycle is a large velocity step: raw differences are mostly noise)."""
    if len(t) < 2:
        return np.zeros(len(t))
    v = np.gradient(p, t)
    k = min(5, len(v))
    return np.convolve(v, np.ones(k) / k, mode="same")


def _settling(t: np.ndarray, err: np.ndarray, band: float, t_from: float) -> float | None:
    """Seconds from t_from until |err| stays within band to the end (None: never)."""
    outside = np.nonzero(np.abs(err) > band)[0]
    if not len(outside):
        return 0.0
    last = outside[-1]
    if last + 1 >= len(t):
        return None
    return max(0.0, float(t[last + 1] - t_from))


def _move_figures(run: TuneRun, seg: dict[str, Any], rows: np.ndarray, scale: float
                  ) -> dict[str, Any]:
    t = rows[:, 0]
    end = seg.get("t_done", t[-1])
    moving = (t >= seg["t_start"]) & (t <= seg["t_end"])
    after = (t >= seg["t_end"]) & (t <= end)
    err = rows[:, 4]
    target, start = seg["target"], seg["from"]
    act = rows[:, 2]
    sign = 1.0 if target >= start else -1.0
    seg_all = (t >= seg["t_start"]) & (t <= end)
    over_p = max(0.0, float(np.max(sign * (act[seg_all] - target)))) if seg_all.any() else 0.0
    dist = abs(target - start)
    settle = _settling(t[after], act[after] - target, seg["band"], seg["t_end"]) \
        if after.any() else None
    unit = abs(scale)
    return {"segment": len([s for s in run.segments if s is not seg and
                            s["t_start"] < seg["t_start"]]) + 1,
            "distance": (target - start) / scale,
            "move_time_s": seg["t_end"] - seg["t_start"],
            "peak_following_error": float(np.max(np.abs(err[moving]))) if moving.any() else 0.0,
            "rms_following_error": float(np.sqrt(np.mean(err[moving] ** 2)))
            if moving.any() else 0.0,
            "overshoot": over_p / unit,
            "overshoot_pct": 100.0 * over_p / dist if dist else 0.0,
            "settling_time_s": settle, "band": seg["band"] / unit,
            "final_error": float((target - act[after][-1]) / scale) if after.any() else None}


def _step_figures(t: np.ndarray, cmd: np.ndarray, fb: np.ndarray, amplitude: float,
                  band: float) -> dict[str, Any]:
    target = cmd[-1]
    base = target - amplitude
    rel = (fb - base) / amplitude              # 0 before, 1 at the set-point
    def first(level: float) -> float | None:
        idx = np.nonzero(rel >= level)[0]
        return float(t[idx[0]]) if len(idx) else None
    t10, t90 = first(0.1), first(0.9)
    over = max(0.0, float(np.max(rel)) - 1.0)
    settle = _settling(t, fb - target, band, float(t[0]))
    return {"segment": 1, "amplitude": amplitude,
            "rise_time_s": None if t10 is None or t90 is None else t90 - t10,
            "overshoot": over * abs(amplitude), "overshoot_pct": 100.0 * over,
            "settling_time_s": settle, "band": band,
            "peak_following_error": float(np.max(np.abs(cmd - fb))),
            "final_error": float(target - fb[-1])}


def check_loop_changes(cfg_loop: LoopConfig | None, axis: str, changes: Any) -> LoopConfig:
    """The axis's loop with `changes` applied (validated by LoopConfig; names `changes.k`)."""
    if cfg_loop is None:
        raise MotionError(f"axis {axis}: no servo loop in the controller to tune (its "
                          "drive closes the loop itself; [axes.<name>.loop] adds one)")
    if not isinstance(changes, dict) or not changes:
        raise MotionError(f"changes must be a non-empty object of loop keys "
                          f"({', '.join(LOOP_KEYS)})")
    for k in changes:
        if k not in LOOP_KEYS:
            raise MotionError(f"changes.{k}: unknown key; valid keys: {', '.join(LOOP_KEYS)}")
    try:
        return dataclasses.replace(cfg_loop, **changes)
    except MotionError as exc:
        raise MotionError(str(exc).replace("loop.", "changes.", 1)) from None
    except TypeError as exc:
        raise MotionError(f"changes: {exc}") from None
