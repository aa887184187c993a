"""G5 cubic spline, G5.1 quadratic spline, G5.2/G5.3 NURBS block (LinuxCNC's dialect).

Each becomes one `SplineFeed`: a NURBS curve (control points in machine coordinates, one
weight each, the order) that the converter flattens into chords within `chord_tol` run at
one feed (one look-ahead chain, as arcs that need chords). G5 is a cubic Bezier (order 4:
start, start + I J, end + P Q, end), G5.1 a quadratic Bezier (order 3: start, start + I J,
end), G5.2 a NURBS with LinuxCNC's open uniform knot vector (knots 0 x order, 1, 2, ...,
n - order + 2 x order). Control points are mapped like end points (offsets, rotation, units):
a NURBS is invariant under those affine maps, so the curve is exact in machine coordinates.

LinuxCNC's checks and texts: XY plane only, X and Y only, no cutter compensation, a feed;
G5 needs P and Q, I and J both or neither (neither: the tangent of the previous G5);
G5.1 needs I and J; G5.2 needs X and Y together, a positive weight P on every point, at least
`order` points at G5.3. Deliberate refusals (LinuxCNC accepts them): a G5 without I J that
does not follow a G5 (LinuxCNC's documentation calls it an error; its interpreter uses a
stale tangent), a G5.2 point without P (rs274 takes weight -1), a G5.2 block left open by
another motion or the program end (LinuxCNC drops its points silently).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import canon
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block

SPLINE_CODES = (50, 51, 52, 53)
#: Chords per knot span at least (the subdivision then refines where the curve bends).
_MIN_CHORDS = 4
#: Chords one spline may need at most (beyond: raise chord_tol).
MAX_CHORDS = 200_000


@dataclass(frozen=True, slots=True)
class SplineFeed:
    """A G5/G5.1/G5.2 curve: `points` (machine coordinates, all axes; the first is the
    start), `weights`, `order` (degree + 1), run at `feed_per_s` (G93: in `duration`)."""

    points: tuple[canon.Point, ...]
    weights: tuple[float, ...]
    order: int
    feed_per_s: float
    line: int
    file: str = ""
    duration: float | None = None
    code: int = 50

    @property
    def end(self) -> canon.Point:
        return self.points[-1]

    def knots(self) -> np.ndarray:
        """LinuxCNC's open uniform knot vector for len(points) points of this order."""
        n, k = len(self.points) - 1, self.order
        return np.array([0.0] * k + [float(i) for i in range(1, n - k + 2)]
                        + [float(n - k + 2)] * k)

    def evaluate(self, u: np.ndarray) -> np.ndarray:
        """Curve points at parameters u (0 .. knots[-1]), shape (len(u), n_axes)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        knots = self.knots()
        p = self.order - 1
        w = np.asarray(self.weights, dtype=float)
        cw = np.asarray(self.points, dtype=float) * w[:, None]
        hom = np.hstack([cw, w[:, None]])
        n = len(self.points) - 1
        out = np.empty((len(u), hom.shape[1]))
        for r, t in enumerate(u):
            span = min(max(int(np.searchsorted(knots, t, side="right")) - 1, p), n)
            d = [hom[j + span - p].copy() for j in range(p + 1)]
            for lev in range(1, p + 1):  # de Boor
                for j in range(p, lev - 1, -1):
                    i = j + span - p
                    den = knots[i + p - lev + 1] - knots[i]
                    a = 0.0 if den == 0.0 else (t - knots[i]) / den
                    d[j] = (1.0 - a) * d[j - 1] + a * d[j]
            out[r] = d[p]
        return out[:, :-1] / out[:, -1:]

    def polyline(self, tol: float) -> np.ndarray:
        """Points along the curve (start and end exact) whose chords stay within `tol` of
        it: each knot span is cut in _MIN_CHORDS pieces, a piece is halved while the curve
        at its quarter points lies farther than tol from the chord."""
        knots = np.unique(self.knots())
        params: list[float] = [float(knots[0])]
        for a, b in zip(knots[:-1], knots[1:], strict=True):
            edges = np.linspace(a, b, _MIN_CHORDS + 1)
            for u0, u1 in zip(edges[:-1], edges[1:], strict=True):
                self._refine(float(u0), float(u1), tol, params, 0)
                if len(params) > MAX_CHORDS:
                    raise ValueError(f"the spline needs more than {MAX_CHORDS} chords "
                                     f"within {tol:g}")
        pts = self.evaluate(np.array(params))
        pts[0] = self.points[0]
        pts[-1] = self.points[-1]
        return pts

    def _refine(self, u0: float, u1: float, tol: float, params: list[float],
                depth: int) -> None:
        q = self.evaluate(np.array([u0, u0 + 0.25 * (u1 - u0), 0.5 * (u0 + u1),
                                    u0 + 0.75 * (u1 - u0), u1]))
        a, b = q[0], q[-1]
        chord = b - a
        c2 = float(chord @ chord)
        dev = 0.0
        for p in q[1:-1]:
            v = p - a
            if c2 > 0.0:
                t = min(max(float(v @ chord) / c2, 0.0), 1.0)
                v = v - t * chord
            dev = max(dev, float(np.sqrt(v @ v)))
        if dev > tol and depth < 40 and len(params) <= MAX_CHORDS:
            mid = 0.5 * (u0 + u1)
            self._refine(u0, mid, tol, params, depth + 1)
            self._refine(mid, u1, tol, params, depth + 1)
        else:
            params.append(u1)

    @property
    def length(self) -> float:
        """Approximate path length (chords within 1e-4 of the first axis unit)."""
        pts = self.polyline(1e-4)
        return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))


@dataclass
class SplineState:
    """Per interpreter: the last G5's end and the I J a following G5 without I J uses
    (-P, -Q), and an open G5.2 block. Kept beside the Modal, not in it: the compile fast
    path (fastpath.py) runs only while the Modal holds the attributes it knows; a line it
    runs (plain G0/G1) sets `motion_prev`, which is how a series or block is seen broken."""

    tangent: tuple[list[float], tuple[float, float]] | None = None
    nurbs: NurbsBlock | None = None


_STATES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def state(m: Modal) -> SplineState:
    st = _STATES.get(m)
    if st is None:
        st = _STATES[m] = SplineState()
    return st


@dataclass
class NurbsBlock:
    """An open G5.2 block: control points (machine), weights, order, the line it began."""

    points: list[list[float]]
    weights: list[float]
    order: int
    line: int


def _common(m: Modal, b: Block, code: int, gpos: int, axes: dict[str, Word]) -> str:
    gword = f"G5.{code - 50}" if code != 50 else "G5"
    if m.comp.side:
        raise b.error("Cannot convert spline with cutter radius compensation", gpos, gword)
    if m.plane != 170:
        raise b.error("Splines must be in the XY plane", gpos, gword)
    other = [L for L in axes if L not in "XY"]
    if other:
        raise b.error(f"Splines may not have motion in {other[0]} (X and Y only)",
                      axes[other[0]].pos, fmt(other[0], axes[other[0]].value))
    for L in "XY":
        if L not in m.letters:
            raise b.error(f"{gword} needs a machine axis for {L}", gpos, gword)
    return gword


def _point(m: Modal, b: Block, x: float, y: float) -> list[float]:
    """Machine point of program X Y (absolute, no diameter mode: offsets of the start)."""
    return m.target_position(b, {"X": Word(x, -1), "Y": Word(y, -1)}, incremental=False,
                             diameter=False)


def _feed(m: Modal, b: Block, words: dict[str, Word], gword: str, gpos: int
          ) -> tuple[float, float | None]:
    if not m.inverse_time and m.feed <= 0.0:
        raise b.error(f"Cannot make {gword} with zero feed rate (give F)", gpos, gword)
    return m.feed_rate(b, words, gword, gpos)


def spline_move(m: Modal, b: Block, code: int, gpos: int, axes: dict[str, Word],
                words: dict[str, Word], used: set[str], out: list) -> None:
    """Execute G5 / G5.1 / G5.2 / G5.3 on one line (see the module docstring)."""
    gword = _common(m, b, code, gpos, axes)
    if code == 52:
        _nurbs_point(m, b, gword, gpos, axes, words, used)
        return
    if code == 53:
        _nurbs_end(m, b, gpos, words, used, out)
        return
    x0, y0 = m.program_position(0), m.program_position(1)
    end = m.target_position(b, axes)
    i, j = words.get("I"), words.get("J")
    if code == 51:
        if i is None or j is None:
            raise b.error("Must specify both I and J with G5.1", gpos, gword)
        if i.value == 0.0 and j.value == 0.0:
            raise b.error("G5.1 needs a control point: I and J are both zero", i.pos,
                          fmt("I", 0.0))
        used.update("IJ")
        ctrl = [_point(m, b, x0 + i.value, y0 + j.value)]
        order = 3
    else:
        p, q = words.get("P"), words.get("Q")
        if p is None or q is None:
            raise b.error("Must specify both P and Q with G5", gpos, gword)
        if (i is None) != (j is None):
            raise b.error("Must specify both I and J, or neither", (i or j).pos,  # type: ignore[union-attr]
                          "I" if i is not None else "J")
        st = state(m)
        if i is None:
            if st.tangent is None or st.tangent[0] != m.pos or m.motion_prev != 50:
                raise b.error("G5 without I and J must follow a G5 (I and J are needed on "
                              "the first G5 of a series)", gpos, gword)
            ij = st.tangent[1]
        else:
            ij = (i.value, j.value)  # type: ignore[union-attr]
        used.update(L for L in "IJPQ" if L in words)
        ex, ey = _end_program(m, axes, x0, y0)
        ctrl = [_point(m, b, x0 + ij[0], y0 + ij[1]),
                _point(m, b, ex + p.value, ey + q.value)]
        order = 4
        st.tangent = (end, (-p.value, -q.value))
    feed, duration = _feed(m, b, words, gword, gpos)
    pts = [tuple(m.pos)] + [tuple(c) for c in ctrl] + [tuple(end)]
    _emit(m, b, pts, [1.0] * len(pts), order, feed, duration, code, gpos, gword, out)
    m.pos = end


def _end_program(m: Modal, axes: dict[str, Word], x0: float, y0: float
                 ) -> tuple[float, float]:
    """The line's X Y end point in program coordinates (G90/G91)."""
    out = []
    for L, v0 in (("X", x0), ("Y", y0)):
        w = axes.get(L)
        out.append(v0 if w is None else (v0 + w.value if m.incremental else w.value))
    return out[0], out[1]


