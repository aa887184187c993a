"""Compare engine: position-compare triggers located exactly on the analytic motion.

(Jobs, sources and actions live in compare_jobs.py and are re-exported here; the solvers
in compare_math.py, compiled in openmotion._compare; outputs and the event log in compare_io.py;
the sources' per-cycle tracks in compare_tracks.py, the re-plan rollback in compare_replan.py.)

Attached to a Controller through a cycle hook. At the end of each cycle [t0, t1] it takes
the motion just executed from the MotionHistory and finds, for every active job, every
trigger in (t0, t1] at its exact time (architecture.md "Events are located exactly").

On hardware with timed outputs (hw.interface.TimedOutputHardware, e.g. the simulator) the
jobs on command positions (DPOS axes, vector distance) run earlier, in the controller's
pre-advance hook: the commanded motion of (t0, t1] is in the history before the hardware
executes it, so their output edges are handed to the hardware with `write_output_at` and
land on the physical line at their exact times (compare_io.OutputLine.send). MPOS jobs
need the encoder at t1 and stay after the cycle (their edges reach the line at the cycle
end). The event log is the same either way.

- sources: `AxisSource(axis, "dpos")` = command position in the command-counter frame;
  `AxisSource(axis, "mpos")` = feedback position in the feedback-counter frame (see
  `feedback model` below); `VectorSource(axes, scale)` = accumulated path length of the
  axes (ZMotion VECTOR_MOVED) in pulses, or in user units with `scale` pulses per unit;
- jobs: `LevelJob` compares against a sequence of values one at a time, the "Value block"
  of HSL-4XMO 4.12 / the HW_PSWITCH2 buffer (a value fires once, then the next is loaded, so
  nothing fires twice when the axis reverses); `repeat=True` keeps one value armed (the
  single-value trigger comparator). `WindowJob` compares 2-D/3-D points with a +-maxerr
  window per axis (ZMotion modes 25/26/35/36), in table order;
- actions on a hit: `Toggle`, `Pulse`, `SetLevel`, or a pulse timer (pso.PulseTimer); each
  drives an `OutputLine` (exact edges) and every hit goes to the `EventLog`.

Feedback model (MPOS): the Hardware boundary reports the encoder only at cycle ends, so
between them the feedback is modelled as move_ratio * command(t) + e(t), with the following
error e(t) linear between its values at the cycle ends. For a stepper that keeps step this
is exactly the encoder; for a servo the error is the part interpolated, and it changes far
more slowly than the position.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ...errors import MotionError, check_finite, check_int, check_positive
from . import compare_math as _cm
from .compare_due import engine_due
from .compare_io import EventLog, OutputLine, send_lines
from .compare_jobs import (
    SOURCE_KINDS,
    Action,
    AxisSource,
    CompareJob,
    LevelJob,
    LevelSeq,
    Pulse,
    SetLevel,
    Source,
    Toggle,
    VectorSource,
    WindowJob,
    every_distance,
)
from .compare_math import Track, VectorCycle
from .compare_replan import CompareReplan
from .compare_tracks import CompareTracks

if TYPE_CHECKING:
    from ..core.controller import Controller

__all__ = [
    "SOURCE_KINDS", "Action", "AxisSource", "CompareEngine", "CompareJob", "LevelJob",
    "LevelSeq", "Pulse", "SetLevel", "Source", "SpeedPwm", "Toggle", "VectorSource", "WindowJob",
    "every_distance",
]

Array = NDArray[np.float64]


class SpeedPwm:
    """Duty-cycle output following the path speed (see CompareEngine.add_speed_pwm)."""

    def __init__(self, source: VectorSource, output: int, full_speed: float,
                 per_cycle: int = 1) -> None:
        self.source = source
        self.output = output
        self.full_speed = full_speed
        self.per_cycle = per_cycle
        self.duties: list[tuple[float, float]] = []  # (PWM period start, duty) for plots/tests

    def apply(self, line: OutputLine, vc: VectorCycle, s0: float, t0: float,
              t1: float) -> None:
        """PWM periods of (t0, t1] (per_cycle equal ones), each with the duty of the mean
        path speed over that period: its length increment / (period * full_speed)."""
        n = self.per_cycle
        tb = [t0 + (t1 - t0) * k / n for k in range(n)] + [t1]
        s = [s0] + [vc.at(t) for t in tb[1:-1]] + [vc.end]
        for k in range(n):
            a, period = tb[k], tb[k + 1] - tb[k]
            duty = min(max((s[k + 1] - s[k]) / (period * self.full_speed), 0.0), 1.0)
            self.duties.append((a, duty))
            line.set(a, duty > 0.0)
            if 0.0 < duty < 1.0:
                line.set(a + duty * period, False)


# ---------------------------------------------------------------------------- engine
class CompareEngine(CompareTracks, CompareReplan):
    """Runs compare jobs on a Controller every cycle (see module docstring).

    buffer_size: total points all jobs may hold; outputs: output numbers able to compare
    (default every general output of the machine).
    """

    def __init__(self, controller: Controller, *, buffer_size: int = 100_000,
                 outputs: Sequence[int] | None = None) -> None:
        if not isinstance(buffer_size, int) or buffer_size < 1:
            raise MotionError(f"buffer_size must be an int >= 1, got {buffer_size!r}")
        self.ctl = controller
        self.buffer_size = buffer_size
        n_do = controller.config.digital_outputs
        caps = range(n_do) if outputs is None else outputs
        if isinstance(caps, (str, bytes)) or not hasattr(caps, "__iter__"):
            raise MotionError(f"outputs must be a sequence of output numbers, "
                              f"got {outputs!r}")
        for o in caps:
            if not isinstance(o, int) or isinstance(o, bool) or not 0 <= o < n_do:
                raise MotionError(f"outputs must be output numbers in [0, {n_do - 1}], "
                                  f"got {o!r}")
        self.capable = frozenset(caps)
        self.log = EventLog(len(controller.axes))
        self._jobs: dict[int, CompareJob] = {}
        self._next_id = 0
        self._lines: dict[int, OutputLine] = {}
        self._vectors: dict[VectorSource, float] = {}
        self._mpos_err: dict[int, float] = {}
        self._pwms: list[SpeedPwm] = []
        self._t_last = controller.time
        self._tracks: dict[AxisSource, Track] = {}
        self._specs: dict[AxisSource, tuple[Any, float, float, float, float, float]] = {}
        self._ranges = {}
        self._vcycles: dict[VectorSource, VectorCycle] = {}
        self._weights: dict[VectorSource, Array] = {}  # (a source's weights, made once)
        self._mpos_e1: dict[int, float] = {}
        self._win = (self._t_last, self._t_last)
        from ...hw.interface import TimedOutputHardware

        #: DPOS/vector jobs run before the hardware advances; edges go out at exact times
        self.timed = isinstance(controller.hardware, TimedOutputHardware)
        self._t_pre = self._t_last
        self._pre_rows: list[_Block] = []  # the pre-advance scan's firings
        self._plan: bytes | None = None  # the records planned (rollback), plan_records
        self._plan_hists: list[Any] = []
        self._plan_key: tuple[int, int, int] | None = None  # what _plan_axes was made for
        self._plan_axes: list[int] = []
        self._timers: dict[int, Any] = {}
        self._prune_due = False  # a job finished: drop unused MPOS error models
        self._jobs_ver = 0  # bumped whenever the job set or its order changes
        self._banks: dict[bool | None, _Group] = {}
        controller.add_cycle_hook(self._on_cycle, due=self._due)
        if self.timed:
            controller.add_pre_advance_hook(self._pre_advance, due=self._due)

    def detach(self) -> None:
        """Stop running (the jobs stay as they are)."""
        self.ctl.remove_cycle_hook(self._on_cycle)
        self.ctl.remove_pre_advance_hook(self._pre_advance)

    # ------------------------------------------------------------------ outputs
    def check_output(self, number: int) -> int:
        if isinstance(number, bool) or not isinstance(number, int) or number not in self.capable:
            raise MotionError(f"output must be a compare-capable output "
                              f"{sorted(self.capable)}, got {number!r}")
        return number

    def output(self, number: int) -> OutputLine:
        """The exact waveform of output `do<number>` (created at its current level)."""
        line = self._lines.get(number) if isinstance(number, int) else None
        if line is None:
            self.check_output(number)
            line = OutputLine(number, False)
            line.attach(self.ctl.hardware)
            self._lines[number] = line
            self._jobs_ver += 1  # (scan groups use the lines that exist)
        return line

    # ------------------------------------------------------------------ jobs
    @property
    def jobs(self) -> dict[int, CompareJob]:
        return dict(self._jobs)

    def buffer_free(self) -> int:
        """Points the buffer can still take (ZMotion ?HW_PSWITCH2)."""
        return self.buffer_size - sum(j.buffer_use for j in self._jobs.values())

    def add(self, job: CompareJob) -> int:
        """Validate and arm `job` from now; returns its id. Nothing changes on refusal."""
        if not isinstance(job, CompareJob):
            raise MotionError(f"job must be a CompareJob, got {type(job).__name__}")
        if job.id >= 0:
            raise MotionError("job was already added")
        self.check_output(job.action.output)
        n_axes = len(self.ctl.axes)
        axes = (job.axes if isinstance(job, WindowJob) else
                job.source.axes if isinstance(job.source, VectorSource)  # type: ignore[attr-defined]
                else (job.source.axis,))  # type: ignore[attr-defined]
        for a in axes:
            if isinstance(a, bool) or not isinstance(a, int) or not 0 <= a < n_axes:
                raise MotionError(f"axis must be in [0, {n_axes - 1}], got {a!r}")
        if isinstance(job, LevelJob):
            src = job.source
            if isinstance(src, AxisSource) and src.kind not in SOURCE_KINDS:
                raise MotionError(f"kind must be one of {SOURCE_KINDS}, got {src.kind!r}")
            if isinstance(src, VectorSource) and (
                    len(src.axes) == 0 or len(set(src.axes)) != len(src.axes)
                    or (src.scale is not None and (len(src.scale) != len(src.axes)
                                                   or not all(math.isfinite(s) and s > 0
                                                              for s in src.scale)))):
                raise MotionError("vector source needs distinct axes and a positive scale "
                                  "per axis")
        with self.ctl.lock:  # the cycle may run on the real-time thread
            return self._add(job, axes)

    def _add(self, job: CompareJob, axes: Sequence[int]) -> int:
        if job.buffer_use > self.buffer_free():
            raise MotionError(f"table too long: {job.buffer_use} points, buffer has "
                              f"{self.buffer_free()} free of {self.buffer_size}")
        if isinstance(job, LevelJob) and isinstance(job.source, VectorSource):
            self.track_vector(job.source)
        kinds = [job.kind] if isinstance(job, WindowJob) else [getattr(job.source, "kind", "")]
        if "mpos" in kinds:
            for a in axes:
                self._start_mpos(a)
        job.id = self._next_id
        self._next_id += 1
        job.t_armed = self.ctl.time
        job.arm(self)
        self._jobs[job.id] = job
        self._jobs_ver += 1
        return job.id

    def remove(self, job_id: int) -> None:
        """Stop a job and drop its unfired points (HW_PSWITCH2(2) for one job)."""
        with self.ctl.lock:
            job = self._jobs.pop(job_id, None)
            self._jobs_ver += 1
            if job is not None:
                job.active = False
                self._prune_mpos()

    def _prune_mpos(self) -> None:
        """Keep the MPOS error model only for axes an active MPOS job compares (a later
        MPOS job starts it again from the error at its arming, as the first one did)."""
        if not self._mpos_err:
            return
        used: set[int] = set()
        for j in self._jobs.values():
            if isinstance(j, WindowJob):
                if j.kind == "mpos":
                    used.update(j.axes)
            elif getattr(j.source, "kind", "") == "mpos":
                used.add(j.source.axis)  # type: ignore[attr-defined]
        for a in [a for a in self._mpos_err if a not in used]:
            del self._mpos_err[a]

    def clear(self) -> None:
        for k in list(self._jobs):
            self.remove(k)

    def job(self, job_id: int) -> CompareJob:
        try:
            return self._jobs[job_id]
        except KeyError:
            raise MotionError(f"no active compare job {job_id!r}") from None

    # ------------------------------------------------------------------ vector distance
    def track_vector(self, source: VectorSource) -> None:
        """Start accumulating `source`'s path length (from 0) if not already."""
        self._vectors.setdefault(source, 0.0)

    def untrack_vector(self, source: VectorSource) -> None:
        """Stop accumulating `source`'s path length (every tracked source costs a path
        integral each moving cycle), unless a job or a speed PWM still reads it."""
        if any(getattr(j, "source", None) == source for j in self._jobs.values()) or \
                any(p.source == source for p in self._pwms):
            return
        self._vectors.pop(source, None)

    def vector_moved(self, source: VectorSource) -> float:
        """Path length accumulated so far (ZMotion VECTOR_MOVED)."""
        self.track_vector(source)
        return self._vectors[source]

    def set_vector_moved(self, source: VectorSource, value: float = 0.0) -> None:
        """VECTOR_MOVED = value (clear it before a job, as the seed says)."""
        if not isinstance(source, VectorSource):
            raise MotionError(f"source must be a VectorSource, got {type(source).__name__}")
        self._vectors[source] = check_finite("value", value)

    # ------------------------------------------------------------------ speed-following PWM
    def add_speed_pwm(self, source: VectorSource, output: int, full_speed: float, *,
                      per_cycle: int = 1) -> SpeedPwm:
        """Laser-power-style output: a PWM of `per_cycle` periods per control cycle on
        `output` whose duty follows the path speed of `source` (duty = mean speed over the
        PWM period / full_speed, capped at 1). On timed hardware the duty is that of the
        period itself (the coming motion is known) and the edges are exact; otherwise the
        periods of a cycle are computed after it, so they come out one cycle late."""
        if not isinstance(source, VectorSource):
            raise MotionError(f"source must be a VectorSource, got {source!r}")
        self.check_output(output)
        check_int("per_cycle", per_cycle, 1, 1000)
        pwm = SpeedPwm(source, output, check_positive("full_speed", full_speed), per_cycle)
        self.track_vector(source)
        self.output(output)
        self._pwms.append(pwm)
        return pwm

    def remove_speed_pwm(self, pwm: SpeedPwm) -> None:
        if pwm in self._pwms:
            self._pwms.remove(pwm)
            self.output(pwm.output).set(self.ctl.time, False)

    # ------------------------------------------------------------------ the cycle
    def _group(self, pre: bool | None) -> _Group:
        """The jobs of a scan group (pre True: command-position ones, False: MPOS ones,
        None: all), split into those the compiled driver runs and the rest; rebuilt only
        when the job set changes."""
        g = self._banks.get(pre)
        if g is not None and g.ver == self._jobs_ver:
            return g
        jobs = [j for j in self._jobs.values()
                if j.active and (pre is None or _on_command(j) == pre)]
        order = {j.id: k for k, j in enumerate(jobs)}
        # (a job whose line does not exist yet runs in Python until its first firing
        # creates it, which rebuilds the group: lines are created at the first firing)
        native = [j for j in jobs if _native(j) and j.action.output in self._lines]
        others = [j for j in jobs if j not in native]
        shared = {j.action.output for j in others} | {p.output for p in self._pwms}
        if any(j.action.output in shared for j in native):
            native, others = [], jobs  # one line edited by both: keep the job order
        slots: dict[AxisSource, int] = {}
        vslots: dict[VectorSource, int] = {}
        lines: dict[int, int] = {}
        specs = []
        for j in native:
            act = j.action
            ln = lines.setdefault(act.output, len(lines))
            kind, flag, width = _ACTIONS[type(act)](act)
            if isinstance(j, WindowJob):
                srcs = [AxisSource(a, j.kind) for a in j.axes]
                vals, n, after, direction, repeat, code = j.points, j.size, None, 0, False, 1
            else:
                srcs = [j.source]
                vals, n, after = j._values()
                direction, repeat = j.direction, j.repeat
                code = 2 if isinstance(j.source, VectorSource) else 0  # type: ignore[attr-defined]
            sl = ((vslots.setdefault(j.source, len(vslots)),) if code == 2  # type: ignore[attr-defined]
                  else tuple(slots.setdefault(x, len(slots)) for x in srcs))
            specs.append((code, sl, direction, repeat, vals, n, after,
                          float(getattr(j, "maxerr", 0.0)), float(j.t_armed), j.id, kind,
                          flag, width, ln, act.output))
        g = _Group(self._jobs_ver, _cm._solvers().bank_new(specs) if specs else None, native,
                   list(slots), [self._lines[o] for o in lines], others, order, list(vslots))
        self._banks[pre] = g
        return g

    def _scan(self, pre: bool | None, ta: float, t1: float) -> list[_Block]:
        """Run the jobs of a group (see _group) over (ta, t1]: blocks of firings."""
        g = self._group(pre)
        blocks: list[_Block] = []
        if g.bank is not None:
            vcs = [self.vector_cycle(v) for v in g.vslots]
            res = _cm._solvers().bank_scan(
                g.bank, g.native, [self.track_spec(x) for x in g.slots], g.lines,
                [self.track_spec(AxisSource(a)) for a in range(len(self.ctl.axes))], ta, t1,
                [(vc.B, vc.S, vc.Q) for vc in vcs])
            if res is not None:
                fb, kb, pb, done = res
                f = np.frombuffer(fb, dtype=np.float64).reshape(-1, 2)
                if f.shape[0]:
                    k = np.frombuffer(kb, dtype=np.int64).reshape(-1, 4)
                    blocks.append((f, k, np.frombuffer(pb, dtype=np.float64).reshape(
                        f.shape[0], -1), g.order, True))  # (in time order)
                for i in done:
                    self._finished(g.native[i])
        rows: list[tuple[float, int, int, float, int, int]] = []
        for job in g.others:
            if not job.active:
                continue
            hits = job.scan(self, ta, t1)
            if hits:
                act = job.action
                many = getattr(act, "apply_many", None)
                if many is not None:  # the job's firings of this cycle in one call
                    states = many(self, [h[0] for h in hits], job.hits)
                    job.hits += len(hits)
                else:
                    states = []
                    for h in hits:
                        states.append(act.apply(self, h[0], job.hits))
                        job.hits += 1
                out, jid = act.output, job.id
                rows.extend([(tf, jid, idx, val, out, int(st))
                             for (tf, idx, val), st in zip(hits, states, strict=True)])
            if job.done:
                self._finished(job)
        if rows:
            f = np.array([(r[0], r[3]) for r in rows], dtype=np.float64)
            k = np.array([(r[1], r[2], r[4], r[5]) for r in rows], dtype=np.int64)
            blocks.append((f, k, self._positions(rows), g.order, False))
        return blocks

    def _finished(self, job: CompareJob) -> None:
        self._jobs.pop(job.id, None)
        self._jobs_ver += 1
        job.active = False
        self._prune_due = True  # (after this cycle's error model update)

    def _positions(self, rows: list[tuple[float, int, int, float, int, int]]) -> Array:
        """Every axis's command position at each row's time: (len(rows), n_axes)."""
        out = np.empty((len(rows), len(self.ctl.axes)))
        tracks = [self.track(AxisSource(a)) for a in range(len(self.ctl.axes))]
        _cm._solvers().positions(tracks, [r[0] for r in rows], out)
        return out

    def _vectors_end(self, ta: float, t1: float) -> None:
        """Speed PWMs over (ta, t1], then every VECTOR_MOVED to its value at t1."""
        for pwm in self._pwms:
            s0 = self._vectors[pwm.source]
            vc = self.vector_cycle(pwm.source)
            if self.timed:
                pwm.apply(self.output(pwm.output), vc, s0, ta, t1)
            else:  # the cycle already ran: its PWM periods are played in the next one
                d = t1 - ta
                pwm.apply(self.output(pwm.output), _Shifted(vc, d), s0, t1, t1 + d)
        for src in self._vectors:
            self._vectors[src] = self.vector_cycle(src).end

    def _due(self, ctl: Controller) -> float:
        """When a hook of the engine may next act (control/trigger/compare_due.py)."""
        return engine_due(self)

    def _pre_advance(self, ctl: Controller, t0: float, t1: float) -> None:
        """Timed hardware, before it runs (t0, t1]: command-position jobs, exact edges."""
        ta = max(self._t_pre, t0)  # (after a jump: the cycles crossed had nothing to do)
        self._t_pre = t1
        if t1 <= ta:
            return
        self._begin(ta, t1)
        self._snapshot(ta, t1)
        self._pre_rows.extend(self._scan(True, ta, t1))
        self._vectors_end(ta, t1)
        send_lines(list(self._lines.values()), ctl.hardware, ta, t1)

    def _on_cycle(self, ctl: Controller, t1: float) -> None:
        # after a jump the window starts at the previous cycle end, as cycle by cycle
        ta = max(self._t_last, ctl._t_origin + (ctl.cycles - 1) * ctl.period)
        self._t_last = t1
        if t1 <= ta:
            return
        # (a jump's landing cycle had no pre-advance scan: nothing to redo)
        replan = self.timed and self._t_pre == t1 and self._moved_off_plan()
        self._begin(ta, t1)
        if replan:  # redo the command-position jobs on the motion as executed
            self._rollback(ta)
            pre = self._scan(True, ta, t1)
            self._vectors_end(ta, t1)
        else:
            pre = self._pre_rows
        self._pre_rows = []
        self._mpos_e1 = {a: self._mpos_error(a) for a in self._mpos_err}
        post = self._scan(False if self.timed else None, ta, t1)
        if not self.timed:
            self._vectors_end(ta, t1)
        self._mpos_err.update(self._mpos_e1)
        if self._prune_due:
            self._prune_due = False
            self._prune_mpos()
        if pre or post:
            _log_blocks(self.log, pre, post)
        # each line's flush and forget_before (waveforms are kept as long as the history)
        _cm._solvers().lines_end(list(self._lines.values()), ctl.hardware, float(ta),
                                 float(t1), float(t1 - ctl.history.window_s))


