"""Homing settings in user units <-> HomeConfig in pulses, and the interface split."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.remote.homeconf import default_home, home_from_user, home_to_user, sequence
from openmotion.remote.interface import default_responses, split_changes

CTL = Controller()


@settings(deadline=None, max_examples=50)
@given(st.sampled_from("xyzu"), st.floats(0.5, 50.0), st.floats(1.0, 20.0),
       st.integers(-2000, 2000), st.sampled_from([0, 1, 2, 7, "mccl_normal"]))
def test_user_units_round_trip(axis, max_vel, ratio, offset, mode):
    ax = CTL.axis(axis)
    base = default_home(ax)
    user = {"max_vel": max_vel, "str_vel": max_vel / ratio, "mode": mode,
            "home_offset": offset / ax.units.pulses_per_unit}
    c = home_from_user(ax, base, user)
    assert c.max_vel == pytest.approx(max_vel * ax.units.pulses_per_unit)
    back = home_to_user(ax, c)
    again = home_from_user(ax, base, back)
    assert dataclasses.replace(again, tdec=None) == dataclasses.replace(c, tdec=None)
    assert sequence(ax, c)


@pytest.mark.parametrize("changes, words", [
    ({"max_vel": 5000.0}, "maximum safe speed"),
    ({"mode": 13}, "mode must be 0..12"),
    ({"direction": 0}, "direction must be"),
    ({"str_vel": 50.0, "max_vel": 10.0}, "str_vel must be <="),
    ({"speed": 1}, "changes.speed: unknown key"),
    ({"max_vel": "fast"}, "max_vel must be a number"),
])
def test_bad_homing_changes(changes, words):
    ax = CTL.axis("x")
    with pytest.raises(MotionError, match=words):
        home_from_user(ax, default_home(ax), changes)


def test_interface_split_keeps_machine_fields_and_responses_apart():
    cfg = CTL.config.axis("x")
    new_cfg, resp = split_changes(cfg, default_responses(),
                                  {"encoder_mode": "ab_x2", "responses": {"rdy": True}})
    assert new_cfg.encoder_mode == "ab_x2" and resp["rdy"] is True
    same, resp2 = split_changes(cfg, default_responses(), {"responses": {"alm": "decel"}})
    assert same is cfg and resp2["alm"] == "decel"
    for bad, words in [({"logic": {"pel": "maybe"}}, "axes.x.logic.pel"),
                       ({"logic": {"xyz": "no"}}, "axes.x.logic.xyz: unknown key"),
                       ({"move_ratio": 0}, "axes.x.move_ratio"),
                       ({"responses": {"sd": {"enabled": 1}}}, "responses.sd.enabled"),
                       ({"responses": {"el": "soft"}}, "responses.el")]:
        with pytest.raises(MotionError, match=words):
            split_changes(cfg, default_responses(), bad)
