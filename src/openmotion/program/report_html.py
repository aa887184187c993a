"""The interactive run report: one HTML page of plotly figures (zoom, pan, hover).

Figures: the path in program coordinates (machine position minus the G54 origin the job
ran with; XY, and 3-D when a third linear axis moves) with rapids dashed and feeds coloured
by the programmed feed, the stretches where each output was on drawn over it, the
soft-limit box (the travel between the limit switches) and the worst contour error marked;
path speed, commanded (programmed feed times the override) against executed; per moving
axis position, velocity, acceleration and jerk against time; contour error against time;
outputs as off/on lanes. report_page.py puts the summary, the extents table, the event
table and the program listing (linked to the path both ways) around them. Lengths, feeds
and speeds are drawn in the program's units (`drawn_units`: G20 -> in, in/min).

Traces are decimated to what a screen shows (`screen_indices`: per pixel column the first,
lowest, highest and last sample), so a 100k-line program gives a page of the same size as a
short one. The page embeds plotly's gl3d partial bundle (plotly_embed.py: scatter and
scatter3d, about 740 kB as gzip + base64), so it is one file that works offline.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .options import MM_PER_INCH
from .report import contour_errors, following_errors, moving_axes

if TYPE_CHECKING:
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


def step_indices(level: np.ndarray, n: int = SCREEN_POINTS) -> np.ndarray:
    """Indices of a step signal (a lane drawn with shape "hv") that draw exactly like all of
    it: the first and last sample and every sample where the level changes; a signal that
    changes more often than 4 * n times falls back to `screen_indices`."""
    m = len(level)
    change = np.flatnonzero(np.diff(level) != 0) + 1
    if len(change) > 4 * n:
        return screen_indices(level, n)
    return np.unique(np.concatenate([[0], change, [m - 1]])) if m else np.arange(0)


#: At most this many extra samples (the first and last of every command) are kept on the
#: path so a click on a listing line finds its stretch even when it is shorter than a pixel.
MAX_BOUNDARY_POINTS = 20_000


def path_indices(pos: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """`screen_indices` of the path plus the first and last sample of every command (when
    there are at most MAX_BOUNDARY_POINTS of them), so every line has points to show."""
    keep = screen_indices(pos)
    if len(idx) < 2:
        return keep
    change = np.nonzero(np.diff(idx) != 0)[0]
    edges = np.concatenate([change, change + 1])
    if edges.size <= MAX_BOUNDARY_POINTS:
        keep = np.union1d(keep, edges)
    return keep


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


def _figures(run: ProgramRunner, err: np.ndarray,
             origin: np.ndarray | None = None) -> list[tuple[str, object]]:
    """The report's figures, (heading, plotly figure) in page order. `err`: the contour
    error per sample of the ACTUAL positions (`contour_errors(run, actual=True)`; its worst
    point is marked where the machine was); `origin`: machine position of program zero per
    runner axis (None: drawn in machine coordinates)."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    t, idx, pos = run.trace()
    figs: list[tuple[str, object]] = []
    if len(t) < 2:
        return figs
    units, to_prog = drawn_units(run)
    k_lin = float(to_prog[~run.scales.rotary][0]) if (~run.scales.rotary).any() else 1.0
    rot = run.scales.rotary
    unit_of = [("deg" if rot[k] else units) for k in range(len(run.letters))]
    tt = t - run.t_start
    moving = moving_axes(pos)
    act = run.actual_trace()
    # the back end reports a following error beyond the count quantisation: the actual
    # path is drawn beside the commanded one
    lags = bool(np.any(np.abs(pos - act) > 1.5 / np.abs(run.scales.ppu)))
    lin = [k for k in moving if not rot[k]]
    # ---- path in program coordinates: rapids dashed, feeds coloured by the programmed
    # feed (units/min), output-on stretches over it, soft-limit box, worst contour error
    rapid = np.array([bool(getattr(run.op_of.get(int(i)), "rapid", False)) for i in idx])
    cutting = np.array([run.op_of.get(int(i)) is not None for i in idx]) & ~rapid
    feed = np.array([60.0 * k_lin * float(getattr(run.op_of.get(int(i)), "feed", 0.0))
                     for i in idx])
    off = np.zeros(pos.shape[1]) if origin is None else np.asarray(origin, dtype=float)
    frame = "machine" if origin is None else "program"
    ppos = (pos - off) * to_prog      # drawn in the program's units (drawn_units)
    pact = (act - off) * to_prog
    err = err * k_lin
    v, a, j = _derivatives(t, pos * to_prog)
    if len(lin) >= 2:
        cols = lin[:3]
        fig = go.Figure()
        keep = path_indices(ppos[:, lin], idx)
        p, r, f = _f32(ppos[keep]), ~cutting[keep], _f32(feed[keep])
        lines = np.array([run.line_of(int(i)) for i in idx[keep]], dtype=np.int32)
        # hover from the per-point data (customdata: the line; the colour: the feed), not
        # a text per point (a third of a long program's path data)
        at = "<br>" + ", ".join(f"{run.letters[c]} %{{{a}:.5g}}" for a, c in zip("xyz", cols,
                                                                                  strict=False))
        feed_at = ("%{line.color:.5g}" if len(cols) == 3 else "%{marker.color:.5g}")
        hover_rapid = f"line %{{customdata}}, rapid{at}<extra></extra>"
        hover_feed = f"line %{{customdata}}, feed {feed_at} {units}/min{at}<extra></extra>"
        cuts = f[~r]
        lo, hi = (float(cuts.min()), float(cuts.max())) if cuts.size else (0.0, 1.0)
        if hi - lo <= 1e-6 * max(abs(hi), 1.0):  # one feed: a scale from 0 to it
            lo, hi = 0.0, max(hi, 1.0)
        scale = {"colorscale": "Viridis", "cmin": lo, "cmax": max(hi, lo + 1e-9),
                 "colorbar": {"title": f"feed ({units}/min)"}}  # the cuts' feeds only
        three = len(cols) == 3
        kind = go.Scatter3d if three else go.Scatter

        def xyz(pts: np.ndarray) -> dict[str, object]:
            return dict(zip("xyz", (pts[:, c] for c in cols), strict=False))

        # output-on stretches first: the path's colours are drawn over them
        for n, on in output_levels(run, t[keep]).items():
            fig.add_trace(kind(**xyz(p * np.where(on, 1.0, np.nan)[:, None]), mode="lines",
                               name=f"do{n} on", hoverinfo="skip", opacity=0.4,
                               line={"width": 12 if three else 10,
                                     "color": _COLOURS[(n + 3) % len(_COLOURS)]}))
        fig.add_trace(kind(**xyz(p * np.where(r, 1.0, np.nan)[:, None]), mode="lines",
                           name="rapid", customdata=lines, hovertemplate=hover_rapid,
                           line={"dash": "dash", "color": "#999"}))
        if three:
            fig.add_trace(kind(**xyz(p * np.where(r, np.nan, 1.0)[:, None]), mode="lines",
                               name="feed", customdata=lines, hovertemplate=hover_feed,
                               line={"color": f, "width": 4, **scale}))
        else:
            fig.add_trace(kind(**xyz(p * np.where(r, np.nan, 1.0)[:, None]),
                               mode="markers+lines", name="feed", customdata=lines,
                               hovertemplate=hover_feed, line={"color": "#bbb", "width": 1},
                               marker={"color": f, "size": 4, **scale}))
        if lags:
            fig.add_trace(kind(**xyz(_f32(pact[keep])), mode="lines",
                               name="actual (feedback)", hoverinfo="skip",
                               line={"color": "#d62728", "width": 2 if three else 1}))
        box = soft_limit_box(run, [int(c) for c in cols], off, to_prog)
        if box is not None:
            # a part (its cuts) far smaller than the travel is a dot inside the box: the box
            # is then listed in the legend (one click shows it) but not drawn at first
            span = np.nanmax(box[:, cols], axis=0) - np.nanmin(box[:, cols], axis=0)
            part = ppos[cutting][:, cols] if cutting.any() else ppos[:, cols]
            small = bool(np.all(np.ptp(part, axis=0) < 0.2 * span))
            fig.add_trace(kind(**xyz(box), mode="lines", name="soft limits (travel)",
                               hoverinfo="skip", visible="legendonly" if small else True,
                               line={"dash": "dot", "color": "#c33"}))
        if np.any(np.isfinite(err)):
            w = int(np.nanargmax(err))
            fig.add_trace(kind(**xyz(pact[w:w + 1]), mode="markers", name="worst contour "
                               f"error {err[w]:.4g} {units} (line {run.line_of(int(idx[w]))}, "
                               "actual position)",
                               marker={"symbol": "x", "size": 8 if three else 14,
                                       "color": "red"}))
        fig.add_trace(kind(**xyz(np.zeros((0, pos.shape[1]))), mode="lines",
                           name="selected line", hoverinfo="skip",
                           line={"color": "#e6007e", "width": 6 if three else 4}))
        labels = [f"{run.letters[c]} ({units}, {frame})" for c in cols]
        if three:
            fig.update_layout(scene={"xaxis_title": labels[0], "yaxis_title": labels[1],
                                     "zaxis_title": labels[2], "aspectmode": "data"})
        else:
            fig.update_xaxes(title=labels[0])
            fig.update_yaxes(title=labels[1], scaleanchor="x", scaleratio=1)
        fig.update_layout(height=620, clickmode="event")
        figs.append(("Path", fig))
    # ---- path speed: commanded (programmed feed times the override) against executed
    if lin:
        ovr = run.group.override / 100.0 if run.group is not None else 1.0
        speed = np.linalg.norm(v[:, lin], axis=1) * 60.0
        keep = screen_indices(np.column_stack([speed, feed]))
        fig = go.Figure()
        fig.add_trace(go.Scatter(x=_f32(tt[keep]),
                                 y=_f32(np.where(cutting, feed * ovr, np.nan)[keep]),
                                 name=f"commanded feed (programmed x {ovr * 100:g} %)",
                                 line={"shape": "hv", "dash": "dot"}))
        fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(speed[keep]),
                                 name="executed path speed"))
        fig.update_layout(height=320, xaxis_title="time (s)",
                          yaxis_title=f"speed ({units}/min)")
        figs.append(("Path speed", fig))
    # ---- per moving axis: position, velocity, acceleration, jerk
    if moving:
        rows = [(f"position ({frame})", ppos, ""), ("velocity", v, "/s"),
                ("acceleration", a, "/s²"), ("jerk", j, "/s³")]
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
        fig.update_layout(height=900)
        figs.append(("Axes (only those that move)", fig))
    # ---- contour error against time (actual and commanded positions), worst marked
    if np.any(np.isfinite(err)):
        cerr = contour_errors(run)[0] * k_lin
        keep = screen_indices(np.column_stack([err, cerr]))
        w = int(np.nanargmax(err))
        fig = go.Figure()
        fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(err[keep]),
                                 name="contour error (actual positions)"))
        fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(cerr[keep]),
                                 name="commanded positions", line={"dash": "dot"}))
        fig.add_trace(go.Scatter(x=[tt[w]], y=[err[w]], mode="markers", name=f"worst, line "
                                 f"{run.line_of(int(idx[w]))}",
                                 marker={"symbol": "x", "size": 12, "color": "red"}))
        fig.update_layout(height=300, xaxis_title="time (s)", yaxis_tickformat="~g",
                          yaxis_title=f"contour error ({units})")
        figs.append(("Contour error", fig))
    # ---- following error (commanded - actual) per moving axis
    if moving:
        fe = following_errors(run) * to_prog
        fig = go.Figure()
        for k in moving:
            keep = screen_indices(fe[:, k])
            fig.add_trace(go.Scatter(x=_f32(tt[keep]), y=_f32(fe[keep, k]),
                                     name=f"{run.letters[k]} ({unit_of[k]})",
                                     line={"color": _COLOURS[k % len(_COLOURS)]}))
        shown = " or ".join(sorted({unit_of[k] for k in moving}))
        fig.update_layout(height=300, xaxis_title="time (s)", yaxis_tickformat="~g",
                          yaxis_title=f"commanded - actual ({shown})")
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
    for _, fig in figs:
        _tidy(fig)
    return figs


