"""The pulse generator of one axis: the commanded cubic and the pulses it emits.

The command for the coming cycle is a cubic over [tc, te]; before tc it holds p0 and after
te it holds the end position (a pulse generator with no new command stops emitting). Over
a stretch of time the command is cut into monotone `Stretch`es, each with the exact pulse
count at its ends, which the plants turn into motor motion.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from .cubic import Cubic, quadratic_roots, velocity_zeros
from .pieces import count_after

if TYPE_CHECKING:
    from .pulserecord import PulseRecord


class Stretch(NamedTuple):
    """Monotone command on [t0, t1] (cubic in local time t - tc). A jump has t0 == t1
    and cubic None; a hold has direction 0."""

    t0: float
    t1: float
    cubic: Cubic | None
    tc: float
    direction: int
    c0: int
    c1: int


class PulseGenerator:
    """Command cubic + emitted pulse count (signed, never wrapped)."""

    __slots__ = ("cubic", "tc", "te", "count", "half", "record")

    def __init__(self, p: float = 0.0, t: float = 0.0, half: float = 0.5) -> None:
        self.cubic = Cubic(p)
        self.tc = t
        self.te = t
        self.half = half  # 0.5: half-pulse rule (the default); 0: pulse at each integer
        self.count = count_after(p, 0, 1 if p > 0 else -1, half)
        self.record: PulseRecord | None = None  # every stretch emitted, when recording

    def set(self, cubic: Cubic, tc: float, te: float) -> None:
        self.cubic, self.tc, self.te = cubic, tc, te

    def pos(self, t: float) -> float:
        """Command position (float pulses) at absolute time t."""
        s = min(max(t - self.tc, 0.0), self.te - self.tc)
        return self.cubic.pos(s)

    def vel(self, t: float) -> float:
        if t < self.tc or t >= self.te:
            return 0.0
        return self.cubic.vel(t - self.tc)

    def acc(self, t: float) -> float:
        if t < self.tc or t >= self.te:
            return 0.0
        return self.cubic.acc(t - self.tc)

    def stretches(self, ta: float, tb: float, cuts: tuple[float, ...] = ()) -> list[Stretch]:
        """Monotone stretches covering [ta, tb]; advances the pulse count to tb.

        `cuts` are extra local-time split points (e.g. where a stepper's speed crosses its
        pull-out limit) so that a plant can treat each stretch uniformly.
        """
        out: list[Stretch] = []
        c = self.cubic
        tc, te = self.tc, self.te
        u = self.pos(ta)
        self._jump_to(u, ta, out)
        lo, hi = max(ta, tc), min(tb, te)
        if hi > lo:
            s_lo, s_hi = lo - tc, hi - tc
            pts = [s_lo, *velocity_zeros(c, s_lo, s_hi)]
            pts += [s for s in cuts if s_lo < s < s_hi]
            pts.sort()
            pts.append(s_hi)
            for k in range(len(pts) - 1):
                s0, s1 = pts[k], pts[k + 1]
                if s1 <= s0:
                    continue
                p0, p1 = c.pos(s0), c.pos(s1)
                d = 1 if p1 > p0 else (-1 if p1 < p0 else 0)
                c0 = self.count
                c1 = count_after(p1, c0, d, self.half)
                self.count = c1
                out.append(Stretch(tc + s0, tc + s1, c, tc, d, c0, c1))
        # holds before tc / after te produce no pulses; the caller sees gaps as holds
        if self.record is not None:
            for st in out:
                self.record.add(st, self.half)
        return out

    def _jump_to(self, u: float, t: float, out: list[Stretch]) -> None:
        c0 = self.count
        d = 1 if u > c0 else -1
        c1 = count_after(u, c0, d, self.half)
        if c1 != c0:
            self.count = c1
            out.append(Stretch(t, t, None, t, 1 if c1 > c0 else -1, c0, c1))


def limit_cuts(c: Cubic, vmax: float, amax: float, s_lo: float, s_hi: float) -> tuple[float, ...]:
    """Local times in (s_lo, s_hi) where |v| crosses vmax or |a| crosses amax (0 = no limit)."""
    cuts: list[float] = []
    if vmax > 0.0:
        cuts += quadratic_roots(c.j / 2.0, c.a0, c.v0 - vmax, s_lo, s_hi)
        cuts += quadratic_roots(c.j / 2.0, c.a0, c.v0 + vmax, s_lo, s_hi)
    if amax > 0.0 and c.j != 0.0:
        for a in (amax, -amax):
            s = (a - c.a0) / c.j
            if s_lo < s < s_hi:
                cuts.append(s)
    return tuple(cuts)
