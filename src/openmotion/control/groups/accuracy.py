"""Pulse accuracy of a recorded run: how far the integer counts strayed from the path.

Issue 4 item 6: the integer command counts of all axes must follow the ideal path within
the quantization bound, half a pulse per axis with the half-pulse rule (control.home.pulserule).
The counts only change at pulses, and between two pulses the deviation of the moving
command is largest at their instants, so checking the counts just before and just after
every pulse of every axis finds the supremum of the error over the run.

`count_accuracy` works on arrays (any recording); `pulse_accuracy` takes them from a
controller whose hardware records pulses (`SimMachine.record_pulses`) and from its motion
history (the planned, ideal positions).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import MotionError, check_finite
from ...path import PathElement
from .pathexec import contour_error

if TYPE_CHECKING:
    from ..core.controller import Controller


@dataclass(frozen=True)
class PulseAccuracy:
    """Largest deviations of the integer counts of a run (pulses)."""

    axis_error: tuple[float, ...]     # per axis: max |count - commanded position|
    command_error: tuple[float, ...]  # per axis: max |commanded - planned position|
    contour_error: float              # max distance of the count point to the path
    contour_time: float               # when that maximum happened
    samples: int                      # instants checked (every pulse, plus the ends)


def count_accuracy(times: np.ndarray, before: np.ndarray, after: np.ndarray,
                   commanded: np.ndarray, planned: np.ndarray,
                   elements: Sequence[PathElement]) -> PulseAccuracy:
    """Accuracy from arrays: at each instant `times[i]` the counts of every axis just before
    (`before[i]`) and just after it (`after[i]`), the position the pulse generators were
    commanded to follow (`commanded[i]`) and the planned one (`planned[i]`); rows are
    instants, columns axes, in the frame of `elements`."""
    t = np.asarray(times, dtype=float)
    b, a, c, p = (np.asarray(x, dtype=float) for x in (before, after, commanded, planned))
    if t.ndim != 1 or len(t) == 0:
        raise MotionError(f"times must be a non-empty 1-D array, got shape {t.shape}")
    for name, x in (("before", b), ("after", a), ("commanded", c), ("planned", p)):
        if x.ndim != 2 or x.shape != b.shape or x.shape[0] != len(t):
            raise MotionError(f"{name} must have one row per time ({len(t)}) and one "
                              f"column per axis like before {b.shape}, got shape {x.shape}")
    if not elements:
        raise MotionError("elements must name at least one path element")
    axis_err = np.maximum(np.abs(b - c), np.abs(a - c)).max(axis=0)
    cmd_err = np.abs(c - p).max(axis=0)
    dist = contour_error(np.concatenate([b, a]), elements)
    k = int(np.argmax(dist))
    return PulseAccuracy(tuple(float(e) for e in axis_err), tuple(float(e) for e in cmd_err),
                         float(dist[k]), float(t[k % len(t)]), len(t))


def pulse_accuracy(ctl: Controller, axes: Sequence[int | str], elements: Sequence[PathElement],
                   t0: float, t1: float) -> PulseAccuracy:
    """Accuracy of the pulses `axes` emitted in [t0, t1] against `elements` (in the axes'
    pulse frame, as the group ran them), the commanded positions and the planned positions
    of `ctl.history`.

    Needs a hardware pulse record (`SimMachine.record_pulses()` before the run). Command
    transforms (control.loops.compensation) add to the pulses on purpose: measure without them.
    """
    hw = ctl.hardware
    pulse_record = getattr(hw, "pulse_record", None)
    if pulse_record is None:
        raise MotionError("pulse_accuracy needs hardware that records pulses "
                          "(SimMachine.record_pulses)")
    t0 = check_finite("t0", t0)
    t1 = check_finite("t1", t1)
    if not t0 < t1:
        raise MotionError(f"t1 must be > t0, got t0={t0!r}, t1={t1!r}")
    if isinstance(axes, str) or len(axes) == 0:
        raise MotionError(f"axes must be a non-empty sequence of axes, got {axes!r}")
    idx = [ctl.axis(a).index for a in axes]
    recs = [pulse_record(i) for i in idx]
    pulses = [r.pulses() for r in recs]
    inside = [tk[(tk >= t0) & (tk <= t1)] for tk, _ in pulses]
    times = np.unique(np.concatenate([[t0, t1], *inside]))
    before = np.empty((len(times), len(idx)))
    after = np.empty_like(before)
    for col, (rec, (tk, ck)) in enumerate(zip(recs, pulses, strict=True)):
        full = np.concatenate([[rec.start_count], ck])
        before[:, col] = full[np.searchsorted(tk, times, side="left")]
        after[:, col] = full[np.searchsorted(tk, times, side="right")]
    commanded = np.stack([r.command_at(times) for r in recs], axis=1)
    planned = np.stack([np.asarray(ctl.history.position_at(i, times)) for i in idx], axis=1)
    return count_accuracy(times, before, after, commanded, planned, elements)