def _tidy(fig: object) -> None:
    """One layout for every figure: the legend in a row above the plot (clear of the axis
    titles below it), and margins no wider than the titles need."""
    titled = bool(fig.layout.annotations)  # type: ignore[attr-defined]  # subplot titles
    legend = ({"yref": "container", "y": 1.0, "yanchor": "top"} if titled
              else {"yref": "paper", "y": 1.0, "yanchor": "bottom"})
    fig.update_layout(margin={"t": 70 if titled else 40, "b": 50, "l": 70, "r": 30},  # type: ignore[attr-defined]
                      legend={"orientation": "h", "x": 0.0, **legend})


_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")


def output_levels(run: ProgramRunner, times: np.ndarray) -> dict[int, np.ndarray]:
    """Per output channel that changed during the run: its level (bool) at `times`
    (controller time, as the trace)."""
    out: dict[int, np.ndarray] = {}
    for n in sorted({e.index for e in run.events if e.index is not None}):
        ev = sorted((e for e in run.events if e.index == n), key=lambda e: e.t)
        at = np.array([e.t for e in ev])
        lv = np.array([bool(e.level) for e in ev])
        k = np.searchsorted(at, times, side="right") - 1
        out[n] = np.where(k >= 0, lv[np.maximum(k, 0)], False)
    return out


