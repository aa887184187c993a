"""Every use of a machine file obeys its [axes.<name>.responses] and [axes.<name>.home]
tables: `openmotion run`, `openmotion config`, `openmotion.open_machine` (machine_file.py;
one implementation in control.guard.responses / control.home.homeconf, the UI's too)."""

from __future__ import annotations

from pathlib import Path

import pytest

import openmotion
from openmotion.cli import main
from openmotion.config_toml import loads_machine_settings
from openmotion.errors import MotionError
from openmotion.machine_file import apply_machine_settings
from openmotion.program import runjob
from openmotion.program.runner import ProgramRunner, RunOptions

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "xyzu.toml"
#: X's +EL described by its far edge: active over [305, 355) mm while the travel the
#: runner allows reaches 355 mm, so a G0 X340 runs into the switch at 305 mm
PEL_OLD = "[axes.x.pel]\nposition = 305.0\nwidth = 50.0"
PEL_NEW = "[axes.x.pel]\nposition = 355.0\nwidth = -50.0"
PROGRAM = "G21 G90 G10 L2 P1 X0 Y0 Z0\nG0 X340\nM2\n"


def machine(tmp_path: Path, extra: str = "", name: str = "m.toml") -> Path:
    text = EXAMPLE.read_text(encoding="utf-8")
    assert PEL_OLD in text
    path = tmp_path / name
    path.write_text(text.replace(PEL_OLD, PEL_NEW) + "\n" + extra, encoding="utf-8")
    return path


DECEL = '[axes.x.responses]\nel = "decel"\n'


def run_to_rest(ctl) -> ProgramRunner:
    ctl.enable_all()
    run = ProgramRunner(ctl, PROGRAM, options=RunOptions())
    run.start()
    ctl.run_until(lambda: not ctl.axis(0).is_moving and ctl.time > 0.7, timeout=5.0)
    return run


def test_open_machine_obeys_the_limit_stop_mode(tmp_path):
    hard = openmotion.open_machine(machine(tmp_path))
    soft = openmotion.open_machine(machine(tmp_path, DECEL, "d.toml"))
    for ctl in (hard, soft):
        run_to_rest(ctl)
        assert ctl.axis(0).fault == "+EL"
        (limit,) = ctl.events.events("limit")
        assert limit.position == pytest.approx(305_000, abs=1)   # the switch edge
    # immediate: the axis stands at the edge (one cycle's travel); decel: it ramps down
    assert hard.axis(0).position == pytest.approx(305_000, abs=500)
    assert soft.axis(0).position > 310_000
    assert soft.axis(0).position < 340_000


def _final_x(tmp_path, monkeypatch, path: Path) -> tuple[int, float]:
    seen = []
    real = runjob.summarize

    def spy(run):   # the run's controller, as `openmotion run` built it
        seen.append(run._ctl.axis(0).position)
        return real(run)

    monkeypatch.setattr(runjob, "summarize", spy)
    prog = tmp_path / "p.ngc"
    prog.write_text(PROGRAM, encoding="utf-8")
    rc = main(["run", str(prog), "--machine", str(path), "--out", str(tmp_path / "out")])
    return rc, seen[-1]


def test_openmotion_run_obeys_the_machine_files_responses(tmp_path, monkeypatch, capsys):
    rc, hard = _final_x(tmp_path, monkeypatch, machine(tmp_path))
    assert rc == 1 and "+EL" in capsys.readouterr().out
    rc, soft = _final_x(tmp_path, monkeypatch, machine(tmp_path, DECEL, "d.toml"))
    assert rc == 1 and "+EL" in capsys.readouterr().out
    assert hard == pytest.approx(305_000, abs=500)
    assert soft > 310_000


@pytest.mark.parametrize("extra, key", [
    ('[axes.x.responses]\nel = "slow"\n', "axes.x.responses.el"),
    ('[axes.y.responses]\nerc_width_s = 5.0\n', "axes.y.responses.erc_width_s"),
    ('[axes.x.responses.sd]\nlatch = true\n', "axes.x.responses.sd"),
    ('[axes.x.home]\nmode = 99\n', "axes.x.home"),
    ('[axes.x.home]\nstr_vel = 50.0\nmax_vel = 10.0\n', "axes.x.home"),
    ('[axes.z.home]\ndirection = 2\n', "axes.z.home"),
    ('[axes.x.home]\nmax_vel = 5000.0\n', "axes.x.home"),
])
def test_bad_tables_are_refused_on_load_naming_the_key(tmp_path, capsys, extra, key):
    path = machine(tmp_path, extra)
    for argv in (["config", str(path)],
                 ["run", str(tmp_path / "p.ngc"), "--machine", str(path),
                  "--out", str(tmp_path / "out")]):
        (tmp_path / "p.ngc").write_text(PROGRAM, encoding="utf-8")
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert key in err and str(path) in err, err
    with pytest.raises(MotionError, match=key.replace(".", r"\.")):
        openmotion.open_machine(path)


def test_config_prints_and_checks_the_tables(tmp_path, capsys):
    path = machine(tmp_path, DECEL + '[axes.x.home]\nmode = 2\nstr_vel = 5.0\n')
    assert main(["config", str(path)]) == 0
    out = capsys.readouterr().out
    settings = loads_machine_settings(out)   # what it prints is the file as resolved
    assert settings["x"]["responses"]["el"] == "decel"
    assert settings["x"]["home"] == {"mode": 2, "str_vel": 5.0}
    ctl = openmotion.open_machine(path)
    assert ctl.home_settings["x"].mode == 2
    assert ctl.home_settings["x"].str_vel == pytest.approx(5.0 * 1000)   # pps
    assert ctl.home_settings["y"].mode == 0                               # default


def test_a_refused_setting_changes_nothing(tmp_path):
    ctl = openmotion.open_machine(machine(tmp_path))
    before = [ctl.safety.settings(i) for i in range(len(ctl.axes))]
    bad = {"x": {"responses": {"el": "decel"}}, "y": {"responses": {"alm": "later"}}}
    with pytest.raises(MotionError, match=r"axes\.y\.responses\.alm"):
        apply_machine_settings(ctl, bad)
    with pytest.raises(MotionError, match=r"axes\.x\.home"):
        apply_machine_settings(ctl, {"x": {"responses": {"el": "decel"},
                                           "home": {"mode": 42}}})
    with pytest.raises(MotionError, match="no axis 'w'"):
        apply_machine_settings(ctl, {"w": {"responses": {}}})
    assert [ctl.safety.settings(i) for i in range(len(ctl.axes))] == before
    assert ctl.safety.settings("x").el_decelerate is False


def test_without_a_safety_layer_only_default_responses_are_accepted(tmp_path):
    plain = openmotion.open_machine(machine(tmp_path), safety=False)
    assert plain.safety is None
    with pytest.raises(MotionError, match="no safety layer"):
        openmotion.open_machine(machine(tmp_path, DECEL, "d.toml"), safety=False)
