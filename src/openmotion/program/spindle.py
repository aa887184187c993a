"""The runner's spindle: an axis run in velocity mode, read back through its encoder and
index, and the moves that follow it (G33 / G76 passes) or position it (M19).

`SpindleDrive` turns the Spindle records (M3 / M4 / M5, S) into velocity moves of the
spindle axis (clockwise = positive counts), keeps the feedback count of the last index
pulse (an `ez` edge, at its exact time) and the measured speed (feedback counts over the
last cycles). It is the only thing that knows which axis is the spindle; the hardware
behind it may be real or simulated (hw/sim/spindle.py).

`SyncMove` runs one synchronised line as LinuxCNC does: it waits for the next index pulse,
then the tool advances `pitch` per measured revolution counted from that pulse. The group
runs the line (exact path); each cycle its feed override is set so the path position
tracks pitch x (revolutions since the index): feed-forward from the measured speed plus a
correction proportional to the position error. Every pass of a thread therefore starts at
the same spindle angle, whatever the spindle's speed or lag.

`OrientMove`: M19, the spindle stops and turns to R degrees after its index (P: the way),
within Q seconds when Q is given.
"""

from __future__ import annotations

import math
from collections import deque
from typing import TYPE_CHECKING

import numpy as np

from ..control.core.states import AxisState
from ..control.groups.group import GroupState
from ..control.home.latch import capture
from ..errors import MotionError
from . import canon
from .css import SpindleMode
from .orient import Orient

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from ..control.groups.group import Group
    from ..hw.interface import InputEdge

#: Speed of an M19 positioning move, revolutions per minute.
ORIENT_RPM = 60.0
#: Cycles over which the spindle speed is measured.
_SPEED_WINDOW = 16


