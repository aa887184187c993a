"""`Homing(ctl, axis)` without a config homes with the machine file's settings for that
axis (`ctl.home_settings`, filled by `open_machine`), else with the default a machine file
without a home table gives."""

from __future__ import annotations

from pathlib import Path

import pytest

import openmotion
from openmotion.control import Controller, Homing
from openmotion.control.home.homeconf import default_home
from openmotion.control.home.homing_modes import HomeConfig
from openmotion.errors import MotionError

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "xyzu.toml"


def test_without_a_config_homing_takes_the_machine_files_table(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(EXAMPLE.read_text(encoding="utf-8")
                    + "\n[axes.x.home]\nmode = 1\nstr_vel = 4.0\nmax_vel = 40.0\n",
                    encoding="utf-8")
    ctl = openmotion.open_machine(path)
    h = Homing(ctl, "x")
    assert h.config is ctl.home_settings["x"]
    assert (h.config.mode, h.config.str_vel) == (1, pytest.approx(4.0 * 1000))   # pps
    assert Homing(ctl, 1).config is ctl.home_settings["y"]     # by index: y's default
    ctl.enable_all()
    ctl.hardware.scenario.place_switch(0, "org", 2000.0, 3000.0, 50.0)
    ctl.axis("x").move_absolute(20000, max_vel=100000, tacc=0.05)
    assert ctl.wait_motion_done(timeout=10)
    h = Homing(ctl, "x")
    h.start()
    assert ctl.run_until(lambda: not h.running, 120.0, event_driven=True)
    assert h.status.state == "done"        # mode 1: the end of ORG moving down
    assert ctl.axis("x").counters.command == 0


def test_a_plain_controller_homes_with_the_default():
    ctl = Controller()
    for ax in ctl.axes:
        assert Homing(ctl, ax.name).config == default_home(ax)
    given = HomeConfig(mode=2, str_vel=100.0, max_vel=1000.0, tacc=0.1)
    assert Homing(ctl, "x", given).config is given              # a config given wins


def test_bad_home_settings_and_axes_are_refused_naming_them():
    ctl = Controller()
    ctl.home_settings = {"x": {"mode": 0}}
    with pytest.raises(MotionError, match=r"ctl\.home_settings\['x'\] must be a HomeConfig"):
        Homing(ctl, "x")
    with pytest.raises(MotionError, match="config must be a HomeConfig"):
        Homing(ctl, "y", {"mode": 0})
    with pytest.raises(MotionError):
        Homing(ctl, "q")