def _emit(m: Modal, b: Block, pts: list[tuple[float, ...]], weights: list[float],
          order: int, feed: float, duration: float | None, code: int, gpos: int,
          gword: str, out: list) -> None:
    xs = [p[m.letters["X"][0]] for p in pts]
    ys = [p[m.letters["Y"][0]] for p in pts]
    lo, hi = list(pts[0]), list(pts[0])
    ix, iy = m.letters["X"][0], m.letters["Y"][0]
    # the convex hull of the control points holds the curve: check it against the limits
    lo[ix], hi[ix], lo[iy], hi[iy] = min(xs), max(xs), min(ys), max(ys)
    m.check_limits(b, lo, hi, gword, gpos)
    if all(p == pts[0] for p in pts):
        return  # no motion
    out.append(SplineFeed(tuple(pts), tuple(weights), order, feed, b.line, b.file, duration,
                          code))


def _nurbs_point(m: Modal, b: Block, gword: str, gpos: int, axes: dict[str, Word],
                 words: dict[str, Word], used: set[str]) -> None:
    x, y = axes.get("X"), axes.get("Y")
    p, lw = words.get("P"), words.get("L")
    st = state(m)
    blk = st.nurbs
    if blk is not None and m.motion_prev != 52:  # a G0/G1 ran between: LinuxCNC drops it
        raise b.error(f"the G5.2 NURBS block of line {blk.line} was not closed with G5.3 "
                      "before another motion", gpos, gword)
    if (x is None) != (y is None):
        raise b.error("You must specify both X and Y coordinates for Control Points",
                      (x or y).pos, "X" if x is not None else "Y")  # type: ignore[union-attr]
    if x is None and blk is not None and p is not None:
        raise b.error("Can specify P without X and Y only for the first control point",
                      p.pos, fmt("P", p.value))
    if x is not None and (p is None or p.value <= 0.0):
        raise b.error("Must specify positive weight P for every Control Point",
                      p.pos if p is not None else gpos, fmt("P", p.value) if p else gword)
    if p is not None and p.value <= 0.0:
        raise b.error("Must specify positive weight P for every Control Point", p.pos,
                      fmt("P", p.value))
    if not m.inverse_time and m.feed <= 0.0:
        raise b.error("Cannot make a NURBS with 0 feedrate", gpos, gword)
    used.update(L for L in "PL" if L in words)
    if blk is None:
        w0 = p.value if (x is None and p is not None) else 1.0
        blk = st.nurbs = NurbsBlock([list(m.pos)], [w0], 3, b.line)
    if lw is not None:
        n = round(lw.value)
        if abs(lw.value - n) > 1e-6 or n < 2:
            raise b.error(f"G5.2 L (order) must be an integer >= 2, got {lw.value:g}",
                          lw.pos, fmt("L", lw.value))
        if n > 3:  # LinuxCNC: an order below 3 leaves the default 3
            blk.order = int(n)
    if x is not None:
        assert p is not None
        # LinuxCNC keeps the current point at the block's start until G5.3 (G91 points
        # are relative to it, #<_x> reads it)
        blk.points.append(m.target_position(b, axes))
        blk.weights.append(p.value)


