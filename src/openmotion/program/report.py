"""What a program run did: a summary (text) and an interactive HTML report (report_html.py).

The runner keeps one trace sample per controller cycle (time, command index, commanded
and actual (feedback) positions in machine units). From it: run time, path length (linear
axes), the largest contour error against the PROGRAMMED geometry (lines: distance to the
segment; arcs: radial distance in the arc's plane; G0 rapids are not contour moves and are
skipped; at a sample the error is the smallest over the executing command and its
neighbours, so a blended corner counts its deviation from the corner, not from one side),
measured on the actual positions (what the machine did: planner deviation, tracking lag and
the count quantisation) and on the commanded ones (the planner's share alone); the largest
following error per moving axis; the I/O events and faults.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MotionError
from . import canon

if TYPE_CHECKING:
    from .runner import ProgramRunner


@dataclass(frozen=True)
class AxisFollowing:
    """The largest following error of one axis during a run."""
    letter: str
    max_error: float                # machine units (deg on rotary axes), absolute value
    line: int                       # source line executing then (0: none)
    time: float                     # s after the run started
    units: str = "mm"
    count: float = 0.0              # one feedback count in the same units (quantisation)


@dataclass(frozen=True)
class RunSummary:
    state: str
    passes: int
    run_time: float                 # s of controller time
    distance: float                 # machine units along the linear axes
    max_contour_error: float        # machine units
    max_error_line: int
    outputs: int                    # output events (immediate and synced)
    faults: list[str] = field(default_factory=list)
    lines: int = 0                  # program lines with motion
    units: str = "mm"
    # the contour error of the commanded positions (the planner's share; max_contour_error
    # is measured on the actual positions the back end reported)
    commanded_contour_error: float = 0.0
    commanded_error_line: int = 0
    # per moving axis: the largest |commanded - actual| and the line where it occurred
    following: tuple[AxisFollowing, ...] = ()


def _lag_cycles(t: np.ndarray, cmd: np.ndarray, act: np.ndarray) -> int:
    """How many cycles the actual positions trail the commanded ones, generously: twice
    the largest |following error| / commanded speed over the samples moving at >= 10 % of
    the peak speed, plus one cycle (0 when actual follows commanded within a cycle)."""
    if len(t) < 3:
        return 0
    speed = np.linalg.norm(np.gradient(cmd, t, axis=0), axis=1)
    lag = np.linalg.norm(cmd - act, axis=1)
    moving = speed >= 0.1 * float(speed.max()) if speed.max() > 0.0 else speed > 0.0
    if not moving.any():
        return 0
    period = float(np.median(np.diff(t)))
    worst = float(np.max(lag[moving] / speed[moving]))
    if period <= 0.0 or worst <= period:
        return 0
    return min(len(t), int(np.ceil(2.0 * worst / period)) + 1)


def contour_errors(run: ProgramRunner, actual: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Per trace sample: contour error (machine units, NaN when no contour move runs) and
    the command index executing. `actual`: measured on the actual (feedback) positions,
    which trail the commanded ones: a sample is then compared with every command executed
    over the lag (`_lag_cycles`) besides its neighbours; False: the commanded positions."""
    t, idx, pos = run.trace()
    lag = 0
    if actual:
        act = run.actual_trace()
        lag = _lag_cycles(t, pos, act)
        pos = act
    err = np.full(len(t), np.nan)
    # the lowest command a sample may still be on: the one executing `lag` cycles before
    # (forward-filled over samples where none runs; the first one run if none ran then)
    ran = idx[idx >= 0]
    n_of = np.arange(len(idx))
    last = np.maximum.accumulate(np.where(idx >= 0, n_of, 0)) if len(idx) else n_of
    before = idx[last[np.maximum(n_of - lag, 0)]]
    if len(ran):
        before = np.where(before >= 0, before, ran[0])
    geo = _Geometry(run)
    if not len(geo.kind):  # no group command at all (outputs, dwells only)
        return err, idx
    kind = geo.kind[np.clip(idx, 0, len(geo.kind) - 1)]
    rows = np.nonzero((idx >= 0) & (idx < len(geo.kind)) & (kind == _CUT))[0]
    if not len(rows):
        return err, idx
    k, p = idx[rows], pos[rows]
    low = np.minimum(before[rows], k) - 1
    best = np.full(len(rows), np.inf)
    # every candidate command from the lowest one a sample may be on to the next one; a
    # rapid neighbour counts: a G64 blend joins it to the cut, and the blend starts on the
    # rapid (the executed path is within P of the programmed one)
    for back in range(int(np.max(k - low)) + 2):
        n = k + 1 - back
        ok = (n >= low) & (n >= 0) & (n < len(geo.kind))
        n = np.where(ok, n, 0)
        ok &= geo.kind[n] != _NONE
        if not ok.any():
            continue
        d = np.full(len(rows), np.inf)
        line = ok & ~geo.arc[n]
        if line.any():
            d[line] = _seg_dists(p[line], geo.a[n[line]], geo.b[n[line]])
        arc = ok & geo.arc[n]
        if arc.any():
            d[arc] = geo.arc_dists(p[arc], n[arc])
        best = np.minimum(best, d)
    err[rows] = best
    return err, idx


