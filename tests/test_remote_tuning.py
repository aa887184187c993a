"""The tuning page's API: test moves recorded every cycle with their figures, the step
response of a servo loop, gains applied live and saved in the machine file, refusals that
change nothing, a stop that ends a run; the figures checked on known responses."""

from __future__ import annotations

import math
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from openmotion.config import load_machine
from openmotion.remote import RemoteError
from openmotion.remote.tuning import _settling, _step_figures
from remote_kit import client, served

WAIT = 20.0
EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "dc_servo.toml"


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    path = tmp_path_factory.mktemp("tune") / "servo.toml"
    shutil.copy(EXAMPLE, path)
    with served(file=path) as (svc, th), client(th) as m:
        m.subscribe(rate_hz=50)
        for ax in ("x", "y"):
            m.call("axis.servo", axis=ax, on=True)
        yield svc, m, path


def _result(m, timeout=WAIT):
    t_end = time.monotonic() + timeout
    while True:
        r = m.call("tune.result", max_points=100_000)
        if r["state"] != "running" or time.monotonic() > t_end:
            return r
        time.sleep(0.05)


def test_tune_get_tells_which_axes_have_a_loop_to_tune(machine):
    _svc, m, _p = machine
    x, y = m.call("tune.get", axis="x"), m.call("tune.get", axis="y")
    assert x["servo_loop"] and x["loop"]["compensator"] == "lead" and x["loop"]["k"] == 0x10
    assert not y["servo_loop"] and y["loop"] is None


def test_a_test_move_there_and_back_is_recorded_with_its_figures(machine):
    _svc, m, _p = machine
    r = m.call("tune.run", axis="x", kind="move", distance=2000.0, max_vel=40000.0,
               tacc=0.02, settle_s=0.2, shape="S")
    assert r["state"] == "running"
    res = _result(m)
    assert res["state"] == "done", res["message"]
    assert len(res["figures"]) == 2
    there, back = res["figures"]
    assert there["distance"] == 2000.0 and back["distance"] == -2000.0
    for f in (there, back):
        assert f["peak_following_error"] > 0          # a real loop lags behind
        assert f["peak_following_error"] >= f["rms_following_error"] > 0
        assert f["settling_time_s"] is not None and f["settling_time_s"] <= 0.2
        assert abs(f["final_error"]) <= f["band"]
    cols = res["columns"]
    n = len(res["t"])
    assert all(len(v) == n for v in cols.values()) and n > 300   # every 1 ms cycle
    assert max(cols["command"]) - cols["command"][0] == pytest.approx(2000.0, abs=1e-6)
    assert cols["command"][-1] == pytest.approx(cols["command"][0], abs=1e-6)   # and back
    assert max(cols["velocity_command"]) == pytest.approx(40000.0, rel=1e-6)
    # the record holds the error the figures were taken from (command - feedback, counts)
    peak = max(there["peak_following_error"], back["peak_following_error"])
    assert max(abs(e) for e in cols["error"]) >= peak > 0


def test_an_ideal_stepper_follows_exactly(machine):
    _svc, m, _p = machine
    m.call("tune.run", axis="y", kind="move", distance=5.0, max_vel=50.0, tacc=0.05,
           settle_s=0.05, back=False)
    res = _result(m)
    assert res["state"] == "done" and len(res["figures"]) == 1
    f = res["figures"][0]
    assert (f["peak_following_error"], f["overshoot"], f["settling_time_s"]) == (0.0, 0.0, 0.0)


def test_gains_apply_live_save_to_the_file_and_change_the_step_response(machine):
    svc, m, path = machine
    m.call("tune.run", axis="x", kind="step", amplitude=200.0, duration_s=0.15)
    soft = _result(m)
    assert soft["state"] == "done" and soft["unit"] == "counts"
    f = soft["figures"][0]
    assert f["rise_time_s"] > 0 and f["settling_time_s"] is not None
    assert abs(f["final_error"]) <= f["band"]
    version = m.call("machine.info")["config_version"]
    out = m.call("tune.gains", axis="x", config_version=version,
                 changes={"k": 0x40, "a": 0xE0})
    assert out["loop"]["k"] == 0x40 and out["saved"] == str(path)
    assert svc.ctl.servo_loops["x"].config.k == 0x40          # live, no rebuild
    assert load_machine(path).axis("x").loop.k == 0x40          # in the machine file
    m.call("tune.run", axis="x", kind="step", amplitude=200.0, duration_s=0.15)
    stiff = _result(m)
    assert stiff["state"] == "done"
    assert stiff["columns"]["actual"] != soft["columns"]["actual"]   # other gains, other curve
    m.call("tune.gains", axis="x", config_version=version + 1, changes={"k": 0x10, "a": 0xD8})


