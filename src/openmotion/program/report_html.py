"""The interactive run report: one HTML page of plotly figures (zoom, pan, hover).

Figures: the path in machine coordinates (XY, and 3-D when a third linear axis moves) with
rapids dashed and feeds coloured by the programmed feed, the travel box and the worst
contour error marked; path speed, programmed against actual; per moving axis position,
velocity, acceleration and jerk against time; contour error against time; outputs as
off/on lanes; the summary and the event table on top of them.

Traces are decimated to what a screen shows (`screen_indices`: per pixel column the first,
lowest, highest and last sample), so a 100k-line program gives a page of the same size as a
short one. plotly.js (4.8 MB) is written once next to the page (`plotly.min.js`), so the
page itself stays small and the report folder works offline.
"""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .report import following_errors

if TYPE_CHECKING:
    from .report import RunSummary
    from .runner import ProgramRunner

#: Pixel columns a trace is drawn at (a wide figure); at most 4 samples kept per column.
SCREEN_POINTS = 1000


def screen_indices(y: np.ndarray, n: int = SCREEN_POINTS) -> np.ndarray:
    """Indices of `y` (1-D, or 2-D: columns share the indices) that draw like all of it at
    `n` pixel columns: per column the first, last, lowest and highest sample."""
    m = len(y)
    if m <= 4 * n:
        return np.arange(m)
    y2 = y.reshape(m, -1)
    edges = np.linspace(0, m, n + 1).astype(int)
    keep = [edges[:-1], edges[1:] - 1]
    for k in range(y2.shape[1]):
        col = np.nan_to_num(y2[:, k], nan=0.0)
        red_min = np.minimum.reduceat(col, edges[:-1])
        red_max = np.maximum.reduceat(col, edges[:-1])
        for red in (red_min, red_max):
            # the first index in each bucket holding the bucket's extreme
            hit = np.nonzero(col == np.repeat(red, np.diff(edges)))[0]
            bucket = np.searchsorted(edges, hit, side="right") - 1
            first = np.unique(bucket, return_index=True)[1]
            keep.append(hit[first])
    return np.unique(np.concatenate(keep))


def _f32(x: np.ndarray) -> np.ndarray:
    """Drawn data as float32 (plotly embeds it as binary: half the bytes, 7 digits)."""
    return np.asarray(x, dtype=np.float32)


def _derivatives(t: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, ...]:
    if len(t) < 3:
        z = np.zeros_like(pos)
        return z, z, z
    v = np.gradient(pos, t, axis=0)
    a = np.gradient(v, t, axis=0)
    j = np.gradient(a, t, axis=0)
    return v, a, j


