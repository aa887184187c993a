"""Position-synchronised outputs (PSO / compare) set up from the remote API, and their
firings for the path view.

A job fires a general output `do<n>` at positions of a group of axes, on the library's
compare engine (control.trigger.compare, the ZMotion PSO / HSL CMP model): `distance`
fires every `every` user units of path length over the axes (HW_PSWITCH2 mode 4 style),
`points` fires at each point of a table when the axes pass within `window` of it (mode
25/35 style). Each firing is a pulse of `pulse_s`. The engine is made on the first job
(its cycle hook costs nothing before). When a setting change restarts the machine (a power
cycle: positions 0), `restore(old)` sets the old session's jobs up again on the new one
from their user-unit setups (a points job with the points it had not reached yet; a
finished one is not re-armed); a job the new machine cannot take (an axis or output it no
longer has) is listed in `dropped` with the reason. `firings(t_lo, t_hi)` gives the
engine's log with every axis's position, in the frame of `Axis.position`, for the path
recorder.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..control.trigger.compare import CompareEngine
from ..control.trigger.compare_jobs import Pulse, VectorSource, WindowJob, every_distance
from ..errors import MotionError

if TYPE_CHECKING:
    from ..control.core.controller import Controller

KINDS = ("distance", "points")
MAX_POINTS = 100_000
MAX_PULSE_S = 1.0


class PsoSession:
    """The compare jobs of one controller, made through the API (see module docstring)."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.engine: CompareEngine | None = None
        self._jobs: dict[int, dict[str, Any]] = {}
        self._setups: dict[int, dict[str, Any]] = {}   # job id -> add()'s arguments
        self.dropped: list[str] = []   # jobs a restart could not set up again, and why

    def add(self, kind: str, axes: list[int], output: int, pulse_s: float, *,
            every: float | None = None, start: float | None = None,
            points: Any = None, window: float | None = None) -> dict[str, Any]:
        """Validate and start one job; the caller holds the controller's lock."""
        ctl = self.ctl
        if kind not in KINDS:
            raise MotionError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
        if not axes or len(set(axes)) != len(axes) or len(axes) > 3:
            raise MotionError("axes must name 1 to 3 different axes")
        n_do = ctl.config.digital_outputs
        if not 0 <= output < n_do:
            raise MotionError(f"output must be in [0, {n_do - 1}] (the machine's digital "
                              f"outputs), got {output}")
        if not 0.0 < pulse_s <= MAX_PULSE_S:
            raise MotionError(f"pulse_s must be in (0, {MAX_PULSE_S:g}] s, got {pulse_s!r}")
        units = [ctl.axes[a].units for a in axes]
        unit = ctl.axes[axes[0]].config.unit
        action = Pulse(output, pulse_s)
        if kind == "distance":
            if every is None or not every > 0.0:
                raise MotionError(f"every must be > 0 {unit} (path length between "
                                  f"firings), got {every!r}")
            if start is not None and not start >= 0.0:
                raise MotionError(f"start must be >= 0 {unit}, got {start!r}")
            src = VectorSource(tuple(axes), tuple(u.pulses_per_unit for u in units))
            job = every_distance(src, every, action, start=start)
            what = f"every {every:g} {unit} of path on {self._names(axes)}"
        else:
            pts = _points(points, len(axes))
            if window is None or not window > 0.0:
                raise MotionError(f"window must be > 0 {unit} (the +- tolerance around "
                                  f"each point), got {window!r}")
            # the engine compares command counters (pulses): the table in that frame
            counters = np.column_stack([
                [float(u.to_pulses(v)) + self._offset(a) for v in pts[:, k]]
                for k, (a, u) in enumerate(zip(axes, units, strict=True))])
            ppu = min(u.pulses_per_unit for u in units)
            job = WindowJob(axes, counters, window * ppu, action)
            what = f"{len(pts)} points on {self._names(axes)} (window {window:g} {unit})"
        if self.engine is None:
            self.engine = CompareEngine(ctl)
        eng = self.engine
        if kind == "distance":   # the path length counts from this job on (VECTOR_MOVED = 0)
            eng.set_vector_moved(src, 0.0)
        job_id = eng.add(job)
        self._jobs[job_id] = {"id": job_id, "kind": kind, "axes": self._names(axes),
                              "output": output, "pulse_s": pulse_s, "what": what}
        self._setups[job_id] = {"kind": kind, "axes": self._names(axes), "output": output,
                                "pulse_s": pulse_s, "every": every, "start": start,
                                "points": None if points is None else pts.tolist(),
                                "window": window}
        return self._job_info(job_id)

    def clear(self) -> None:
        if self.engine is not None:
            self.engine.clear()
        self._jobs.clear()
        self._setups.clear()
        self.dropped.clear()

    def restore(self, old: PsoSession) -> list[int]:
        """Set `old`'s jobs up again on this (restarted) machine, in their order; the axes
        they use (indices, for the path view). Never raises: a job this machine refuses
        goes to `dropped` with the reason."""
        used: list[int] = []
        self.dropped = list(old.dropped)
        for job_id, setup in old._setups.items():
            s = dict(setup)
            if s["kind"] == "points":
                job = old.engine.jobs.get(job_id) if old.engine is not None else None
                left = s["points"][job.index:] if job is not None and not job.done else []
                if not left:
                    continue                      # finished before the restart
                s["points"] = left
            try:
                axes = [self.ctl.axis(a).index for a in s["axes"]]
                self.add(s["kind"], axes, s["output"], s["pulse_s"], every=s["every"],
                         start=s["start"], points=s["points"], window=s["window"])
            except MotionError as exc:
                self.dropped.append(f"job {job_id} ({old._jobs[job_id]['what']}): {exc}")
                continue
            used = axes
        return used

    def _names(self, axes: list[int]) -> list[str]:
        return [self.ctl.axes[a].name for a in axes]

    def _offset(self, axis: int) -> float:
        """Command counter minus Axis.position (pulses) right now."""
        return -self.ctl.axes[axis].counters.pulses_from_command(0.0)

    def _job_info(self, job_id: int) -> dict[str, Any]:
        info = dict(self._jobs[job_id])
        eng = self.engine
        job = eng.jobs.get(job_id) if eng is not None else None
        if info["kind"] == "distance":
            info["remaining"] = None        # endless: every `every` while the axes move
        else:                               # a finished table job leaves the engine
            info["remaining"] = 0 if job is None else job.remaining
        info["active"] = job is not None and not job.done
        return info

    def info(self) -> dict[str, Any]:
        n = len(self.engine.log) if self.engine is not None else 0
        return {"jobs": [self._job_info(j) for j in self._jobs], "firings": n,
                "dropped": list(self.dropped)}

    def firings(self, t_lo: float, t_hi: float) -> list[dict[str, Any]]:
        """Firings with t_lo < t <= t_hi: time, job, output, state and every axis's
        position in pulses (Axis.position frame)."""
        eng = self.engine
        if eng is None or not len(eng.log):
            return []
        a = eng.log.arrays()
        sel = np.nonzero((a["time"] > t_lo) & (a["time"] <= t_hi))[0]
        if not len(sel):
            return []
        offsets = np.array([self._offset(k) for k in range(len(self.ctl.axes))])
        return [{"t": float(a["time"][i]), "job": int(a["job"][i]),
                 "output": int(a["output"][i]), "level": bool(a["state"][i] > 0),
                 "pulses": a["positions"][i] - offsets} for i in sel]


def _points(points: Any, width: int) -> np.ndarray:
    if not isinstance(points, list) or not points or len(points) > MAX_POINTS:
        raise MotionError(f"points must be a list of 1..{MAX_POINTS} points, got "
                          f"{type(points).__name__}")
    for k, p in enumerate(points):
        if not isinstance(p, list) or len(p) != width or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
                for v in p):
            raise MotionError(f"points[{k}] must be a list of {width} finite numbers (one "
                              f"per axis), got {p!r}")
    return np.array(points, dtype=np.float64)