def _nurbs_end(m: Modal, b: Block, gpos: int, words: dict[str, Word], used: set[str],
               out: list) -> None:
    st = state(m)
    blk = st.nurbs
    if blk is None:
        raise b.error("Cannot use G5.3 without G5.2 first", gpos, "G5.3")
    st.nurbs = None
    if m.motion_prev != 52:
        raise b.error(f"the G5.2 NURBS block of line {blk.line} was not closed with G5.3 "
                      "before another motion", gpos, "G5.3")
    if len(blk.points) < blk.order:
        raise b.error(f"You must specify a number of control points at least equal to the "
                      f"order L = {blk.order}", gpos, "G5.3")
    if m.inverse_time:
        raise b.error("G5.2 NURBS in inverse time (G93) is not supported: use G94", gpos,
                      "G5.3")
    feed, duration = _feed(m, b, words, "G5.3", gpos)
    m.motion = None  # LinuxCNC: no motion mode after G5.3
    _emit(m, b, [tuple(p) for p in blk.points], blk.weights, blk.order, feed, duration, 52,
          gpos, "G5.3", out)
    m.pos = list(blk.points[-1])


def open_block_error(m: Modal, b: Block, gpos: int, word: str) -> None:
    """A motion other than G5.2/G5.3 (or the program end) while a G5.2 block is open."""
    blk = state(m).nurbs
    if blk is not None:
        raise b.error(f"the G5.2 NURBS block of line {blk.line} is not closed with G5.3 "
                      f"before {word}", gpos, word)


def chord_count(sp: SplineFeed, tol: float) -> int:
    """How many chords `polyline(tol)` gives (tests and reports)."""
    return len(sp.polyline(tol)) - 1


def bezier(points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The Bezier curve of control `points` at t in [0, 1] (Bernstein form; a reference
    independent of the de Boor evaluation, for tests)."""
    n = len(points) - 1
    t = np.asarray(t, dtype=float)[:, None]
    return sum(math.comb(n, k) * t ** k * (1 - t) ** (n - k) * points[k]
               for k in range(n + 1))
