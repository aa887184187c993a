"""The interactive run report: decimation keeps what a screen shows, the page stays small
for long programs, figures only for axes that move."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from longrun import size
from openmotion.cli import main
from openmotion.program.report_html import SCREEN_POINTS, path_indices, screen_indices
from pagecheck import inflate


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
    # short moves (60: about 6,000 trace samples, more than the 4,000 a figure keeps;
    # 3000 with --long): the page is bounded by the screen, not by the program
    rng = np.random.default_rng(5)
    pts = rng.uniform(-5, 5, size=(size(60, 3000), 2))
    prog = tmp_path / "zigzag.ngc"
    prog.write_text("G21 G90 G64 P0.05 F6000\n" + "".join(
        f"G1 X{x:.3f} Y{y:.3f}\n" for x, y in pts) + "M2\n")
    assert main(["run", str(prog), "--out", str(tmp_path)]) == 0
    run_time = float(capsys.readouterr().out.split("run time")[1].split()[0])
    assert run_time / 0.001 > 4 * SCREEN_POINTS   # more cycles than a figure keeps
    page = (tmp_path / "zigzag.html")
    assert page.stat().st_size < 1_500_000
    html = page.read_text()
    assert '"name":"X"' in html and '"name":"Y"' in html
    assert '"name":"Z"' not in html and '"name":"A"' not in html   # they do not move
    assert "worst contour error" in html


def test_path_indices_keep_every_commands_first_and_last_sample():
    idx = np.repeat(np.arange(3000), 7)            # 3000 commands of 7 samples
    pos = np.cumsum(np.ones((idx.size, 2)), axis=0)
    keep = path_indices(pos, idx)
    firsts = np.arange(0, idx.size, 7)
    assert np.isin(firsts, keep).all() and np.isin(firsts[1:] - 1, keep).all()
    assert len(screen_indices(pos)) < len(keep) < idx.size


LASER = Path(__file__).resolve().parents[1] / "examples" / "programs" / "laser_contour.ngc"


@pytest.fixture(scope="module")
def laser_page(laser_report):
    """examples/programs/laser_contour.ngc run once (conftest.laser_report), its report
    page (text) and folder."""
    return (laser_report / "laser_contour.html").read_text(), laser_report


def _extents(page: str) -> dict[str, list[str]]:
    table = re.search(r"<table id=extents>(.*?)</table>", page).group(1)
    rows = re.findall(r"<tr><td>(\w)</td>(.*?)</tr>", table)
    return {k: re.findall(r"<td class=num>([^<]*)</td>", cells) for k, cells in rows}


def test_report_draws_the_path_in_program_coordinates_with_extents_and_soft_limits(
        laser_page):
    page, _ = laser_page
    ext = _extents(page)
    assert set(ext) == {"X", "Y"}                   # only the axes that move
    # the part spans X -30..30, Y -20..20 in the program (the machine puts program zero
    # at the middle of its travel, 150/100 mm from machine zero)
    x_lo, x_hi, all_lo, _, soft_lo, soft_hi = map(float, ext["X"])
    assert abs(x_lo + 30) < 0.06 and abs(x_hi - 30) < 1e-3
    assert abs(float(ext["Y"][1]) - 20) < 1e-3
    assert all_lo == pytest.approx(-150.0)          # the first rapid starts at machine 0
    assert (soft_lo, soft_hi) == (-155.0, 155.0)    # the EL edges, in program coordinates
    assert "X (mm, program)" in page and '"name":"soft limits (travel)"' in page


def test_report_marks_outputs_on_the_path_and_lists_the_program(laser_page):
    page, _ = laser_page
    assert '"name":"do0 on"' in page                # the laser's on-stretches on the path
    assert '"name":"selected line"' in page
    assert "commanded feed (programmed x 100 %)" in page
    # every source line listed, the motion lines marked as such (the page's script makes
    # the rows from this data; the browser test below clicks them)
    data = json.loads(inflate(page, "listing-data"))
    src = LASER.read_text().splitlines()
    assert data["lines"] == src
    moving = {n for a, b in data["moves"] for n in range(a, b + 1)}
    assert 7 in moving and 13 not in moving and 1 not in moving
    from openmotion.control import Controller
    from openmotion.program.runjob import work_origin
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    ops = ProgramRunner(ctl, LASER, gcode={"parameters": work_origin(ctl)}).ops
    assert moving == {o.line for o in ops if o.kind in ("line", "arc")}
    assert "<tr id=L1 " not in page   # no markup per line: 20,000 rows cost 1.8 MB


def test_output_levels_follow_the_events_of_the_run():
    from openmotion.control import Controller
    from openmotion.program.report_html import output_levels
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, "G90 G21 F600\nM62 P1\nG1 X5\nM63 P1\nG1 X10\nM2\n")
    run.start()
    assert run.wait(30)
    t, _, pos = run.trace()
    on = output_levels(run, t)[1]
    assert on.any() and not on[-1]
    # on while the first move runs (X below 5), off along the second
    assert np.all(pos[on, 0] <= 5 + 1e-9) and np.all(pos[~on & (pos[:, 0] > 5.01), 0] > 5)


def test_soft_limit_box_has_the_edges_of_the_travel():
    from openmotion.control import Controller
    from openmotion.program.report_html import soft_limit_box, soft_limits
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, "G0 X1 Y1 Z1\nM2\n")
    run.start()
    assert run.wait(30)
    lims = soft_limits(run)
    off = np.array([1.0, 2.0, 3.0, 0.0])
    for cols, edges in (([0, 1], 4), ([0, 1, 2], 12)):
        box = soft_limit_box(run, cols, off)
        pts = box[~np.isnan(box[:, cols[0]])][:, cols]
        assert len(pts) == 2 * edges
        for k, c in enumerate(cols):
            assert set(np.round(pts[:, k], 9)) == {round(lims[c][0] - off[c], 9),
                                                   round(lims[c][1] - off[c], 9)}


def test_report_page_links_the_listing_and_the_path_in_the_browser(laser_page, tab):
    _, out = laser_page
    pg = tab
    errors: list[str] = []

    def on_error(e: object) -> None:
        errors.append(str(e))

    pg.on("pageerror", on_error)
    try:
        pg.goto((out / "laser_contour.html").as_uri())
        pg.wait_for_function("() => { const d = document.getElementById('om-path');"
                             " return d && d.data; }", timeout=30000)
        pg.click("#L8")                          # the G3 arc of the bracket
        pg.wait_for_function("() => window.openmotionSelected", timeout=30000)
        sel = pg.evaluate("() => window.openmotionSelected")
        assert sel["line"] == 8 and sel["points"] > 10
        assert "sel" in pg.get_attribute("#L8", "class")
        pg.click("#L1")                          # a comment: no stretch, row marked
        pg.wait_for_function("() => window.openmotionSelected.line === 1", timeout=30000)
        assert pg.evaluate("() => window.openmotionSelected.points") == 0
        assert not errors, errors
    finally:
        pg.remove_listener("pageerror", on_error)
        pg.goto("about:blank")


def test_a_100k_line_listing_is_small_and_cut_at_the_limit():
    from types import SimpleNamespace

    from openmotion.program.report_page import MAX_LISTING_LINES, _listing

    text = "".join(f"X{30 * np.cos(k / 1e4):.4f} Y{30 * np.sin(k / 1e4):.4f}\n"
                   for k in range(100_000))
    ops = [SimpleNamespace(kind="line", line=n) for n in range(1, 100_001)]
    part = _listing(SimpleNamespace(ops=ops), text)
    data = json.loads(inflate(part, "listing-data"))
    assert len(data["lines"]) == MAX_LISTING_LINES and data["moves"] == [[1, MAX_LISTING_LINES]]
    assert data["lines"] == text.splitlines()[:MAX_LISTING_LINES]
    assert f"{100_000 - MAX_LISTING_LINES} more lines not listed" in part
    assert len(part) < 10 * MAX_LISTING_LINES    # 20,000 lines of ~17 characters, packed
