"""The ZMotion PSO article's examples through the facade: the firings, pulse counts and
widths the article states (examples/zmotion/*.py)."""

import importlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "zmotion"
SPEED = 100.0  # SPEED=100 units/s, UNITS=100


# The examples without a timer (modes 1, 3, 25) run time-scaled by K: SPEED, ACCEL/DECEL and
# SRAMP times K, K^2 and 1/K trace the article's path and firing positions in 1/K of the
# machine time (and cycles); their times and widths are checked divided by K. The examples
# with HW_TIMER pulses (fixed in microseconds) keep the article's speeds.
K = 10.0


def time_scaled(module, k):
    """`module`'s controller() with the article's motion time-scaled by k."""
    make = module.controller

    def controller():
        c = make()
        c.SPEED = (SPEED * k,) * 3
        c.ACCEL = (1000.0 * k * k,) * 3
        c.DECEL = (1000.0 * k * k,) * 3
        c.SRAMP = (50.0 / k,) * 3
        return c
    return controller


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("zmotion")
    sys.path.insert(0, str(EXAMPLES))
    cache = {}

    def go(name, k=1.0, **kw):
        key = (name, k, tuple(sorted(kw.items())))
        if key not in cache:
            module = importlib.import_module(name)
            make = module.controller
            if k != 1.0:
                module.controller = time_scaled(module, k)
            try:
                cache[key] = module.main(out, **kw)
            finally:
                module.controller = make
        return cache[key]

    try:
        yield go
    finally:
        sys.path.remove(str(EXAMPLES))


def test_mode1_table_three_pulses_of_50_units(run):
    r = run("mode1_table", K)
    np.testing.assert_allclose(r["positions"][:, 0], [100, 150, 250, 300, 400, 450], atol=1e-9)
    assert r["states"].tolist() == [1, 0, 1, 0, 1, 0]     # first point ON, then inverting
    np.testing.assert_allclose(r["widths"], [50 / SPEED / K] * 3, atol=1e-9)  # at cruise
    np.testing.assert_allclose(np.diff(r["times"]), np.array([0.5, 1.0, 0.5, 1.0, 0.5]) / K,
                               atol=1e-9)
    assert all(Path(f).stat().st_size > 1000 for f in r["files"])


def test_mode3_vector_distance_of_the_interpolation(run):
    r = run("mode3_vector", K)
    l1, l2 = math.hypot(300, 200), math.hypot(100, 200)
    assert r["vector_moved"] == pytest.approx(l1 + l2, abs=0.02)  # MERGE rounds the corner
    assert r["states"].tolist() == [1, 0, 1, 0, 1, 0]
    along = [math.hypot(x, y) for x, y, _ in r["positions"][:4]]
    np.testing.assert_allclose(along, [100, 150, 250, 300], atol=1e-6)  # first leg
    second = [l1 + math.hypot(x - 300, y - 200) for x, y, _ in r["positions"][4:]]
    np.testing.assert_allclose(second, [400, 450], atol=0.02)
    np.testing.assert_allclose(r["widths"], [0.5 / K] * 3, atol=1e-6)  # 50 units at SPEED K


def test_mode25_inverts_at_each_of_8_points(run):
    r = run("mode25_26_2d", K, modes=("mode25",))["mode25"]
    pts = np.array([(0, 0), (50, 50), (100, 100), (50, 150), (0, 200), (-50, 150),
                    (-100, 100), (-50, 50)], float)
    assert r["index"].tolist() == list(range(8))
    assert r["states"].tolist() == [1, 0, 1, 0, 1, 0, 1, 0]
    assert np.all(np.abs(r["positions"][:, :2] - pts) <= 0.1 + 1e-9)  # maxerr 10 pulses
    assert r["times"][0] == pytest.approx(0.0, abs=1e-12)  # the axes start on point 0
    assert r["widths"].size == 4                      # 4 blue (ON) stretches


def test_mode26_two_50ms_pulses_per_point(run):
    r = run("mode25_26_2d", modes=("mode26",))["mode26"]
    assert r["index"].tolist() == list(range(8))
    np.testing.assert_allclose(r["widths"], [0.05] * 16, atol=1e-9)


@pytest.mark.parametrize("mode", ["mode35", "mode36"])
def test_mode35_36_one_50ms_pulse_per_point(run, mode):
    r = run("mode35_36_3d")[mode]
    pts = np.array([20, 40, 70, 100, 140, 180], float)
    assert r["index"].tolist() == list(range(6))
    assert np.all(np.abs(r["positions"] - pts[:, None]) <= 0.1 + 1e-9)
    np.testing.assert_allclose(r["widths"], [0.05] * 6, atol=1e-9)
    # each pulse starts at its comparison: the point enters the +-10 pulse window on the
    # diagonal at SPEED 100 units/s along the path
    entry = (pts - 0.1) * math.sqrt(3) / SPEED
    np.testing.assert_allclose(np.diff(r["times"]), np.diff(entry), atol=1e-9)


def test_hw_timer_edits_and_soft_close(run):
    r = run("hw_timer")
    assert r["index"].tolist() == list(range(8))
    np.testing.assert_allclose(r["widths"], [0.05] * 8 + [0.005] * 6, atol=1e-9)
    assert r["ignored"] == 2


def test_article_main_program_runs_the_selected_subroutines(tmp_path):
    # the two shortest subroutines, one after the other on one controller (Clean_Pos
    # between them): each gives what its example gives on a fresh controller
    sys.path.insert(0, str(EXAMPLES))
    try:
        r = importlib.import_module("article").main(tmp_path, cmds=(36, 35))
        with pytest.raises(ValueError, match="g_cmd 4"):
            importlib.import_module("article").main(tmp_path, cmds=(4,))
    finally:
        sys.path.remove(str(EXAMPLES))
    pts = np.array([20, 40, 70, 100, 140, 180], float)
    entry = (pts - 0.1) * math.sqrt(3) / SPEED  # as test_mode35_36_one_50ms_pulse_per_point
    for cmd in (35, 36):
        assert r[cmd]["index"].tolist() == list(range(6))
        np.testing.assert_allclose(r[cmd]["widths"], [0.05] * 6, atol=1e-9)
        np.testing.assert_allclose(np.diff(r[cmd]["times"]), np.diff(entry), atol=1e-9)
