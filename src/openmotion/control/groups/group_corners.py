"""Group look-ahead settings: corner velocity of unblended corners, minimum cruise ratio.

Both feed `pathexec.Limits` (and through it `path.plan_speeds`) whenever a chain is
planned or re-planned: a new chain, a streaming extension, an override, a continue. See
docs/groups.md, "Corners and short segments".
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import MotionError, check_nonnegative


class LookaheadSettings:
    """Mixin of `GroupEngine`: the two settings and the Limits fields they give."""

    axes: tuple[Any, ...]
    _corner_velocity: float = 0.0
    _cruise_ratio: float = 0.0

    @property
    def corner_velocity(self) -> float:
        """Speed through a 90 degree corner that is not blended (0: exact stop)."""
        return self._corner_velocity

    @property
    def min_cruise_ratio(self) -> float:
        """Fraction of a short move the look-ahead keeps at cruise (0: time-optimal)."""
        return self._cruise_ratio

    def set_corner_velocity(self, velocity: float) -> None:
        """Cross corners that are not blended at speed instead of stopping exactly.

        `velocity` (pps, or user units/s) is the square corner velocity of junction
        deviation (Klipper): a 90 degree corner is taken at exactly `velocity`, others
        faster or slower by the deviation rule, and never so fast that any axis's velocity
        steps by more than `velocity` at the corner (at a 90 degree corner each axis steps
        by exactly that much). 0, the default, keeps exact stops. Applies from the next
        plan (new chain, extension, override, continue).
        """
        self._corner_velocity = check_nonnegative("velocity", velocity)

    def set_min_cruise_ratio(self, ratio: float) -> None:
        """Minimum cruise ratio of the look-ahead (Klipper's minimum_cruise_ratio).

        0 <= ratio < 1. A short move between two corners of equal speed cruises for at
        least `ratio` of its length instead of accelerating and braking back to back, and
        zig-zags of short moves get fewer acceleration reversals, at the price of a longer
        run. 0, the default, keeps the time-optimal plan. Applies from the next plan.
        """
        r = check_nonnegative("ratio", ratio)
        if r >= 1.0:
            raise MotionError(f"ratio must be in [0, 1), got {ratio!r}")
        self._cruise_ratio = r

    def _corner_limits(self) -> dict[str, Any]:
        """The Limits fields of these settings (in the group's logical units)."""
        v = self._corner_velocity
        return {"square_corner_velocity": v,
                "axis_vjump": np.full(len(self.axes), v) if v > 0.0 else None,
                "min_cruise_ratio": self._cruise_ratio}
