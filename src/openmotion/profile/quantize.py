"""Quantization: the integer command counts a profile produces at a sample period.

This is the one place where planned (float) positions become integer pulse counts. Count k
is the nearest integer to the position at t_k = k * period; the sequence always includes
t = duration rounded up to a whole period, where the profile holds its exact end position,
so a move to an integer target ends exactly on that count.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import MotionError
from ..limits import check_quantity
from .segments import Profile


def sample_times(profile: Profile, period: float) -> NDArray[np.float64]:
    """Times 0, period, ... up to the first multiple of period at or after the end."""
    if not isinstance(profile, Profile):
        raise MotionError(f"profile must be a Profile, got {type(profile).__name__}")
    period = check_quantity("period", period, "period")
    n = max(0, math.ceil(profile.duration / period - 1e-12))
    if n > 50_000_000:
        raise MotionError(
            f"period too small for this profile: {n} samples exceed the 50,000,000 limit"
        )
    return np.arange(n + 1, dtype=np.float64) * period


def quantize(profile: Profile, period: float) -> NDArray[np.int64]:
    """Integer command counts at every sample period; the last equals round(end position)."""
    t = sample_times(profile, period)
    p = profile.sample(t).p
    counts = np.rint(p).astype(np.int64)
    counts[-1] = round(profile.end.p)
    return counts


def check_quantized(counts: NDArray[np.int64], profile: Profile, period: float) -> float:
    """Verify a count sequence against its profile; return the largest |count - position|.

    Raises MotionError if any count is more than half a pulse from the exact position, so a
    caller can re-check any stored or transmitted sequence (the stepcompress idea).
    """
    t = sample_times(profile, period)
    if not isinstance(counts, np.ndarray):
        raise MotionError(f"counts must be a numpy array, got {type(counts).__name__}")
    if counts.shape != t.shape:
        raise MotionError(f"counts must have {t.size} entries for this profile, got {counts.size}")
    err = np.abs(counts - profile.sample(t).p)
    worst = float(err.max()) if err.size else 0.0
    if worst > 0.5 + 1e-9 * max(1.0, abs(profile.end.p)):
        k = int(err.argmax())
        raise MotionError(f"count {k} is {worst:.6g} pulses from the profile (limit 0.5)")
    return worst
