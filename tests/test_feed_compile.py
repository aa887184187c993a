"""The compile's fast pieces give what the code they replace gives, bit for bit.

- convert.py: G0/G1 (`canon.Rapid`/`canon.Feed`) ops made by `_line_op` and the inline
  uniform feed equal the `Op(...)` the general branch made from `np.linalg.norm` and
  `feed_of` (checked against that reference, written out here);
- fastpath.py: the soft-limit bounds of a plain line accept and refuse exactly the points
  `Modal.check_limits` does, with its error (the general path's) at the tolerance's edge.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.program import GCodeError, GCodeOptions, canon, compile_text
from openmotion.program.convert import ConvertOptions, Op, Scales, _line_op, convert
from openmotion.program.interp import _compile_full
from openmotion.units import AxisUnits

LETTERS = ["X", "Y", "Z", "A"]
UNITS = [AxisUnits("X", "mm", 1000.0, 1, 50.0), AxisUnits("Y", "mm", 2000.0, -1, 80.0),
         AxisUnits("Z", "mm", 500.0, 1, 20.0), AxisUnits("A", "degree", 100.0, 1, 900.0)]
SCALES = Scales.build(UNITS, LETTERS, "mm")


def reference(cmds: list, scales: Scales, start: np.ndarray, opts: ConvertOptions) -> list[Op]:
    """The general branch of convert() for Rapid/Feed before the fast path (verbatim)."""
    lin = ~scales.rotary
    vmax = scales.vmax_units
    sys_max = float(np.max(vmax))
    pos = np.asarray(start, dtype=float) / scales.ppu
    ops = []
    for cmd in cmds:
        end = np.asarray(cmd.end, dtype=float)
        d = end - pos
        length = float(np.linalg.norm(d))
        if length == 0.0:
            continue
        if isinstance(cmd, canon.Rapid):
            moving = np.abs(d) > 0.0
            f = float(np.min(opts.rapid_ratio * vmax[moving] * length / np.abs(d[moving])))
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(end), min(f, sys_max),
                          True, end=end, source=cmd))
        else:
            if cmd.duration is not None:
                f = length / cmd.duration
            else:
                f = cmd.feed_per_s
                moving = np.abs(d) > 0.0
                if opts.feed_mode == "exact" and (moving & lin).any() and \
                        (moving & ~lin).any():
                    f *= length / float(np.linalg.norm(d[lin]))
            if not f > 0.0 or not math.isfinite(f):
                raise GCodeError(f"feed {cmd.feed_per_s:g} units/s gives no usable speed",
                                 line=cmd.line, file=cmd.file)
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(end), min(f, sys_max),
                          end=end, source=cmd))
        pos = end
    return ops


def same_ops(a: list[Op], b: list[Op]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        dx, dy = vars(x), vars(y)
        assert list(dx) == list(dy)  # the same attributes, in the same order
        for k in dx:
            u, v = dx[k], dy[k]
            if isinstance(u, np.ndarray):
                assert u.dtype == v.dtype and u.tobytes() == v.tobytes(), k
            else:
                assert type(u) is type(v) and (u == v or u is v), k


def test_line_op_is_the_dataclass_op():
    end = np.array([1.0, -2.0, 3.0, 0.5])
    cmd = canon.Feed(tuple(end), 10.0, 7, "f.ngc", None)
    made = _line_op(7, "f.ngc", end * SCALES.ppu, 10.0, False, end, cmd)
    same_ops([made], [Op("line", 7, "f.ngc", end * SCALES.ppu, 10.0, end=end, source=cmd)])
    assert type(made) is Op and made.source is cmd
    ref = Op("line", 7, "f.ngc", end, 10.0, end=end, source=cmd)
    # a key-sharing dict as the dataclass's own (a copied table would be ~1.6x larger)
    assert sys.getsizeof(vars(made)) == sys.getsizeof(vars(ref))
    with pytest.raises(AttributeError):
        made.feed = 1.0  # type: ignore[misc]  # still frozen


coord = st.one_of(st.sampled_from([0.0, 1.0, -1.0, 1e-200, 5e-324]),
                  st.floats(-500, 500, allow_nan=False))
move = st.tuples(st.sampled_from(["G0", "G1", "G1", "G93"]),
                 st.lists(coord, min_size=4, max_size=4),
                 st.sampled_from([10.0, 40.0, 1e9, 0.0, -1.0, math.inf]), st.booleans())


@settings(max_examples=300, deadline=None)
@given(st.lists(move, min_size=1, max_size=30), st.sampled_from(["uniform", "exact"]),
       st.sampled_from([1.0, 0.3]))
def test_lines_convert_as_the_general_branch(moves, mode, ratio):
    cmds: list = []
    last: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)
    for k, (kind, xs, feed, repeat) in enumerate(moves, 1):
        end = last if repeat else tuple(xs)  # zero-length moves are dropped
        if kind == "G0":
            cmds.append(canon.Rapid(end, k, "f.ngc"))
        else:
            cmds.append(canon.Feed(end, feed, k, "f.ngc", 0.5 if kind == "G93" else None))
        last = end
    opts = ConvertOptions(ratio, mode)
    start = np.array([0.0, 0.0, 0.0, 0.0])

    def run(fn):
        try:
            return fn(cmds, SCALES, start, opts), None
        except GCodeError as exc:
            return None, (str(exc), exc.line)
        except ArithmeticError as exc:  # (feed_of, "exact": a linear part of 1e-200)
            return None, (type(exc).__name__, str(exc))

    mine, err = run(convert)
    ref, ref_err = run(reference)
    assert err == ref_err
    if ref is not None:
        same_ops(mine, ref)


LIMITS = [(-100.0, 100.0), (-0.5, 250.0), None, (-1e-12, 1e-12)]
OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}, soft_limits=LIMITS)


def _edges(lim: float) -> list[float]:
    tol = 1e-9 * max(1.0, abs(lim))
    return [lim + tol, lim - tol, math.nextafter(lim + tol, math.inf),
            math.nextafter(lim - tol, -math.inf), lim, math.nextafter(lim, math.inf)]


EDGES = sorted({v for lim in LIMITS if lim for x in lim for v in _edges(x)})


def outcome(fn, text):
    try:
        return "ok", repr(fn(text, OPTS, "f.ngc"))
    except GCodeError as exc:
        return "error", str(exc)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from("XYZA"), st.sampled_from(EDGES)), min_size=1,
                max_size=6), st.sampled_from(["G0", "G1"]))
def test_soft_limit_edges_as_the_general_path(words, g):
    lines = ["G1 F600"] + [f"{g} {letter}{np.format_float_positional(v)}"
                           for letter, v in words]
    text = "\n".join(lines)
    assert outcome(compile_text, text) == outcome(_compile_full, text)


def test_convert_restores_the_collector():
    import gc

    bad = [canon.Feed((1.0, 0.0, 0.0, 0.0), 0.0, 3, "f.ngc", None)]  # F 0: refused
    start = np.zeros(4)
    assert gc.isenabled()
    with pytest.raises(GCodeError, match="no usable speed"):
        convert(bad, SCALES, start, ConvertOptions())
    assert gc.isenabled()
    gc.disable()
    try:
        convert(bad[:0], SCALES, start, ConvertOptions())
        assert not gc.isenabled()  # a caller's pause is left as it was
    finally:
        gc.enable()