class SpindleDrive:
    """The spindle axis `index` of `ctl`; `acc_time`: seconds of a speed ramp."""

    def __init__(self, ctl: Controller, index: int, acc_time: float) -> None:
        self.ctl = ctl
        self.axis = ctl.axes[index]
        self.index = index
        cfg = ctl.config.axes[index]
        self.counts_per_rev = cfg.pulses_per_rev * self.axis.counters.move_ratio
        self.acc_time = acc_time
        self.index_count: float | None = None  # feedback count at the last index pulse
        self.index_time: float | None = None
        self._index_listeners: list = []
        self._samples: deque[tuple[float, float]] = deque(maxlen=_SPEED_WINDOW)
        self._pending: float | None = None  # velocity to start once a reversal stopped
        self.rpm = 0.0  # commanded, signed (+ clockwise)
        self.css: SpindleMode | None = None  # G96 in force
        self._x_now = None  # G96: reads the tool's machine X
        self._cmd: canon.Spindle | None = None  # the M3/M4/S in force
        self.override = 1.0  # the operator's spindle-speed factor (runoverride.py)
        self._css_tick = 0
        self.axis.fix_speed_range(self.axis.max_speed)  # speed changes up to the maximum
        ctl.add_edge_hook(self._on_edge, signals=("ez",))

    # -- readings ------------------------------------------------------------------------
    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if e.axis != self.index or e.signal != "ez":
            return
        active = e.level != (ctl.axes[self.index].config.signal_logic("ez") == "nc")
        if not active:
            return
        count = float(capture(ctl, self.index, e).feedback)
        self.index_count, self.index_time = count, e.time
        for f in list(self._index_listeners):
            f(count, e.time)

    def count(self) -> float:
        """Feedback count now."""
        return float(self.axis.counters.feedback_unwrapped())

    def sample(self, t: float) -> None:
        """Once per cycle: remember the count (for the measured speed); in G96 follow the
        tool's X every few cycles."""
        self._samples.append((t, self.count()))
        if self._pending is not None and self.axis.state is AxisState.STANDSTILL:
            v, self._pending = self._pending, None
            self.axis.move_velocity(v, tacc=self.acc_time)
        self._css_tick += 1
        if self.css is not None and self._cmd is not None and self._cmd.on \
                and self._css_tick >= 4 and self.axis.state is AxisState.CONTINUOUS_MOTION:
            self._css_tick = 0
            want = self.target_rpm(self._cmd)
            if abs(want - abs(self.rpm)) > 2e-3 * max(abs(self.rpm), 1.0):
                self._css_change(want)

    def _css_change(self, rpm: float) -> None:
        """A small G96 speed change: at the spindle's full acceleration (max rpm per
        acc_time), not a whole acc_time ramp, so the speed keeps up with X."""
        ax = self.axis
        v = rpm / 60.0 * self.counts_per_rev / ax.counters.move_ratio
        dv = abs(abs(v) - abs(ax.velocity))
        tacc = max(4.0 * self.ctl.period, self.acc_time * dv / ax.max_speed)
        ax.change_speed(abs(v), tacc)
        self.rpm = rpm if self.rpm >= 0.0 else -rpm

    def set_override(self, factor: float) -> None:
        """The spindle-speed override (a factor on S, capped at the spindle's maximum): a
        turning spindle changes speed at once."""
        if factor == self.override:
            return
        self.override = factor
        if self._cmd is not None and self._cmd.on and self.rpm != 0.0:
            self.apply(self._cmd)

    def set_mode(self, mode: SpindleMode, x_now) -> None:
        """G96 (follow X through `x_now()`, machine units) or G97."""
        self.css = mode if mode.per_s_unit > 0.0 else None
        self._x_now = x_now
        if self._cmd is not None and self._cmd.on:
            self.apply(self._cmd)

    @property
    def max_rpm(self) -> float:
        return self.axis.max_speed * self.axis.counters.move_ratio * 60.0 / self.counts_per_rev

    def target_rpm(self, cmd: canon.Spindle) -> float:
        """The rpm the command asks for now (G96: at the tool's X, limited by D and by the
        spindle's maximum, as LinuxCNC limits it)."""
        if self.css is None or self._x_now is None:
            if self.override == 1.0:
                return cmd.speed
            return min(cmd.speed * self.override, self.max_rpm)
        return min(self.css.rpm(cmd.speed, float(self._x_now())) * self.override,
                   self.max_rpm)

    def revs_per_s(self) -> float:
        """Measured speed (signed revolutions per second) over the last cycles."""
        s = self._samples
        if len(s) < 2 or s[-1][0] <= s[0][0]:
            return 0.0
        return (s[-1][1] - s[0][1]) / (s[-1][0] - s[0][0]) / self.counts_per_rev

    def revs_per_s_now(self) -> float:
        """Measured speed extrapolated to now: the slopes of the window's two halves give
        the acceleration (a ramping spindle's average speed lags by half the window)."""
        s = list(self._samples)
        n = len(s)
        if n < 5:
            return self.revs_per_s()
        h = n // 2
        (ta, ca), (tm, cm), (tb, cb) = s[0], s[h], s[-1]
        if not ta < tm < tb:
            return self.revs_per_s()
        va, vb = (cm - ca) / (tm - ta), (cb - cm) / (tb - tm)
        acc = (vb - va) / (0.5 * (tb - ta))
        return (vb + acc * 0.5 * (tb - tm)) / self.counts_per_rev

    # -- commands ------------------------------------------------------------------------
    def apply(self, cmd: canon.Spindle) -> None:
        """M3 / M4 / M5 / S: start, change, reverse or stop the spindle."""
        self._cmd = cmd
        speed = self.target_rpm(cmd)
        rpm = (speed if cmd.clockwise else -speed) if cmd.on else 0.0
        ax = self.axis
        self.rpm = rpm
        self._pending = None
        moving = ax.state in (AxisState.CONTINUOUS_MOTION, AxisState.DISCRETE_MOTION,
                              AxisState.STOPPING)
        if rpm == 0.0:
            if moving:
                ax.stop()
            return
        v = rpm / 60.0 * self.counts_per_rev / ax.counters.move_ratio  # pps
        if abs(v) > ax.max_speed:
            raise MotionError(f"S{abs(rpm):g}: the spindle's maximum is "
                              f"{ax.max_speed * 60.0 / self.counts_per_rev:g} rpm")
        if ax.state is AxisState.CONTINUOUS_MOTION and ax.velocity * v > 0.0:
            ax.change_speed(abs(v), self.acc_time)
        elif moving:
            ax.stop()
            self._pending = v  # reversed (or after M19): start once it rests
        else:
            ax.move_velocity(v, tacc=self.acc_time)

    def stop(self) -> None:
        """Stop the spindle (program end, abort, fault)."""
        self._pending = None
        self.rpm = 0.0
        if self.axis.state in (AxisState.CONTINUOUS_MOTION, AxisState.DISCRETE_MOTION):
            self.axis.stop()

    def close(self) -> None:
        self.ctl.remove_edge_hook(self._on_edge)


