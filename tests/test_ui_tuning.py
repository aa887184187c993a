"""Motion Creator in the browser, on a machine with a DC servo axis (examples/dc_servo.toml):
the tuning page (a test move with its figures, gains applied and saved, the step response),
the end-limit response saved in the machine file's own table and read back, PSO firings
on the path page, a general input on the scope. Waits are for states that persist."""

from __future__ import annotations

import shutil
import tomllib
from collections.abc import Iterator
from pathlib import Path

import pytest

import ui_browser
from ui_browser import error_of, field, goto, ready_axis, shot, status, wait_status

page = ui_browser.page

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")
EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "dc_servo.toml"


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ui_browser.Server]:
    ui_browser.need_browser()
    work = tmp_path_factory.mktemp("ui-tune")
    path = work / "servo.toml"
    shutil.copy(EXAMPLE, path)
    srv = ui_browser.Server(work, "--machine", str(path))
    srv.machine = path      # type: ignore[attr-defined]
    try:
        yield srv
    finally:
        srv.stop()


def _done(pg) -> None:
    pg.wait_for_selector("#tune-state[data-state=done]", timeout=30_000)


def test_a_test_move_shows_following_error_overshoot_and_settling(page):
    ready_axis(page, "x")
    goto(page, "tuning")
    page.wait_for_selector("#tune-run")
    assert page.locator("#tune-loop").count() == 1          # x has a loop to tune
    field(page, "tune-move", "distance").fill("2000")
    field(page, "tune-move", "max_vel").fill("40000")
    field(page, "tune-move", "tacc").fill("0.02")
    field(page, "tune-move", "tdec").fill("0.02")
    field(page, "tune-move", "shape").select_option("S")
    field(page, "tune-move", "settle_s").fill("0.2")
    page.click("#tune-run")
    _done(page)
    rows = page.locator("#tune-figure-table tr[data-segment]")
    assert rows.count() == 2                                 # there and back
    text = page.inner_text("#tune-figure-table")
    assert "counts" in text and "ms" in text and "not settled" not in text
    n = page.evaluate("window.openmotion && document.querySelectorAll('#tune-chart-0 canvas')"
                      ".length")
    assert n >= 1
    shot(page, "tuning")


def test_gains_are_applied_saved_and_the_step_response_shown(page, server):
    ready_axis(page, "x")
    goto(page, "tuning")
    page.wait_for_selector("#tune-apply")
    field(page, "tune-loop", "k").fill("300")                # refused in the browser
    assert "must be <= 255" in error_of(page, "tune-loop", "k")
    page.click("#tune-apply")
    assert "nothing was sent" in page.inner_text("#tune-loop .form-error[role=alert]")
    field(page, "tune-loop", "k").fill("24")
    page.click("#tune-apply")
    page.wait_for_selector("#log:has-text('gains applied')", timeout=30_000)
    loop = tomllib.loads(server.machine.read_text())["axes"]["x"]["loop"]
    assert loop["k"] == 24
    field(page, "tune-step", "amplitude").fill("150")
    page.click("#tune-step-run")
    page.wait_for_selector("#tune-state:has-text('step of 150')", timeout=30_000)
    _done(page)
    assert "rise" in page.inner_text("#tune-figure-table")
    # the middle chart shows the loop's output (duty) for a step
    page.wait_for_selector("#tune-chart-1[data-kind=duty]")
    assert page.evaluate("window.openmotion.tuneCharts[1].t.length") > 10
    # a stepper axis has no loop in the controller: the page says so, the move still runs
    page.select_option("#axis-select", "y")
    page.wait_for_selector("#tune-no-loop")


def test_the_limit_response_is_saved_in_the_machine_file_and_read_back(page, server):
    goto(page, "interface")
    page.select_option("#axis-select", "y")
    page.wait_for_selector("#page-interface b:has-text('Axis y')")
    el_resp = field(page, "if-responses", "responses.el")
    new = "decel" if el_resp.input_value() != "decel" else "immediate"
    el_resp.select_option(new)
    page.click("#if-save")
    page.wait_for_selector("#if-saved:has-text('saved to')", timeout=30_000)
    data = tomllib.loads(server.machine.read_text())
    assert data["axes"]["y"].get("responses", {}).get("el", "immediate") == new
    assert not server.machine.with_name("servo.ui.toml").exists()   # no sidecar any more
    page.reload()
    page.wait_for_selector("#conn[data-state=open]")
    goto(page, "interface")
    page.select_option("#axis-select", "y")
    page.wait_for_selector("#page-interface b:has-text('Axis y')")
    assert field(page, "if-responses", "responses.el").input_value() == new


def test_pso_firings_are_marked_on_the_path(page):
    ready_axis(page, "y")
    goto(page, "path")
    page.wait_for_selector("#pso-set")
    field(page, "pso-form", "axes").fill("y")
    field(page, "pso-form", "output").fill("2")
    field(page, "pso-form", "every").fill("5")
    page.click("#pso-set")
    page.wait_for_selector("#pso-info:has-text('every 5')", timeout=30_000)
    goto(page, "operation")
    field(page, "op-target", "mode").select_option("relative")
    field(page, "op-target", "distance").fill("22")
    field(page, "op-motion", "max_vel").fill("50")
    before = status(page, "s.axes.y.command")
    page.click("#op-play2")
    wait_status(page, f"s.axes.y.command === {before} + 22 * 2000 && !s.axes.y.moving")
    goto(page, "path")
    page.wait_for_function("() => window.openmotion.pathView.markers"
                           ".filter((m) => m.colour === '#c0c').length === 4", timeout=30_000)
    assert "4 PSO" in page.inner_text("#path-info")
    shot(page, "path-pso")
    page.click("#pso-clear")
    page.wait_for_selector("#pso-info:has-text('no PSO job')", timeout=30_000)


def test_a_general_input_is_a_scope_channel(page):
    goto(page, "scope")
    page.wait_for_selector("#scope-board-picks")
    page.check("#scope-board-picks input[value='di.5']")
    page.click("#scope-apply")
    page.wait_for_function("""async () => {
        const s = await window.openmotion.call('scope.get', {}, { quiet: true });
        return s.channels.includes('di.5');
    }""", timeout=30_000, polling=200)
    goto(page, "simulation")
    page.click("#sim-di-5")
    wait_status(page, "s.board.di[5] === true")
    goto(page, "scope")
    page.wait_for_function("""() => {
        const c = window.openmotion.scopeChart;
        const i = c ? c.channels.findIndex((ch) => ch.key === 'di.5') : -1;
        return i >= 0 && c.cols[i].some((v) => v === 1);
    }""", timeout=30_000)
    goto(page, "simulation")
    page.click("#sim-di-5")
    wait_status(page, "s.board.di[5] === false")
