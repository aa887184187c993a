"""Per-axis extent (smallest and largest coordinate) of a path element.

Used to refuse a queued path command that would take an axis past a soft limit when it is
accepted, before any motion: an arc can bulge past a limit although both its end points are
inside. Lines: their end points. Arcs and helices: besides the end points, each in-plane
coordinate c + R*(cos(phi)*e1 + sin(phi)*e2) = c + R*A*cos(phi - gamma) is extreme at
phi = gamma + k*pi; those angles inside the sweep are evaluated (exact up to the arc's
end-point correction of at most ARC_TOL*R, spread along it). The in-plane coordinates repeat
every turn and the other axes move linearly (extreme at the end points), so only the angles
of the first turn are needed: the work is bounded whatever the number of turns.
"""

from __future__ import annotations

import math

import numpy as np

from .geometry import Array, PathElement


def element_extent(el: PathElement) -> tuple[Array, Array]:
    """(lowest, highest) coordinate of every axis along `el`."""
    if el.max_curvature == 0.0 or el.length == 0.0:
        a, b = np.asarray(el.start, dtype=float), np.asarray(el.end, dtype=float)
        return np.minimum(a, b), np.maximum(a, b)
    basis = getattr(el, "basis", None)
    sweep = getattr(el, "sweep", None)
    if basis is None or sweep is None:  # another curve: dense samples
        pts = el.point(np.linspace(0.0, el.length, 4097))
        return pts.min(axis=0), pts.max(axis=0)
    e1, e2 = basis() if callable(basis) else basis
    gamma = np.arctan2(e2, e1)
    phis = [0.0, float(sweep)]
    last = min(float(sweep), 2.0 * math.pi)  # one turn holds every in-plane extreme
    for g, amp in zip(gamma, np.hypot(e1, e2), strict=True):
        if amp == 0.0:
            continue
        k0 = math.ceil(-g / math.pi)
        k = k0
        while g + k * math.pi <= last:
            phis.append(float(g + k * math.pi))
            k += 1
    s = np.clip(np.array(phis) / float(sweep) * el.length, 0.0, el.length)
    pts = el.point(s)
    return pts.min(axis=0), pts.max(axis=0)
