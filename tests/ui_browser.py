"""Fixtures of the browser tests: the real `openmotion ui` server and Debian's chromium.

The server runs as a subprocess (`python -m openmotion ui --port 0`, the address read from
its first line) on a machine file in a temporary directory, so saving settings is real.
Playwright drives /usr/bin/chromium (it cannot download its own browser here). Without
chromium or the playwright package the tests are skipped, except under CI=1, where they fail.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

import openmotion

CHROMIUM = os.environ.get("OPENMOTION_CHROMIUM", "/usr/bin/chromium")
SRC = Path(openmotion.__file__).resolve().parent.parent
ROOT = SRC.parent
SHOTS = ROOT / "docs" / "img"


def need_browser() -> None:
    """Skip (locally) or fail (under CI: CI set, not 0/false) when Playwright or chromium is
    missing."""
    missing = []
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        missing.append("the playwright package (pip install playwright)")
    if not Path(CHROMIUM).exists():
        missing.append(f"{CHROMIUM} (apt-get install chromium)")
    if missing:
        msg = "browser tests need " + " and ".join(missing)
        if os.environ.get("CI", "").lower() not in ("", "0", "false"):  # CI=1, CI=true
            pytest.fail(msg)
        pytest.skip(msg)


class Server:
    """`openmotion ui` in a subprocess; `url` is the address it printed."""

    def __init__(self, workdir: Path, *extra: str) -> None:
        env = dict(os.environ, PYTHONPATH=str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", ""),
                   PYTHONUNBUFFERED="1")
        self.workdir = workdir
        self.log = workdir / "server.log"
        self._log = open(self.log, "w")   # noqa: SIM115 (closed in stop())
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "openmotion", "ui", "--port", "0", *extra],
            cwd=workdir, env=env, stdout=subprocess.PIPE, stderr=self._log, text=True)
        self.url = self._address()

    def _address(self) -> str:
        deadline = time.monotonic() + 60
        assert self.proc.stdout is not None
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                if self.proc.poll() is not None:
                    raise RuntimeError(f"openmotion ui exited: {self.log.read_text()[-2000:]}")
                time.sleep(0.05)
                continue
            m = re.search(r"(http://\S+)", line)
            if m:
                return m.group(1)
        raise RuntimeError("openmotion ui printed no address within 60 s")

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        self._log.close()


class External:
    """A server already running (OPENMOTION_UI_URL): for debugging the tests by hand."""

    def __init__(self, url: str, workdir: Path) -> None:
        self.url = url
        self.workdir = workdir

    def stop(self) -> None:
        pass


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server | External]:
    need_browser()
    work = tmp_path_factory.mktemp("ui")
    url = os.environ.get("OPENMOTION_UI_URL")
    srv: Server | External = External(url, work) if url else Server(work)
    try:
        yield srv
    finally:
        srv.stop()


def chromium() -> Iterator[object]:
    """Chromium under Playwright, until the generator is closed: conftest.py's session
    fixture `browser`, one per test process, shared by every module's pages (the UI
    tests load a fresh document into one tab: `tab`, `page`)."""
    need_browser()
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, headless=True,
                               args=["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"])
        try:
            yield b
        finally:
            b.close()


def tab(browser: object) -> Iterator[object]:
    """One context and tab for every `page` of a test process (conftest.py's session
    fixture `tab`): a new context costs a renderer process (~1.3 s of CPU more than a
    navigation); each test still gets a fresh document (`page`), and the app keeps nothing
    in the browser (no storage, no cookies) that a navigation would not clear."""
    ctx = browser.new_context(viewport={"width": 1400, "height": 1000})   # type: ignore[attr-defined]
    ctx.set_default_timeout(30_000)      # every Playwright wait, unless a test asks for more
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.page_errors = errors   # type: ignore[attr-defined]
    try:
        yield pg
    finally:
        ctx.close()


@pytest.fixture
def page(tab: object, server: Server | External) -> Iterator[object]:
    """The UI freshly loaded in the process's tab (conftest.py's `tab`), connected (lamp
    green) and showing the operation page. Left for about:blank afterwards: the tab's socket
    closes (the server stops its jogs, as when a tab is closed) and nothing runs in it
    until the next test."""
    pg = tab
    errors: list[str] = pg.page_errors   # type: ignore[attr-defined]
    errors.clear()
    pg.goto(server.url)   # type: ignore[attr-defined]
    pg.wait_for_selector("#conn[data-state=open]", timeout=30_000)   # type: ignore[attr-defined]
    pg.wait_for_function("() => window.openmotion && window.openmotion.status !== null",   # type: ignore[attr-defined]
                         timeout=30_000)
    try:
        yield pg
    finally:
        pg.goto("about:blank")   # type: ignore[attr-defined]
    assert not errors, f"JavaScript errors on the page: {errors}"


def status(pg: object, expr: str) -> object:
    """Evaluate `expr` on the page's merged live status (`s`)."""
    return pg.evaluate(f"() => {{ const s = window.openmotion.status; return {expr}; }}")  # type: ignore[attr-defined]


