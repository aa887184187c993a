"""The passes of LinuxCNC's lathe cycles: G70 finishing, G71/G72 roughing (+ .1, .2).

A `Profile` is the cycle's start point followed by the elements read from the profile
subroutine (lathegeom.py). Each cycle first turns its copy of the profile into a working
frame where the cut runs towards -Z with X (the depth) falling: G72 rotates the plane by
90 degrees, then X and/or Z are mirrored as the profile's direction needs; every motion is
mapped back on its way out. Then:

- fillets (A) and chamfers (C) are made, elements shorter than 1e-3 dropped, and the
  profile must be monotonic ("Not monotonic");
- G71/G72: the profile is offset by D towards the start (arcs round convex joints), then
  layers I deep are cut from the start level down; each layer feeds along Z to the profile,
  retracts R at 45 degrees, rapids back, and drops by I; where the profile climbs again a
  pocket begins and is cut the same way (G7x.1 skips pockets and follows the profile, G7x.2
  only cuts from the first pocket on);
- G70: P passes at distances (pass-1)(D-E)/P + E from the profile, each a rapid to the
  start, a rapid to the profile's first point and the profile itself.

This follows interp_g7x.cc of LinuxCNC 2.9 step for step (the results are compared against
rs274 in tests/test_gcode_lathe.py).
"""

from __future__ import annotations

from .lathegeom import TOL, Arc, Element, Emit, Line, ProfileError, finish_corner, join

_MAX_STEPS = 1_000_000  # offset / pocket steps: LinuxCNC loops forever on some profiles


def _rotate(p: complex) -> complex:
    return -p * 1j


def _flip_x(p: complex) -> complex:
    return p.conjugate()


def _flip_z(p: complex) -> complex:
    return -p.conjugate()


