"""Fuzz the method table: random parameters for every method never give an internal
error (-32603) and never break the controller; every answer is a JSON-RPC response."""

from __future__ import annotations

import asyncio
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from openmotion.remote.methods import Context
from openmotion.remote.server import RemoteServer
from openmotion.remote.service import MachineService

KEYS = ["axis", "kind", "position", "distance", "velocity", "max_vel", "str_vel", "tacc",
        "tdec", "shape", "vs_acc", "vs_dec", "on", "p1", "p2", "delay_s", "count", "mode",
        "direction", "speed", "ratio", "jog", "changes", "signal", "active", "pressed",
        "factor", "channels", "divider", "seconds", "trigger", "since", "max_points",
        "text", "name", "first", "percent", "feed_override", "single_block", "repeat",
        "rate_hz", "fields", "subscription", "command", "feedback", "target", "start",
        "end", "config_version", "speed_range", "reason", "max", "amplitude", "duration_s",
        "back", "settle_s", "band", "output", "every", "points", "window", "pulse_s", "axes"]
VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-10**12, 10**12),
    st.floats(allow_nan=False, allow_infinity=False, width=32),
    st.sampled_from(["x", "y", "u", "w", "", "relative", "absolute", "velocity", "S", "T",
                     "pel", "decel", "jog-1", "x.command", "G1 X1 F100\nM2\n", "G9999",
                     "move", "step", "points", "di.3", "do.99"]),
    st.lists(st.sampled_from(["x.command", "y.velocity", "nope", 3, "x", "di.2"]), max_size=3),
    st.lists(st.lists(st.floats(-1e3, 1e3, width=32), max_size=3), max_size=3),
    st.dictionaries(st.sampled_from(["pulse_mode", "responses", "logic", "max_vel", "mode",
                                     "channel", "el", "k", "kp", "compensator"]),
                    st.one_of(st.integers(-3, 3), st.text(max_size=4),
                              st.dictionaries(st.sampled_from(["el", "pel", "sd"]),
                                              st.sampled_from(["nc", "decel", 1, True])),
                              ), max_size=3),
)
#: methods that touch files or the pacing thread are fuzzed elsewhere
SKIP = {"machine.save", "machine.load", "sim.speed", "status.subscribe", "scope.subscribe"}


@pytest.fixture(scope="module")
def rig():
    svc = MachineService()   # virtual time: nothing paces it, the calls are what happens
    server = RemoteServer(svc)
    yield svc, server
    server.close()


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(st.data())
def test_no_params_reach_an_internal_error(rig, data):
    svc, server = rig
    names = sorted(set(server.methods) - SKIP)
    method = data.draw(st.sampled_from(names))
    params = data.draw(st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=6))
    params.pop("path", None)
    frame = json.dumps({"jsonrpc": "2.0", "id": 1, "method": method, "params": params})
    out = json.loads(asyncio.run(server.handle_frame(Context(svc), frame)))
    assert out["id"] == 1 and ("result" in out) != ("error" in out)
    if "error" in out:
        assert out["error"]["code"] != -32603, (method, params, out["error"])
    for _ in range(5):
        svc.ctl.step()
    assert svc.ctl.cycle_errors == 0 and not svc.hook_errors