def _log_blocks(log: EventLog, pre: list[_Block], post: list[_Block]) -> None:
    """Add a cycle's firings to the log in time order; equal times keep the order of the
    scans: pre-advance before after-cycle, then job order, then hit order (a stable sort)."""
    blocks = pre + post
    if len(blocks) == 1:  # one block is in job order: a stable sort by time alone
        f, k, p, _, in_order = blocks[0]
        if in_order or f.shape[0] < 2 or bool(np.all(f[1:, 0] >= f[:-1, 0])):
            log.add_arrays(f, k, p)
        else:
            order = np.argsort(f[:, 0], kind="stable")
            log.add_arrays(f[order], k[order], p[order])
        return
    f = np.concatenate([b[0] for b in blocks])
    k = np.concatenate([b[1] for b in blocks])
    p = np.concatenate([b[2] for b in blocks])
    group = np.concatenate([np.full(b[0].shape[0], int(i >= len(pre)))
                            for i, b in enumerate(blocks)])
    pos = np.concatenate([np.fromiter((b[3].get(j, -1) for j in b[1][:, 0].tolist()),
                                      dtype=np.int64, count=b[1].shape[0]) for b in blocks])
    order = np.lexsort((pos, group, f[:, 0]))
    if bool(np.all(order[1:] > order[:-1])):
        log.add_arrays(f, k, p)
    else:
        log.add_arrays(f[order], k[order], p[order])


