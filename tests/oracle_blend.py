"""Slow oracle: the line-line corner blend as blend.blend_corner computed it before the
fast constructors (validated Line/Arc3D.from_frame, np.linalg.norm); equivalence tests
compare the fast one with it bit for bit."""

from __future__ import annotations

import math

import numpy as np

from openmotion.path import Arc3D, Line


def blend_lines(first: Line, second: Line, t: float, frac: float = 0.5):
    u1, u2 = first.end_tangent, second.start_tangent
    cos_t = float(np.linalg.norm(u1 - u2)) / 2.0
    sin_t = float(np.linalg.norm(u1 + u2)) / 2.0
    turn = 2.0 * math.atan2(cos_t, sin_t)
    corner = first.end
    d_tol = t * (1.0 + sin_t) / cos_t
    d = min(frac * first.length, frac * second.length, d_tol)
    radius = d * sin_t / cos_t
    normal = (u2 - u1) / np.linalg.norm(u2 - u1)
    centre = corner + normal * (d / cos_t)
    a_start = corner - u1 * d
    a_end = corner + u2 * d
    e1 = -(u1 * cos_t + normal)
    e1 = e1 - (e1 @ u1) * u1
    e1 = e1 / np.linalg.norm(e1)
    e2 = u1 - (u1 @ e1) * e1
    e2 = e2 / np.linalg.norm(e2)
    arc = Arc3D.from_frame(centre, e1, e2, radius, turn, start=a_start, end=a_end)
    dev = d * (1.0 - sin_t) / cos_t
    return Line(first.start, a_start), arc, Line(a_end, second.end), dev


def blend_run(first, lines, tol: float, accel=None, feed=None):
    """Slow oracle of path/blend.py `_line_run`: blend_corner corner after corner (each
    corner's first line the previous corner's trimmed second), a blend kept only where
    groupstream._blend_pays says it pays (no corner velocity) when accel and feed are
    given; what the group's `_blend_new` did for every corner before the compiled run."""
    from openmotion.control.groups.groupstream import _blend_pays
    from openmotion.path import blend_corner

    out = []
    prev = first
    for k, el in enumerate(lines):
        b = blend_corner(prev, el, tol)
        if b is not None and accel is not None:
            trims = (float(prev.length - b.first.length), float(el.length - b.second.length))
            if not _blend_pays(b, accel[k], feed[k], 0.0, trims):
                b = None
        out.append(None if b is None else (b.first, b.arc, b.second))
        prev = el if b is None else b.second
    return out
