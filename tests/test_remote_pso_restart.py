"""PSO jobs set up through the API survive a machine restart caused by a setting change
(a power cycle: positions 0): set up again from their user-unit setups, a points job with
the points not reached yet; a job the new machine cannot take is listed as dropped. Virtual
time on the service's controller, no server: nothing depends on timing."""

from __future__ import annotations

import dataclasses

import pytest

from openmotion.remote.service import MachineService


@pytest.fixture
def svc():
    s = MachineService()
    try:
        yield s
    finally:
        s.shutdown()


def _move(svc, axis: str, mm: float) -> None:
    ax = svc.ctl.axis(axis)
    ax.move_relative(mm, max_vel=50.0, tacc=0.05, units=True)
    assert svc.ctl.wait_motion_done(timeout=60)


def _pso_positions(svc, axis: int, output: int) -> list[float]:
    """Where `axis` was at each firing (rising edge) of `output` on this machine."""
    return [float(svc.ctl.axes[axis].units.to_units(f["pulses"][axis]))
            for f in svc.pso.firings(-1.0, svc.ctl.time + 1.0)
            if f["level"] and f["output"] == output]


def _restart(svc, **axis_changes):
    cfg = svc.config
    x = dataclasses.replace(cfg.axis("x"), **axis_changes)
    svc.rebuild(cfg.with_axis(x))


def test_jobs_are_set_up_again_after_a_restart(svc):
    svc.ctl.enable_all()
    with svc.ctl.lock:
        svc.pso.add("distance", [0], 2, 0.002, every=5.0)
        svc.pso.add("points", [1], 4, 0.002, points=[[5.0], [10.0]], window=0.5)
    _move(svc, "y", 7.0)                       # past the first point only
    assert _pso_positions(svc, 1, 4) == pytest.approx([5.0], abs=0.5)
    old = svc.ctl
    _restart(svc, pulse_mode="cw_ccw")
    assert svc.ctl is not old                   # a new machine, positions 0
    info = svc.pso.info()
    assert [(j["kind"], j["axes"], j["output"]) for j in info["jobs"]] == [
        ("distance", ["x"], 2), ("points", ["y"], 4)]
    assert info["jobs"][1]["remaining"] == 1 and info["dropped"] == []
    assert all(j["active"] for j in info["jobs"])
    svc.ctl.enable_all()
    _move(svc, "x", 12.0)
    assert _pso_positions(svc, 0, 2) == pytest.approx([5.0, 10.0], abs=1e-6)
    _move(svc, "y", 12.0)                       # the point not reached before: at 10 mm
    assert _pso_positions(svc, 1, 4) == pytest.approx([10.0], abs=0.5)
    assert svc.pso.info()["jobs"][1]["remaining"] == 0
    _restart(svc, pulse_mode="out_dir")       # a finished points job is not re-armed
    assert [j["kind"] for j in svc.pso.info()["jobs"]] == ["distance"]


def test_a_job_the_new_machine_cannot_take_is_listed_as_dropped(svc):
    svc.ctl.enable_all()
    with svc.ctl.lock:
        svc.pso.add("distance", [0], 9, 0.002, every=5.0)
        svc.pso.add("distance", [1], 1, 0.002, every=2.0)
    svc.rebuild(dataclasses.replace(svc.config, digital_outputs=4))
    info = svc.pso.info()
    assert [j["output"] for j in info["jobs"]] == [1]
    assert len(info["dropped"]) == 1 and "output must be in [0, 3]" in info["dropped"][0]
    with svc.ctl.lock:
        svc.pso.clear()
    assert svc.pso.info() == {"jobs": [], "firings": 0, "dropped": []}


def test_loading_another_machine_file_starts_without_jobs(svc, tmp_path):
    from openmotion.config_toml import save_machine

    path = tmp_path / "other.toml"
    save_machine(svc.config, path)
    with svc.ctl.lock:
        svc.pso.add("distance", [0], 2, 0.002, every=5.0)
    svc.load(str(path))
    assert svc.pso.info() == {"jobs": [], "firings": 0, "dropped": []}
