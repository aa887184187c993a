"""Profile elements of the lathe cycles (G70/G71/G72) in the ZX plane.

A point is the complex number z + i x (program units, X as a radius). Elements are lines
and arcs with mutable ends, because the cycles offset them and move their joints onto each
other's intersections. The numbers (1e-6 tolerance, 1e-3 for "too short", 1e-2 for
"these ends no longer meet") are LinuxCNC's (interp_g7x.cc), so the passes come out as
LinuxCNC cuts them; the oracle (tests/test_gcode_lathe.py) checks that against rs274.

`Emit` is where the cycles send their motion: rapid(end), feed(end), arc(ccw, centre,
end), all in the cycle's working frame (the cycle maps them back, lathecycles.py).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable
from dataclasses import dataclass

TOL = 1e-6  # LinuxCNC's g7x tolerance


class ProfileError(Exception):
    """A profile the cycle cannot cut (the message names why); the caller locates it."""


@dataclass
class Emit:
    """Motion sinks of a cycle: rapid(end), feed(end), arc(ccw, centre, end)."""

    rapid: Callable[[complex], None]
    feed: Callable[[complex], None]
    arc: Callable[[bool, complex, complex], None]


def _rot(a: complex, b: complex) -> complex:
    """The unit rotation that turns the direction a - b onto the real axis."""
    d = a - b
    return d.conjugate() / abs(d)


class Line:
    """A straight element from `start` to `end`; `finish` > 0 marks a chamfer corner."""

    def __init__(self, start: complex, end: complex, finish: float = 0.0) -> None:
        self.start, self.end, self.finish = start, end, finish

    def copy(self) -> Line:
        return Line(self.start, self.end, self.finish)

    def length_scale(self) -> float:  # LinuxCNC's radius(): the element's smallest size
        return abs(self.start - self.end)

    def monotonic(self) -> bool:
        return (self.end - self.start).real <= 1e-3

    def offset(self, d: float) -> None:
        v = 1j * d * (self.start - self.end) / abs(self.start - self.end)
        self.start += v
        self.end += v

    def move(self, d: complex) -> None:
        self.start += d
        self.end += d

    def transform(self, f: Callable[[complex], complex], mirror: bool) -> None:
        self.start, self.end = f(self.start), f(self.end)

    def crossings(self, x: float) -> list[float]:
        """Z where the element meets the line X = x (both ends if it lies on it)."""
        s, e = self.start, self.end
        if min(s.imag, e.imag) > x + TOL or max(s.imag, e.imag) < x - TOL:
            return []
        if abs(s.imag - e.imag) < TOL:
            return [s.real, e.real]
        return [(x - s.imag) / (e.imag - s.imag) * (e.real - s.real) + s.real]

    def draw(self, out: Emit) -> None:
        out.feed(self.end)

    def climb(self, at: complex, out: Emit) -> tuple[bool, complex]:
        """Follow the element up (X growing); (True: it does not climb, position)."""
        if self.end.imag + TOL < self.start.imag:
            return True, at
        if abs(at - self.start) > TOL:
            raise ProfileError("How did we get here?")
        out.feed(self.end)
        return False, self.end

    def climb_only(self, at: complex, out: Emit) -> complex:
        if self.end.imag < self.start.imag:
            return at
        zs = self.crossings(at.imag)
        if not zs:
            return at
        at = complex(zs[0], at.imag)
        out.feed(at)
        out.feed(self.end)
        return self.end

    def dive(self, at: complex, x: float, out: Emit, fast: bool) -> tuple[bool, complex]:
        """Follow the element down to X = x; (True: it does not dive, position)."""
        if self.start.imag <= self.end.imag + TOL:
            return True, at
        move = out.rapid if fast else out.feed
        if x < self.end.imag:
            move(self.end)
            return False, self.end
        zs = self.crossings(x)
        if not zs:
            raise ProfileError("x too large in straight dive")
        p = complex(zs[0], x)
        move(p)
        return False, p


class Arc:
    """A circular element (`ccw`: G3 in the working frame); `finish` > 0 marks a fillet."""

    def __init__(self, ccw: bool, start: complex, centre: complex, end: complex,
                 finish: float = 0.0) -> None:
        self.ccw, self.start, self.centre, self.end = ccw, start, centre, end
        self.finish = finish

    def copy(self) -> Arc:
        return Arc(self.ccw, self.start, self.centre, self.end, self.finish)

    def length_scale(self) -> float:
        return min(abs(self.start - self.end), abs(self.start - self.centre))

    def monotonic(self) -> bool:
        if self.finish != 0:
            return True
        entry = (self.start - self.centre).imag
        leave = (self.end - self.centre).imag
        dz = (self.end - self.start).real
        if self.ccw:
            return entry >= -1e-3 and leave >= -1e-3 and dz <= -1e-3
        return entry <= 1e-3 and leave <= 1e-3 and dz <= -1e-3

    def offset(self, d: float) -> None:
        r = abs(self.start - self.centre)
        k = (r + (d if self.ccw else -d)) / r
        self.start = k * (self.start - self.centre) + self.centre
        self.end = k * (self.end - self.centre) + self.centre

    def move(self, d: complex) -> None:
        self.start += d
        self.centre += d
        self.end += d

    def transform(self, f: Callable[[complex], complex], mirror: bool) -> None:
        self.start, self.centre, self.end = f(self.start), f(self.centre), f(self.end)
        if mirror:
            self.ccw = not self.ccw

    def _on(self, p: complex) -> bool:
        a = ((self.start - self.centre).conjugate() * (p - self.centre)).imag
        b = ((self.end - self.centre).conjugate() * (p - self.centre)).imag
        if self.ccw:
            return a >= -TOL and b <= TOL
        return a <= TOL and b >= -TOL

    def crossings(self, x: float) -> list[float]:
        r = abs(self.start - self.centre)
        c = self.centre
        s = -(x - r - c.imag) * (x + r - c.imag)
        if s < -TOL:
            return []
        s = math.sqrt(max(s, 0.0))
        return [p.real for p in (complex(c.real + s, x), complex(c.real - s, x)) if self._on(p)]

    def draw(self, out: Emit) -> None:
        out.arc(self.ccw, self.centre, self.end)

    def _top(self) -> complex:
        """Where a G3 climbing the profile stops: its end, or its highest point."""
        if self.end.real < self.centre.real:
            return complex(self.centre.real, self.centre.imag + abs(self.start - self.centre))
        return self.end

    def climb(self, at: complex, out: Emit) -> tuple[bool, complex]:
        if not self.ccw:
            if at.real > self.centre.real:
                return True, at
            if abs(at - self.end) > 1e-3:
                out.arc(False, self.centre, self.end)
            return False, self.end
        if at.real < self.centre.real:
            return True, at
        top = self._top()
        if abs(at - top) > 1e-3:
            out.arc(True, self.centre, top)
        return True, top

    def climb_only(self, at: complex, out: Emit) -> complex:
        zs = self.crossings(at.imag)
        if not zs:
            return at
        if not self.ccw:
            if zs[-1] > self.centre.real:
                return at
            at = complex(zs[-1], at.imag)
            out.feed(at)
            if abs(at - self.end) > 1e-3:
                out.arc(False, self.centre, self.end)
            return self.end
        if zs[0] < self.centre.real:
            return at
        at = complex(zs[0], at.imag)
        out.feed(at)
        top = self._top()
        if abs(at - top) > 1e-3:
            out.arc(True, self.centre, top)
        return top

    def dive(self, at: complex, x: float, out: Emit, fast: bool) -> tuple[bool, complex]:
        if abs(at - self.end) < TOL or (at - self.end).real <= TOL:
            return False, self.end
        zs = self.crossings(x) or self.crossings(x - TOL)
        c = self.centre
        if self.ccw:
            if at.real - TOL > c.real:
                return True, at
            if not zs or zs[-1] > c.real:
                out.arc(True, c, self.end)
                return False, self.end
            p = complex(zs[-1], x)
            out.arc(True, c, p)
            return False, p
        if at.real <= c.real:
            return True, at  # already climbing
        if not zs:
            out.arc(False, c, self.end)
            return False, self.end
        if zs[0] < c.real:
            return False, at  # only the back side is hit: the pocket lowers x
        p = complex(zs[0], x)
        out.arc(False, c, p)
        return False, p


Element = Line | Arc


def _line_after(p: Element, n: Line) -> None:
    """Join element p to the line n that follows it (p's end, n's start)."""
    if isinstance(p, Line):
        rot = _rot(n.start, n.end)
        ps, pe = (p.start - n.end) * rot, (p.end - n.end) * rot
        if (ps - pe).imag == 0:
            raise ProfileError("Cannot intersect parallel lines")
        f = ps.imag / (ps - pe).imag
        n.start = p.end = (ps + f * (pe - ps)) / rot + n.end
        return
    if abs(n.start - p.end) < TOL:
        return
    rot = _rot(n.start, n.end)
    pe, pc = (p.end - n.end) * rot, (p.centre - n.end) * rot
    b = math.sqrt(max(abs(pc - pe) ** 2 - pc.imag ** 2, 0.0))
    s1, s2 = (pc.real + b) / rot + n.end, (pc.real - b) / rot + n.end
    n.start = p.end = s1 if abs(n.start - s1) < abs(n.start - s2) else s2


def _arc_after(p: Element, n: Arc) -> None:
    """Join element p to the arc n that follows it."""
    if isinstance(p, Line):
        if abs(n.start - p.end) < TOL:
            return
        rot = _rot(p.start, p.end)
        pe, pc = (n.end - p.end) * rot, (n.centre - p.end) * rot
        b = math.sqrt(max(abs(pc - pe) ** 2 - pc.imag ** 2, 0.0))
        s1, s2 = (pc.real + b) / rot + p.end, (pc.real - b) / rot + p.end
        n.start = p.end = s1 if abs(n.start - s1) < abs(n.start - s2) else s2
        return
    a = abs(n.start - n.centre)
    b = abs(p.start - p.centre)
    c = abs(n.centre - p.centre)
    cos_b = (c * c + a * a - b * b) / 2.0 / a / c
    rot = complex(cos_b, math.sqrt(1.0 - min(cos_b * cos_b, 1.0)))
    p.end = n.start = rot * (p.centre - n.centre) / c * a + n.centre


def join(p: Element, n: Element) -> None:
    """Move the joint of consecutive elements p, n onto their intersection."""
    if isinstance(n, Line):
        _line_after(p, n)
    else:
        _arc_after(p, n)


def finish_corner(corner: Element, prev: Element, nxt: Element) -> None:
    """Turn a fillet (Arc) or chamfer (Line) marker between prev and nxt into its element:
    both neighbours are cut back where, offset by the size, they meet."""
    d = corner.finish
    p, n = prev.copy(), nxt.copy()
    p.offset(d)
    n.offset(d)
    if (p.end - n.start).real > 1e-2:
        d = -d
        p, n = prev.copy(), nxt.copy()
        p.offset(d)
        n.offset(d)
    if (p.end - n.start).real > 1e-2:
        z, x = prev.end.real, prev.end.imag
        raise ProfileError(f"Corner finish failed at ({z:g},{x:g})")
    join(p, n)
    centre = (p.end + n.start) / 2.0
    p.offset(-d)
    n.offset(-d)
    corner.start = prev.end = p.end
    corner.end = nxt.start = n.start
    if isinstance(corner, Arc):
        corner.centre = centre
        corner.ccw = (corner.start - centre).imag > 0 or (corner.end - centre).imag > 0
        corner.finish = 0.0
    else:
        corner.finish = d


def radius_centre(start: complex, end: complex, r: float, ccw: bool) -> complex:
    """The centre of an R-form arc (LinuxCNC's g7x: the shorter side for either sign)."""
    chord2 = abs(end - start) ** 2
    q = (r * r - chord2 / 4) / chord2
    if q < 0:
        raise ProfileError(f"arc radius {abs(r):g} is shorter than half the chord")
    d = 1j * cmath.sqrt(q).real * (end - start)
    mid = (start + end) / 2.0
    return mid + d if ccw else mid - d
