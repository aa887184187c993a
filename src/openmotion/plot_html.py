"""Interactive (plotly) pages of a profile and of a recorded trace, in the run report's style.

`plot.plot_profile(..., html=True)` and `plot.plot_trace(..., html=True)` write these beside
their PNG: the same rows (position, velocity, acceleration, jerk of a profile; velocity,
position and the I/O and state lanes of a trace) with zoom, pan and hover, decimated to the
screen (`screen_indices`), one self-contained file with plotly.js embedded as the run report
is (program/plotly_embed.py).
"""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

_STYLE = ("body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px}"
          "p{color:#444}")


def _page(path: Path, title: str, subtitle: str, fig: Any) -> Path:
    from .program.plotly_embed import figure_html, head_scripts

    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">"
        f"<title>{html.escape(title)}</title>{head_scripts()}"
        f"<style>{_STYLE}</style></head>\n<body>\n<h1>{html.escape(title)}</h1>\n"
        f"<p>{html.escape(subtitle)}</p>\n{figure_html(fig, 'om-fig')}\n</body></html>\n",
        encoding="utf-8")
    return path


def _f32(x: NDArray[Any]) -> NDArray[np.float32]:
    return np.asarray(x, dtype=np.float32)


def profile_page(t: NDArray[Any], rows: Sequence[tuple[str, NDArray[Any]]],
                 boundaries: NDArray[Any], path: Path, title: str, subtitle: str) -> Path:
    """A profile's stacked rows (label, values at `t`) with the segment boundaries drawn."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    from .program.report_html import screen_indices

    fig = make_subplots(rows=len(rows), cols=1, shared_xaxes=True, vertical_spacing=0.03)
    for k, (label, y) in enumerate(rows, start=1):
        keep = screen_indices(np.asarray(y, dtype=float))
        fig.add_trace(go.Scatter(x=_f32(t[keep]), y=_f32(y[keep]), name=label,
                                 line={"width": 1.6}), row=k, col=1)
        fig.update_yaxes(title_text=label, row=k, col=1)
    for tk in boundaries:
        fig.add_vline(x=float(tk), line={"color": "#ccc", "width": 1})
    fig.update_xaxes(title_text="time (s)", row=len(rows), col=1)
    fig.update_layout(height=220 * len(rows) + 80, showlegend=False)
    return _page(path, title, subtitle, fig)


def trace_page(t: NDArray[Any], velocity: Mapping[str, NDArray[Any]],
               position: Mapping[str, NDArray[Any]], lanes: Sequence[tuple[str, NDArray[Any],
                                                                         list[str]]],
               units: tuple[str, str], path: Path, title: str) -> Path:
    """A recorded trace: velocity (name -> values), position (name -> values; dashed when
    the name says feedback) and digital lanes (label, level index per sample, level names),
    on one time axis. `units`: the velocity and position axis titles."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    from .program.report_html import screen_indices, step_indices

    n_rows = 2 + bool(lanes)
    lane_px = max(160, 26 * len(lanes))  # one readable label per lane
    heights = [300, 220, lane_px][:n_rows]
    fig = make_subplots(rows=n_rows, cols=1, shared_xaxes=True, vertical_spacing=0.04,
                        row_heights=[h / sum(heights) for h in heights],
                        subplot_titles=["velocity", "position",
                                        "I/O (off/on) and state (hover: its name)"][:n_rows])
    for row, series in ((1, velocity), (2, position)):
        for name, y in series.items():
            keep = screen_indices(np.asarray(y, dtype=float))
            fig.add_trace(go.Scatter(x=_f32(t[keep]), y=_f32(y[keep]), name=name,
                                     line={"dash": "dash" if "feedback" in name else "solid"}),
                          row=row, col=1)
    fig.update_yaxes(title_text=units[0], row=1, col=1)
    fig.update_yaxes(title_text=units[1], row=2, col=1)
    ticks: list[float] = []
    text: list[str] = []
    for lane, (label, level, names) in enumerate(lanes):
        keep = step_indices(np.asarray(level, dtype=float))  # exact for a step line
        top = max(len(names) - 1, 1)
        y = lane * 1.5 + np.asarray(level, dtype=float)[keep] / top
        hover = [f"{label}: {names[int(v)]}" for v in np.asarray(level)[keep]]
        fig.add_trace(go.Scatter(x=_f32(t[keep]), y=_f32(y), name=label, text=hover,
                                 hoverinfo="text+x", line={"shape": "hv"}, showlegend=False),
                      row=3, col=1)
        ticks.append(lane * 1.5 + 0.5)
        text.append(label)
    if lanes:
        fig.update_yaxes(tickvals=ticks, ticktext=text, row=3, col=1)
    fig.update_xaxes(title_text="time (s)", row=n_rows, col=1)
    fig.update_layout(height=sum(heights) + 60 * n_rows + 120, legend={"orientation": "h"})
    return _page(path, title, "", fig)