def drawn_units(run: ProgramRunner) -> tuple[str, np.ndarray]:
    """The unit the report draws lengths in, the program's at its first motion ("in" for
    G20, "mm" for G21; `run.program_units`), and per runner axis the factor from machine
    units to it (1 on rotary axes, which stay in degrees)."""
    prog = run.program_units.units
    k = 1.0 if prog == run.machine_units else (1.0 / MM_PER_INCH if prog == "inch"
                                                else MM_PER_INCH)
    return ("in" if prog == "inch" else "mm"), np.where(run.scales.rotary, 1.0, k)


def soft_limits(run: ProgramRunner) -> list[tuple[float, float] | None]:
    """Per runner axis: the travel between its limit switches (machine units), the range
    the runner refuses moves beyond; None when the axis has no switch."""
    from .runner import travel_limits

    ctl = run.group._ctl if run.group is not None else None
    if ctl is None:
        return [None] * len(run.letters)
    return [travel_limits(ctl, i) for i in run.axis_indices]


def soft_limit_box(run: ProgramRunner, cols: list[int], off: np.ndarray,
                   scale: np.ndarray | None = None) -> np.ndarray | None:
    """The soft-limit box of axes `cols` (2 or 3) as a polyline (NaN rows split edges), in
    the drawn frame (minus `off`, times `scale` per axis: `drawn_units`); None when one of
    them has an open side."""
    lims = soft_limits(run)
    sel = [lims[c] for c in cols]
    if any(s is None or not all(map(math.isfinite, s)) for s in sel):
        return None
    f = np.ones(len(run.letters)) if scale is None else np.asarray(scale, dtype=float)
    lo = (np.array([s[0] for s in sel]) - off[cols]) * f[cols]  # type: ignore[index]
    hi = (np.array([s[1] for s in sel]) - off[cols]) * f[cols]  # type: ignore[index]
    n = len(cols)
    corner = [lo + (hi - lo) * np.array([(k >> b) & 1 for b in range(n)]) for k in range(2 ** n)]
    rows: list[np.ndarray] = []
    for a in range(2 ** n):  # every edge: corners differing in one coordinate
        for b in range(n):
            if not a >> b & 1:
                rows += [corner[a], corner[a | 1 << b], np.full(n, np.nan)]
    box = np.full((len(rows), len(run.letters)), np.nan)
    box[:, cols] = np.array(rows)
    return box
