"""Plots: files are written (PNG signature, HTML with inline SVG), envelope, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.errors import MotionError
from openmotion.plot import envelope, plot_profile, plot_trace, profile_times
from openmotion.profile.segments import ProfileBuilder, empty_profile
from openmotion.recording import Recorder, load_trace
from pagecheck import assert_self_contained

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def scurve():
    b = ProfileBuilder(0.0)
    b.segment(0.1, 1000.0).segment(0.1, -1000.0).segment(0.5).segment(0.1, -1000.0)
    b.segment(0.1, 1000.0)
    return b.build(end_p=7.0)


def trace(n: int = 400) -> dict:
    pr = scurve()
    rec = Recorder(2, n)
    t = np.arange(n) * 2.5e-3
    s = pr.sample(t - 0.05)
    for k in range(n):
        rec.record(t[k], [s.p[k], -s.p[k]], [s.p[k] - 0.1, -s.p[k]], [s.v[k], -s.v[k]],
                   [int(s.v[k] > 0), 0], [int(s.v[k] > 5.0) | (1 << 5), 0])
    return rec.arrays()


def assert_png(path) -> None:
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert len(data) > 5000  # an actual figure, not an empty canvas


def assert_html(path, title: str) -> None:
    """An interactive plotly page (the run report's style), one file: plotly.js embedded."""
    text = path.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert "application/vnd.plotly+json" in text and f"<title>{title}</title>" in text
    assert_self_contained(text)
    assert not (path.parent / "plotly.min.js").exists()


def test_plot_profile_png_and_html(tmp_path) -> None:
    out = plot_profile(scurve(), tmp_path / "sub" / "move.png", title="S <move>", html=True)
    assert out == [tmp_path / "sub" / "move.png", tmp_path / "sub" / "move.html"]
    assert_png(out[0])
    assert_html(out[1], "S &lt;move&gt;")  # title is escaped


def test_plot_profile_html_only(tmp_path) -> None:
    out = plot_profile(scurve(), tmp_path / "move.html")
    assert out == [tmp_path / "move.html"]
    assert_html(out[0], "Motion profile")
    assert not (tmp_path / "move.png").exists()


def test_plot_profile_svg_and_empty_profile(tmp_path) -> None:
    out = plot_profile(empty_profile(3.0), tmp_path / "still.svg")
    assert out[0].read_text().lstrip().startswith("<?xml")


def test_profile_times_cover_jumps() -> None:
    b = ProfileBuilder(0.0)
    b.segment(0.2, accel=50.0).segment(0.3, accel=0.0).segment(0.2, accel=-50.0)
    pr = b.build()
    t = profile_times(pr, 100)
    assert np.all(np.diff(t) > 0)
    s = pr.sample(t)
    # Both sides of each acceleration jump are sampled: the drawn line is vertical there.
    for tk in pr.t0[1:]:
        i = np.searchsorted(t, tk)
        assert t[i] == tk and t[i - 1] == np.nextafter(tk, -np.inf)
        assert s.a[i] != s.a[i - 1]


def test_plot_trace_png_and_html(tmp_path) -> None:
    out = plot_trace(trace(), tmp_path / "trace.png", html=True, title="run 1")
    assert [p.name for p in out] == ["trace.png", "trace.html"]
    assert_png(out[0])
    assert_html(out[1], "run 1")


def test_plot_trace_accepts_recorder_and_loaded_file(tmp_path) -> None:
    rec = Recorder(1, 50)
    for k in range(50):
        rec.record(k * 1e-3, [k], [k], [1000.0], [1], [k % 2])
    assert_png(plot_trace(rec, tmp_path / "rec.png")[0])
    path = rec.save(tmp_path / "rec.csv")
    assert_png(plot_trace(load_trace(path), tmp_path / "loaded.png")[0])


def test_plot_trace_axis_subset_and_missing_channels(tmp_path) -> None:
    a = trace()
    only_pos = {"t": a["t"], "cmd_pos": a["cmd_pos"]}  # velocity derived from position
    out = plot_trace(only_pos, tmp_path / "pos.png", axes=[1])
    assert_png(out[0])


def test_plot_trace_long_recording_is_reduced() -> None:
    t = np.linspace(0.0, 100.0, 1_000_001)
    y = np.zeros_like(t)
    y[123_457] = 5.0  # a one-sample spike survives the reduction
    tt, yy = envelope(t, y, 2000)
    assert tt.size <= 2100
    assert np.all(np.diff(tt) >= 0)
    assert yy.max() == 5.0 and yy.min() == 0.0
    assert tt[0] == 0.0 and tt[-1] == 100.0
    short_t, short_y = envelope(t[:10], y[:10], 2000)
    assert np.array_equal(short_t, t[:10]) and np.array_equal(short_y, y[:10])


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda p: plot_profile("move", p / "x.png"), "profile"),
        (lambda p: plot_profile(scurve(), p / "x.jpg"), "path"),
        (lambda p: plot_profile(scurve(), p / "x.png", n=1), "n"),
        (lambda p: plot_trace({"cmd_pos": np.zeros((2, 1))}, p / "x.png"), "'t'"),
        (lambda p: plot_trace({"t": np.zeros(3), "cmd_pos": np.zeros((2, 1))}, p / "x.png"),
         "shape"),
        (lambda p: plot_trace({"t": np.zeros(3)}, p / "x.png"), "no per-axis"),
        (lambda p: plot_trace(trace(10), p / "x.png", axes=[2]), "axes"),
        (lambda p: plot_trace(trace(10), p / "x.png", axes=[]), "axes"),
        (lambda p: plot_trace(trace(10), p / "x.gif"), "path"),
    ],
)
def test_bad_input_writes_nothing(tmp_path, call, match) -> None:
    with pytest.raises(MotionError, match=match):
        call(tmp_path)
    assert not list(tmp_path.iterdir())


def test_plot_trace_with_the_machine_names_axes_units_and_signals(tmp_path) -> None:
    from openmotion.config import AxisConfig, MachineConfig

    cfg = MachineConfig("t", (AxisConfig(name="x", lead=10.0), AxisConfig(name="a",
                                                                         unit="degree",
                                                                         lead=360.0)))
    svg = plot_trace(trace(), tmp_path / "named.svg", machine=cfg)[0].read_text()
    for text in ("X [mm/s]", "A [deg/s]", "X command [mm]", "X rdy (off/on)", "X state",
                 "Standstill"):
        assert text in svg, text
    assert "axis 0" not in svg and "io0" not in svg and "state/" not in svg
