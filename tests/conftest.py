"""Suite-wide options: long fuzz, soak and property runs stay out of the normal run."""

from __future__ import annotations

import gc
import os
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import settings

# Where PYTHONDONTWRITEBYTECODE is set (no __pycache__ beside the sources), the suite still
# keeps the compiled modules, in .pytest_cache/pycache: otherwise every xdist worker
# recompiles the package and re-runs pytest's assertion rewriting of every test module at
# each run (about 9 s of CPU per worker). Child processes (the `openmotion` subprocesses
# of the CLI and browser tests) are left as they are: they import modules that collection
# never imports, which would then be compiled from source in each of them.
if sys.dont_write_bytecode and not sys.pycache_prefix:
    _PYCACHE = Path(__file__).resolve().parents[1] / ".pytest_cache" / "pycache"
    sys.pycache_prefix = str(_PYCACHE)
    sys.dont_write_bytecode = False

# CI replays the same examples on every run (derandomize) so that a landing is decided by the
# code, not by the draw; local runs keep drawing new examples, and a failure they find is
# added as an @example (OPENMOTION_HYPOTHESIS_RANDOM=1 draws randomly under CI too).
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI") and not os.environ.get("OPENMOTION_HYPOTHESIS_RANDOM"):
    settings.load_profile("ci")


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("openmotion long runs")
    group.addoption("--fuzz-long", action="store_true", default=False,
                    help="run the fuzz suite with 100k inputs per entry point family")
    group.addoption("--soak-long", action="store_true", default=False,
                    help="run the soak test for its long duration")
    group.addoption("--long", action="store_true", default=False,
                    help="run heavy property and comparison runs in full")


def pytest_configure(config: pytest.Config) -> None:
    if config.getoption("--long"):
        os.environ["OPENMOTION_LONG"] = "1"  # read by tests/longrun.py at import time
    config.addinivalue_line("markers", "long: a heavy run, reduced unless --long is given")


# The normal run draws a quarter of each property test's `max_examples` (at least
# PROPERTY_FLOOR, never more than the test asks): every property is still checked on every
# run, on fewer drawn cases; `--long` draws the full count. Tests that need a small count
# already ask for it and are left alone by the floor.
PROPERTY_SHARE = 4
PROPERTY_FLOOR = 20


def reduced_examples(n: int) -> int:
    """The normal run's example count for a property test that asks for `n`."""
    return min(n, max(PROPERTY_FLOOR, n // PROPERTY_SHARE))


def _reduce_properties(items: list[pytest.Item]) -> None:
    done: set[int] = set()
    for item in items:
        test = getattr(item, "obj", None)
        test = getattr(test, "__func__", test)  # (a method's function holds the settings)
        current = getattr(test, "_hypothesis_internal_use_settings", None)
        if current is None or not hasattr(test, "hypothesis") or id(test) in done:
            continue
        done.add(id(test))  # (parametrized items share the function)
        n = reduced_examples(current.max_examples)
        if n < current.max_examples:  # hypothesis reads this attribute when the test runs
            test._hypothesis_internal_use_settings = settings(current, max_examples=n)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Property tests reduced unless --long (see PROPERTY_SHARE). Browser modules first (a
    module with a test that uses `page`, `tab` or `browser`, whole, so that its module fixtures
    are made once; a stable sort: module order kept). They are the longest and run one
    after another on a module's server, so under xdist (`--dist worksteal`, set in
    pyproject.toml) they start at once and the short tests fill the other worker around
    them, instead of the browser modules running alone at the end."""
    browser_modules = {item.nodeid.split("::")[0] for item in items
                       if {"page", "tab", "browser"} & set(getattr(item, "fixturenames", ()))}

    def browser_first(item: pytest.Item) -> int:
        return 0 if item.nodeid.split("::")[0] in browser_modules else 1

    if not config.getoption("--long"):
        _reduce_properties(items)
    items.sort(key=browser_first)


def pytest_collection_finish(session: pytest.Session) -> None:
    """The modules and tests collected now live for the whole session: frozen (gc.freeze),
    so that a full garbage collection, automatic or asked for by a test or by the realtime
    executor, does not scan them again each time (~0.1 s of CPU per collection)."""
    gc.collect()
    gc.freeze()


@pytest.hookimpl(trylast=True)
def pytest_runtest_teardown(item: pytest.Item, nextitem: pytest.Item | None) -> None:
    """At the end of a module, freeze again if a realtime executor unfroze everything (it
    freezes the objects alive while it runs). Only there: gc.get_freeze_count() walks the
    frozen objects (~10 ms), too dear after every test."""
    if nextitem is not None and nextitem.nodeid.split("::")[0] == item.nodeid.split("::")[0]:
        return
    if gc.get_freeze_count() == 0:
        gc.collect()
        gc.freeze()


@pytest.fixture(scope="session")
def browser() -> Iterator[object]:
    """Chromium for the browser tests (tests/ui_browser.py), started once per process."""
    from ui_browser import chromium

    yield from chromium()


@pytest.fixture(scope="session")
def tab(browser: object) -> Iterator[object]:
    """The tab every UI test's `page` loads the UI into (tests/ui_browser.py), one per
    process."""
    from ui_browser import tab as make_tab

    yield from make_tab(browser)


@pytest.fixture(scope="session")
def laser_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """examples/programs/laser_contour.ngc run once per process (`openmotion run`, default
    options): the folder holding its report page laser_contour.html. The report tests
    (test_report_html.py, test_report_embed.py) only read it."""
    from openmotion.cli import main

    out = tmp_path_factory.mktemp("laser")
    prog = Path(__file__).resolve().parents[1] / "examples" / "programs" / "laser_contour.ngc"
    assert main(["run", str(prog), "--out", str(out)]) == 0
    return out


@pytest.fixture
def fuzz_long(request: pytest.FixtureRequest) -> bool:
    """True when the suite was started with --fuzz-long."""
    return bool(request.config.getoption("--fuzz-long"))


@pytest.fixture
def soak_long(request: pytest.FixtureRequest) -> bool:
    """True when the suite was started with --soak-long."""
    return bool(request.config.getoption("--soak-long"))


@pytest.fixture
def long_run(request: pytest.FixtureRequest) -> bool:
    """True when the suite was started with --long."""
    return bool(request.config.getoption("--long"))
