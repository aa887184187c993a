"""svgplot: decimation to the drawn resolution keeps what the eye sees."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.svgplot import column_envelope, nice_ticks, path_chart, pixel_path, time_charts


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 50_000), st.integers(10, 800), st.integers(0, 2**31))
def test_column_envelope_keeps_every_columns_extremes(n, columns, seed):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 10.0, n))
    y = rng.normal(size=n)
    tt, yy = column_envelope(t, y, columns)
    assert len(tt) <= max(n, 4 * columns)
    assert np.all(np.diff(tt) >= 0.0)
    assert yy.max() == y.max() and yy.min() == y.min()
    assert tt[0] == t[0] and tt[-1] == t[-1]
    if n > 4 * columns:  # every column's min and max survive
        col = np.minimum(((t - t[0]) / (t[-1] - t[0]) * columns).astype(int), columns - 1)
        kept = set(zip(tt.tolist(), yy.tolist(), strict=True))
        for c in np.unique(col)[:20]:
            sel = col == c
            k_min = np.flatnonzero(sel)[np.argmin(y[sel])]
            assert (t[k_min], y[k_min]) in kept


def test_pixel_path_and_ticks():
    s = np.linspace(0.0, 200 * np.pi, 1_000_000)
    xy = np.column_stack([np.cos(s), np.sin(s)]) * 50.0
    idx = pixel_path(xy, 0.2)
    assert idx[0] == 0 and idx[-1] == len(xy) - 1
    assert len(idx) < 0.2 * len(xy)
    d = np.linalg.norm(np.diff(xy[idx], axis=0), axis=1)
    assert d.max() < 0.2 * np.sqrt(2) * 2.01  # no kept step skips more than a pixel cell
    assert nice_ticks(0.0, 10.0) == [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
    assert nice_ticks(3.0, 3.0) == [3.0]


def test_charts_are_svg_of_bounded_size():
    t = np.linspace(0.0, 100.0, 2_000_000)
    xy = np.column_stack([np.cos(t), np.sin(3 * t)])
    svg = path_chart(xy, np.abs(np.sin(t)), "X", "Y", "speed", "path")
    assert svg.startswith("<svg") and svg.endswith("</svg>")
    assert len(svg) < 2_000_000
    svg = time_charts(t, [("x", xy[:, 0]), ("y", xy[:, 1])], "time (s)")
    assert svg.count("<polyline") == 2 and len(svg) < 300_000