_NONE, _MOVE, _CUT = 0, 1, 2   # no line/arc; a rapid line/arc; a contour (feed) move


class _Geometry:
    """The programmed lines and arcs by group command index, as arrays (machine units), so
    contour errors are computed for all samples at once."""

    def __init__(self, run: ProgramRunner) -> None:
        m = max(run.op_of, default=-1) + 1
        dim = len(run.letters)
        ppu = run.scales.ppu
        self.kind = np.zeros(m, dtype=np.int8)
        self.arc = np.zeros(m, dtype=bool)
        self.a = np.zeros((m, dim))
        self.b = np.zeros((m, dim))
        arcs: dict[int, canon.ArcMove] = {}
        for n, o in run.op_of.items():
            if o.kind not in ("line", "arc") or n < 0:
                continue
            self.kind[n] = _MOVE if o.rapid else _CUT
            if isinstance(o.source, canon.ArcMove):
                self.arc[n] = True
                arcs[n] = o.source
            else:
                assert o.target is not None
                self.a[n] = run.starts_of[n] / ppu
                self.b[n] = o.target / ppu
        # arc parameters: plane axes, centre, start/end in the plane, radii, sweep, sense
        self.pi = np.zeros(m, dtype=int)
        self.pj = np.ones(m, dtype=int) if dim > 1 else np.zeros(m, dtype=int)
        self.par = np.zeros((m, 11))
        for n, arc in arcs.items():
            i, j = arc.plane
            self.pi[n], self.pj[n] = i, j
            a0 = math.atan2(arc.start[j] - arc.centre[j], arc.start[i] - arc.centre[i])
            turn = 1.0 if arc.direction == canon.Direction.CCW else -1.0
            self.par[n] = (arc.centre[i], arc.centre[j], arc.start[i], arc.start[j],
                           arc.end[i], arc.end[j], arc.radius, arc.end_radius, arc.sweep,
                           a0, turn)

    def arc_dists(self, p: np.ndarray, n: np.ndarray) -> np.ndarray:
        """Distance of each point p[r] to arc n[r] in the arc's plane: radial within the
        arc's sweep (a slight spiral counts its radius change as error, an upper bound),
        to the nearer end point outside it."""
        r = np.arange(len(n))
        x, y = p[r, self.pi[n]], p[r, self.pj[n]]
        cx, cy, sx, sy, ex, ey, r0, r1, sweep, a0, turn = self.par[n].T
        dx, dy = x - cx, y - cy
        radial = np.abs(np.hypot(dx, dy) - 0.5 * (r0 + r1)) + 0.5 * np.abs(r1 - r0)
        phi = np.mod(turn * (np.arctan2(dy, dx) - a0), 2.0 * math.pi)
        ends = np.minimum(np.hypot(x - sx, y - sy), np.hypot(x - ex, y - ey))
        inside = (sweep >= 2.0 * math.pi) | (phi <= sweep)
        return np.where(inside, radial, ends)


