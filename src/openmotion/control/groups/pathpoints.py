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


#: The per-element arrays of an `ElementTable` (sliced and concatenated row by row).
_FIELDS = ("kind", "trimmed", "offset", "stop", "blen", "start", "end", "dirn", "centre",
           "e1", "e2", "lin", "helix", "radius", "k", "rs", "lengths", "curvature")


class ElementTable:
    """Line/arc parameters of `elements`, row i for element i (see the module doc).

    A streaming chain is re-planned at every join as the old chain (its travelled part
    dropped, its last element perhaps trimmed by a blend) plus the new elements:
    `sliced` and `concat` build that chain's table from the old table's rows and a table
    of the new elements only, the same arrays value for value as building it anew."""

    def __init__(self, elements: Sequence[PathElement]) -> None:
        from .pathexec import Trimmed

        n = len(elements)
        dim = elements[0].dim
        self.elements = elements
        zero = np.zeros(dim)
        kind = [_GENERIC] * n
        trimmed = [False] * n
        offset = [0.0] * n
        stop = [0.0] * n                 # a Trimmed's end on its base
        blen = [0.0] * n                 # length of the evaluated (base) element
        start: list = [zero] * n
        end: list = [zero] * n
        dirn: list = [zero] * n          # lines: unit direction
        centre: list = [zero] * n        # arcs: the circle frame
        e1: list = [zero] * n
        e2: list = [zero] * n
        lin: list = [zero] * n
        helix: list = [zero] * n
        radius = [0.0] * n
        k = [0.0] * n                    # sweep / length
        rs = [0.0] * n                   # radius * sweep
        for i, el in enumerate(elements):
            base = el
            tr = False
            if type(el) is Trimmed and type(el.base) is not Trimmed:
                base = el.base
                tr = True
            if type(base) is Line:
                kind[i] = _LINE
                dirn[i] = base.direction
            elif isinstance(base, _ArcQueries):
                f = base._frame
                kind[i] = _ARC
                centre[i], e1[i], e2[i] = f.centre, f.e1, f.e2
                lin[i], helix[i] = f.lin, f.helix
                radius[i] = f.radius
                k[i] = f.sweep / f.length
                rs[i] = f.radius * f.sweep
                base = f
            else:
                continue
            if tr:
                trimmed[i] = True
                offset[i] = el.offset
                stop[i] = el._stop
            blen[i] = base.length
            start[i], end[i] = base.start, base.end
        self.kind = np.array(kind, dtype=np.int8)
        self.trimmed = np.array(trimmed, dtype=bool)
        self.offset = np.array(offset, dtype=float)
        self.stop = np.array(stop, dtype=float)
        self.blen = np.array(blen, dtype=float)
        self.radius = np.array(radius, dtype=float)
        self.k = np.array(k, dtype=float)
        self.rs = np.array(rs, dtype=float)
        for name, rows in (("start", start), ("end", end), ("dirn", dirn),
                           ("centre", centre), ("e1", e1), ("e2", e2), ("lin", lin),
                           ("helix", helix)):
            setattr(self, name, np.array(rows, dtype=float).reshape(n, dim))
        self.lengths = np.array([el.length for el in elements], dtype=float)
        self.curvature = np.array([el.max_curvature for el in elements], dtype=float)

    @property
    def packed(self) -> Array | None:
        """The rows as one float64 matrix for the compiled knots (`_profile.axis_knots`:
        kind, trimmed, offset, stop, blen, radius, k, rs, length, curvature, then the
        start, end, dirn, centre, e1, e2, lin and helix vectors); None when an element is
        neither a line nor an arc (the numpy version evaluates it). Built once."""
        memo = self.__dict__.get("_packed", False)
        if memo is not False:
            return memo
        out = None
        if not np.any(self.kind == _GENERIC):
            out = np.ascontiguousarray(np.concatenate(
                [np.stack([self.kind.astype(float), self.trimmed.astype(float), self.offset,
                           self.stop, self.blen, self.radius, self.k, self.rs, self.lengths,
                           self.curvature], axis=1),
                 self.start, self.end, self.dirn, self.centre, self.e1, self.e2, self.lin,
                 self.helix], axis=1), dtype=np.float64)
        self._packed = out
        return out

    def sliced(self, a: int, b: int | None = None) -> ElementTable:
        """The table of elements[a:b] (rows a..b-1)."""
        out = object.__new__(ElementTable)
        out.elements = self.elements[a:b]
        for name in _FIELDS:
            setattr(out, name, getattr(self, name)[a:b])
        return out

    def concat(self, other: ElementTable) -> ElementTable:
        """This table's elements followed by `other`'s."""
        out = object.__new__(ElementTable)
        out.elements = tuple(self.elements) + tuple(other.elements)
        for name in _FIELDS:
            setattr(out, name, np.concatenate([getattr(self, name), getattr(other, name)]))
        return out

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
