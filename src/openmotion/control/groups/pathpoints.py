"""A chain's elements evaluated all at once: points and tangents at (element, local s).

`pathexec.axis_profiles` samples a chain at every knot. Asking each element for its points
costs a few Python calls per element, and a streaming chain holds hundreds of short
elements, so that loop was most of a re-plan. `ElementTable` gathers the parameters of the
chain's lines and arcs (path/geometry.py `Line`, path/arcs.py `Arc`/`Arc3D`, and a
`pathexec.Trimmed` of one of them) into arrays once and evaluates every knot with numpy,
using the same formulas with the same floating-point operations in the same order as the
elements' own `point`/`tangent`: the results are the same bit for bit (tested). Any other
element type is asked itself.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...path.arcs import _ArcQueries
from ...path.geometry import Array, Line, PathElement

_GENERIC, _LINE, _ARC = 0, 1, 2


class ElementTable:
    """Line/arc parameters of `elements`, row i for element i (see the module doc)."""

    def __init__(self, elements: Sequence[PathElement]) -> None:
        from .pathexec import Trimmed

        n = len(elements)
        dim = elements[0].dim
        self.elements = elements
        self.kind = np.zeros(n, dtype=np.int8)
        self.trimmed = np.zeros(n, dtype=bool)
        self.offset = np.zeros(n)
        self.stop = np.zeros(n)            # a Trimmed's end on its base
        self.blen = np.zeros(n)            # length of the evaluated (base) element
        self.start = np.zeros((n, dim))
        self.end = np.zeros((n, dim))
        self.dirn = np.zeros((n, dim))     # lines: unit direction
        self.centre = np.zeros((n, dim))   # arcs: the circle frame
        self.e1 = np.zeros((n, dim))
        self.e2 = np.zeros((n, dim))
        self.lin = np.zeros((n, dim))
        self.helix = np.zeros((n, dim))
        self.radius = np.zeros(n)
        self.k = np.zeros(n)               # sweep / length
        self.rs = np.zeros(n)              # radius * sweep
        self.lengths = np.array([el.length for el in elements], dtype=float)
        self.curvature = np.array([el.max_curvature for el in elements], dtype=float)
        for i, el in enumerate(elements):
            base = el
            if type(el) is Trimmed and type(el.base) is not Trimmed:
                base = el.base
                self.trimmed[i] = True
                self.offset[i] = el.offset
                self.stop[i] = el._stop
            if type(base) is Line:
                self.kind[i] = _LINE
                self.dirn[i] = base.direction
            elif isinstance(base, _ArcQueries):
                f = base._frame
                self.kind[i] = _ARC
                self.centre[i], self.e1[i], self.e2[i] = f.centre, f.e1, f.e2
                self.lin[i], self.helix[i] = f.lin, f.helix
                self.radius[i] = f.radius
                self.k[i] = f.sweep / f.length
                self.rs[i] = f.radius * f.sweep
                base = f
            else:
                self.trimmed[i] = False
                continue
            self.blen[i] = base.length
            self.start[i], self.end[i] = base.start, base.end

    def _base_s(self, k: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Local s on the evaluated element: a Trimmed adds its offset (capped at its end
        on the base), then s is clipped to the element like `path_positions` does."""
        ub = u.astype(float, copy=True)
        t = self.trimmed[k]
        if np.any(t):
            ub[t] = np.minimum(u[t] + self.offset[k[t]], self.stop[k[t]])
        return np.clip(ub, 0.0, self.blen[k])

    def point(self, k: np.ndarray, u: np.ndarray) -> Array:
        """Points of elements k at local positions u (within each element's length)."""
        return self._eval(k, u, tangent=False)

    def tangent(self, k: np.ndarray, u: np.ndarray) -> Array:
        """Unit tangents of elements k at local positions u."""
        return self._eval(k, u, tangent=True)

    def _eval(self, k: np.ndarray, u: np.ndarray, *, tangent: bool) -> Array:
        out = np.empty((len(k), self.start.shape[1]))
        kind = self.kind[k]
        ub = self._base_s(k, u)
        m = kind == _LINE
        if np.any(m):
            kl, sl = k[m], ub[m]
            if tangent:
                out[m] = self.dirn[kl]
            else:
                out[m] = self._snap(kl, sl, self.start[kl] + sl[:, None] * self.dirn[kl])
        m = kind == _ARC
        if np.any(m):
            ka, sa = k[m], ub[m]
            phi = (sa * self.k[ka])[:, None]
            if tangent:
                t = self.rs[ka][:, None] * (np.cos(phi) * self.e2[ka]
                                            - np.sin(phi) * self.e1[ka]) + self.helix[ka]
                out[m] = t / np.linalg.norm(t, axis=-1, keepdims=True)
            else:
                p = (self.centre[ka] + self.radius[ka][:, None] * (
                    np.cos(phi) * self.e1[ka] + np.sin(phi) * self.e2[ka])
                    + (sa / self.blen[ka])[:, None] * self.lin[ka])
                out[m] = self._snap(ka, sa, p)
        for i in np.unique(k[kind == _GENERIC]):
            mi = k == i
            el = self.elements[int(i)]
            out[mi] = el.tangent(u[mi]) if tangent else el.point(u[mi])
        return out

    def _snap(self, k: np.ndarray, s: np.ndarray, p: np.ndarray) -> np.ndarray:
        """`geometry.snap_ends`: the exact end at s >= length, the exact start at s <= 0."""
        p = np.where((s >= self.blen[k])[:, None], self.end[k], p)
        return np.where((s <= 0.0)[:, None], self.start[k], p)

    def line_tangents(self, k: np.ndarray) -> Array:
        """Tangent at local s = 0 of straight elements k (what `el.tangent(0.0)` gives)."""
        out = self.dirn[k].copy()
        for j in np.nonzero(self.kind[k] != _LINE)[0]:
            out[j] = np.asarray(self.elements[int(k[j])].tangent(0.0))
        return out
