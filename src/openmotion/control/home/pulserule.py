"""The pulse rule: which integer count a pulse generator shows for a command position.

The hardware boundary hands each axis a float command (`AxisCommand`); the generator emits
pulse k when the command reaches k - 1/2 going up (k + 1/2 going down), Klipper's
step_dist/2 rule, so its count is the command rounded to the nearest integer and never more
than half a pulse from it. A back end that counts otherwise says so with a `half_pulse`
attribute set to False (the simulator's `set_half_pulse(False)` opt-out: pulse k at k
itself, so the count lags the command by up to one pulse).

The control layer rebuilds counts from its planned positions when it needs them at an
instant between cycles (a latch at an edge, a homing mark): `pulse_count` does it.
"""

from __future__ import annotations

import math

#: An edge fired by a pulse lands on that pulse's threshold of the emitted command; the
#: planned position (the history) may differ from it by the Hermite blend of a cycle that
#: straddles a segment boundary (motion.py), far below this.
TIE_EPS = 0.05


def half_pulse(hardware: object) -> bool:
    """Whether `hardware` counts by the half-pulse rule (True unless it says otherwise)."""
    return bool(getattr(hardware, "half_pulse", True))


def pulse_count(p: float, v: float, half: bool = True) -> int:
    """Pulse count of a command at p moving with velocity v (v = 0: as if moving up).

    Half-pulse rule: p rounded to nearest; within TIE_EPS of a threshold k + 1/2 the pulse
    that an edge there fired has left, so the count is k + 1 moving up, k moving down.
    Floor rule: the last integer reached (floor up, ceil down; within TIE_EPS of an
    integer, that integer).
    """
    if half:
        k = math.floor(p)
        if abs(p - (k + 0.5)) <= TIE_EPS:
            return k + 1 if v >= 0.0 else k
        return round(p)
    r = round(p)
    if abs(p - r) <= TIE_EPS:
        return int(r)
    return math.floor(p) if v >= 0.0 else math.ceil(p)
