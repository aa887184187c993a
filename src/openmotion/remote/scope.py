"""The scope: channels sampled inside the control cycle into a ring buffer on the server.

A channel is `<axis>.<quantity>`: command, feedback (user units), velocity (user units/s),
acceleration (user units/s^2, the difference of successive velocity samples), error
(following error, counts), state (AxisState code) or `io.<lamp>` (0/1, logical level); or
a general line of the board, `di.<n>` (input, electrical level) / `do.<n>` (output, the
level written), 0/1.
The cycle stores raw values only (pulses, counts, the I/O word: one list per sample); units
and derived channels are computed when the data is read, so sampling stays cheap.

Trigger: mode "level" (the value is at or above `level`), "rising" / "falling" (it crosses
`level`), "none" (free running). Armed, the scope keeps `pre_s` seconds before the trigger,
fills the rest of the history after it and stops. The history stays until the next
`configure` or `arm`, so any client can read it (`data`, `csv`).

Reading never holds the cycle for long: the ring is copied in slices of SLICE_ROWS rows,
the lock (which the cycle's `sample` takes too) taken once per slice, oldest slice first,
so a 600 s x 16 channel read lets the cycle run between its slices; rows the cycle
overwrote before their slice was copied are left out (the read starts later).
"""

from __future__ import annotations

import io as _io
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..control.core.controller import STATE_CODES
from ..control.guard.safety import IO_STATUS_BITS, io_status
from ..errors import MotionError

if TYPE_CHECKING:
    from ..control.core.controller import Controller

QUANTITIES = ("command", "feedback", "velocity", "acceleration", "error", "state")
LAMPS = ("alm", "pel", "mel", "org", "ez", "inp", "sd", "rdy", "erc", "emg", "ltc", "svon")
TRIGGER_MODES = ("none", "level", "rising", "falling")
MAX_CHANNELS = 16
MAX_SAMPLES = 600_000
FLUSH_ROWS = 64
SLICE_ROWS = 4096   # rows copied per lock hold by a read (16 channels: ~0.5 MB, ~0.1 ms)
BOARD = ("di", "do")
DEFAULT_QUANTITIES = ("command", "velocity", "acceleration", "error")


@dataclass(frozen=True)
class Trigger:
    channel: str = ""
    mode: str = "none"
    level: float = 0.0
    pre_s: float = 0.0

    def to_json(self) -> dict[str, Any]:
        return {"channel": self.channel, "mode": self.mode, "level": self.level,
                "pre_s": self.pre_s}


def channel_names(ctl: Controller) -> list[dict[str, str]]:
    out = []
    for ax in ctl.axes:
        u = ax.config.unit
        units = {"command": u, "feedback": u, "velocity": f"{u}/s",
                 "acceleration": f"{u}/s^2", "error": "counts", "state": "code"}
        out += [{"name": f"{ax.name}.{q}", "unit": units[q]} for q in QUANTITIES]
        out += [{"name": f"{ax.name}.io.{lamp}", "unit": "0/1"} for lamp in LAMPS]
    out += [{"name": f"di.{k}", "unit": "0/1"} for k in range(ctl.config.digital_inputs)]
    if hasattr(ctl.hardware, "read_output"):
        out += [{"name": f"do.{k}", "unit": "0/1"} for k in range(ctl.config.digital_outputs)]
    return out


def default_channels(ctl: Controller) -> list[str]:
    axes = [a.name for a in ctl.axes[:2]]
    return [f"{a}.{q}" for q in DEFAULT_QUANTITIES for a in axes]


