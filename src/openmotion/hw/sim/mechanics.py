"""From motor to load: backlash, then lead-screw pitch error.

Backlash (b pulses): the load position z stays within [m, m + b] of the motor position m.
Moving up, the motor pushes the load (z = max(z_start, m)); moving down it pulls it from
b above (z = min(z_start, m + b)). The sim starts with z = m (as after a positive move), so
the first reversal costs b pulses of motor travel before the load moves.

Pitch error table (DriveConfig.pitch_error = (e0, e1, ..., e_{n-1})): e_k is the lead-screw
error, in command pulses, at nominal load position z_k = k * S, where S is one screw
revolution in command pulses (pulses_per_rev * gear_ratio). Between points the error is
interpolated linearly; below z_0 it is e0, beyond z_{n-1} it is e_{n-1}. The position that
encoder and switches see is y = z + e(z). Consecutive entries must differ by less than S so
that y stays strictly increasing in z.
"""

from __future__ import annotations

import bisect

from openmotion.errors import MotionError, check_finite


class PitchTable:
    """y = z + e(z), piecewise linear, with its inverse."""

    __slots__ = ("z", "y", "e", "spacing")

    def __init__(self, errors: tuple[float, ...], spacing: float) -> None:
        errs = [check_finite(f"pitch_error[{k}]", e) for k, e in enumerate(errors)]
        for k in range(len(errs) - 1):
            if errs[k + 1] - errs[k] <= -spacing:
                raise MotionError(
                    f"pitch_error[{k + 1}] - pitch_error[{k}] must be > -{spacing:g} "
                    "(one screw revolution) so the load position stays monotonic")
        self.spacing = spacing
        self.e = errs
        self.z = [k * spacing for k in range(len(errs))]
        self.y = [z + e for z, e in zip(self.z, errs, strict=True)]

    def forward(self, z: float) -> float:
        e, zs = self.e, self.z
        if not e:
            return z
        if z <= zs[0]:
            return z + e[0]
        if z >= zs[-1]:
            return z + e[-1]
        k = bisect.bisect_right(zs, z) - 1
        f = (z - zs[k]) / self.spacing
        return z + e[k] + f * (e[k + 1] - e[k])

    def inverse(self, y: float) -> float:
        e, ys = self.e, self.y
        if not e:
            return y
        if y <= ys[0]:
            return y - e[0]
        if y >= ys[-1]:
            return y - e[-1]
        k = bisect.bisect_right(ys, y) - 1
        return self.z[k] + (y - ys[k]) * self.spacing / (ys[k + 1] - ys[k])


class Transmission:
    """Backlash + pitch error of one axis; holds the load position z."""

    __slots__ = ("backlash", "pitch", "z")

    def __init__(self, backlash: float, pitch: PitchTable, m: float = 0.0) -> None:
        self.backlash = backlash
        self.pitch = pitch
        self.z = m

    def z_after(self, z_start: float, m: float, direction: int) -> float:
        if direction > 0:
            return m if m > z_start else z_start
        if direction < 0:
            mb = m + self.backlash
            return mb if mb < z_start else z_start
        return z_start

    def y_of(self, z: float) -> float:
        return self.pitch.forward(z) if self.pitch.e else z

    def motor_level(self, y_level: float, direction: int) -> float:
        """Motor level whose crossing (in `direction`) makes y cross `y_level`."""
        z = self.pitch.inverse(y_level) if self.pitch.e else y_level
        return z if direction > 0 else z - self.backlash
