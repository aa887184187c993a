"""Small inline-SVG charts for run reports, drawn at the resolution they are shown at.

A report figure is a few hundred pixels wide, so no line needs more points than it has
pixels: time series keep each pixel column's first, lowest, highest and last sample (spikes
survive), paths keep the samples where the drawn point moves to another pixel. With that
and no plotting library to import, a report is written in milliseconds for any trace.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: Colours of the speed scale, slow to fast (viridis anchors).
_RAMP = ((68, 1, 84), (59, 82, 139), (33, 145, 140), (94, 201, 98), (253, 231, 37))
_BINS = 16
_LINES = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")
_FONT = "font-family='sans-serif' font-size='11'"


def nice_ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    """About n round tick values covering [lo, hi]."""
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        return [lo]
    raw = (hi - lo) / max(1, n)
    mag = 10.0 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * mag >= raw)
    first = math.ceil(lo / step - 1e-9) * step
    return [first + k * step for k in range(int((hi - first) / step + 1e-9) + 1)]


def column_envelope(t: Array, y: Array, columns: int) -> tuple[Array, Array]:
    """Per pixel column of t: the first, lowest, highest and last sample, in time order
    (at most 4*columns points; the drawn line looks the same as the full one)."""
    n = t.size
    if n <= 4 * columns or n < 2:
        return t, y
    span = float(t[-1] - t[0]) or 1.0
    col = np.minimum(((t - t[0]) / span * columns).astype(np.int64), columns - 1)
    edges = np.flatnonzero(np.diff(col)) + 1  # t rises: each column is one run
    starts = np.concatenate(([0], edges))
    ends = np.concatenate((edges, [n])) - 1
    keep = np.zeros(n, dtype=bool)
    keep[starts] = True
    keep[ends] = True
    for key in (y, -y):  # sorted by column, then value: each run's first is its extreme
        keep[np.lexsort((key, col))[starts]] = True
    idx = np.flatnonzero(keep)
    return t[idx], y[idx]


def pixel_path(xy: Array, pixel: float) -> Array:
    """Indices of the samples of a 2-D path where the drawn point enters another pixel
    (plus the last sample)."""
    if len(xy) < 3 or pixel <= 0.0:
        return np.arange(len(xy))
    cell = np.floor(xy / pixel).astype(np.int64)
    moved = np.any(cell[1:] != cell[:-1], axis=1)
    idx = np.concatenate(([0], np.flatnonzero(moved) + 1))
    if idx[-1] != len(xy) - 1:
        idx = np.append(idx, len(xy) - 1)
    return idx


def _colour(f: float) -> str:
    f = min(1.0, max(0.0, f)) * (len(_RAMP) - 1)
    k = min(int(f), len(_RAMP) - 2)
    w = f - k
    c = [round(a + (b - a) * w) for a, b in zip(_RAMP[k], _RAMP[k + 1], strict=True)]
    return f"#{c[0]:02x}{c[1]:02x}{c[2]:02x}"


def _num(v: float) -> str:
    return f"{v:.1f}"


def _label(v: float) -> str:
    return f"{v:.6g}"


class _Frame:
    """A plot area of w x h pixels at (x0, y0) for data ranges; maps data to pixels."""

    def __init__(self, x0: float, y0: float, w: float, h: float, xr: tuple[float, float],
                 yr: tuple[float, float]) -> None:
        self.x0, self.y0, self.w, self.h = x0, y0, w, h
        self.xr = xr if xr[1] > xr[0] else (xr[0] - 1.0, xr[0] + 1.0)
        self.yr = yr if yr[1] > yr[0] else (yr[0] - 1.0, yr[0] + 1.0)

    def px(self, x: Array) -> Array:
        return self.x0 + (x - self.xr[0]) / (self.xr[1] - self.xr[0]) * self.w

    def py(self, y: Array) -> Array:
        return self.y0 + self.h - (y - self.yr[0]) / (self.yr[1] - self.yr[0]) * self.h

    def axes(self, xlabel: str, ylabel: str) -> list[str]:
        out = [f"<rect x='{_num(self.x0)}' y='{_num(self.y0)}' width='{_num(self.w)}' "
               f"height='{_num(self.h)}' fill='none' stroke='#444'/>"]
        for v in nice_ticks(*self.xr):
            x = float(self.px(np.array(v)))
            out.append(f"<line x1='{_num(x)}' y1='{_num(self.y0 + self.h)}' x2='{_num(x)}' "
                       f"y2='{_num(self.y0 + self.h + 4)}' stroke='#444'/><text x='{_num(x)}' "
                       f"y='{_num(self.y0 + self.h + 15)}' text-anchor='middle' {_FONT}>"
                       f"{_label(v)}</text>")
        for v in nice_ticks(*self.yr):
            y = float(self.py(np.array(v)))
            out.append(f"<line x1='{_num(self.x0 - 4)}' y1='{_num(y)}' x2='{_num(self.x0)}' "
                       f"y2='{_num(y)}' stroke='#444'/><text x='{_num(self.x0 - 6)}' "
                       f"y='{_num(y + 4)}' text-anchor='end' {_FONT}>{_label(v)}</text>")
        out.append(f"<text x='{_num(self.x0 + self.w / 2)}' y='{_num(self.y0 + self.h + 30)}' "
                   f"text-anchor='middle' {_FONT}>{html.escape(xlabel)}</text>")
        cy = self.y0 + self.h / 2
        out.append(f"<text x='12' y='{_num(cy)}' text-anchor='middle' {_FONT} "
                   f"transform='rotate(-90 12 {_num(cy)})'>{html.escape(ylabel)}</text>")
        return out


def _polyline(xs: Array, ys: Array, colour: str, width: float = 1.2) -> str:
    pts = " ".join(f"{x:.1f},{y:.1f}" for x, y in zip(xs.tolist(), ys.tolist(), strict=True))
    return (f"<polyline points='{pts}' fill='none' stroke='{colour}' "
            f"stroke-width='{width}' stroke-linejoin='round'/>")


def _svg(width: int, height: int, body: list[str], title: str) -> str:
    head = (f"<svg xmlns='http://www.w3.org/2000/svg' width='{width}' height='{height}' "
            f"viewBox='0 0 {width} {height}'>")
    t = f"<text x='{width / 2:.0f}' y='14' text-anchor='middle' {_FONT}>{html.escape(title)}"
    return "".join([head, t, "</text>", *body, "</svg>"])


def path_chart(xy: Array, speed: Array, xlabel: str, ylabel: str, speed_label: str,
               title: str, size: int = 520) -> str:
    """The 2-D path, equal scale, coloured by speed (16 colour steps), with a colour bar."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = float(max(hi[0] - lo[0], hi[1] - lo[1])) or 1.0
    mid = 0.5 * (lo + hi)
    xr = (float(mid[0] - 0.55 * span), float(mid[0] + 0.55 * span))
    yr = (float(mid[1] - 0.55 * span), float(mid[1] + 0.55 * span))
    fr = _Frame(60, 24, size, size, xr, yr)
    idx = pixel_path(xy, 1.1 * span / size)
    p, sp = xy[idx], speed[idx]
    s_lo, s_hi = float(np.min(speed)), float(np.max(speed))
    scale = (sp - s_lo) / (s_hi - s_lo) if s_hi > s_lo else np.zeros(len(sp))
    bins = np.minimum((scale * _BINS).astype(np.int64), _BINS - 1)
    X, Y = fr.px(p[:, 0]), fr.py(p[:, 1])
    body = fr.axes(xlabel, ylabel)
    cuts = np.concatenate(([0], np.flatnonzero(np.diff(bins)) + 1, [len(bins)]))
    for a, b in zip(cuts[:-1].tolist(), cuts[1:].tolist(), strict=True):
        e = min(b + 1, len(bins))  # overlap one point: the runs join
        if e - a >= 2:
            body.append(_polyline(X[a:e], Y[a:e], _colour((bins[a] + 0.5) / _BINS), 1.5))
    bx = 60 + size + 20
    for k in range(_BINS):
        y = 24 + size - (k + 1) * size / _BINS
        body.append(f"<rect x='{bx}' y='{y:.1f}' width='14' height='{size / _BINS + 0.5:.1f}' "
                    f"fill='{_colour((k + 0.5) / _BINS)}'/>")
    body.append(f"<text x='{bx + 18}' y='{24 + size}' {_FONT}>{_label(s_lo)}</text>"
                f"<text x='{bx + 18}' y='34' {_FONT}>{_label(s_hi)}</text>"
                f"<text x='{bx + 18}' y='{24 + size / 2:.0f}' {_FONT}>"
                f"{html.escape(speed_label)}</text>")
    return _svg(60 + size + 150, size + 70, body, title)


