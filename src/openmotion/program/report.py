"""What a program run did: a summary (text) and an HTML report with embedded SVG figures.

The runner keeps one trace sample per controller cycle (time, command index, positions in
machine units). From it: run time, path length (linear axes), the largest contour error
against the PROGRAMMED geometry (lines: distance to the segment; arcs: radial distance in
the arc's plane; G0 rapids are not contour moves and are skipped; at a sample the error is
the smallest over the executing command and its neighbours, so a blended corner counts its
deviation from the corner, not from one side), the I/O events and faults.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import MotionError
from ..svgplot import path_chart, step_chart, time_charts
from . import canon

if TYPE_CHECKING:
    from .runner import ProgramRunner, RunEvent


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


def _figures(run: ProgramRunner) -> list[tuple[str, str]]:
    """The report's figures as inline SVG, drawn at the resolution they are shown at
    (svgplot.py: never more points than pixels), so any trace is drawn in milliseconds."""
    t, _, pos = run.trace()
    figs: list[tuple[str, str]] = []
    if len(t) >= 2:
        v = np.gradient(pos, t, axis=0)
        lin = ~run.scales.rotary
        speed = np.linalg.norm(v[:, lin], axis=1) * 60.0 if lin.any() else np.zeros(len(t))
        units = run.machine_units
        if pos.shape[1] >= 2:
            figs.append(("Path", path_chart(
                pos[:, :2], speed, f"{run.letters[0]} ({units})",
                f"{run.letters[1]} ({units})", f"speed ({units}/min)",
                "path coloured by speed")))
        series = [(f"{letter} ({'deg' if run.scales.rotary[k] else units}/s)", v[:, k])
                  for k, letter in enumerate(run.letters)]
        figs.append(("Velocity per axis", time_charts(t - run.t_start, series, "time (s)")))
    io_ev = [e for e in run.events if e.index is not None]
    if io_ev:
        lanes = []
        for n in sorted({e.index for e in io_ev}):
            ev = [e for e in io_ev if e.index == n]
            ts = [run.t_start] + [e.t for e in ev] + [max(run.t_end, ev[-1].t)]
            lv = [0] + [int(bool(e.level)) for e in ev] + [int(bool(ev[-1].level))]
            lanes.append((f"do{n}", np.array(ts) - run.t_start, np.array(lv, dtype=float)))
        figs.append(("Outputs", step_chart(lanes, "time (s)")))
    return figs


def _event_rows(events: list[RunEvent], limit: int = 2000) -> str:
    rows = [f"<tr><td>{e.t:.4f}</td><td>{html.escape(e.kind)}</td><td>{e.line}</td>"
            f"<td>{html.escape(e.text)}</td></tr>" for e in events[:limit]]
    if len(events) > limit:
        rows.append(f"<tr><td colspan=4>... {len(events) - limit} more</td></tr>")
    return "\n".join(rows)


def write_report(run: ProgramRunner, out_dir: str | Path, name: str = "report") -> Path:
    """Write `<out_dir>/<name>.html` (summary, figures as inline SVG, events); its path."""
    if not isinstance(name, str) or not name or "/" in name or "\\" in name:
        raise MotionError(f"name must be a plain file name, got {name!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    s = summarize(run)
    title = html.escape(run.file or "program")
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>openmotion run: {title}"
             "</title><style>body{font-family:sans-serif;margin:2em}table{border-collapse:"
             "collapse}td,th{border:1px solid #ccc;padding:2px 8px}</style></head><body>",
             f"<h1>openmotion run: {title}</h1><pre>{html.escape(format_summary(s))}</pre>"]
    for heading, svg in _figures(run):
        parts.append(f"<h2>{heading}</h2>{svg}")
    parts.append("<h2>Events</h2><table><tr><th>t (s)</th><th>kind</th><th>line</th>"
                 f"<th>what</th></tr>{_event_rows(run.events)}</table></body></html>")
    path = out / f"{name}.html"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path

