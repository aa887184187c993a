"""Backlash, vibration suppression and pitch-error compensation of one axis.

One mechanism carries all three: an *offset* o between the planned command position p
(what the planners produce, what the command counter shows) and the pulse output p + o
(what the motor gets). Each cycle the wanted offset is

    o* = backlash(dir) + pitch(x, dir) + vibration(t)

with dir the last planned direction of travel (+1 at start, as after a positive move or a
homing in the positive direction) and x the planned position at the cycle end in the
command-counter frame. The offset then moves towards o* under its own limits and inside
what the planned piece leaves of the axis limits (see `_bump` for the derivation), so the
pulse output never exceeds the axis's velocity or acceleration limit (LinuxCNC's screw
compensation can reach 150 % of them; anchors.md b8).

Seed semantics:
- backlash (HSL-4XMO 4.13, HSL_M_backlash_comp): after a reversal to negative travel the
  output runs `b` pulses behind the plan (o = -b), after a reversal to positive travel it
  comes back (o = 0): the corrective pulses go out at each direction change. Matches the
  simulator's mechanics (load = motor going up, motor + b going down).
- vibration suppression (HSL 4.13, HSL_M_suppress_vibration): T1 after a move completes,
  one pulse in the negative direction; T2 after that pulse, one in the positive direction.
- pitch error (MCCL 2.10.1): tables of up to 256 points every `interval` pulses, point
  `home_index` at position 0 (value 0 there), forward table used in positive travel,
  backward table in negative travel; inside a section
  comp(x) = T[k] + round((x - x_k) / interval * (T[k+1] - T[k])), the seed's
  15,000 -> 15,011 pulse example.

Counters: the command counter (and error counter, general "command" source) shows the
*planned* position; the hardware's pulses_out (SimMachine.command_position) shows
planned + offset (Counters.out_offset, whole pulses, is taken off).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import MotionError, check_finite, check_positive, check_range
from ...hw.interface import AxisCommand
from ...units import MAX_PULSE_RATE
from ..core.states import AxisState

if TYPE_CHECKING:
    from ..core.axis import Axis

#: motion_done code while a finished move waits for its correction (seed-facts 2.5, 7).
BACKLASH_COMPENSATING = 7
#: MCCL MAX_COMP_POINT (seed-facts 5).
MAX_COMP_POINTS = 256
_I16_MAX = 32767


def _round_half_up(x: float) -> int:
    return math.floor(x + 0.5)


def _check_int(name: str, value: object, lo: int, hi: int) -> int:
    if isinstance(value, bool):
        raise MotionError(f"{name} must be a whole number, got {value!r}")
    x = check_finite(name, value)  # type: ignore[arg-type]
    if x != int(x):
        raise MotionError(f"{name} must be a whole number, got {value!r}")
    if not lo <= x <= hi:
        raise MotionError(f"{name} must be in [{lo}, {hi}], got {value!r}")
    return int(x)


@dataclass(frozen=True)
class PitchCompTable:
    """MCCL SYS_COMP_PARAM: interval (pulses), home index, forward/backward tables (pulses)."""

    interval: int
    home_index: int
    forward: tuple[int, ...]
    backward: tuple[int, ...]

    @classmethod
    def make(cls, interval: int, home_index: int, forward: Sequence[int],
             backward: Sequence[int] | None = None) -> PitchCompTable:
        """Validate and build a table (MotionError naming the bad field)."""
        iv = _check_int("interval", interval, 1, 2**27 - 1)
        tables = []
        for name, tab in (("forward", forward), ("backward", forward if backward is None
                                                 else backward)):
            if isinstance(tab, (str, bytes)) or not isinstance(tab, Sequence):
                raise MotionError(f"{name} must be a sequence of whole pulse counts, "
                                  f"got {tab!r}")
            if not 2 <= len(tab) <= MAX_COMP_POINTS:
                raise MotionError(f"{name} must have 2..{MAX_COMP_POINTS} points, "
                                  f"got {len(tab)}")
            vals = tuple(_check_int(f"{name}[{k}]", e, -_I16_MAX, _I16_MAX)
                         for k, e in enumerate(tab))
            for k in range(len(vals) - 1):
                if abs(vals[k + 1] - vals[k]) >= iv:
                    raise MotionError(f"{name}[{k + 1}] - {name}[{k}] must be smaller than "
                                      f"the interval {iv} in magnitude (the output must "
                                      "stay monotonic in the position)")
            tables.append(vals)
        fw, bw = tables
        if len(bw) != len(fw):
            raise MotionError(f"backward must have as many points as forward ({len(fw)}), "
                              f"got {len(bw)}")
        h = _check_int("home_index", home_index, 0, len(fw) - 1)
        if fw[h] != 0 or bw[h] != 0:
            raise MotionError(f"forward[{h}] and backward[{h}] (the home point) must be 0, "
                              f"got {fw[h]} and {bw[h]}")
        return cls(iv, h, fw, bw)

    @classmethod
    def from_slots(cls, interval: int, home_index: int, forward: Sequence[int],
                   backward: Sequence[int], stroke: tuple[float, float]) -> PitchCompTable:
        """A table from MCCL's fixed slots (SYS_COMP_PARAM: 256 per direction, no count):
        the points the stroke (lo, hi) in pulses (home = 0) needs, home_index -
        ceil(-lo/interval) .. home_index + ceil(hi/interval). Refused (MotionError) when
        the slots cannot cover the stroke ("the compensation range must cover the whole
        stroke": +interval*(last - home), -interval*home)."""
        iv = _check_int("interval", interval, 1, 2**27 - 1)
        n = min(len(forward), len(backward)) if isinstance(forward, Sequence) and \
            isinstance(backward, Sequence) else 0
        h = _check_int("home_index", home_index, 0, max(0, n - 1))
        lo = check_finite("stroke[0]", stroke[0])
        hi = check_finite("stroke[1]", stroke[1])
        below = math.ceil(-lo / iv - 1e-9) if lo < 0.0 else 0
        above = math.ceil(hi / iv - 1e-9) if hi > 0.0 else 0
        first, last = h - below, h + max(above, 1 if below == 0 else 0)
        if first < 0 or last > n - 1:
            raise MotionError(f"the compensation range [{-h * iv}, {(n - 1 - h) * iv}] "
                              f"pulses (interval {iv}, home point {h}) must cover the "
                              f"stroke [{lo:g}, {hi:g}]")
        return cls.make(iv, h - first, list(forward[first:last + 1]),
                        list(backward[first:last + 1]))

    @property
    def span(self) -> tuple[int, int]:
        """Positions (pulses, home = 0) covered by the table."""
        n = len(self.forward)
        return -self.home_index * self.interval, (n - 1 - self.home_index) * self.interval

    def value(self, x: float, direction: int) -> int:
        """Compensation (pulses) at position x for travel in `direction` (MCCL 2.10.1);
        beyond the table the end value holds."""
        tab = self.forward if direction >= 0 else self.backward
        u = x / self.interval + self.home_index
        n = len(tab)
        if u <= 0.0:
            return tab[0]
        if u >= n - 1:
            return tab[-1]
        k = int(u)
        frac = (x - (k - self.home_index) * self.interval) / self.interval
        return tab[k] + _round_half_up(frac * (tab[k + 1] - tab[k]))


class Compensation:
    """Compensation of one axis; attached to the axis while it exists (`remove()`).

    max_accel: the axis's acceleration limit (pps^2) the output must respect;
    max_vel: the axis's velocity limit (pps, default its maximum safe speed);
    comp_vel / comp_accel: the offset's own ramp limits (default: the axis limits).
    Starts with everything disabled (offset 0).
    """

    def __init__(self, axis: Axis, *, max_accel: float, max_vel: float | None = None,
                 comp_vel: float | None = None, comp_accel: float | None = None) -> None:
        vlim = min(axis.config.max_speed_pps, MAX_PULSE_RATE)
        a = check_positive("max_accel", max_accel)
        v = vlim if max_vel is None else check_range("max_vel", max_vel, 0.0, vlim)
        if v <= 0.0:
            raise MotionError(f"max_vel must be > 0, got {max_vel!r}")
        cv = v if comp_vel is None else check_range("comp_vel", comp_vel, 0.0, v)
        ca = a if comp_accel is None else check_range("comp_accel", comp_accel, 0.0, a)
        if cv <= 0.0 or ca <= 0.0:
            raise MotionError("comp_vel and comp_accel must be > 0")
        if any(isinstance(t, Compensation) for t in axis.command_transforms):
            raise MotionError(f"axis {axis.name} already has a Compensation")
        self.axis = axis
        self.max_vel, self.max_accel, self.comp_vel, self.comp_accel = v, a, cv, ca
        self._backlash = 0
        self._table: PitchCompTable | None = None
        self._vib: tuple[float, float] | None = None
        self._vib_phase = 0          # 0 idle, 1 waiting/going to -1, 2 waiting/going back
        self._vib_at = 0.0           # time the current phase may start
        self._dir = 1
        self._o = 0.0
        self._target = 0.0
        self._was_moving = False
        self._lock = axis._ctl.lock  # the axis's controller (Axis has no public link)
        with self._lock:
            axis.command_transforms.append(self)
            axis.done_gates.append(self._gate)

    # ------------------------------------------------------------------ settings
    def backlash_comp(self, pulses: int, mode: int = 1) -> None:
        """HSL_M_backlash_comp(Axis, BCompPulse, Mode): corrective pulses (0..32767) output
        on every direction change; mode 1 on, 0 off (the seed gives no Mode values)."""
        b = _check_int("pulses", pulses, 0, _I16_MAX)
        m = _check_int("mode", mode, 0, 1)
        with self._lock:
            self._backlash = b if m else 0

    def suppress_vibration(self, t1: float, t2: float) -> None:
        """HSL_M_suppress_vibration(Axis, T1, T2) with T1, T2 in seconds (0..1): after each
        completed move, one reverse pulse T1 later, one forward pulse T2 after it. Both 0
        disables. Times start on the cycle grid (the pulses are ramped like any offset)."""
        a = check_range("t1", t1, 0.0, 1.0)
        b = check_range("t2", t2, 0.0, 1.0)
        with self._lock:
            self._vib = None if a == 0.0 and b == 0.0 else (a, b)
            if self._vib is None:
                self._vib_phase = 0

    def set_pitch_table(self, interval: int, home_index: int, forward: Sequence[int],
                        backward: Sequence[int] | None = None, *,
                        stroke: tuple[float, float] | None = None) -> PitchCompTable:
        """MCC_SetCompParam + MCC_UpdateCompParam: install a pitch-error table.

        `stroke` (lo, hi) in command-counter pulses is the travel the table must cover
        (MCCL: "the compensation range must cover the whole stroke"); by default the span
        between the axis's MEL and PEL switches. Refused (nothing changes) when a table
        has the wrong length, a home index outside it, a non-zero home value, or does not
        cover the stroke.
        """
        table = PitchCompTable.make(interval, home_index, forward, backward)
        lo, hi = self._stroke(stroke)
        t_lo, t_hi = table.span
        if lo < t_lo or hi > t_hi:
            raise MotionError(f"the table covers [{t_lo}, {t_hi}] pulses, which must cover "
                              f"the stroke [{lo:g}, {hi:g}]")
        with self._lock:
            self._table = table
        return table

    def clear_pitch_table(self) -> None:
        """Disable pitch compensation (MCCL dwInterval <= 0); the offset ramps out."""
        with self._lock:
            self._table = None

    def remove(self) -> None:
        """Detach from the axis; only once the offset is back to 0 (disable everything and
        let it ramp out first), as dropping an offset would jump the motor."""
        with self._lock:
            if self._o != 0.0:
                raise MotionError(f"compensation offset is {self._o:g} pulses; disable the "
                                  "compensation and let it ramp to 0 before remove()")
            self.axis.command_transforms.remove(self)
            self.axis.done_gates.remove(self._gate)

    def _stroke(self, stroke: tuple[float, float] | None) -> tuple[float, float]:
        if stroke is None:
            cfg = self.axis.config
            if cfg.mel is None or cfg.pel is None:
                raise MotionError(f"axis {self.axis.name} has no MEL/PEL switches: give "
                                  "stroke=(lo, hi) in command pulses")
            to_cmd = -self.axis.counters.pulses_from_command(0.0)
            return cfg.mel.position + to_cmd, cfg.pel.position + to_cmd
        if not isinstance(stroke, (tuple, list)) or len(stroke) != 2:
            raise MotionError(f"stroke must be a pair (lo, hi), got {stroke!r}")
        lo = check_finite("stroke[0]", stroke[0])
        hi = check_finite("stroke[1]", stroke[1])
        if not lo < hi:
            raise MotionError(f"stroke must satisfy lo < hi, got {stroke!r}")
        return lo, hi

    # ------------------------------------------------------------------ status
    @property
    def offset(self) -> float:
        """Current offset: pulse output minus planned position (pulses)."""
        return self._o

    @property
    def target(self) -> float:
        """The offset the compensation is heading for (as of the last cycle)."""
        return self._target

    @property
    def settled(self) -> bool:
        """True when the offset has reached its target and no vibration pulse is pending."""
        return self._o == self._target and self._vib_phase == 0

    @property
    def direction(self) -> int:
        """Last planned direction of travel (+1 / -1)."""
        return self._dir

    def _gate(self, axis: Axis) -> int:
        return 0 if self.settled else BACKLASH_COMPENSATING

    # ------------------------------------------------------------------ the transform
    def __call__(self, axis: Axis, cmd: AxisCommand) -> AxisCommand:
        h = cmd.dt
        if h <= 0.0 or axis.state in (AxisState.DISABLED, AxisState.ERROR_STOP):
            return _shift(cmd, self._o, 0.0)  # frozen: an unpowered or faulted axis holds
        v0, a0, j = cmd.v0, cmd.a0, cmd.j
        p1 = cmd.p0 + h * (v0 + h * (a0 * 0.5 + h * j / 6.0))
        v1 = v0 + h * (a0 + h * j * 0.5)
        dp = p1 - cmd.p0  # the cycle's travel gives the direction (a move's last piece
        if abs(dp) > 1e-9:  # can end with a velocity of +-1e-12 either way)
            self._dir = 1 if dp > 0.0 else -1
        t1 = cmd.t0 + h
        m = axis.motion
        moving = m is not None and not m.finished(t1)
        self._vibration(moving, cmd.t0 if m is None else min(m.t_end, t1))
        tgt = -float(self._backlash) if self._dir < 0 else 0.0
        if self._table is not None:
            x1 = p1 - axis.counters.pulses_from_command(0.0)
            tgt += self._table.value(x1, self._dir)
        if self._vib_phase == 2 or self._vib_phase == 1 and cmd.t0 >= self._vib_at:
            tgt -= 1.0  # the reverse pulse is out (phase 2) or going out (phase 1)
        self._target = tgt
        dmax = self._bump_limit(h, v0, a0, j, v1)
        d = tgt - self._o
        if abs(d) <= dmax:
            o_new = tgt
        else:
            d = math.copysign(dmax, d)
            o_new = self._o + d
        out = _shift(cmd, self._o, d)
        self._o = o_new
        axis.counters.out_offset = _round_half_up(o_new)
        if self._vib_phase == 1 and cmd.t0 >= self._vib_at and o_new == tgt:
            self._vib_phase, self._vib_at = 2, t1 + self._vib[1]  # type: ignore[index]
        return out

    def _vibration(self, moving: bool, t_done: float) -> None:
        """Advance the reverse/forward pulse pair; `t_done`: when the planned move ends."""
        if moving:
            self._vib_phase = 0  # a new move cancels a pending pulse pair
        elif self._was_moving and self._vib is not None:
            self._vib_phase, self._vib_at = 1, t_done + self._vib[0]
        elif self._vib_phase == 2 and t_done >= self._vib_at:
            self._vib_phase = 0  # the forward pulse: the target is back without the -1
        self._was_moving = moving

    def _bump_limit(self, h: float, v0: float, a0: float, j: float, v1: float) -> float:
        """Largest |delta| the offset may move in this cycle.

        The offset moves by a rest-to-rest cubic bump o(s) = o + d*(3u^2 - 2u^3), u = s/h:
        its velocity peaks at 1.5|d|/h, its acceleration at 6|d|/h^2, and it is at rest at
        both cycle ends, so no velocity carries into a cycle whose planned piece might use
        the whole budget. By the triangle inequality the output stays within the limits if
            1.5|d|/h <= V - max|v_plan|   and   6|d|/h^2 <= A - max|a_plan|  on [t0, t1],
        and the offset within its own limits if 1.5|d|/h <= comp_vel, 6|d|/h^2 <= comp_accel.
        The planned piece is a cubic: |a| peaks at an end, |v| at an end or where a = 0.
        """
        amax = max(abs(a0), abs(a0 + j * h))
        vmax = max(abs(v0), abs(v1))
        if j != 0.0:
            s = -a0 / j
            if 0.0 < s < h:
                vmax = max(vmax, abs(v0 + s * (a0 + s * j * 0.5)))
        vb = min(self.max_vel - vmax, self.comp_vel)
        ab = min(self.max_accel - amax, self.comp_accel)
        if vb <= 0.0 or ab <= 0.0:
            return 0.0
        return min(vb * h / 1.5, ab * h * h / 6.0) * (1.0 - 1e-12)


def _shift(cmd: AxisCommand, o: float, d: float) -> AxisCommand:
    """cmd + o + d*(3u^2 - 2u^3): coefficients of the bump in the AxisCommand basis."""
    h = cmd.dt
    if d == 0.0:
        return AxisCommand(cmd.t0, h, cmd.p0 + o, cmd.v0, cmd.a0, cmd.j)
    return AxisCommand(cmd.t0, h, cmd.p0 + o, cmd.v0, cmd.a0 + 6.0 * d / (h * h),
                       cmd.j - 12.0 * d / (h * h * h))
