"""control/groups/pathpoints.py: a chain's elements evaluated at once give, bit for bit, what each
element's own point/tangent gives (lines, arcs, helices, 3-D arcs, trimmed elements, and
element types the table does not know)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.control.groups.pathexec import Trimmed
from openmotion.control.groups.pathpoints import ElementTable
from openmotion.path import Arc, Arc3D, Line


class _Wrapped:
    """An element type the table does not know (it asks the element itself)."""

    def __init__(self, el) -> None:  # noqa: ANN001
        self.el = el
        for name in ("start", "end", "length", "dim", "max_curvature"):
            setattr(self, name, getattr(el, name))

    def point(self, s):  # noqa: ANN001, ANN201
        return self.el.point(s)

    def tangent(self, s):  # noqa: ANN001, ANN201
        return self.el.tangent(s)


def _on_circle(centre: tuple[float, float], start: np.ndarray, turn: float,
               z: float) -> list[float]:
    """The point `turn` radians from `start` around `centre` (plane XY), at height z."""
    r = math.hypot(start[0] - centre[0], start[1] - centre[1])
    a = math.atan2(start[1] - centre[1], start[0] - centre[0]) + turn
    return [centre[0] + r * math.cos(a), centre[1] + r * math.sin(a), z]


def _elements() -> list:
    line = Line([0.1, 0.2, 0.3], [3.3, 4.7, 0.9])
    arc = Arc(line.end, [3.1, 2.2], _on_circle((3.1, 2.2), line.end, -1.1, 0.9),
              direction="CW")
    helix = Arc(arc.end, [2.7, 0.35], _on_circle((2.7, 0.35), arc.end, 0.7, 3.4), turns=1)
    arc3 = Arc3D(helix.end, [0.3, 1.7, 3.1], [1.3, 0.55, 2.05])
    return [line, arc, helix, arc3, Line([1.3, 0.5, 2.0], [1.3, 0.5, 2.0]),  # zero length
            Trimmed(line, 1.25), Trimmed(arc, 0.3, 1.0), Trimmed(helix, 2.0),
            Trimmed(Trimmed(arc3, 0.1), 0.2), _Wrapped(arc), _Wrapped(line)]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=30), st.integers(0, 2**31))
def test_table_equals_each_elements_own_methods(fractions, seed):
    els = _elements()
    table = ElementTable(els)
    rng = np.random.default_rng(seed)
    k = rng.integers(0, len(els), size=len(fractions))
    lens = np.array([el.length for el in els])
    u = np.array(fractions) * lens[k]
    u[::3] = lens[k[::3]]  # the exact ends are snapped: include them
    pts = table.point(k, u)
    tans = table.tangent(k, u)
    for j, (i, s) in enumerate(zip(k, u, strict=True)):
        el = els[int(i)]
        assert np.array_equal(pts[j], el.point(np.array([s]))[0])
        assert np.array_equal(tans[j], el.tangent(np.array([s]))[0])
    assert np.array_equal(table.lengths, lens)
    straight = [i for i, el in enumerate(els) if el.max_curvature == 0.0]
    assert np.array_equal(table.line_tangents(np.array(straight)),
                          np.array([els[i].tangent(0.0) for i in straight]))


def test_joined_and_dropped_chains_carry_the_same_table_as_built_anew():
    """A streaming join builds its chain's table from the old rows and the new elements
    only (Chain.joined / Chain.dropped): every array equals a table built from scratch."""
    from openmotion.control.groups.pathexec import Chain
    from openmotion.control.groups.pathpoints import _FIELDS

    pts = [np.array([10.0 * k, 3.0 * (k % 2), 0.5 * k]) for k in range(8)]
    lines = [Line(a, b) for a, b in zip(pts, pts[1:], strict=False)]
    arc = Arc3D(lines[-1].end, lines[-1].end + [1.0, 1.0, 0.0], lines[-1].end + [2.0, 0.0, 0.0])
    chain = Chain(lines[:4], [0, 1, 2, 3])
    _ = chain.table
    trimmed_last = Trimmed(lines[3], 0.0, lines[3].length * 0.5)
    cases = [chain.joined(lines[4:], [4, 5, 6], None, None),
             chain.joined([arc], [7], None, None, replace_last=trimmed_last),
             chain.dropped(2)[0],
             chain.joined(lines[4:], [4, 5, 6], None, None).dropped(3)[0]]
    for c in cases:
        assert c._table is not None
        fresh = ElementTable(c.elements)
        assert tuple(c.table.elements) == tuple(fresh.elements)
        for name in _FIELDS:
            a, b = getattr(c.table, name), getattr(fresh, name)
            assert a.dtype == b.dtype and a.shape == b.shape, name
            assert np.array_equal(a, b), name