#: the shortest wait for a state: a loaded CI machine can be slow, never wait less
MIN_WAIT_S = 20.0


def wait_status(pg: object, cond: str, timeout_s: float = MIN_WAIT_S) -> None:
    """Wait until the JS condition `cond` on the live status `s` holds (at least
    MIN_WAIT_S; wait only for states that persist, never for a passing one)."""
    pg.wait_for_function(   # type: ignore[attr-defined]
        f"() => {{ const s = window.openmotion.status; return Boolean(s && ({cond})); }}",
        timeout=max(timeout_s, MIN_WAIT_S) * 1000)


def after_pushes(pg: object, n: int = 3) -> None:
    """Wait until `n` more status pushes reached the page (each one redraws what follows
    the live status): what a page keeps must survive them."""
    pg.evaluate("""(n) => new Promise((done) => {
        const a = window.openmotion;
        const on = () => { if (--n <= 0) { a.removeEventListener('status', on); done(); } };
        a.addEventListener('status', on);
    })""", n)


def wait_jogged(pg: object, axis: str, before: float, sign: int) -> None:
    """Wait until a deadman jog moved `axis` from `before` in the direction `sign`. The
    moved position lasts; the jog's speed does not: a browser stalled for longer than the
    deadman (a loaded machine) lets the server stop the jog, by design, before a status
    shows it moving."""
    op = ">" if sign > 0 else "<"
    wait_status(pg, f"s.axes.{axis}.position {op} {before!r}")


def shot(pg: object, name: str, settle_ms: int = 0) -> None:
    """Save docs/img/creator-<name>.png when OPENMOTION_SHOTS=1 (the committed screenshots),
    `settle_ms` after the call (a chart's redraw): only then, the tests wait for states."""
    if os.environ.get("OPENMOTION_SHOTS") == "1":
        pg.wait_for_timeout(settle_ms)   # type: ignore[attr-defined]
        SHOTS.mkdir(parents=True, exist_ok=True)
        pg.screenshot(path=str(SHOTS / f"creator-{name}.png"), full_page=True)   # type: ignore[attr-defined]


def goto(pg: object, name: str) -> None:
    """Show the UI page `name` (its nav hash) and wait until it is the active one."""
    pg.evaluate(f"location.hash = '#{name}'")
    pg.wait_for_selector(f"#page-{name}.active")


def ready_axis(pg: object, axis: str = "x") -> None:
    """Operation page on `axis`, E-stop released, axis reset and servo on (through the UI)."""
    if status(pg, "s.estop"):
        pg.click("#estop-reset")
        wait_status(pg, "!s.estop")
    goto(pg, "operation")
    pg.select_option("#axis-select", axis)
    pg.wait_for_selector("#op-state")
    if status(pg, f"s.axes.{axis}.state") == "ErrorStop":
        pg.click("#op-reset")
        wait_status(pg, f"s.axes.{axis}.state !== 'ErrorStop'")
    if not status(pg, f"s.axes.{axis}.servo"):
        pg.click("#op-servo")
        try:
            wait_status(pg, f"s.axes.{axis}.servo")
        except Exception as exc:
            raise AssertionError(f"servo on {axis} failed: {pg.inner_text('#log')}") from exc
    wait_status(pg, f"!s.axes.{axis}.moving")


def field(pg: object, form: str, name: str) -> object:
    """The input (or select) of field `name` in the form with id `form` (a locator)."""
    row = f"#{form} [data-name='{name}']"
    return pg.locator(f"{row} input, {row} select").first


def error_of(pg: object, form: str, name: str) -> str:
    """The error text shown beside field `name` of form `form`."""
    return pg.inner_text(f"#{form} [data-name='{name}'] .field-error")
