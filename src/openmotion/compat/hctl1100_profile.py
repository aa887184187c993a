"""The HCTL-1100's internal command generators, in sample units (counts, samples).

- Trapezoidal profile: the chip's rule (appendix 1) is the minimum-time trapezoid under the
  acceleration and maximum velocity; if Vmax is not reached by the halfway point the profile
  is a triangle with the same acceleration. That is exactly the core PCL T-curve with start
  velocity 0 and the peak lowered on short moves, so the plan comes from
  `openmotion.profile.pcl.trapezoid` in time units of samples (no planning logic here). The
  chip emits one integer command position per sample; the last one is the final position.
- Integral velocity: each sample the command velocity steps toward the target by at most
  the acceleration and the command position integrates it with a fractional accumulator.
"""

from __future__ import annotations

import math

import numpy as np

from openmotion.profile.pcl import trapezoid


def trapezoid_commands(start: int, distance: int, accel: float, vmax: float) -> np.ndarray:
    """Command positions (unwrapped ints) for samples 1..n of a move; the last is the end.

    `accel` in counts/sample^2 and `vmax` in counts/sample, both > 0 unless distance is 0.
    """
    if distance == 0:
        return np.array([start], dtype=np.int64)
    tacc = vmax / accel
    prof = trapezoid(float(distance), 0.0, float(vmax), tacc, tacc, start=float(start))
    n = max(1, math.ceil(prof.duration - 1e-9))
    k = np.arange(1, n + 1, dtype=float)
    k[-1] = min(k[-1], prof.duration)
    pos = np.rint(prof.sample(k).p).astype(np.int64)
    pos[-1] = start + distance
    return pos


class IntegralVelocity:
    """Velocity profiler of integral velocity mode (counts/sample, counts/sample^2)."""

    __slots__ = ("velocity", "position", "frac")

    def __init__(self, position: int) -> None:
        self.velocity = 0.0
        self.position = position  # integer command position (unwrapped)
        self.frac = 0.0           # fractional counts carried between samples

    def step(self, target: float, accel: float) -> int:
        """Advance one sample toward `target` velocity; returns the new command position."""
        v = self.velocity
        if v < target:
            v = min(target, v + accel)
        elif v > target:
            v = max(target, v - accel)
        self.velocity = v
        f = self.frac + v
        whole = math.floor(f)
        self.frac = f - whole
        self.position += whole
        return self.position