class SyncMove:
    """One G33 / G76 pass on the group, locked to the spindle (module doc): a chain of
    consecutive synchronised lines (a G76 pass with its tapers) runs as one, from one index
    pulse; line k advances `pitch_k` per revolution."""

    GAIN = 40.0  # 1/s: position error -> speed correction
    EVERY = 4    # cycles between fine re-plans of the override

    def __init__(self, drive: SpindleDrive, g: Group,
                 lines: list[tuple[np.ndarray, np.ndarray, float]], push) -> None:
        self.drive = drive
        self.g = g
        self.lines = lines  # (start, end, pitch), machine units
        self.lengths = [float(np.linalg.norm(e - s)) for s, e, _ in lines]
        self.length = sum(self.lengths)
        self.pitch = min(p for _, _, p in lines)
        self._cum_len = np.concatenate(([0.0], np.cumsum(self.lengths)))
        self._cum_rev = np.concatenate(([0.0], np.cumsum(
            [L / p for L, (_, _, p) in zip(self.lengths, lines, strict=True)])))
        self._push = push  # push(speed_rps) queues the lines; returns their group indices
        self._idx: list[int] = []
        self.c0: float | None = None
        self.t0: float | None = None
        self.speed0 = 0.0
        self._pct = 100.0
        self._since = 0
        #: per cycle after the start: (time, tool position along the chain, position of
        #: the spindle's revolutions since the index - tool position), machine units
        self.errors: list[tuple[float, float, float]] = []
        if abs(drive.revs_per_s()) * 60.0 < 1e-3 and drive.rpm == 0.0:
            raise MotionError("a synchronised move (G33/G76) needs the spindle turning")
        drive._index_listeners.append(self._on_index)

    def _on_index(self, count: float, t: float) -> None:
        if self.c0 is None:
            self.c0, self.t0 = count, t
            self.drive._index_listeners.remove(self._on_index)

    def position(self) -> tuple[float, int]:
        """Tool position along the chain (machine units) and the line it is on."""
        cur = self.g.current_index
        k = self._idx.index(cur) if cur in self._idx else (
            len(self.lines) - 1 if self.g.state is GroupState.IDLE else 0)
        start, end, _ = self.lines[k]
        u = (end - start) / self.lengths[k]
        pos = np.array([a.position for a in self.g.axes], dtype=float) / self._ppu
        return float(self._cum_len[k] + np.dot(pos - start, u)), k

    def _target(self, revs: float) -> float:
        k = int(np.searchsorted(self._cum_rev, revs, side="right")) - 1
        if k >= len(self.lines):
            return self.length
        return float(self._cum_len[k] + (revs - self._cum_rev[k]) * self.lines[k][2])

    def poll(self, ppu: np.ndarray) -> bool:
        """Per cycle; True when the pass has ended (the group at rest at its end)."""
        self._ppu = ppu
        if self.c0 is None:
            return False
        revs = abs(self.drive.count() - self.c0) / self.drive.counts_per_rev
        if self.speed0 == 0.0:  # the index has passed: start the lines
            # the programmed feed is pitch x the commanded speed (the spindle may still be
            # ramping up to it): the override (1..200 %) then covers slower and catch-up
            self.speed0 = max(abs(self.drive.revs_per_s()), abs(self.drive.rpm) / 60.0,
                              1e-9)
            self._idx = self._push(self.speed0)
            return False
        s, k = self.position()
        err = self._target(revs) - s
        self.errors.append((self.drive.ctl.time, s, err))
        if revs < self._cum_rev[-1]:
            rps = abs(self.drive.revs_per_s_now()) + self.GAIN * err / self.lines[k][2]
            pct = min(200.0, max(1.0, 100.0 * rps / self.speed0))
            self._since += 1
            # a re-plan costs: only on a real change, or every few cycles to fine-tune
            step = abs(pct - self._pct)
            if (step >= 0.5 or (step >= 0.02 and self._since >= self.EVERY)) and (
                    self.g.queue_length or self.g.current_index >= 0):
                self.g.set_override(pct)
                self._pct, self._since = pct, 0
        if self.g.state is GroupState.IDLE and self.g.queue_length == 0:
            self.g.set_override(100.0)
            return True
        return False

    @property
    def steady_error(self) -> float:
        """Largest |error| once the start has caught up (the error first below 0.1 % of
        the pitch) and before the last quarter of the line (where the group brakes for the
        end), machine units."""
        tol = 1e-3 * self.pitch
        first = next((i for i, (_, _, e) in enumerate(self.errors) if abs(e) < tol), None)
        if first is None:
            return max((abs(e) for _, _, e in self.errors), default=0.0)
        mid = [abs(e) for _, s, e in self.errors[first:] if s <= 0.75 * self.length]
        return max(mid, default=0.0)

    def close(self) -> None:
        if self._on_index in self.drive._index_listeners:
            self.drive._index_listeners.remove(self._on_index)


