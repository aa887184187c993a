"""Path geometry for coordinated motion: lines, arcs, helices, corner blends, look-ahead.

Pure math, no clocks or state. Elements map path position s (arc length) to points of
N >= 2 axes; the look-ahead gives each element's entry/cruise/exit speed so an executor can
build its profile.
"""

from .arcs import ARC_TOL, Arc, Arc3D
from .blend import BLEND_DIST_FRACTION, Blend, blend_corner, centripetal_speed, corner_speed
from .contour import contour_error
from .extent import element_extent
from .geometry import Direction, Line, PathElement
from .lookahead import (
    ElementSpeeds,
    acceleration_reversals,
    plan_speeds,
    speed_caps,
    tangential_accels,
)
from .polyline import PolylinePlan, plan_polyline

__all__ = [
    "ARC_TOL",
    "BLEND_DIST_FRACTION",
    "Arc",
    "Arc3D",
    "Blend",
    "Direction",
    "ElementSpeeds",
    "Line",
    "PathElement",
    "PolylinePlan",
    "acceleration_reversals",
    "blend_corner",
    "centripetal_speed",
    "contour_error",
    "corner_speed",
    "element_extent",
    "plan_polyline",
    "plan_speeds",
    "speed_caps",
    "tangential_accels",
]
