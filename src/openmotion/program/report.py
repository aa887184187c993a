"""What a program run did: a summary (text) and an interactive HTML report (report_html.py).

The runner keeps one trace sample per controller cycle (time, command index, positions in
machine units). From it: run time, path length (linear axes), the largest contour error
against the PROGRAMMED geometry (lines: distance to the segment; arcs: radial distance in
the arc's plane; G0 rapids are not contour moves and are skipped; at a sample the error is
the smallest over the executing command and its neighbours, so a blended corner counts its
deviation from the corner, not from one side), the I/O events and faults.
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


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    dd = float(d @ d)
    if dd == 0.0:
        return np.linalg.norm(p - a, axis=1)
    u = np.clip((p - a) @ d / dd, 0.0, 1.0)
    return np.linalg.norm(p - (a + u[:, None] * d), axis=1)


def _arc_dist(p: np.ndarray, arc: canon.ArcMove) -> np.ndarray:
    i, j = arc.plane
    rho = np.hypot(p[:, i] - arc.centre[i], p[:, j] - arc.centre[j])
    return np.abs(rho - 0.5 * (arc.radius + arc.end_radius)) + 0.5 * abs(arc.end_radius
                                                                          - arc.radius)


def contour_errors(run: ProgramRunner) -> tuple[np.ndarray, np.ndarray]:
    """Per trace sample: contour error (machine units, NaN when no contour move runs) and
    the command index executing."""
    t, idx, pos = run.trace()
    err = np.full(len(t), np.nan)
    starts = run.starts_of
    for k in np.unique(idx[idx >= 0]):
        op = run.op_of.get(int(k))
        if op is None or op.rapid or op.kind not in ("line", "arc"):
            continue
        sel = np.nonzero(idx == k)[0]
        best = np.full(len(sel), np.inf)
        for n in (k - 1, k, k + 1):
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
            best = np.minimum(best, d)
        err[sel] = best
    return err, idx


def following_errors(run: ProgramRunner) -> np.ndarray:
    """Per trace cycle and group axis: commanded minus actual (feedback) position, machine
    units (deg on rotary axes); rows as `run.trace()`."""
    return run.trace()[2] - run.actual_trace()


def summarize(run: ProgramRunner) -> RunSummary:
    """Figures of a finished (or stopped) run."""
    t, idx, pos = run.trace()
    lin = ~run.scales.rotary
    dist = float(np.sum(np.linalg.norm(np.diff(pos[:, lin], axis=0), axis=1))) \
        if len(t) > 1 and lin.any() else 0.0
    err, _ = contour_errors(run)
    if np.all(np.isnan(err)):
        emax, eline = 0.0, 0
    else:
        k = int(np.nanargmax(err))
        emax, eline = float(err[k]), run.line_of(int(idx[k]))
    end = run.t_end if run.t_end > 0.0 else (t[-1] if len(t) else run.t_start)
    return RunSummary(
        state=run.state.value, passes=run.passes_done, run_time=float(end - run.t_start),
        distance=dist, max_contour_error=emax, max_error_line=eline,
        outputs=sum(e.kind in ("output", "sync_output") for e in run.events),
        faults=[e.text for e in run.events if e.kind == "fault"],
        lines=len({o.line for o in run.ops if o.kind in ("line", "arc")}),
        units=run.machine_units)


def format_summary(s: RunSummary) -> str:
    """The text `openmotion run` prints."""
    out = [f"state          {s.state} ({s.passes} pass(es))",
           f"run time       {s.run_time:.3f} s",
           f"distance       {s.distance:.3f} {s.units}",
           f"contour error  {s.max_contour_error:.6f} {s.units} max"
           + (f" (line {s.max_error_line})" if s.max_error_line else ""),
           f"motion lines   {s.lines}",
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
    report_page.py page; plotly.min.js beside it); its path. `options`: a line on the
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
    err, _ = contour_errors(run)
    zero = None if origin is None else np.array([float(origin.get(k, 0.0))
                                                 for k in run.letters])
    return write_page(run, s, format_summary(s), err, out / f"{name}.html", options, zero)
