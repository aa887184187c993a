"""Switches on the machine: a fixed span with hysteresis (+EL, -EL, ORG, SD/LTC, user
switches) and the encoder index (EZ), a narrow window once per motor revolution.

Both answer one question for the event finder: moving in direction d from load position y,
at which level does the switch toggle next? Thresholds follow one convention: moving up a
level x is reached when y >= x, moving down when y < x, so a span [lo, hi) is active at lo
and inactive at hi.
"""

from __future__ import annotations

import math


class Switch:
    """Active while lo <= y < hi; once active, releases only below lo - h or at/above hi + h."""

    __slots__ = ("lo", "hi", "hyst", "active")

    def __init__(self, position: float, width: float, hysteresis: float, y: float = 0.0) -> None:
        self.lo = min(position, position + width)
        self.hi = max(position, position + width)
        self.hyst = hysteresis
        self.active = False
        self.reset(y)

    def reset(self, y: float) -> None:
        """Set the state from the position alone (at start, or after the switch moved)."""
        self.active = self.lo <= y < self.hi

    def next_threshold(self, y: float, d: int) -> float | None:
        if self.active:
            return self.hi + self.hyst if d > 0 else self.lo - self.hyst
        if d > 0:
            return self.lo if y < self.lo else None
        return self.hi if y >= self.hi else None


class IndexSwitch:
    """Active while (y mod period) lies in [0, width): the encoder's EZ window."""

    __slots__ = ("period", "width", "active")

    def __init__(self, period: float, width: float, y: float = 0.0) -> None:
        self.period = period
        self.width = width
        self.active = False
        self.reset(y)

    def reset(self, y: float) -> None:
        k = math.floor(y / self.period)
        self.active = y - k * self.period < self.width

    def next_threshold(self, y: float, d: int) -> float | None:
        p = self.period
        k = math.floor(y / p)
        base = k * p
        if d > 0:
            if self.active:
                return base + self.width
            return base + p
        if self.active:
            return base
        return base + self.width if y >= base + self.width else base - p + self.width
