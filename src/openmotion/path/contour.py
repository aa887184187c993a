"""Contour error: the distance of recorded points to the programmed path elements.

Checks recorded runs against the programmed path (issue 4, accuracy): lines and planar
circular arcs in closed form, other curves by a sampled search refined by Gauss-Newton.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .geometry import PathElement


def contour_error(points: np.ndarray, elements: Sequence[PathElement],
                  step: float = 50.0) -> np.ndarray:
    """Distance of every recorded point (rows of `points`) to the nearest element.

    Lines and planar circular arcs are measured exactly (closed form). Other elements: the
    nearest of points every `step` of arc length, a local search (33 points over one step)
    and three Gauss-Newton rounds find the foot point, and the distance is taken to the
    tangent line there (the foot's residual enters as kappa*ds**2/2). Checks recorded runs
    against the programmed path (issue 4, accuracy; control.groups.accuracy for pulse counts).
    """
    pts = np.asarray(points, dtype=float)
    best = np.full(len(pts), np.inf)
    for el in elements:
        if el.max_curvature == 0.0:
            a, b = np.asarray(el.start), np.asarray(el.end)
            ab = b - a
            den = float(ab @ ab)
            u = np.zeros(len(pts)) if den == 0.0 else np.clip(((pts - a) @ ab) / den, 0.0, 1.0)
            d = np.linalg.norm(pts - (a + u[:, None] * ab), axis=1)
        else:
            d = _circle_distance(pts, el)
            if d is None:
                d = _curve_distance(pts, el, step)
        best = np.minimum(best, d)
    return best


def _circle_distance(pts: np.ndarray, el: PathElement) -> np.ndarray | None:
    """Exact distance to a planar circular arc (no helix), else None: the foot point is the
    radial projection when its angle lies on the arc, otherwise the nearer end."""
    try:
        c, r, sweep = np.asarray(el.circle_centre), float(el.radius), float(el.sweep)
        e1, e2 = (np.asarray(e) for e in el.basis)
    except AttributeError:
        return None
    last = c + r * (math.cos(sweep) * e1 + math.sin(sweep) * e2)
    if np.linalg.norm(np.asarray(el.end) - last) > 1e-9 * max(1.0, r):
        return None  # a helix, or an end corrected onto the circle: the general search
    d = pts - c
    u, w = d @ e1, d @ e2
    off = d - u[:, None] * e1 - w[:, None] * e2  # out of the plane (explicit: no cancellation)
    on = np.sqrt((np.hypot(u, w) - r) ** 2 + (off * off).sum(axis=1))
    phi = np.mod(np.arctan2(w, u), 2.0 * math.pi)
    if sweep >= 2.0 * math.pi - 1e-12:
        return on
    ends = np.minimum(np.linalg.norm(pts - np.asarray(el.start), axis=1),
                      np.linalg.norm(pts - np.asarray(el.end), axis=1))
    return np.where(phi <= sweep, on, ends)


def _curve_distance(pts: np.ndarray, el: PathElement, step: float) -> np.ndarray:
    s_ref = np.linspace(0.0, el.length, max(2, int(el.length / step) + 2))
    ref = el.point(s_ref)
    s_best = np.empty(len(pts))
    for lo in range(0, len(pts), 512):  # blocks: bounded memory
        diff = pts[lo:lo + 512, None, :] - ref[None]
        s_best[lo:lo + 512] = s_ref[np.argmin((diff * diff).sum(axis=2), axis=1)]
    w = float(s_ref[1] - s_ref[0])
    offs = np.linspace(-1.0, 1.0, 33)
    cand = np.clip(s_best[:, None] + w * offs[None], 0.0, el.length)
    diff = el.point(cand) - pts[:, None, :]
    s_best = cand[np.arange(len(pts)), np.argmin((diff * diff).sum(axis=2), axis=1)]
    # Gauss-Newton on (x - P(s)).T(s) = 0 from within step/16: it contracts by about
    # kappa*distance per round, so points near the curve (the ones that matter) converge
    for _ in range(3):
        r = pts - el.point(s_best)
        s_best = np.clip(s_best + (r * el.tangent(s_best)).sum(axis=1), 0.0, el.length)
    # distance to the tangent line at the foot point: the arc-length residual of the search
    # then enters only to second order (kappa*ds**2/2)
    r = pts - el.point(s_best)
    tan = el.tangent(s_best)
    r -= (r * tan).sum(axis=1)[:, None] * tan
    return np.linalg.norm(r, axis=1)