class Profile:
    """The cycle start (element 0 runs from it to the profile) and the profile."""

    def __init__(self, elements: list[Element]) -> None:
        self.el = elements
        self.state = 0  # bit 1: Z mirrored, 2: X mirrored, 4: rotated (G72)
        self.delta = 0.5
        self.escape = 0.3 + 0.3j
        self.pocket_starts: list[complex] = []
        self._steps = 0

    def copy(self) -> Profile:
        p = Profile([e.copy() for e in self.el])
        p.state, p.delta, p.escape = self.state, self.delta, self.escape
        return p

    # -- the working frame ---------------------------------------------------------
    def _apply(self, f, mirror: bool) -> None:  # type: ignore[no-untyped-def]
        for e in self.el:
            e.transform(f, mirror)

    def rotate(self) -> None:
        self._apply(_rotate, False)
        self.state ^= 4

    def normalise(self) -> None:
        """Mirror so that the profile runs towards -Z and -X (LinuxCNC's swap)."""
        d = self.el[0].end - self.el[-1].end
        if d.imag > 0:
            self._apply(_flip_x, True)
            self.state ^= 2
        if d.real < 0:
            self._apply(_flip_z, True)
            self.state ^= 1

    def output(self, out: Emit) -> Emit:
        """`out` seen from the working frame: points mapped back to the program's."""
        state = self.state

        def back(p: complex) -> complex:
            if state & 1:
                p = _flip_z(p)
            if state & 2:
                p = _flip_x(p)
            if state & 4:
                p = p * 1j
            return p

        mirrored = bool(state & 1) != bool(state & 2)
        return Emit(lambda p: out.rapid(back(p)), lambda p: out.feed(back(p)),
                    lambda ccw, c, p: out.arc(ccw != mirrored, back(c), back(p)))

    def check_monotonic(self) -> None:
        first = self.el[0]
        if (first.end - first.start).real > 0:
            first.start = complex(first.end.real, first.start.imag)
        if not all(e.monotonic() for e in self.el):
            raise ProfileError("Not monotonic")

    def finish_corners(self) -> None:
        for k in range(1, len(self.el) - 1):
            e = self.el[k]
            if e.finish != 0 and (isinstance(e, Arc) or e.start == e.end):
                finish_corner(e, self.el[k - 1], self.el[k + 1])
        self.el = [e for e in self.el if e.length_scale() >= 1e-3]

    def _step(self) -> None:
        self._steps += 1
        if self._steps > _MAX_STEPS:
            raise ProfileError("the cycle makes no progress on this profile (LinuxCNC "
                               "loops forever here)")

    # -- D: offset the profile towards the start --------------------------------------
    def add_distance(self, distance: float) -> None:
        v1 = self.el[0].end - self.el[0].start
        v2 = self.el[-1].start - self.el[0].start
        if (v1 / v2).imag < 0:
            distance = -distance
        head = self.el.pop(0)
        el = self.el
        done = 0.0
        while done != distance:
            self._step()
            step = min([1e9] + [e.length_scale() / 2 for e in el] + [abs(distance - done)])
            if step == 0:
                raise ProfileError("the profile cannot be offset by D (no progress)")
            if distance < 0:
                step = -step
            kept = []
            for e in el:
                e.offset(step)
                if e.length_scale() >= 1e-3:
                    kept.append(e)
            el[:] = kept
            k = 0
            while k < len(el) - 1:
                p, n = el[k], el[k + 1]
                if (p.end - n.start).real > 1e-2:  # a convex joint: a connecting arc
                    s, t = p.copy(), n.copy()
                    s.offset(-step)
                    t.offset(-step)
                    el.insert(k + 1, Arc(distance > 0, p.end, (s.end + t.start) / 2.0,
                                         n.start))
                    k += 1
                k += 1
            self._rejoin(el)
            done += step
        for k in range(len(el) - 1):
            mid = (el[k].end + el[k + 1].start) / 2.0
            el[k].end = el[k + 1].start = mid
        head.end = el[0].start
        el.insert(0, head)

    def _rejoin(self, el: list[Element]) -> None:
        """Drop elements the offset turned round or shrank, join the rest."""
        k = 0
        while k < len(el) - 1:
            self._step()
            if not el[k].monotonic():
                j = k - 1 if k > 0 else len(el) - 1
                if el[k].length_scale() < el[j].length_scale():
                    del el[k]
                else:
                    del el[j]
                k = 0
            if k >= len(el) - 1:
                break
            if el[k].length_scale() < 1e-3:
                del el[k]
                k = 0
            else:
                join(el[k], el[k + 1])
            k += 1

    # -- the cycles ------------------------------------------------------------------
    def g70(self, out: Emit, d: float, e: float, passes: float) -> None:
        probe = self.copy()
        probe.el.pop(0)
        probe.normalise()
        if not all(x.monotonic() for x in probe.el):
            probe.rotate()
            probe.normalise()
        probe.check_monotonic()
        if probe.state & 4:
            self.rotate()
        self.normalise()
        self.finish_corners()
        self.check_monotonic()
        work = self.output(out)
        k = int(passes)
        while k > 0:
            path = self.copy()
            path.add_distance((k - 1) * (d - e) / passes + e)
            work.rapid(path.el[0].start)
            work.rapid(path.el[0].end)
            for x in path.el[1:]:
                x.draw(work)
            k -= 1

    def g71(self, out: Emit, sub: int, d: float, i: float, r: float,
            rotate: bool = False) -> None:
        if rotate:
            self.rotate()
        self.normalise()
        self.finish_corners()
        self.check_monotonic()
        self.add_distance(d)
        work = self.output(out)
        self.delta = max(i, 2 * TOL)
        self.escape = r * (1 + 1j)
        start = self.el[0].start
        work.rapid(start)
        last = self.el[-1].end
        if last.imag < start.imag:
            self.el.append(Line(last, complex(last.real, start.imag)))
        self.pocket_starts.append(start)
        self._pocket(sub, start, 0, work)

    def _pocket(self, cycle: int, at: complex, k: int, out: Emit) -> None:  # noqa: C901
        el = self.el
        n = len(el)
        x = self.pocket_starts[-1].imag
        if cycle == 2:  # skip the first roughing pass
            while k < n:
                flat, at = el[k].dive(at, -1e9, out, k == 0)
                if flat:
                    break
                k += 1
            cycle = 3
        before = None
        while k < n:
            self._step()
            if before == (k, x, at):  # nothing changed: LinuxCNC would loop forever
                raise ProfileError("the cycle makes no progress on this profile (LinuxCNC "
                                   "loops forever here)")
            before = (k, x, at)
            while x - TOL > at.imag:
                x -= self.delta
            flat, at = el[k].dive(at, x, out, k == 0)
            if flat:
                if cycle == 1:  # after the roughing layers: along the profile, done
                    while k < n:
                        at = el[k].climb_only(at, out)
                        k += 1
                    return
                while k < n:  # along the profile to the next pocket
                    up, at = el[k].climb(at, out)
                    if up:
                        if cycle == 3:
                            if at.imag > self.pocket_starts[-1].imag \
                                    and len(self.pocket_starts) > 1:
                                self.pocket_starts.pop()
                            if len(self.pocket_starts) == 1:
                                self.pocket_starts.append(at)
                        self._pocket(cycle, at, k, out)
                        return
                    k += 1
                return
            if abs(at.imag - x) > TOL:  # below this element: on to the next
                k += 1
                continue
            for j in range(k, n):
                zs = el[j].crossings(at.imag)
                if not zs:
                    continue
                dest_z = zs[0] if j != k else zs[-1]
                dist = abs(dest_z - at.real)
                if dest_z - TOL > at.real:
                    continue  # the diving element at its own start
                if dist < TOL:
                    if j == k:
                        continue
                    if abs(at - el[j].start) < TOL:
                        k = j  # at the next element's start: follow it
                        break
                    x -= self.delta  # a zero-length layer
                    break
                dest = complex(dest_z, at.imag)
                out.feed(dest)
                s = min(1.0, dist / 2 / self.escape.real)
                dest += s * self.escape
                out.rapid(dest)
                out.rapid(at - (s * self.escape).conjugate())
                (out.rapid if k == 0 else out.feed)(at)
                x -= self.delta
                break


def corner(kind: str, size: float, at: complex) -> Element:
    """A fillet (A) or chamfer (C) marker at the end of the element before it."""
    if kind == "A":
        return Arc(False, at, at, at, finish=size)
    return Line(at, at, finish=size)


__all__ = ["Profile", "ProfileError", "Line", "Arc", "corner"]