class Scope:
    """Sampled channels of one controller (see the module docstring)."""

    def __init__(self, ctl: Controller, channels: Sequence[str] | None = None,
                 divider: int = 1, seconds: float = 30.0, trigger: Trigger | None = None
                 ) -> None:
        self.ctl = ctl
        self._lock = threading.Lock()
        self.version = 0
        self.configure(default_channels(ctl) if channels is None else channels, divider,
                       seconds, trigger or Trigger())

    # ------------------------------------------------------------------ setup
    def configure(self, channels: Sequence[str], divider: int, seconds: float,
                  trigger: Trigger) -> None:
        ctl = self.ctl
        if isinstance(channels, str) or not 1 <= len(channels) <= MAX_CHANNELS:
            raise MotionError(f"channels must be a list of 1..{MAX_CHANNELS} channel names")
        if len(set(channels)) != len(channels):
            raise MotionError("channels must not repeat a name")
        if isinstance(divider, bool) or not isinstance(divider, int) or not 1 <= divider <= 1000:
            raise MotionError(f"divider must be an integer in [1, 1000], got {divider!r}")
        if not 1.0 <= seconds <= 600.0:
            raise MotionError(f"seconds must be in [1, 600], got {seconds!r}")
        specs = [self._parse(c) for c in channels]
        if trigger.mode not in TRIGGER_MODES:
            raise MotionError(f"trigger.mode must be one of {', '.join(TRIGGER_MODES)}, "
                              f"got {trigger.mode!r}")
        if trigger.mode != "none":
            if trigger.channel not in channels:
                raise MotionError(f"trigger.channel must be one of the channels, got "
                                  f"{trigger.channel!r}")
            if not (math.isfinite(trigger.level) and 0.0 <= trigger.pre_s <= seconds):
                raise MotionError(f"trigger.pre_s must be in [0, {seconds:g}] s and "
                                  "trigger.level finite")
        dt = ctl.period * divider
        cap = int(min(MAX_SAMPLES, max(2, round(seconds / dt))))
        # raw getters: one per channel, values in pulses / counts / codes
        getters = [self._getter(ax, q) for ax, q in specs]
        t_buf, buf = np.zeros(cap), np.zeros((cap, len(channels)))   # outside the locks
        # under the cycle's lock: never between the getters and the write of a sample
        with ctl.lock, self._lock:
            self.channels = list(channels)
            self._specs = specs
            self._getters = getters
            self.divider = divider
            self.seconds = seconds
            self.trigger = trigger
            self.dt = dt
            self.cap = cap
            self._t, self._buf = t_buf, buf
            self.n = 0
            self._pend_t: list[float] = []
            self._pend: list[list[float]] = []
            self._tick = 0
            self.running = True
            self.version += 1
            self._arm_state()

    def _parse(self, name: Any) -> tuple[Any, str]:
        if not isinstance(name, str) or "." not in name:
            raise MotionError(f"channel must be '<axis>.<quantity>', 'di.<n>' or 'do.<n>', "
                              f"got {name!r}")
        axis, q = name.split(".", 1)
        if axis in BOARD:
            return None, self._board_line(name, axis, q)
        ax = self.ctl.axis(axis)
        if q in QUANTITIES or (q.startswith("io.") and q[3:] in LAMPS):
            return ax, q
        raise MotionError(f"channel {name!r}: quantity must be one of "
                          f"{', '.join(QUANTITIES)} or io.<{'|'.join(LAMPS)}>")

    def _board_line(self, name: str, kind: str, number: str) -> str:
        """'di3' / 'do3' for channel di.3 / do.3 (a line of the board)."""
        ctl = self.ctl
        count = ctl.config.digital_inputs if kind == "di" else ctl.config.digital_outputs
        if not (number.isdigit() and int(number) < count):
            raise MotionError(f"channel {name!r}: {kind} line must be a number in "
                              f"[0, {count - 1}]" if count else
                              f"channel {name!r}: the machine has no {kind} lines")
        if kind == "do" and not hasattr(ctl.hardware, "read_output"):
            raise MotionError(f"channel {name!r}: this hardware does not report its outputs")
        return f"{kind}{int(number)}"

    def _getter(self, ax: Any, q: str) -> Callable[[], float]:
        ctl = self.ctl
        if ax is None:   # a board line: di<n> / do<n>
            hw = ctl.hardware
            if q.startswith("di"):
                return lambda: 1.0 if hw.read_input(q) else 0.0
            read_out = hw.read_output
            return lambda: 1.0 if read_out(None, q) else 0.0
        if q == "command":
            return lambda: ax.position
        if q in ("velocity", "acceleration"):
            return lambda: ax.velocity
        if q == "feedback":
            return lambda: ax.counters.feedback
        if q == "error":
            return lambda: ax.counters.error
        if q == "state":
            return lambda: STATE_CODES[ax.state]
        bit = IO_STATUS_BITS[q[3:]]
        return lambda: (io_status(ctl, ax.index) >> bit) & 1

    def _arm_state(self) -> None:
        self.triggered_at: float | None = None
        self._stop_at: int | None = None
        self._floor = 0   # triggered: the first sample kept (pre_s before the trigger)
        self._prev: float | None = None
        self._prev_raw: float | None = None
        tr = self.trigger
        self._trig_col = self.channels.index(tr.channel) if tr.mode != "none" else -1
        self._pre = int(round(tr.pre_s / self.dt))

    def arm(self) -> None:
        with self.ctl.lock, self._lock:
            self.n = 0
            self._pend_t, self._pend = [], []
            self.running = True
            self.version += 1
            self._arm_state()

    def set_running(self, on: bool) -> None:
        with self._lock:
            self.running = on

    # ------------------------------------------------------------------ the cycle
    def sample(self, t: float) -> None:
        """Control cycle: record one sample every `divider` cycles."""
        if not self.running:
            return
        self._tick += 1
        if self._tick < self.divider:
            return
        self._tick = 0
        row = [g() for g in self._getters]
        with self._lock:
            # rows wait in a list and reach the ring in blocks: one numpy write per
            # FLUSH_ROWS samples instead of one per cycle (a row write costs microseconds)
            self._pend_t.append(t)
            self._pend.append(row)
            self.n += 1
            if len(self._pend) >= min(FLUSH_ROWS, self.cap):
                self._flush()
            if self._trig_col >= 0:
                self._check_trigger(row[self._trig_col], t)

    def _check_trigger(self, raw: float, t: float) -> None:
        if self._stop_at is not None:
            if self.n >= self._stop_at:
                self.running = False
            return
        ax, q = self._specs[self._trig_col]
        if q == "acceleration":
            prev_v = raw if self._prev_raw is None else self._prev_raw
            self._prev_raw = raw
            raw = (raw - prev_v) / self.dt
        v = self._convert_one(ax, q, raw)
        prev, self._prev = self._prev, v
        if self.n <= self._pre:   # wait for the pre-trigger history first
            return
        tr = self.trigger
        hit = (tr.mode == "level" and v >= tr.level) or (
            prev is not None and ((tr.mode == "rising" and prev < tr.level <= v)
                                  or (tr.mode == "falling" and prev > tr.level >= v)))
        if hit:
            self.triggered_at = t
            self._floor = max(0, self.n - 1 - self._pre)
            self._stop_at = self.n + (self.cap - self._pre - 1)

    # ------------------------------------------------------------------ reading
    def _convert_one(self, ax: Any, q: str, raw: float) -> float:
        if ax is None:
            return raw
        u = ax.units
        if q == "command":
            return raw / (u.sign * u.pulses_per_unit)
        if q == "feedback":
            return raw / ax.counters.move_ratio / (u.sign * u.pulses_per_unit)
        if q in ("velocity", "acceleration"):
            return raw / (u.sign * u.pulses_per_unit)
        return raw

    def _columns(self, t: np.ndarray, raw: np.ndarray, prev_row: np.ndarray | None
                 ) -> dict[str, np.ndarray]:
        cols = {}
        for k, (name, (ax, q)) in enumerate(zip(self.channels, self._specs, strict=True)):
            col = raw[:, k]
            if ax is None:     # board line: 0/1 as sampled
                cols[name] = col
                continue
            if q == "acceleration":
                before = col[0] if prev_row is None else prev_row[k]
                col = np.diff(col, prepend=before) / self.dt
            u = ax.units
            if q in ("command", "velocity", "acceleration"):
                col = col / (u.sign * u.pulses_per_unit)
            elif q == "feedback":
                col = col / ax.counters.move_ratio / (u.sign * u.pulses_per_unit)
            cols[name] = col
        return cols

    def _flush(self) -> None:
        """Move the waiting rows into the ring (lock held)."""
        k = len(self._pend)
        if not k:
            return
        idx = np.arange(self.n - k, self.n) % self.cap
        self._t[idx] = self._pend_t
        self._buf[idx] = self._pend
        self._pend_t, self._pend = [], []

    def _read(self, since: int) -> tuple[int, int, int, float | None, np.ndarray,
                                          np.ndarray, np.ndarray | None]:
        """(version, start, end, triggered_at, t, raw, row before start): samples
        [start, end) in time order, copied SLICE_ROWS rows per lock hold (module
        docstring). A configure / arm during the read starts it again on the new ring."""
        while True:
            with self._lock:
                self._flush()
                version, end, trig = self.version, self.n, self.triggered_at
                first = self._first()
                start = first if since < 0 else min(max(since, first), end)
            t_parts: list[np.ndarray] = []
            r_parts: list[np.ndarray] = []
            prev: np.ndarray | None = None
            a = start
            restart = False
            while a < end:
                with self._lock:
                    if self.version != version:
                        restart = True
                        break
                    oldest = self._first()
                    if a < oldest:          # overwritten before its slice was copied
                        t_parts, r_parts, prev = [], [], None
                        a = start = oldest
                    b = min(end, a + SLICE_ROWS)
                    if a == start and a > oldest:
                        prev = self._buf[(a - 1) % self.cap].copy()
                    idx = np.arange(a, b) % self.cap
                    t_parts.append(self._t[idx])        # fancy indexing copies
                    r_parts.append(self._buf[idx])
                a = b
            if restart:
                continue
            width = len(self.channels)
            t = np.concatenate(t_parts) if t_parts else np.zeros(0)
            raw = np.concatenate(r_parts) if r_parts else np.zeros((0, width))
            return version, start, end, trig, t, raw, prev

    def _first(self) -> int:
        return max(self._floor, self.n - self.cap)

    def data(self, since: int = -1, max_points: int = 5000) -> dict[str, Any]:
        version, start, end, trig, t, raw, prev = self._read(since)
        with self._lock:
            first = self._first()
        cols = self._columns(t, raw, prev)
        t_out, cols = _decimate(t, cols, max_points)
        return {"scope_version": version, "first": first, "start": start, "next": end,
                "t": _round(t_out, 9), "columns": {k: _round(v, 9) for k, v in cols.items()},
                "triggered_at": trig}

    def csv(self, start: float | None = None, end: float | None = None) -> str:
        _v, _s, _e, _tr, t, raw, prev = self._read(-1)
        cols = self._columns(t, raw, prev)
        mask = np.ones(len(t), bool)
        if start is not None:
            mask &= t >= start
        if end is not None:
            mask &= t <= end
        out = _io.StringIO()
        out.write("t," + ",".join(self.channels) + "\n")
        table = np.column_stack([t[mask]] + [cols[c][mask] for c in self.channels])
        np.savetxt(out, table, delimiter=",", fmt="%.9g")
        return out.getvalue()

    def info(self) -> dict[str, Any]:
        with self._lock:
            return {"channels": list(self.channels), "divider": self.divider,
                    "seconds": self.seconds, "trigger": self.trigger.to_json(),
                    "running": self.running, "scope_version": self.version,
                    "samples": self.n - self._first(), "first": self._first(),
                    "next": self.n, "triggered_at": self.triggered_at,
                    "rate_hz": 1.0 / self.dt}


def _round(a: np.ndarray, digits: int) -> list[float]:
    return [float(x) for x in np.round(a, digits)]


def _decimate(t: np.ndarray, cols: dict[str, np.ndarray], max_points: int
              ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """At most `max_points` samples: per bucket its first sample and, for every column, the
    sample of its largest excursion from the bucket mean (peaks survive decimation)."""
    n = len(t)
    if n <= max_points:
        return t, cols
    buckets = max(1, max_points // 2)
    edges = np.linspace(0, n, buckets + 1).astype(int)
    keep: list[int] = []
    stacked = np.column_stack(list(cols.values())) if cols else np.zeros((n, 0))
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if b <= a:
            continue
        seg = stacked[a:b]
        dev = np.abs(seg - seg.mean(axis=0)).max(axis=1) if seg.size else np.zeros(b - a)
        k = a + int(np.argmax(dev))
        keep.extend(sorted({a, k}))
    sel = np.array(keep, dtype=int)
    return t[sel], {k: v[sel] for k, v in cols.items()}
