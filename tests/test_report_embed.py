"""The HTML pages are one self-contained file: plotly's gl3d partial bundle is shipped
gzipped as package data, embedded as base64 and inflated in the browser; every trace type
the pages draw is in it, and chromium draws every figure with it."""

from __future__ import annotations

import gzip
import re
import tomllib
from pathlib import Path, PurePosixPath

import numpy as np
import pytest

from longrun import long_run
from openmotion.cli import main
from openmotion.program import plotly_embed
from pagecheck import assert_self_contained, draw, figures, trace_types

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def pages(tmp_path_factory, laser_report):
    """A 2-D report (laser_contour: conftest.laser_report), a 3-D one, a profile and a
    trace page (paths)."""
    from openmotion.plot import plot_profile, plot_trace
    from test_plot import scurve, trace

    out = tmp_path_factory.mktemp("pages")
    prog = out / "helix.ngc"
    prog.write_text("G21 G90 F1200\nG0 X0 Y0 Z0\nM62 P0\nG1 X5\nG2 X5 Y0 Z-2 I-5 J0\n"
                    "M63 P0\nG0 Z5\nM2\n")
    assert main(["run", str(prog), "--out", str(out)]) == 0
    plot_profile(scurve(), out / "move.png", html=True)
    plot_trace(trace(), out / "trace.png", html=True)
    paths = {name: out / f"{name}.html" for name in ("helix", "move", "trace")}
    return {"laser_contour": laser_report / "laser_contour.html", **paths}


def test_the_bundle_is_package_data_with_its_licence_and_version():
    js = gzip.decompress(plotly_embed.BUNDLE.read_bytes()).decode()
    name, version = plotly_embed.bundle_version().split()
    assert name == "plotly.js-gl3d-dist-min" and f"v{version}" in js[:200]
    assert "MIT" in (plotly_embed.VENDOR / "LICENSE").read_text()
    globs = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"]["openmotion"]
    for f in plotly_embed.VENDOR.iterdir():
        rel = PurePosixPath(f.relative_to(ROOT / "src" / "openmotion").as_posix())
        assert any(rel.match(g) for g in globs), rel
    assert "program/vendor" in (ROOT / "MANIFEST.in").read_text()


def test_the_bundle_matches_the_plotly_that_writes_the_figures():
    # python plotly writes figure JSON for the plotly.js it bundles: the embedded bundle is
    # the same major version (tools/update_plotly_bundle.sh picks that version by default)
    from plotly.offline import get_plotlyjs

    py_js = re.search(r"plotly\.js v(\d+)\.", get_plotlyjs()[:200]).group(1)
    assert plotly_embed.bundle_version().split()[1].split(".")[0] == py_js


def test_every_page_is_one_file_and_uses_only_the_bundles_trace_types(pages):
    have = plotly_embed.bundle_trace_types()
    assert {"scatter", "scatter3d"} <= have and "heatmap" not in have   # the partial bundle
    seen: set[str] = set()
    for path in pages.values():
        text = path.read_text()
        assert_self_contained(text)
        assert figures(text)
        seen |= trace_types(text)
    assert seen == {"scatter", "scatter3d"} and seen <= have
    assert sorted(p.name for p in pages["move"].parent.glob("*.js")) == []


def test_chromium_draws_every_figure_with_the_embedded_bundle(pages, tab):
    for path in pages.values():
        got = draw(path, tab)
        assert got["version"] == plotly_embed.bundle_version().split()[1]
        figs = figures(path.read_text())
        assert set(got["figures"]) == set(figs)
        for div, f in figs.items():
            assert got["figures"][div] == {"traces": len(f["data"]), "drawn": True}, div
        assert not got["errors"], got["errors"]


def _spiral(path: Path, n: int, notes: bool) -> None:
    """n G1 lines of about 0.1 mm along a spiral (about one cycle each at F6000); `notes`:
    a comment line after each (a listing twice as long)."""
    k = np.arange(n)
    r = 5 + 20 * k / n
    th = 0.1 * k / r
    note = "(next point on the spiral)\n" if notes else ""
    path.write_text("G21 G90 G64 P0.05 F6000\n" + "".join(
        f"G1 X{a:.4f} Y{b:.4f}\n{note}" for a, b in zip(r * np.cos(th), r * np.sin(th),
                                                        strict=True)) + "M2\n")


@pytest.mark.parametrize("n, notes", [(100_000, False)] if long_run() else [(10_000, True)])
def test_a_long_programs_page_is_one_file_under_2_mb(tmp_path, n, notes):
    # 10,000 moves and a comment after each: the largest page there is (the path keeps the
    # first and last sample of every command up to 20,000 such points, a longer program
    # drops them; the listing shows 20,000 lines at most); a 100k-line program with --long
    prog = tmp_path / "spiral.ngc"
    _spiral(prog, n, notes)
    assert main(["run", str(prog), "--out", str(tmp_path)]) == 0
    page = tmp_path / "spiral.html"
    assert page.stat().st_size < 2_000_000, page.stat().st_size
    assert_self_contained(page.read_text())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spiral.html", "spiral.ngc"]


def test_step_lanes_keep_exactly_their_changes():
    import numpy as np

    from openmotion.program.report_html import SCREEN_POINTS, step_indices

    level = np.zeros(100_000)
    level[30_000:30_010] = 1.0
    level[70_000:] = 2.0
    keep = step_indices(level)
    assert keep.tolist() == [0, 30_000, 30_010, 70_000, 99_999]
    # held from each kept sample to the next (shape "hv"), the kept samples give every value
    held = level[keep][np.searchsorted(keep, np.arange(len(level)), side="right") - 1]
    assert np.array_equal(held, level)
    busy = np.arange(10 * SCREEN_POINTS) % 2.0  # more changes than pixels: decimated
    assert len(step_indices(busy)) < len(busy)
    assert step_indices(np.zeros(0)).tolist() == [] and step_indices(np.ones(1)).tolist() == [0]
