"""The compare engine's per-cycle data: each source's motion over the cycle window.

A mixin of `compare.CompareEngine` (the state lives there). For the window (ta, t1] of one
scan it builds, once per source and cycle, what the jobs compare against: the track of an
axis in the command (DPOS) or feedback (MPOS, with the following-error model) counter
frame, its range, the arguments the compiled driver cuts its own track with, and the
path-length cycle of a vector source (VECTOR_MOVED). `_begin` starts a window and forgets
the previous one's caches. The jobs and the scan that reads these stay in compare.py.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .compare_jobs import AxisSource, VectorSource
from .compare_math import Track, VectorCycle, affine_track, history_track, track_range

if TYPE_CHECKING:
    from ..core.controller import Controller

Array = NDArray[np.float64]


class CompareTracks:
    """Mixin of `CompareEngine`: the sources' tracks, ranges and vector cycles of a scan."""

    ctl: Controller
    _win: tuple[float, float]
    _tracks: dict[AxisSource, Track]
    _specs: dict[AxisSource, tuple[Any, float, float, float, float, float]]
    _vcycles: dict[VectorSource, VectorCycle]
    _weights: dict[VectorSource, Array]
    _vectors: dict[VectorSource, float]
    _mpos_err: dict[int, float]
    _mpos_e1: dict[int, float]

    def _cmd_offset(self, axis: int) -> float:
        return -self.ctl.axes[axis].counters.pulses_from_command(0.0)

    def _mpos_error(self, axis: int) -> float:
        """Following error in feedback counts at the current time."""
        ctr = self.ctl.axes[axis].counters
        h = self.ctl.history.position_at(axis, self.ctl.time)
        return ctr.feedback_unwrapped() - ctr.move_ratio * (h + self._cmd_offset(axis))

    def _start_mpos(self, axis: int) -> None:
        if axis not in self._mpos_err:
            self._mpos_err[axis] = self._mpos_error(axis)

    def track(self, src: AxisSource) -> Track:
        """The source's track over this cycle (cached per cycle)."""
        tr = self._tracks.get(src)
        if tr is None:
            ta, t1 = self._win
            h = history_track(self.ctl.history, src.axis, ta, t1)
            off = self._cmd_offset(src.axis)
            if src.kind == "dpos":
                tr = affine_track(h, 1.0, off)
            else:
                r = self.ctl.axes[src.axis].counters.move_ratio
                e0 = self._mpos_err[src.axis]
                e1 = self._mpos_e1[src.axis]
                tr = affine_track(h, r, r * off, e0, (e1 - e0) / (t1 - ta), ta)
            self._tracks[src] = tr
        return tr

    def track_spec(self, src: AxisSource) -> tuple[Any, float, float, float, float, float]:
        """The source's track over this cycle as the compiled driver cuts it from the
        history itself: (the axis's record store, scale, offset, e0, slope, t_ref), the
        arguments of `affine_track` (cached per cycle; `track` builds the same rows)."""
        sp = self._specs.get(src)
        if sp is None:
            ta, t1 = self._win
            h = self.ctl.history._tracks[src.axis]
            off = self._cmd_offset(src.axis)
            if src.kind == "dpos":
                sp = (h, 1.0, off, 0.0, 0.0, 0.0)
            else:
                r = self.ctl.axes[src.axis].counters.move_ratio
                e0 = self._mpos_err[src.axis]
                e1 = self._mpos_e1[src.axis]
                sp = (h, r, r * off, e0, (e1 - e0) / (t1 - ta), ta)
            self._specs[src] = sp
        return sp

    def track_range(self, src: AxisSource) -> tuple[float, float]:
        """(min, max) of the source over this cycle (cached per cycle)."""
        r = self._ranges.get(src)
        if r is None:
            r = self._ranges[src] = track_range(self.track(src), *self._win)
        return r

    def window_inputs(self, axes: tuple[int, ...], kind: str
                      ) -> tuple[list[Track], list[tuple[float, float]]]:
        """The tracks and ranges of `axes` in frame `kind` over this cycle (cached per
        cycle: jobs on the same axes share them)."""
        key = (axes, kind)
        hit = self._windows.get(key)
        if hit is None:
            srcs = [AxisSource(a, kind) for a in axes]
            hit = self._windows[key] = ([self.track(s) for s in srcs],
                                        [self.track_range(s) for s in srcs])
        return hit

    def reachable(self, src: AxisSource, level: float) -> bool:
        """Can the source touch `level` in this cycle? (skips the exact solver if not)"""
        lo, hi = self.track_range(src)
        slack = 1e-9 * (abs(level) + 1.0)
        return lo - slack <= level <= hi + slack

    def vector_cycle(self, src: VectorSource) -> VectorCycle:
        vc = self._vcycles.get(src)
        if vc is None:
            ta, t1 = self._win
            w = self._weights.get(src)
            if w is None:
                w = self._weights[src] = src.weights
            stores = self.ctl.history._tracks  # (the rows as stored: history.rows)
            vc = VectorCycle([(stores[a],) for a in src.axes], w, ta, t1, self._vectors[src])
            self._vcycles[src] = vc
        return vc

    def _begin(self, ta: float, t1: float) -> None:
        self._win = (ta, t1)
        self._tracks = {}
        self._specs = {}
        self._ranges: dict[AxisSource, tuple[float, float]] = {}
        self._vcycles = {}
        self._windows: dict[tuple[tuple[int, ...], str],
                            tuple[list[Track], list[tuple[float, float]]]] = {}
