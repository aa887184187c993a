"""JSON-RPC framing, parameter checks and status diffs of the remote API (no server)."""

from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from openmotion.remote.protocol import (
    INVALID_PARAMS,
    INVALID_REQUEST,
    MAX_MESSAGE_BYTES,
    PARSE_ERROR,
    TOO_LARGE,
    Params,
    Request,
    RpcError,
    dumps,
    parse_frame,
)
from openmotion.remote.status import diff, merge


def _one(text):
    reqs, batch = parse_frame(text)
    assert not batch and len(reqs) == 1
    return reqs[0]


def test_a_request_parses_with_named_params():
    r = _one('{"jsonrpc":"2.0","id":3,"method":"axis.move","params":{"axis":"x"}}')
    assert r == Request("axis.move", {"axis": "x"}, 3, False)
    n = _one('{"jsonrpc":"2.0","method":"jog.confirm","params":{"jog":"jog-1"}}')
    assert n.notify and n.id is None


@pytest.mark.parametrize("text, code", [
    ("{nope", PARSE_ERROR),
    ("[]", INVALID_REQUEST),
    (json.dumps([{"jsonrpc": "2.0", "id": i, "method": "m"} for i in range(33)]),
     INVALID_REQUEST),
    (b"\x00binary", INVALID_REQUEST),
])
def test_bad_frames_are_refused_as_a_whole(text, code):
    with pytest.raises(RpcError) as e:
        parse_frame(text)
    assert e.value.code == code


@pytest.mark.parametrize("obj, code", [
    (1, INVALID_REQUEST),
    ({"id": 1, "method": "m"}, INVALID_REQUEST),                       # no jsonrpc
    ({"jsonrpc": "1.0", "id": 1, "method": "m"}, INVALID_REQUEST),
    ({"jsonrpc": "2.0", "id": 1, "method": 5}, INVALID_REQUEST),
    ({"jsonrpc": "2.0", "id": 1.5, "method": "m"}, INVALID_REQUEST),
    ({"jsonrpc": "2.0", "id": True, "method": "m"}, INVALID_REQUEST),
    ({"jsonrpc": "2.0", "id": 1, "method": "m", "extra": 1}, INVALID_REQUEST),
    ({"jsonrpc": "2.0", "id": 1, "method": "m", "params": [1, 2]}, INVALID_PARAMS),
    ({"jsonrpc": "2.0", "id": 1, "method": "m", "params": "x"}, INVALID_PARAMS),
])
def test_bad_requests_become_errors(obj, code):
    r = _one(json.dumps(obj))
    assert isinstance(r, RpcError) and r.code == code


def test_oversized_frame_is_too_large():
    with pytest.raises(RpcError) as e:
        parse_frame('"' + "x" * MAX_MESSAGE_BYTES + '"')
    assert e.value.code == TOO_LARGE and e.value.data == {"max_bytes": MAX_MESSAGE_BYTES}


def test_params_name_the_parameter_and_the_rule():
    p = Params({"v": -1.0, "n": "x", "s": 3, "extra": 1})
    with pytest.raises(RpcError, match=r"params.v must be >= 0, got -1.0"):
        p.number("v", lo=0.0)
    with pytest.raises(RpcError, match=r"params.n must be an integer"):
        p.integer("n")
    with pytest.raises(RpcError, match=r"params.s must be a string"):
        p.string("s")
    with pytest.raises(RpcError, match=r"params.missing is required"):
        p.number("missing")
    with pytest.raises(RpcError, match=r"params.extra: unknown parameter") as e:
        p.done()
    assert e.value.code == INVALID_PARAMS and e.value.data == {"param": "extra"}
    with pytest.raises(RpcError, match="a finite number"):
        Params({"v": float("nan")}).number("v")
    with pytest.raises(RpcError, match="true or false"):
        Params({"b": 1}).boolean("b")


def test_non_finite_numbers_are_sent_as_null():
    assert json.loads(dumps({"a": float("inf"), "b": [float("nan"), 1.0]})) == \
        {"a": None, "b": [None, 1.0]}


leaf = st.one_of(st.integers(-5, 5), st.booleans(), st.text(max_size=3), st.none(),
                st.floats(-10, 10))
axis = st.fixed_dictionaries({"command": leaf, "state": leaf,
                              "io": st.fixed_dictionaries({"pel": leaf, "org": leaf})})
status = st.fixed_dictionaries({"time": leaf, "axes": st.fixed_dictionaries(
    {"x": axis, "y": axis}), "program": st.fixed_dictionaries({"line": leaf})})


@settings(suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(status, status)
def test_merging_the_diff_gives_the_new_snapshot(old, new):
    # a status keeps its fields from push to push; the diff carries the changed ones only
    merged = merge(json.loads(json.dumps(old)), diff(old, new))
    assert merged == new
    assert diff(new, new) == {}
    assert all(k in new for k in diff(old, new))


@pytest.mark.parametrize("text, param", [
    ("max_vel on axis x must be in (0, 500] mm/s (maximum safe speed), got 900", "max_vel"),
    ("axes.x.pulse_mode must be one of out_dir, cw_ccw; got 'bogus'", "axes.x.pulse_mode"),
    ("changes.colour: unknown key; valid keys: mode", "changes.colour"),
    ("axes.x.drive.pitch_error[2] must be a finite number", "axes.x.drive.pitch_error[2]"),
    ("axis 'w' is unknown; axes: x, y", None),
    ("E-stop is active: release it before resetting the axes", None),
])
def test_refusals_name_the_parameter_for_the_field(text, param):
    from openmotion.errors import MotionError
    from openmotion.remote.protocol import REFUSED, refused

    err = refused(MotionError(text))
    assert err.code == REFUSED and err.data == {"type": "MotionError", "param": param}