def _seg_dists(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point p[r] to the segment a[r]-b[r]."""
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    u = np.einsum("ij,ij->i", p - a, d) / np.where(dd > 0.0, dd, 1.0)
    u = np.where(dd > 0.0, np.clip(u, 0.0, 1.0), 0.0)
    return np.linalg.norm(p - (a + u[:, None] * d), axis=1)


def following_errors(run: ProgramRunner) -> np.ndarray:
    """Per trace cycle and group axis: commanded minus actual (feedback) position, machine
    units (deg on rotary axes); rows as `run.trace()`."""
    return run.trace()[2] - run.actual_trace()


def moving_axes(pos: np.ndarray) -> list[int]:
    """Columns of a trace's positions that move during the run."""
    return [k for k in range(pos.shape[1]) if len(pos) and np.ptp(pos[:, k]) > 1e-9]


def worst(err: np.ndarray, idx: np.ndarray, run: ProgramRunner) -> tuple[float, int, int]:
    """The largest contour error, its sample and source line; (0, -1, 0) when none."""
    if not np.any(np.isfinite(err)):
        return 0.0, -1, 0
    k = int(np.nanargmax(err))
    return float(err[k]), k, run.line_of(int(idx[k]))


def summarize(run: ProgramRunner) -> RunSummary:
    """Figures of a finished (or stopped) run."""
    t, idx, pos = run.trace()
    lin = ~run.scales.rotary
    dist = float(np.sum(np.linalg.norm(np.diff(pos[:, lin], axis=0), axis=1))) \
        if len(t) > 1 and lin.any() else 0.0
    emax, _, eline = worst(contour_errors(run, actual=True)[0], idx, run)
    cmax, _, cline = worst(contour_errors(run)[0], idx, run)
    fe = np.abs(following_errors(run))
    following = []
    for k in moving_axes(pos):
        w = int(np.argmax(fe[:, k]))
        following.append(AxisFollowing(
            letter=run.letters[k], max_error=float(fe[w, k]), line=run.line_of(int(idx[w])),
            time=float(t[w] - run.t_start),
            units="deg" if run.scales.rotary[k] else run.machine_units,
            count=float(1.0 / abs(run.scales.ppu[k]))))
    end = run.t_end if run.t_end > 0.0 else run.t_start
    end = max(end, float(t[-1])) if len(t) else end   # an abort's stop is traced to rest
    return RunSummary(
        state=run.state.value, passes=run.passes_done, run_time=float(end - run.t_start),
        distance=dist, max_contour_error=emax, max_error_line=eline,
        outputs=sum(e.kind in ("output", "sync_output") for e in run.events),
        faults=[e.text for e in run.events if e.kind == "fault"],
        lines=len({o.line for o in run.ops if o.kind in ("line", "arc")}),
        units=run.machine_units, commanded_contour_error=cmax, commanded_error_line=cline,
        following=tuple(following))


def format_summary(s: RunSummary) -> str:
    """The text `openmotion run` prints."""
    def at(line: int) -> str:
        return f" (line {line})" if line else ""

    out = [f"state          {s.state} ({s.passes} pass(es))",
           f"run time       {s.run_time:.3f} s",
           f"distance       {s.distance:.3f} {s.units}",
           f"contour error  {s.max_contour_error:.6f} {s.units} max{at(s.max_error_line)},"
           " actual positions",
           f"  commanded    {s.commanded_contour_error:.6f} {s.units} max"
           f"{at(s.commanded_error_line)}"]
    out += [f"following {f.letter:<4} {f.max_error:.6f} {f.units} max{at(f.line)}"
            f" at {f.time:.3f} s" + (", within one count" if f.max_error <= f.count * (1 + 1e-9)
                                     else "") for f in s.following]
    out += [f"motion lines   {s.lines}",
           f"I/O events     {s.outputs}",
           f"faults         {len(s.faults)}"]
    out += [f"  fault: {f}" for f in s.faults]
    return "\n".join(out)


def g54_origin(run: ProgramRunner, parameters: Mapping[int, float]) -> dict[str, float]:
    """Program zero of G54 per runner axis letter (machine units) from the numbered
    parameters the job ran with (#5221 + the letter's place in XYZABCUVW; 0 when unset)."""
    from .options import AXIS_LETTERS

    return {k: float(parameters.get(5221 + AXIS_LETTERS.index(k), 0.0)) for k in run.letters}


def write_report(run: ProgramRunner, out_dir: str | Path, name: str = "report",
                 options: str = "", origin: Mapping[str, float] | None = None) -> Path:
    """Write `<out_dir>/<name>.html`, the interactive report (report_html.py figures,
    report_page.py page, one file with plotly.js embedded); its path. `options`: a line on the
    machine and run options shown above the summary. `origin`: program zero per axis
    letter in machine units (`g54_origin`): positions are drawn in program coordinates;
    None: in machine coordinates."""
    if not isinstance(name, str) or not name or "/" in name or "\\" in name:
        raise MotionError(f"name must be a plain file name, got {name!r}")
    if origin is not None and (not isinstance(origin, Mapping) or any(
            k not in run.letters or not isinstance(v, float | int) or isinstance(v, bool)
            or not math.isfinite(v) for k, v in origin.items())):
        raise MotionError(f"origin must map the program's axis letters "
                          f"{''.join(run.letters)} to finite positions, got {origin!r}")
    from .report_page import write_page

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    s = summarize(run)
    err, _ = contour_errors(run, actual=True)
    zero = None if origin is None else np.array([float(origin.get(k, 0.0))
                                                 for k in run.letters])
    return write_page(run, s, format_summary(s), err, out / f"{name}.html", options, zero)
