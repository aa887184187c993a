"""Arc geometry for G2/G3: centre from I/J/K or R, sweep, radius checks, bounding box.

All in machine coordinates of the two plane axes (a, b), with CCW turning from a to b.
Tolerances follow LinuxCNC (interp_arc.cc constants), in the program's length unit and
converted to machine units by the caller:
- centre form: the end radius may differ from the start radius by up to CENTRE_TOL
  (0.0028284 in / 0.028284 mm, = 2*sqrt(2) * 0.001 in / 0.01 mm), or by more as long as
  it is within 0.1 % of the larger radius, but never by more than 100 * CENTRE_TOL; beyond
  that the arc is inconsistent.
- radius form: |R| may be short of half the chord by at most RADIUS_TOL (0.00005 in /
  0.00127 mm); it is then stretched to half the chord. Start == end is an error.
- a start or end radius below RADIUS_TOL is a zero-radius arc (error).
"""

from __future__ import annotations

import math

TWO_PI = 2.0 * math.pi
#: Centre-form end radius tolerance per program unit ("mm" / "inch").
CENTRE_TOL = {"mm": 2 * 0.01 * math.sqrt(2.0), "inch": 2 * 0.001 * math.sqrt(2.0)}
#: Relative end-radius tolerance (LinuxCNC SPIRAL_RELATIVE_TOLERANCE).
CENTRE_REL_TOL = 0.001
#: Radius-form and zero-radius tolerance per program unit.
RADIUS_TOL = {"mm": 0.00005 * 25.4, "inch": 0.00005}
#: Start and end closer than this (relative to the radius) make a full circle.
FULL_CIRCLE_REL = 1e-9


class ArcGeometryError(Exception):
    """Inconsistent arc data; `word` names the G-code word to blame."""

    def __init__(self, message: str, word: str) -> None:
        super().__init__(message)
        self.message = message
        self.word = word


def centre_from_radius(sa: float, sb: float, ea: float, eb: float, r: float, ccw: bool,
                       radius_tol: float) -> tuple[float, float]:
    """Centre of the R-form arc from (sa, sb) to (ea, eb); R < 0 asks for the long way.

    The centre lies on the chord's perpendicular bisector at h = sqrt(R^2 - d^2) from the
    chord midpoint (d = half chord), to the left of start->end for a short CCW arc and to
    the right for a short CW arc; a negative R swaps the side (arc > 180 deg).
    """
    da, db = ea - sa, eb - sb
    chord = math.hypot(da, db)
    if chord <= radius_tol:
        raise ArcGeometryError("R-form arc needs an end point different from the start "
                               "(use I/J/K for a full circle)", "R")
    half = 0.5 * chord
    rr = abs(r)
    if rr < half:
        if half - rr > radius_tol:
            raise ArcGeometryError(f"arc radius {rr:.6g} is too small to reach the end point "
                                   f"(half chord {half:.6g})", "R")
        rr = half
    h = math.sqrt(max(rr * rr - half * half, 0.0))
    na, nb = -db / chord, da / chord  # left normal of the chord
    side = 1.0 if ccw else -1.0
    if r < 0:
        side = -side
    return sa + 0.5 * da + side * h * na, sb + 0.5 * db + side * h * nb


def check_radii(sa: float, sb: float, ea: float, eb: float, ca: float, cb: float,
                centre_tol: float, radius_tol: float) -> tuple[float, float]:
    """Start and end radius of a centre-form arc; error when they disagree (LinuxCNC rule)."""
    r1 = math.hypot(sa - ca, sb - cb)
    r2 = math.hypot(ea - ca, eb - cb)
    if r1 < radius_tol or r2 < radius_tol:
        raise ArcGeometryError(f"zero-radius arc (start radius {r1:.6g}, end radius "
                               f"{r2:.6g})", "I/J/K")
    err = abs(r1 - r2)
    rel = err / max(r1, r2)
    if err > 100.0 * centre_tol or (rel > CENTRE_REL_TOL and err > centre_tol):
        raise ArcGeometryError(
            f"radius to end of arc ({r2:.6g}) differs from radius to start ({r1:.6g}) by "
            f"{err:.6g} ({rel:.3%}); allowed: up to {centre_tol:.6g}, or up to "
            f"{CENTRE_REL_TOL:.1%} of the radius but at most {100 * centre_tol:.6g}",
            "I/J/K")
    return r1, r2


def sweep_angle(sa: float, sb: float, ea: float, eb: float, ca: float, cb: float,
                ccw: bool, turns: int) -> float:
    """Angle travelled (rad, > 0): start to end in the given sense, plus whole `turns`."""
    a0 = math.atan2(sb - cb, sa - ca)
    a1 = math.atan2(eb - cb, ea - ca)
    r = math.hypot(sa - ca, sb - cb)
    if math.hypot(ea - sa, eb - sb) <= FULL_CIRCLE_REL * r:
        sweep = TWO_PI
    else:
        sweep = (a1 - a0) % TWO_PI if ccw else (a0 - a1) % TWO_PI
        if sweep == 0.0:
            sweep = TWO_PI
    return sweep + TWO_PI * turns


def arc_extent(ca: float, cb: float, r_max: float, a0: float, sweep: float, ccw: bool,
               sa: float, sb: float, ea: float, eb: float) -> tuple[float, float, float, float]:
    """Bounding box (amin, amax, bmin, bmax) of the arc: end points plus every axis
    extreme (angles 0, 90, 180, 270 deg) the sweep passes, at the larger radius."""
    amin, amax = min(sa, ea), max(sa, ea)
    bmin, bmax = min(sb, eb), max(sb, eb)
    if sweep >= TWO_PI:
        return ca - r_max, ca + r_max, cb - r_max, cb + r_max
    sign = 1.0 if ccw else -1.0
    for k in range(4):
        target = k * 0.5 * math.pi
        # angle from the start to `target` in the direction of travel
        delta = ((target - a0) * sign) % TWO_PI
        if delta <= sweep:
            if k == 0:
                amax = max(amax, ca + r_max)
            elif k == 1:
                bmax = max(bmax, cb + r_max)
            elif k == 2:
                amin = min(amin, ca - r_max)
            else:
                bmin = min(bmin, cb - r_max)
    return amin, amax, bmin, bmax
