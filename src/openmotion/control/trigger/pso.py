"""ZMotion-style position-synchronised output: HW_PSWITCH2 modes and the HW_TIMER.

Seed: zmotion-pso-2d-3d-and-hw-timer.txt; seed-facts.md section 4. A `ZPso` sits on a
`CompareEngine` and speaks the controller's BASIC:

- `table(start, *values)` = TABLE; `base(*axes)` = BASE; `set_units(axis, u)` = UNITS
  (table values and distances are in units, positions are units * pulses; maxerr is in
  pulses, as the seed stresses); `source(axis, "dpos"|"mpos")` = ATYPE (MPOS is compared
  when the axis has an encoder, DPOS otherwise);
- `hw_pswitch2(mode, ...)`: 1 (1-D table on BASE axis 0 with direction), 2 (stop and delete
  the unfinished points of BASE axis 0), 3 (table of VECTOR_MOVED values), 4/5/6 (vector
  distance every period; parameter lists NOT FOUND in the seeds - ours are documented in
  docs/pso.md), 7 (VECTOR_MOVED table, each point fires the timer), 25/26 (2-D points with
  maxerr window), 35/36 (3-D); `remaining(axis)` = ?HW_PSWITCH2(axis), free buffer space;
- `hw_timer(mode, cycle_us, on_us, reptimes, opstate, opnum)` = HW_TIMER (one timer).

Outputs: on the first point the output takes `opstate`, then each point inverts it (1, 3;
25 and 35 while no HW_TIMER runs on their output). The timer modes 6, 7, 26 and 36 start a
pulse train of the timer at each point, and so do 25 and 35 while the timer runs on their
output (the seed: "for the mode that is matched with HW_TIMER together, the pulse output
width is determined by HW_TIMER"). The timer is looked up when a point fires, not when
HW_PSWITCH2 is called: the seed calls HW_PSWITCH2 first and HW_TIMER after it, and "HW_TIMER
can be edited independently to adjust parameters dynamically" (`TimerTrigger`).

BASE lists shorter than a command needs are extended with the axes numbered after the last
BASE axis (`base_axes`): BASE(0) then MOVEABS(300, 200) moves axes 0 and 1 (seed Test_Mode3),
and VECTOR_MOVED of BASE axis 0 is the path length of that interpolation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...errors import MotionError, check_finite, check_positive, show
from .compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    LevelSeq,
    Pulse,
    Toggle,
    VectorSource,
    WindowJob,
)

MODES = (1, 2, 3, 4, 5, 6, 7, 25, 26, 35, 36)


def base_axes(base: Sequence[int], count: int | None, n_axes: int) -> tuple[int, ...]:
    """The first `count` axes of the BASE list extended by the axes numbered after its last
    axis (count None: the whole extension up to `n_axes`); MotionError if there are too few."""
    ext = list(base)
    nxt = max(base) + 1
    want = n_axes if count is None else count
    while len(ext) < want and nxt < n_axes:
        if nxt not in ext:
            ext.append(nxt)
        nxt += 1
    if count is not None and len(ext) < count:
        raise MotionError(f"{count} axes needed from BASE {tuple(base)!r}, the machine has "
                          f"axes 0..{n_axes - 1}")
    return tuple(ext if count is None else ext[:count])


def _int(name: str, value: object, lo: int, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or (isinstance(value, float) and not math.isfinite(value)) or value != int(value):
        raise MotionError(f"{name} must be an integer, got {show(value)}")
    v = int(value)
    if v < lo or (hi is not None and v > hi):
        rng = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise MotionError(f"{name} must be {rng}, got {value!r}")
    return v


class PulseTimer:
    """HW_TIMER: on a trigger, `reptimes` pulses of `on` s every `cycle` s at the level
    opposite to `opstate` (the output's default). One timer: each configure() replaces the
    previous one; reptimes 0 soft-closes it (trains already started finish, no new ones).
    A trigger while a train is still running is ignored and counted in `overruns`."""

    def __init__(self, eng: CompareEngine) -> None:
        self.eng = eng
        self.mode = 0
        self.cycle = 0.01
        self.on = 0.006
        self.reptimes = 1
        self.opstate = False
        self.output = -1
        self.busy_until = -math.inf
        self.soft_closed = False
        self.overruns = 0
        self.ignored = 0

    @property
    def running(self) -> bool:
        return self.mode == 2 and not self.soft_closed

    def serves(self, output: int) -> bool:
        """Is the timer configured (run, or soft-closed) on `output`?"""
        return self.mode == 2 and self.output == output

    def configure(self, mode: int, cycle_us: float, on_us: float, reptimes: int,
                  opstate: bool, opnum: int) -> None:
        """HW_TIMER(mode, cyclonetime, optime, reptimes, opstate, opnum); times in us."""
        mode, cycle, on, reps, opnum = self.check(mode, cycle_us, on_us, reptimes, opnum)
        now = self.eng.ctl.time
        if mode == 2 and reps == 0:
            if self.mode == 2:
                self.soft_closed = True  # pulses in progress keep going
            return
        self.stop()
        if mode == 0:
            return
        self.mode, self.cycle, self.on, self.reptimes = 2, cycle, on, reps
        self.opstate, self.output, self.soft_closed = bool(opstate), opnum, False
        self.eng.output(opnum).set(now, self.opstate)

    def check(self, mode: int, cycle_us: float, on_us: float, reptimes: int,
              opnum: int) -> tuple[int, float, float, int, int]:
        """Validate HW_TIMER parameters; returns (mode, cycle s, on s, reptimes, opnum)."""
        mode = _int("mode", mode, 0, 2)
        if mode == 1:
            raise MotionError("mode must be 0 (stop) or 2 (run), got 1")
        cycle = check_positive("cycle_us", cycle_us) * 1e-6
        on = check_positive("on_us", on_us) * 1e-6
        if on >= cycle:
            raise MotionError(f"on_us must be < cycle_us (on-time longer than cycle), got "
                              f"on_us={on_us!r}, cycle_us={cycle_us!r}")
        reps = _int("reptimes", reptimes, 0)
        opnum = self.eng.check_output(_int("opnum", opnum, 0))
        return mode, cycle, on, reps, opnum

    def stop(self) -> None:
        """Stop now: scheduled pulses are dropped and the output returns to its default."""
        if self.mode == 2 and self.output >= 0:
            now = self.eng.ctl.time
            line = self.eng.output(self.output)
            line.cancel_after(now)
            line.set(now, self.opstate)
        self.mode = 0
        self.busy_until = -math.inf
        self.soft_closed = False

    def apply(self, eng: CompareEngine, t: float, hit: int) -> bool:
        """Start a pulse train at t (the compare action); returns the output level at t."""
        line = eng.output(self.output)
        if not self.running:
            self.ignored += 1
            return line.level_at(t)
        if t < self.busy_until:
            self.overruns += 1
            return line.level_at(t)
        active = not self.opstate
        for k in range(self.reptimes):
            t_on = t + k * self.cycle
            line.set(t_on, active)
            line.set(t_on + self.on, self.opstate)
        self.busy_until = t + (self.reptimes - 1) * self.cycle + self.on
        return active


class TimerTrigger:
    """Compare action of the timer modes: at each point, the HW_TIMER train on `output` as
    the timer is configured at that instant. While the timer is not configured on `output`
    the point does `fallback` (25/35: invert, a Toggle) or, without one (6/7/26/36), only
    its log entry; such firings are counted in `timer.ignored`."""

    def __init__(self, timer: PulseTimer, output: int, fallback: Toggle | None = None) -> None:
        self.timer = timer
        self.output = output
        self.fallback = fallback

    def apply(self, eng: CompareEngine, t: float, hit: int) -> bool:
        tm = self.timer
        if tm.serves(self.output):
            return tm.apply(eng, t, hit)
        if self.fallback is not None:
            return self.fallback.apply(eng, t, hit)
        tm.ignored += 1
        return eng.output(self.output).level_at(t)


class ZPso:
    """ZMotion PSO on a CompareEngine (see module docstring).

    table_size: TABLE entries; outputs: the PSO-capable outputs (default 0..3, as a ZMC406).
    """

    def __init__(self, engine: CompareEngine, *, table_size: int = 100_000,
                 outputs: Sequence[int] = (0, 1, 2, 3)) -> None:
        if not isinstance(engine, CompareEngine):
            raise MotionError(f"engine must be a CompareEngine, got {type(engine).__name__}")
        self.eng = engine
        self.table_data = np.zeros(_int("table_size", table_size, 1))
        self.outputs = frozenset(engine.check_output(o) for o in outputs)
        n = len(engine.ctl.axes)
        self._base: tuple[int, ...] = tuple(range(min(n, 3)))
        self._units = [1.0] * n
        self._kind = ["dpos"] * n
        self._jobs: dict[int, list[int]] = {}  # BASE axis -> job ids
        self.timer = PulseTimer(engine)

    # ------------------------------------------------------------------ settings
    def table(self, start: int, *values: float) -> None:
        """TABLE(start, v0, v1, ...)."""
        start = _int("start", start, 0, self.table_data.size - 1)
        vals = [check_finite(f"values[{i}]", v) for i, v in enumerate(values)]
        if start + len(vals) > self.table_data.size:
            raise MotionError(f"values overflow the table of {self.table_data.size}")
        self.table_data[start:start + len(vals)] = vals

    def base(self, *axes: int) -> None:
        n = len(self.eng.ctl.axes)
        if not axes:
            raise MotionError("base needs at least one axis")
        chk = tuple(_int("axis", a, 0, n - 1) for a in axes)
        if len(set(chk)) != len(chk):
            raise MotionError(f"axes must be distinct, got {axes!r}")
        self._base = chk
        self.eng.track_vector(self._vector())  # VECTOR_MOVED accumulates from now on

    def set_units(self, axis: int, units: float) -> None:
        a = _int("axis", axis, 0, len(self._units) - 1)
        u = check_positive("units", units)
        old = self._vector()
        self._units[a] = u
        new = self._vector()
        if new != old:  # UNITS=100,100,100 sets one axis after the other: the half-set
            self.eng.untrack_vector(old)  # scales would be integrated every cycle for nothing
        self.eng.track_vector(new)

    def source(self, axis: int, kind: str) -> None:
        if not isinstance(kind, str) or kind not in ("dpos", "mpos"):
            raise MotionError(f"kind must be 'dpos' or 'mpos', got {kind!r}")
        self._kind[_int("axis", axis, 0, len(self._kind) - 1)] = kind

    @property
    def base_list(self) -> tuple[int, ...]:
        return self._base

    def units(self, axis: int) -> float:
        return self._units[_int("axis", axis, 0, len(self._units) - 1)]

    def kind(self, axis: int) -> str:
        return self._kind[_int("axis", axis, 0, len(self._kind) - 1)]

    def _vector(self, axis: int | None = None) -> VectorSource:
        n = len(self._units)
        head = self._base if axis is None or axis == self._base[0] else \
            (_int("axis", axis, 0, n - 1),)
        b = base_axes(head, None, n)
        return VectorSource(b, tuple(self._units[a] for a in b))

    def vector_moved(self, axis: int | None = None) -> float:
        """VECTOR_MOVED of the BASE axes (or of `axis` as the main axis), in units."""
        return self.eng.vector_moved(self._vector(axis))

    def set_vector_moved(self, value: float = 0.0, axis: int | None = None) -> None:
        self.eng.set_vector_moved(self._vector(axis), value)

    def remaining(self, axis: int | None = None) -> int:
        """?HW_PSWITCH2(axis): free compare buffer space."""
        return self.eng.buffer_free()

    def pending(self, axis: int | None = None) -> int:
        """Points not yet fired by the jobs of `axis` (default BASE axis 0)."""
        a = self._base[0] if axis is None else axis
        jobs = self.eng.jobs
        return sum(jobs[i].buffer_use for i in self._jobs.get(a, []) if i in jobs)

    # ------------------------------------------------------------------ HW_TIMER
    def hw_timer(self, mode: int, cycle_us: float, on_us: float, reptimes: int,
                 opstate: bool | int, opnum: int) -> None:
        """HW_TIMER(mode, cyclonetime, optime, reptimes, opstate, opnum)."""
        self._check_op(opnum)
        self.timer.configure(mode, cycle_us, on_us, reptimes, bool(opstate), opnum)

    def _check_op(self, opnum: object) -> int:
        op = _int("opnum", opnum, 0)
        if op not in self.outputs:
            raise MotionError(f"opnum must be a PSO-capable output {sorted(self.outputs)}, "
                              f"got {opnum!r}")
        return op

    # ------------------------------------------------------------------ HW_PSWITCH2
    def _slice(self, start: object, end: object) -> np.ndarray:
        s = _int("table_start", start, 0, self.table_data.size - 1)
        e = _int("table_end", end, 0, self.table_data.size - 1)
        if e < s:
            raise MotionError(f"table_end must be >= table_start (table not empty), got "
                              f"{start!r}..{end!r}")
        return self.table_data[s:e + 1].copy()

    def hw_pswitch2(self, mode: int, *p: float) -> int | None:
        """HW_PSWITCH2(mode, ...) on the BASE axes; returns the compare job id (None for 2).

        Everything is validated before anything changes: a refused call leaves the running
        jobs, the timer and the outputs as they were.
        """
        mode = _int("mode", mode, 1)
        if mode not in MODES:
            raise MotionError(f"mode must be one of {MODES}, got {mode!r}")
        axis0 = self._base[0]
        if mode == 2:
            for jid in self._jobs.pop(axis0, []):
                self.eng.remove(jid)
            return None
        nparams = {1: (5, 5), 3: (4, 4), 4: (4, 4), 5: (5, 5), 6: (4, 5), 7: (4, 4),
                   25: (5, 8), 26: (5, 8), 35: (5, 8), 36: (5, 8)}[mode]
        if not nparams[0] <= len(p) <= nparams[1] or (mode in (25, 26, 35, 36)
                                                       and len(p) not in (5, 8)):
            raise MotionError(f"mode {mode} takes {nparams[0]}"
                              f"{'' if nparams[0] == nparams[1] else '..' + str(nparams[1])}"
                              f" parameters after the mode, got {len(p)}")
        op = self._check_op(p[0])
        opstate = bool(_int("opstate", p[1], 0, 1))
        u = self._units
        if mode == 1:
            direction = _int("dir", p[4], 0, 1)
            pts = self._slice(p[2], p[3]) * u[axis0]
            job = LevelJob(AxisSource(axis0, self._kind[axis0]), pts, Toggle(op, opstate),
                           direction=1 if direction else -1, monotonic=True, name="mode1")
        elif mode in (3, 7):
            pts = self._slice(p[2], p[3])
            action = Toggle(op, opstate) if mode == 3 else TimerTrigger(self.timer, op)
            job = LevelJob(self._vector(), pts, action, direction=1, monotonic=True,
                           name=f"mode{mode}")
        elif mode in (4, 5):
            dis = check_positive("vectordis", p[2])
            width = check_positive("fixtime_us", p[3]) * 1e-6
            count = _int("count", p[4], 1) if mode == 5 else None
            s0 = self.eng.vector_moved(self._vector())
            job = LevelJob(self._vector(), LevelSeq(s0 + dis, dis, count),
                           Pulse(op, width, opstate), direction=1, name=f"mode{mode}")
        elif mode == 6:
            start = check_finite("start", p[2])
            period = check_positive("period", p[3])
            count = _int("count", p[4], 1) if len(p) == 5 else None
            job = LevelJob(self._vector(), LevelSeq(start, period, count),
                           TimerTrigger(self.timer, op), direction=1, name="mode6")
        else:
            job = self._window_job(mode, op, opstate, p)
        jid = self.eng.add(job)  # may refuse (buffer); nothing was changed before this
        self._jobs.setdefault(axis0, []).append(jid)
        return jid

    def _window_job(self, mode: int, op: int, opstate: bool, p: tuple[float, ...]) -> WindowJob:
        dim = 2 if mode in (25, 26) else 3
        axes = base_axes(self._base, dim, len(self._units))
        maxerr = check_finite("maxerr", p[2])
        if maxerr <= 0.0:
            raise MotionError(f"maxerr must be > 0 (never 0), got {p[2]!r}")
        num = _int("num", p[3], 1)
        pos = _int("tablepos", p[4], 0)
        if pos + num * dim > self.table_data.size:
            raise MotionError(f"num={num} points from tablepos={pos} overflow the table")
        pts = self.table_data[pos:pos + num * dim].reshape(num, dim) * np.array(
            [self._units[a] for a in axes])
        kinds = {self._kind[a] for a in axes}
        if len(kinds) != 1:
            raise MotionError("the BASE axes must share one compare source (dpos or mpos)")
        kind = kinds.pop()
        if mode in (25, 35):  # invert, or the timer's pulse while it runs on this output
            return WindowJob(axes, pts, maxerr, TimerTrigger(self.timer, op, Toggle(op, opstate)),
                             kind=kind, name=f"mode{mode}")
        job = WindowJob(axes, pts, maxerr, TimerTrigger(self.timer, op), kind=kind,
                        name=f"mode{mode}")
        if len(p) == 8:  # ophwtimeus, ophwtimes, hwcyctimeus: configure the timer too
            on_us, reps, cyc_us = p[5], p[6], p[7]
            _int("ophwtimes", reps, 1)
            self.timer.check(2, cyc_us, on_us, reps, op)
            if self.eng.buffer_free() < num:
                raise MotionError(f"table too long: {num} points, buffer has "
                                  f"{self.eng.buffer_free()} free")
            self.timer.configure(2, cyc_us, on_us, reps, not opstate, op)
        return job