def _figures(run: ProgramRunner, err: np.ndarray) -> list[tuple[str, object]]:
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    t, idx, pos = run.trace()
    figs: list[tuple[str, object]] = []
    if len(t) < 2:
        return figs
    units = run.machine_units
    rot = run.scales.rotary
    unit_of = [("deg" if rot[k] else units) for k in range(len(run.letters))]
    tt = t - run.t_start
    v, a, j = _derivatives(t, pos)
    moving = [k for k in range(pos.shape[1]) if np.ptp(pos[:, k]) > 1e-9]
    lin = [k for k in moving if not rot[k]]
    # ---- path: rapids dashed, feeds coloured by the programmed feed (units/min)
    rapid = np.array([bool(getattr(run.op_of.get(int(i)), "rapid", False)) for i in idx])
    cutting = np.array([run.op_of.get(int(i)) is not None for i in idx]) & ~rapid
    feed = np.array([60.0 * float(getattr(run.op_of.get(int(i)), "feed", 0.0)) for i in idx])
    if len(lin) >= 2:
        ax_x, ax_y = lin[0], lin[1]
        three = len(lin) >= 3
        fig = go.Figure()
        keep = screen_indices(pos[:, lin])
        p, r, f, ti = _f32(pos[keep]), ~cutting[keep], _f32(feed[keep]), idx[keep]
        lines = [run.line_of(int(i)) for i in ti]
        hover = [f"line {ln}, feed {fe:g} {units}/min" for ln, fe in zip(lines, f, strict=True)]
        cut = np.where(r, np.nan, 1.0)
        rap = np.where(r, 1.0, np.nan)
        cuts = f[~r]
        lo, hi = (float(cuts.min()), float(cuts.max())) if cuts.size else (0.0, 1.0)
        if hi - lo <= 1e-6 * max(abs(hi), 1.0):  # one feed: a scale from 0 to it
            lo, hi = 0.0, max(hi, 1.0)
        scale = {"colorscale": "Viridis", "cmin": lo, "cmax": max(hi, lo + 1e-9),
                 "colorbar": {"title": f"feed ({units}/min)"}}  # the cuts' feeds only
        labels = {"x": f"{run.letters[ax_x]} ({units}, machine)",
                  "y": f"{run.letters[ax_y]} ({units}, machine)"}
        if three:
            ax_z = lin[2]
            fig.add_trace(go.Scatter3d(
                x=p[:, ax_x] * rap, y=p[:, ax_y] * rap, z=p[:, ax_z] * rap, mode="lines",
                name="rapid", line={"dash": "dash", "color": "#999"}, hoverinfo="skip"))
            fig.add_trace(go.Scatter3d(
                x=p[:, ax_x] * cut, y=p[:, ax_y] * cut, z=p[:, ax_z] * cut, mode="lines",
                name="feed", text=hover, hoverinfo="text+x+y+z",
                line={"color": f, "width": 4, **scale}))
            fig.update_layout(scene={"xaxis_title": labels["x"], "yaxis_title": labels["y"],
                                     "zaxis_title": f"{run.letters[ax_z]} ({units}, machine)",
                                     "aspectmode": "data"})
        else:
            fig.add_trace(go.Scatter(x=p[:, ax_x] * rap, y=p[:, ax_y] * rap, mode="lines",
                                     name="rapid", line={"dash": "dash", "color": "#999"}))
            fig.add_trace(go.Scatter(
                x=p[:, ax_x] * cut, y=p[:, ax_y] * cut, mode="markers+lines", name="feed",
                text=hover, line={"color": "#bbb", "width": 1},
                marker={"color": f, "size": 4, **scale}))
            _travel_box(fig, run, ax_x, ax_y)
            if np.any(np.isfinite(err)):
                w = int(np.nanargmax(err))
                fig.add_trace(go.Scatter(
                    x=[pos[w, ax_x]], y=[pos[w, ax_y]], mode="markers", name="worst contour "
                    f"error {err[w]:.4g} {units} (line {run.line_of(int(idx[w]))})",
                    marker={"symbol": "x", "size": 14, "color": "red"}))
            fig.update_xaxes(title=labels["x"])
            fig.update_yaxes(title=labels["y"], scaleanchor="x", scaleratio=1)
        fig.update_layout(height=620, legend={"orientation": "h"})
        figs.append(("Path", fig))
    # ---- path speed: programmed feed (times the override it ran at) against actual
    if lin:
        speed = np.linalg.norm(v[:, lin], axis=1) * 60.0
        keep = screen_indices(np.column_stack([speed, feed]))
        fig = go.Figure()
        fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(np.where(cutting, feed, np.nan)[keep]),
                                 name="programmed feed", line={"shape": "hv", "dash": "dot"}))
        fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(speed[keep]),
                                 name="actual path speed"))
        fig.update_layout(height=320, xaxis_title="time (s)",
                          yaxis_title=f"speed ({units}/min)", legend={"orientation": "h"})
        figs.append(("Path speed", fig))
    # ---- per moving axis: position, velocity, acceleration, jerk
    if moving:
        rows = [("position", pos, ""), ("velocity", v, "/s"), ("acceleration", a, "/s²"),
                ("jerk", j, "/s³")]
        fig = make_subplots(rows=4, cols=1, shared_xaxes=True, vertical_spacing=0.04,
                            subplot_titles=[r[0] for r in rows])
        for row, (_, data, per) in enumerate(rows, start=1):
            for k in moving:
                keep = screen_indices(data[:, k])
                fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(data[keep, k]),
                                         name=run.letters[k],
                                         legendgroup=run.letters[k], showlegend=row == 1,
                                         line={"color": _COLOURS[k % len(_COLOURS)]}),
                              row=row, col=1)
            shown = sorted({unit_of[k] for k in moving})
            fig.update_yaxes(title_text=" or ".join(f"{u}{per}" for u in shown), row=row,
                             col=1)
        fig.update_xaxes(title_text="time (s)", row=4, col=1)
        fig.update_layout(height=900, legend={"orientation": "h"})
        figs.append(("Axes (only those that move)", fig))
    # ---- contour error against time, worst marked
    if np.any(np.isfinite(err)):
        keep = screen_indices(err)
        w = int(np.nanargmax(err))
        fig = go.Figure()
        fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(err[keep]), name="contour error"))
        fig.add_trace(go.Scatter(x=[tt[w]], y=[err[w]], mode="markers", name=f"worst, line "
                                 f"{run.line_of(int(idx[w]))}",
                                 marker={"symbol": "x", "size": 12, "color": "red"}))
        fig.update_layout(height=300, xaxis_title="time (s)",
                          yaxis_title=f"contour error ({units})")
        figs.append(("Contour error", fig))
    # ---- following error (commanded - actual) per moving axis
    if moving:
        fe = following_errors(run)
        fig = go.Figure()
        for k in moving:
            keep = screen_indices(fe[:, k])
            fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(fe[keep, k]),
                                     name=f"{run.letters[k]} ({unit_of[k]})",
                                     line={"color": _COLOURS[k % len(_COLOURS)]}))
        fig.update_layout(height=300, xaxis_title="time (s)", legend={"orientation": "h"},
                          yaxis_title="following error (commanded - actual)")
        figs.append(("Following error", fig))
    # ---- outputs: off/on lanes
    io_ev = [e for e in run.events if e.index is not None]
    if io_ev:
        fig = go.Figure()
        chans = sorted({e.index for e in io_ev})
        for lane, n in enumerate(chans):
            ev = [e for e in io_ev if e.index == n]
            ts = [0.0] + [e.t - run.t_start for e in ev] + [max(tt[-1], ev[-1].t - run.t_start)]
            lv = [0] + [int(bool(e.level)) for e in ev] + [int(bool(ev[-1].level))]
            fig.add_trace(go.Scatter(x=ts, y=[lane * 1.5 + x for x in lv], name=f"do{n}",
                                     line={"shape": "hv"}))
        fig.update_yaxes(tickvals=[lane * 1.5 + x for lane in range(len(chans)) for x in (0, 1)],
                         ticktext=[f"do{n} {s}" for n in chans for s in ("off", "on")])
        fig.update_layout(height=120 + 60 * len(chans), xaxis_title="time (s)")
        figs.append(("Outputs", fig))
    return figs


