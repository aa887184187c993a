"""HSL-4XMO trigger comparator (comparator 5) on a CompareEngine.

Seed: hsl-4xmo-users-manual.txt section 4.12 (Position Compare), 3.11 (CMP output);
enumerations from seed-facts.md 2.x (CmpSrc 0 command / 1 feedback; CmpMethod 0 disabled,
1 "=", 2 "=" counting up, 3 "=" counting down, 4 ">", 5 "<").

- Only axes 0 and 1 have the trigger comparator; each drives its CMP pin, mapped here to a
  general output `do<n>` (`cmp_outputs`, default axis 0 -> do0, axis 1 -> do1).
- A hit outputs a CMP pulse of `pulse_width` s. Trigger type (3.11): normal high (default,
  the pulse is a low-going, falling-edge pulse) or normal low (rising edge).
- `set_trigger_comparator` arms one value: it fires each time the condition comes into
  existence. On a continuous position ">" comes into existence when the counter passes the
  value upward, "<" downward, "=" either way (2/3: only up/down).
- `build_compare_function(start, end, interval)` / `build_compare_table(table, size)` load a
  list and `set_auto_compare(axis, 1)` starts it: each value fires once, then the next is
  loaded. After the final point the "after-final" value is loaded: for the function it is
  (end + interval * count) * move_ratio (4.12); for a table it is the table's last entry, so
  the manual asks for a dummy point there, far from the stroke. A loaded value that the
  motion reaches fires - as on the board, a dummy must be out of reach.
- `check_compare_data(axis)`: the value loaded now.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...errors import MotionError, check_finite, check_positive
from .compare import AxisSource, CompareEngine, LevelJob, Pulse

TRIGGER_AXES = (0, 1)
METHODS = {1: 0, 2: 1, 3: -1, 4: 1, 5: -1, "=": 0, ">": 1, "<": -1}
NORMAL_HIGH, NORMAL_LOW = 0, 1
DEFAULT_PULSE_S = 10e-6  # CMP pulse width: not given in the seed; our default


class HslTrigger:
    """HSL_M_* position-compare calls for the trigger comparator (module docstring)."""

    def __init__(self, engine: CompareEngine, *, cmp_outputs: Sequence[int] = (0, 1),
                 pulse_width: float = DEFAULT_PULSE_S) -> None:
        if not isinstance(engine, CompareEngine):
            raise MotionError(f"engine must be a CompareEngine, got {type(engine).__name__}")
        if len(cmp_outputs) != len(TRIGGER_AXES):
            raise MotionError(f"cmp_outputs must name {len(TRIGGER_AXES)} outputs")
        self.eng = engine
        self.cmp_out = {a: engine.check_output(o) for a, o in zip(TRIGGER_AXES, cmp_outputs,
                                                                  strict=True)}
        width = check_positive("pulse_width", pulse_width)
        self._src = dict.fromkeys(TRIGGER_AXES, 1)
        self._method = dict.fromkeys(TRIGGER_AXES, 1)
        self._type = dict.fromkeys(TRIGGER_AXES, NORMAL_HIGH)
        self._width = dict.fromkeys(TRIGGER_AXES, width)
        self._list: dict[int, tuple[np.ndarray, float]] = {}
        self._job: dict[int, int] = {}
        for a in TRIGGER_AXES:  # idle level of a normal-high CMP
            engine.output(self.cmp_out[a]).initial = True
            engine.output(self.cmp_out[a]).set(engine.ctl.time, True)

    # ------------------------------------------------------------------ checks
    @staticmethod
    def _axis(axis: object) -> int:
        if axis not in TRIGGER_AXES or isinstance(axis, bool):
            raise MotionError(f"axis must be 0 or 1 (only they have the trigger comparator),"
                              f" got {axis!r}")
        return int(axis)  # type: ignore[call-overload]

    def _action(self, axis: int) -> Pulse:
        idle_high = self._type[axis] == NORMAL_HIGH
        return Pulse(self.cmp_out[axis], self._width[axis], active=not idle_high)

    def _source(self, axis: int) -> AxisSource:
        return AxisSource(axis, "dpos" if self._src[axis] == 0 else "mpos")

    def _replace(self, axis: int, job: LevelJob | None) -> None:
        """Swap the axis's compare job; a refused new job leaves the old one running."""
        old = self._job.get(axis)
        jobs = self.eng.jobs
        if job is not None:
            held = jobs[old].buffer_use if old in jobs else 0
            if job.buffer_use > self.eng.buffer_free() + held:
                raise MotionError(f"table too long: {job.buffer_use} points, buffer has "
                                  f"{self.eng.buffer_free() + held} free")
            self.eng.check_output(job.action.output)
        if old is not None:
            self.eng.remove(old)
            del self._job[axis]
        if job is not None:
            self._job[axis] = self.eng.add(job)

    # ------------------------------------------------------------------ settings
    def set_trigger_type(self, axis: int, trigger_type: int) -> None:
        """0 = normal high (falling-edge pulse, default), 1 = normal low (rising edge)."""
        a = self._axis(axis)
        if trigger_type not in (NORMAL_HIGH, NORMAL_LOW) or isinstance(trigger_type, bool):
            raise MotionError(f"trigger_type must be 0 (normal high) or 1 (normal low), got "
                              f"{trigger_type!r}")
        self._type[a] = trigger_type
        line = self.eng.output(self.cmp_out[a])
        line.initial = trigger_type == NORMAL_HIGH
        line.set(self.eng.ctl.time, line.initial)

    def set_pulse_width(self, axis: int, width_s: float) -> None:
        self._width[self._axis(axis)] = check_positive("width_s", width_s)

    def set_trigger_comparator(self, axis: int, cmp_src: int, method: int | str,
                               data: float) -> None:
        """Arm a single value (method 0 disables); source 0 command, 1 feedback."""
        a = self._axis(axis)
        if cmp_src not in (0, 1) or isinstance(cmp_src, bool):
            raise MotionError(f"cmp_src must be 0 (command) or 1 (feedback), got {cmp_src!r}")
        if method != 0 and not (isinstance(method, (int, str)) and method in METHODS):
            raise MotionError(f"method must be 0..5 or '=', '>', '<', got {method!r}")
        d = check_finite("data", data)
        self._src[a] = cmp_src
        if method == 0:
            self._method[a] = 0
            self._replace(a, None)
            return
        self._method[a] = method  # type: ignore[assignment]
        job = LevelJob(self._source(a), [d], self._action(a), direction=METHODS[method],
                       repeat=True, name=f"hsl trigger axis {a}")
        self._replace(a, job)

    def build_compare_function(self, axis: int, start: float, end: float,
                               interval: float) -> int:
        """Load start, start + interval, ... up to end; returns the number of points."""
        a = self._axis(axis)
        s, e = check_finite("start", start), check_finite("end", end)
        iv = check_finite("interval", interval)
        if iv == 0.0 or (e - s) * iv < 0.0:
            raise MotionError(f"interval must be non-zero and lead from start to end, got "
                              f"start={start!r}, end={end!r}, interval={interval!r}")
        n = int(np.floor((e - s) / iv + 1e-9)) + 1
        if n > self.eng.buffer_size:
            raise MotionError(f"table too long: {n} points, buffer holds "
                              f"{self.eng.buffer_size}")
        pts = s + iv * np.arange(n, dtype=np.float64)
        after = (e + iv * n) * self.eng.ctl.axes[a].counters.move_ratio
        self._list[a] = (pts, after)
        return n

    build_comp_function = build_compare_function

    def build_compare_table(self, axis: int, table: ArrayLike, size: int) -> None:
        """Load `size` values of `table`; the last should be the after-final dummy."""
        a = self._axis(axis)
        arr = np.asarray(table, dtype=np.float64).reshape(-1)
        if isinstance(size, bool) or not isinstance(size, int) or not 1 <= size <= arr.size:
            raise MotionError(f"size must be an int in [1, {arr.size}] (table not empty), "
                              f"got {size!r}")
        if size > self.eng.buffer_size:
            raise MotionError(f"table too long: {size} points, buffer holds "
                              f"{self.eng.buffer_size}")
        pts = arr[:size].copy()
        if not np.all(np.isfinite(pts)):
            raise MotionError("table must hold finite values")
        self._list[a] = (pts[:-1], float(pts[-1])) if size > 1 else (pts, float(pts[-1]))

    build_comp_table = build_compare_table

    def set_auto_compare(self, axis: int, enable: int) -> None:
        """1: start continuous compare of the loaded list; 0: stop it."""
        a = self._axis(axis)
        if enable not in (0, 1) or isinstance(enable, bool):
            raise MotionError(f"enable must be 0 or 1, got {enable!r}")
        if not enable:
            self._replace(a, None)
            return
        if a not in self._list:
            raise MotionError("build_compare_function or build_compare_table first")
        if self._method[a] == 0:
            raise MotionError("set_trigger_comparator with a method first (method is 0)")
        pts, after = self._list[a]
        job = LevelJob(self._source(a), pts, self._action(a),
                       direction=METHODS[self._method[a]], after_final=after,
                       name=f"hsl auto compare axis {a}")
        self._replace(a, job)

    def check_compare_data(self, axis: int, comp_type: int = 5) -> float | None:
        """The value loaded in the trigger comparator now (None when nothing is armed)."""
        a = self._axis(axis)
        if comp_type != 5:
            raise MotionError(f"comp_type must be 5 (the trigger comparator), got {comp_type!r}")
        jid = self._job.get(a)
        if jid is None or jid not in self.eng.jobs:
            return None
        return self.eng.jobs[jid].value  # type: ignore[attr-defined,no-any-return]

    def check_compare_status(self, axis: int) -> bool:
        """True while a compare job of `axis` is armed (auto-trigger running)."""
        jid = self._job.get(self._axis(axis))
        return jid is not None and jid in self.eng.jobs
