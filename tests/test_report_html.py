"""The interactive run report: decimation keeps what a screen shows, the page stays small
for long programs, figures only for axes that move."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from longrun import size
from openmotion.cli import main
from openmotion.program.report_html import screen_indices


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, st.integers(1, 30_000),
              elements=st.floats(-1e6, 1e6, allow_nan=False)), st.integers(10, 500))
def test_screen_indices_keep_ends_and_every_columns_extremes(y, n):
    k = screen_indices(y, n)
    assert np.all(np.diff(k) > 0) and k[0] == 0 and k[-1] == len(y) - 1
    assert len(k) <= max(len(y), 0) and (len(y) <= 4 * n or len(k) <= 4 * n)
    edges = np.linspace(0, len(y), n + 1).astype(int)
    if len(y) > 4 * n:
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            if b > a:
                inside = k[(k >= a) & (k < b)]
                assert y[inside].max() == y[a:b].max() and y[inside].min() == y[a:b].min()


def test_long_program_page_stays_small_and_shows_moving_axes(tmp_path, capsys):
    # short moves (150: over 10,000 trace samples, more than a figure keeps; 3000 with
    # --long): the page is bounded by the screen, not by the program
    rng = np.random.default_rng(5)
    pts = rng.uniform(-5, 5, size=(size(150, 3000), 2))
    prog = tmp_path / "zigzag.ngc"
    prog.write_text("G21 G90 G64 P0.05 F6000\n" + "".join(
        f"G1 X{x:.3f} Y{y:.3f}\n" for x, y in pts) + "M2\n")
    assert main(["run", str(prog), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    page = (tmp_path / "zigzag.html")
    assert page.stat().st_size < 1_500_000
    html = page.read_text()
    assert '"name":"X"' in html and '"name":"Y"' in html
    assert '"name":"Z"' not in html and '"name":"A"' not in html   # they do not move
    assert "worst contour error" in html