_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")


def _travel_box(fig: object, run: ProgramRunner, ax_x: int, ax_y: int) -> None:
    """The machine's travel (limit switch edges) as a dotted rectangle."""
    from .runner import travel_limits

    ctl = run.group._ctl if run.group is not None else None
    if ctl is None:
        return
    lx = travel_limits(ctl, run.axis_indices[ax_x])
    ly = travel_limits(ctl, run.axis_indices[ax_y])
    if lx is None or ly is None or not all(map(math.isfinite, (*lx, *ly))):
        return
    fig.add_shape(type="rect", x0=lx[0], x1=lx[1], y0=ly[0], y1=ly[1],  # type: ignore[attr-defined]
                  line={"dash": "dot", "color": "#c33"}, name="travel")


def _events_table(run: ProgramRunner, limit: int = 2000) -> str:
    rows = [f"<tr><td>{e.t - run.t_start:.4f}</td><td>{html.escape(e.kind)}</td>"
            f"<td>{e.line}</td><td>{html.escape(e.text)}</td></tr>"
            for e in run.events[:limit]]
    if len(run.events) > limit:
        rows.append(f"<tr><td colspan=4>... {len(run.events) - limit} more</td></tr>")
    return "\n".join(rows)


_STYLE = ("body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px}"
          "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 8px;"
          "text-align:left}pre{background:#f6f6f6;padding:.8em}h2{margin-top:1.5em}")


def write_html(run: ProgramRunner, summary: RunSummary, summary_text: str, err: np.ndarray,
               path: Path, options: str = "") -> Path:
    """Write the page to `path` and plotly.min.js beside it; the page's path."""
    title = html.escape(run.file or "program")
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>openmotion run: "
             f"{title}</title><script src='plotly.min.js'></script><style>{_STYLE}</style>"
             f"</head><body><h1>openmotion run: {title}</h1>"]
    if options:
        parts.append(f"<p>{html.escape(options)}</p>")
    parts.append(f"<pre>{html.escape(summary_text)}</pre>")
    for heading, fig in _figures(run, err):
        parts.append(f"<h2>{html.escape(heading)}</h2>")
        parts.append(fig.to_html(full_html=False, include_plotlyjs=False,  # type: ignore[attr-defined]
                                 config={"displaylogo": False, "responsive": True}))
    parts.append("<h2>Events</h2><table><tr><th>t (s)</th><th>kind</th><th>line</th>"
                 f"<th>what</th></tr>{_events_table(run)}</table></body></html>")
    path.write_text("\n".join(parts), encoding="utf-8")
    write_plotly_js(path.parent)
    return path


def write_plotly_js(folder: Path) -> Path:
    """plotly.min.js in `folder` (once: an existing copy of the same size is kept)."""
    from plotly.offline import get_plotlyjs

    js = get_plotlyjs()
    out = folder / "plotly.min.js"
    if not (out.exists() and out.stat().st_size == len(js.encode("utf-8"))):
        out.write_text(js, encoding="utf-8")
    return out
