"""Stepper drives: the motor follows the pulse train, or stalls and loses the pulses.

ideal_stepper: motor position = pulses emitted (minus injected step losses).
stepper: while |commanded speed| > pullout_speed or |commanded accel| > pullout_accel (a
limit of 0 is "no limit"), and for an instantaneous command jump, the motor stalls: the
pulses emitted in that time are lost and counted. An alarm (scenario) also stalls it.
"""

from __future__ import annotations

from .pieces import JumpPiece, Piece, StepPiece
from .pulses import PulseGenerator, limit_cuts


class StepperPlant:
    """Motor of a stepper axis. m = pulse count - lost."""

    __slots__ = ("ideal", "vmax", "amax", "lost", "enabled")

    def __init__(self, ideal: bool, pullout_speed: float = 0.0, pullout_accel: float = 0.0
                 ) -> None:
        self.ideal = ideal
        self.vmax = 0.0 if ideal else pullout_speed
        self.amax = 0.0 if ideal else pullout_accel
        self.lost = 0
        self.enabled = True

    def motor(self, gen: PulseGenerator) -> float:
        return gen.count - self.lost

    def pieces(self, gen: PulseGenerator, ta: float, tb: float) -> list[Piece]:
        """Moving pieces of the motor over [ta, tb]; advances the pulse count and losses."""
        cuts: tuple[float, ...] = ()
        if self.vmax > 0.0 or self.amax > 0.0:
            cuts = limit_cuts(gen.cubic, self.vmax, self.amax, ta - gen.tc, tb - gen.tc)
        out: list[Piece] = []
        for st in gen.stretches(ta, tb, cuts):
            if st.direction == 0:
                continue
            if st.cubic is None:  # the command jumped: infinitely fast
                if self.enabled and self.ideal:
                    out.append(JumpPiece(st.t0, st.c0 - self.lost, st.c1 - self.lost))
                else:
                    self.lost += st.c1 - st.c0
                continue
            if not self.enabled or self._over_limit(st.cubic, 0.5 * (st.t0 + st.t1) - st.tc):
                self.lost += st.c1 - st.c0
                continue
            if st.c1 != st.c0:
                out.append(StepPiece(st.cubic, st.tc, st.t0, st.t1, st.c0, st.c1, self.lost,
                                     st.direction, gen.half))
        return out

    def _over_limit(self, c, s: float) -> bool:
        if self.vmax > 0.0 and abs(c.vel(s)) > self.vmax:
            return True
        return self.amax > 0.0 and abs(c.acc(s)) > self.amax
