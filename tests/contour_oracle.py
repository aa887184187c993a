"""The contour error computed command by command, the way report.contour_errors did
before it was vectorised over all samples: the oracle of its equivalence tests."""

from __future__ import annotations

import math

import numpy as np

from openmotion.program import canon, report


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    dd = float(d @ d)
    if dd == 0.0:
        return np.linalg.norm(p - a, axis=1)
    u = np.clip((p - a) @ d / dd, 0.0, 1.0)
    return np.linalg.norm(p - (a + u[:, None] * d), axis=1)


def _arc_dist(p: np.ndarray, arc: canon.ArcMove) -> np.ndarray:
    """Distance in the arc's plane: radial within the arc's sweep (a slight spiral counts
    its radius change as error, an upper bound), to the nearer end point outside it."""
    i, j = arc.plane
    dx, dy = p[:, i] - arc.centre[i], p[:, j] - arc.centre[j]
    rho = np.hypot(dx, dy)
    radial = np.abs(rho - 0.5 * (arc.radius + arc.end_radius)) \
        + 0.5 * abs(arc.end_radius - arc.radius)
    if arc.sweep >= 2.0 * math.pi:
        return radial
    a0 = math.atan2(arc.start[j] - arc.centre[j], arc.start[i] - arc.centre[i])
    turn = 1.0 if arc.direction == canon.Direction.CCW else -1.0
    phi = np.mod(turn * (np.arctan2(dy, dx) - a0), 2.0 * math.pi)
    ends = np.minimum(np.hypot(p[:, i] - arc.start[i], p[:, j] - arc.start[j]),
                      np.hypot(p[:, i] - arc.end[i], p[:, j] - arc.end[j]))
    return np.where(phi <= arc.sweep, radial, ends)


def loop_contour_errors(run, actual: bool = False):
    """Per trace sample: contour error (machine units, NaN when no contour move runs) and
    the command index executing. `actual`: measured on the actual (feedback) positions,
    which trail the commanded ones: a sample is then compared with every command executed
    over the lag (`_lag_cycles`) besides its neighbours; False: the commanded positions."""
    t, idx, pos = run.trace()
    lag = 0
    if actual:
        act = run.actual_trace()
        lag = report._lag_cycles(t, pos, act)
        pos = act
    err = np.full(len(t), np.nan)
    starts = run.starts_of
    # the lowest command a sample may still be on: the one executing `lag` cycles before
    # (forward-filled over samples where none runs; the first one run if none ran then)
    ran = idx[idx >= 0]
    n_of = np.arange(len(idx))
    last = np.maximum.accumulate(np.where(idx >= 0, n_of, 0)) if len(idx) else n_of
    before = idx[last[np.maximum(n_of - lag, 0)]]
    if len(ran):
        before = np.where(before >= 0, before, ran[0])
    for k in np.unique(idx[idx >= 0]):
        op = run.op_of.get(int(k))
        if op is None or op.rapid or op.kind not in ("line", "arc"):
            continue
        sel = np.nonzero(idx == k)[0]
        low = np.minimum(before[sel], k) - 1
        best = np.full(len(sel), np.inf)
        for n in range(int(low.min()), int(k) + 2):
            o = run.op_of.get(int(n))
            # a rapid neighbour counts: a G64 blend joins it to the cut, and the blend
            # starts on the rapid (the executed path is within P of the programmed one)
            if o is None or o.kind not in ("line", "arc"):
                continue
            if isinstance(o.source, canon.ArcMove):
                d = _arc_dist(pos[sel], o.source)
            else:
                assert o.target is not None
                d = _seg_dist(pos[sel], starts[int(n)] / run.scales.ppu,
                              o.target / run.scales.ppu)
            best = np.minimum(best, np.where(low <= n, d, np.inf))
        err[sel] = best
    return err, idx