# f, k, positions, job order, in time order already (a driver block: time, job, hit order)
_Block = tuple[Array, NDArray[np.int64], Array, dict[int, int], bool]


class _Group:
    """A scan group's jobs: the compiled driver's bank (and its jobs, track sources, lines
    and path-length sources, in its order) and the jobs run in Python; job id -> position
    in the group."""

    def __init__(self, ver: int, bank: Any, native: list[CompareJob], slots: list[AxisSource],
                 lines: list[OutputLine], others: list[CompareJob], order: dict[int, int],
                 vslots: list[VectorSource]) -> None:
        self.ver, self.bank, self.native, self.slots = ver, bank, native, slots
        self.lines, self.others, self.order, self.vslots = lines, others, order, vslots


_ACTIONS = {  # the actions the driver applies itself: (code, flag, width)
    Toggle: lambda a: (0, int(bool(a.first)), 0.0),
    SetLevel: lambda a: (1, int(bool(a.level)), 0.0),
    Pulse: lambda a: (2, int(bool(a.active)), float(a.width)),
}


def _native(job: CompareJob) -> bool:
    """Does the compiled driver run this job (a LevelJob on an axis or a path length, or a
    WindowJob, with a built-in action)?"""
    if type(job.action) not in _ACTIONS:
        return False
    return type(job) is WindowJob or type(job) is LevelJob


def _on_command(job: CompareJob) -> bool:
    """Does the job compare command positions only (DPOS axes or vector distance)?"""
    if isinstance(job, WindowJob):
        return job.kind == "dpos"
    src = getattr(job, "source", None)
    return isinstance(src, VectorSource) or getattr(src, "kind", "dpos") == "dpos"


class _Shifted:
    """A VectorCycle read `d` seconds later (the PWM of a cycle played in the next one)."""

    def __init__(self, vc: VectorCycle, d: float) -> None:
        self.vc, self.d, self.end = vc, d, vc.end

    def at(self, t: float) -> float:
        return self.vc.at(t - self.d)