def time_charts(t: Array, series: Sequence[tuple[str, Array]], xlabel: str,
                width: int = 640, height: int = 110) -> str:
    """One panel per (label, values) over the shared time axis t, stacked."""
    body: list[str] = []
    top = 24
    for k, (label, y) in enumerate(series):
        tt, yy = column_envelope(t, y, width)
        fr = _Frame(70, top, width, height, (float(t[0]), float(t[-1])),
                    (float(np.min(y)), float(np.max(y))))
        body += fr.axes(xlabel if k == len(series) - 1 else "", label)
        body.append(_polyline(fr.px(tt), fr.py(yy), _LINES[k % len(_LINES)]))
        top += height + 40
    return _svg(width + 90, top, body, "")


def step_chart(lanes: Sequence[tuple[str, Array, Array]], xlabel: str, width: int = 640,
               height: int = 120) -> str:
    """Digital lanes (label, times, levels 0/1) as steps, lane n drawn at n + 0.8*level."""
    t_all = np.concatenate([t for _, t, _ in lanes])
    fr = _Frame(70, 24, width, height, (float(t_all.min()), float(t_all.max())),
                (-0.1, len(lanes) - 0.1))
    body = fr.axes(xlabel, "output")
    for n, (label, t, lv) in enumerate(lanes):
        ts = np.repeat(t, 2)[1:]
        ls = np.repeat(lv * 0.8 + n, 2)[:-1]
        body.append(_polyline(fr.px(ts), fr.py(ls), _LINES[n % len(_LINES)]))
        body.append(f"<text x='{70 + width + 4}' y='{float(fr.py(np.array(n + 0.4))):.1f}' "
                    f"{_FONT}>{html.escape(label)}</text>")
    return _svg(width + 120, height + 70, body, "")
