"""The machine file's [axes.<name>.responses] and [axes.<name>.home] tables (config_toml):
read back as written, defaults left out, every key and value checked naming its path, and
the machine part unchanged by them."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from openmotion.config import default_machine, loads_machine
from openmotion.config_toml import (
    default_responses,
    dumps_machine,
    load_machine_settings,
    loads_machine_settings,
    save_machine,
)
from openmotion.errors import MotionError

RESP = {"el": "decel", "el_enabled": True, "el_direction_sensitive": False, "alm": "decel",
        "erc_width_s": 0.002, "sd": {"enabled": True, "latched": True, "stop": False},
        "inp": True, "rdy": False}
HOME = {"mode": 11, "direction": 1, "str_vel": 2.5, "max_vel": 40.0, "tacc": 0.2,
        "tdec": 0.3, "ez_count": 2, "org_offset": 1.5, "home_offset": -3.0,
        "final": "stay", "el_stop": "immediate", "auto_search": True, "timeout_s": 60.0}


def test_tables_round_trip_and_leave_the_machine_alone(tmp_path):
    cfg = default_machine()
    text = dumps_machine(cfg, {"x": {"responses": RESP, "home": HOME}})
    assert "[axes.x.responses]" in text and "[axes.x.home]" in text
    assert "[axes.y.responses]" not in text        # defaults are not written
    assert loads_machine(text) == cfg
    got = loads_machine_settings(text)
    assert got["x"] == {"responses": RESP, "home": HOME}
    assert got["y"] == {"responses": default_responses(), "home": {}}
    path = tmp_path / "m.toml"
    save_machine(cfg, path, {"x": {"home": {"mode": "mccl_normal"}}})
    assert load_machine_settings(path)["x"]["home"] == {"mode": "mccl_normal"}
    assert dumps_machine(cfg) == dumps_machine(cfg, {})   # no settings: the old format


@pytest.mark.parametrize(("table", "body", "message"), [
    ("responses", 'el = "sideways"', r"axes\.x\.responses\.el must be one of immediate"),
    ("responses", "erc_width_s = 2.0", r"axes\.x\.responses\.erc_width_s must be a number"),
    ("responses", "inp = 1", r"axes\.x\.responses\.inp must be true or false"),
    ("responses", "colour = 1", r"axes\.x\.responses\.colour: unknown key"),
    ("responses.sd", "enabled = 1", r"axes\.x\.responses\.sd\.enabled must be true"),
    ("responses.sd", "latch = true", r"axes\.x\.responses\.sd\.latch: unknown key.*latched"),
    ("home", "max_vel = \"fast\"", r"axes\.x\.home\.max_vel must be a (real )?number"),
    ("home", "mode = true", r"axes\.x\.home\.mode must be a mode number"),
    ("home", "ez_count = 1.5", r"axes\.x\.home\.ez_count must be an integer"),
    ("home", "maxvel = 3.0", r"axes\.x\.home\.maxvel: unknown key; did you mean 'max_vel'"),
])
def test_bad_entries_are_refused_naming_their_path(table, body, message):
    text = dumps_machine(default_machine()) + f"\n[axes.x.{table}]\n{body}\n"
    with pytest.raises(MotionError, match=message):
        loads_machine(text)          # `openmotion config` and `run` refuse it too
    with pytest.raises(MotionError, match=message):
        loads_machine_settings(text)


@given(el=st.sampled_from(["immediate", "decel"]), alm=st.sampled_from(["immediate", "decel"]),
       erc=st.floats(0.0, 1.0), flags=st.lists(st.booleans(), min_size=6, max_size=6),
       vel=st.floats(0.001, 400.0), off=st.floats(-100.0, 100.0))
def test_any_valid_settings_read_back_exactly(el, alm, erc, flags, vel, off):
    resp = {"el": el, "el_enabled": flags[0], "el_direction_sensitive": flags[1], "alm": alm,
            "erc_width_s": erc, "sd": {"enabled": flags[2], "latched": flags[3],
                                       "stop": flags[4]}, "inp": flags[5], "rdy": False}
    home = {"max_vel": vel, "home_offset": off, "auto_search": flags[0]}
    text = dumps_machine(default_machine(), {"z": {"responses": resp, "home": home}})
    assert loads_machine_settings(text)["z"] == {"responses": resp, "home": home}