class OrientMove:
    """M19 on the spindle (module doc)."""

    def __init__(self, drive: SpindleDrive, o: Orient) -> None:
        if drive.index_count is None:
            raise MotionError("M19: the spindle's index pulse has not been seen yet (turn "
                              "the spindle once before orienting it)")
        self.drive = drive
        self.o = o
        self.deadline = None if o.timeout is None else drive.ctl.time + o.timeout
        self.target: float | None = None
        drive._pending = None
        drive.rpm = 0.0
        if drive.axis.state is not AxisState.STANDSTILL:
            drive.axis.stop()

    def _goal(self) -> float:
        d = self.drive
        cpr = d.counts_per_rev
        assert d.index_count is not None
        base = d.index_count + self.o.angle / 360.0 * cpr
        c = d.count()
        k = (c - base) / cpr
        up = base + math.ceil(k - 1e-9) * cpr     # the next one turning clockwise (+)
        down = base + math.floor(k + 1e-9) * cpr  # ... counter-clockwise
        if self.o.mode == 0:
            goal = up
        elif self.o.mode == 1:
            goal = down
        else:
            goal = up if up - c <= c - down else down
        return float(round(goal))  # a whole count

    def poll(self) -> bool:
        """Per cycle; True once oriented, or at once after starting without Q (MotionError
        past the Q timeout)."""
        d = self.drive
        ax = d.axis
        if self.deadline is not None and d.ctl.time > self.deadline + 1e-12:
            raise MotionError(f"M19: the spindle did not reach its orientation within "
                              f"{self.o.timeout:g} s")
        if self.target is None:
            if ax.state is not AxisState.STANDSTILL:
                return False  # still stopping
            self.target = self._goal()
            ratio = ax.counters.move_ratio
            if abs(self.target - d.count()) >= 0.5:
                # in the command frame: just stopped, the feedback still lags the command
                # (servo), and an absolute move measures from the feedback (HSL), so it
                # would end that lag past the goal once the drive settles
                ax.move_relative(self.target / ratio - ax.position,
                                 max_vel=ORIENT_RPM / 60.0 * d.counts_per_rev / ratio,
                                 tacc=0.05)
            return self.deadline is None
        return ax.state is AxisState.STANDSTILL and abs(d.count() - self.target) <= 1.0

    def close(self) -> None:
        pass