@pytest.mark.parametrize(("method", "params", "message"), [
    ("tune.run", {"axis": "y", "kind": "step", "amplitude": 10.0}, "needs a servo loop"),
    ("tune.run", {"axis": "x", "kind": "move", "distance": 0.0, "max_vel": 100.0},
     "distance must be a non-zero"),
    ("tune.run", {"axis": "x", "kind": "move", "distance": 10.0, "max_vel": 100.0,
                  "settle_s": 20.0}, r"settle_s must be in \[0, 10\]"),
    ("tune.run", {"axis": "x", "kind": "move", "distance": 10.0, "max_vel": 9e9},
     "max_vel"),
    ("tune.run", {"axis": "x", "kind": "step", "amplitude": 0.0}, "amplitude"),
    ("tune.gains", {"axis": "x", "changes": {"k": 300}}, r"changes\.k must be"),
    ("tune.gains", {"axis": "x", "changes": {"gain": 3}}, r"changes\.gain: unknown key"),
    ("tune.gains", {"axis": "y", "changes": {"k": 3}}, "no servo loop"),
])
def test_refusals_name_the_parameter_and_change_nothing(machine, method, params, message):
    svc, m, path = machine
    before = (path.read_text(), svc.ctl.servo_loops["x"].config, svc.tuning.run)
    with pytest.raises(RemoteError, match=message):
        m.call(method, **params)
    assert (path.read_text(), svc.ctl.servo_loops["x"].config, svc.tuning.run) == before


def test_a_stop_ends_a_test_move_as_aborted(machine):
    _svc, m, _p = machine
    m.call("tune.run", axis="y", kind="move", distance=40.0, max_vel=10.0, tacc=0.1)
    assert m.call("tune.result")["state"] == "running"
    m.call("axis.stop", axis="y")
    res = _result(m)
    assert res["state"] == "aborted" and "stop" in res["message"]
    assert m.wait(lambda s: not s["axes"]["y"]["moving"], WAIT)


def test_step_figures_of_a_first_order_response():
    tau, amp = 0.01, 100.0
    t = np.arange(0, 0.2, 1e-4)
    fb = amp * (1 - np.exp(-t / tau))
    f = _step_figures(t, np.full_like(t, amp), fb, amp, band=0.02 * amp)
    assert f["rise_time_s"] == pytest.approx(tau * math.log(9), abs=2e-4)
    assert f["overshoot_pct"] == 0.0
    assert f["settling_time_s"] == pytest.approx(tau * math.log(50), abs=2e-4)


def test_step_figures_of_an_underdamped_response():
    zeta, wn, amp = 0.3, 200.0, 50.0
    t = np.arange(0, 0.3, 1e-5)
    wd = wn * math.sqrt(1 - zeta**2)
    y = 1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2)
                                      * np.sin(wd * t))
    f = _step_figures(t, np.full_like(t, amp), amp * y, amp, band=0.02 * amp)
    assert f["overshoot_pct"] == pytest.approx(100 * math.exp(-zeta * math.pi /
                                                              math.sqrt(1 - zeta**2)), rel=1e-3)
    assert f["settling_time_s"] is not None and 0.0 < f["settling_time_s"] < 4.5 / (zeta * wn)


def test_settling_is_none_when_the_error_never_stays_in_the_band():
    t = np.linspace(0, 1, 11)
    err = np.array([5, 4, 3, 2, 1, 0, 0, 0, 0, 0, 3.0])
    assert _settling(t, err, 0.5, 0.0) is None
    assert _settling(t, err[:-1], 0.5, 0.0) == pytest.approx(0.5)


def test_a_running_loop_keeps_its_sample_rate():
    import dataclasses

    from openmotion.config import load_machine as load
    from openmotion.control import Controller
    from openmotion.errors import MotionError

    ctl = Controller(load(EXAMPLE))
    loop = ctl.servo_loops["x"]
    with pytest.raises(MotionError, match="samples_per_cycle must stay 2"):
        loop.retune(dataclasses.replace(loop.config, samples_per_cycle=1))
    loop.retune(dataclasses.replace(loop.config, compensator="pid", kp=0.01))
    assert loop.config.compensator == "pid" and type(loop.compensator).__name__ == "PIDFF"
