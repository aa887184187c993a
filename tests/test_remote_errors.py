"""Bad input at the server: malformed frames, unknown methods, bad parameters, oversized
messages, auth. Every one gets a JSON-RPC error naming what was wrong, the controller is
left exactly as it was, and the server keeps answering."""

from __future__ import annotations

import json
import urllib.error
import urllib.request

import pytest

from openmotion.remote import RemoteError
from openmotion.remote.protocol import MAX_MESSAGE_BYTES
from remote_kit import client, served


@pytest.fixture(scope="module")
def server():
    with served() as (svc, th):
        yield svc, th


@pytest.fixture
def m(server):
    with client(server[1]) as c:
        yield c


def _err(answer):
    assert "error" in answer, answer
    return answer["error"]


@pytest.mark.parametrize("frame, code", [
    ("{not json", -32700),
    ("[]", -32600),
    ('{"jsonrpc": "2.0", "id": null, "method": 7}', -32600),
    ('"just a string"', -32600),
    ('{"id": 1, "method": "server.info"}', -32600),
    ('{"jsonrpc": "2.0", "id": {"a": 1}, "method": "server.info"}', -32600),
])
def test_malformed_frames_get_errors_and_the_server_stays_up(m, frame, code):
    assert _err(m.raw(frame))["code"] == code
    assert m.call("server.info")["api"] == 1


def test_binary_and_oversized_frames(m):
    assert _err(m.raw(b"\x01\x02"))["code"] == -32600
    big = json.dumps({"jsonrpc": "2.0", "id": 1, "method": "program.load",
                      "params": {"text": "G0 X1\n" * (MAX_MESSAGE_BYTES // 6 + 10)}})
    e = _err(m.raw(big))
    assert e["code"] == -32002 and e["data"] == {"max_bytes": MAX_MESSAGE_BYTES}
    assert m.call("server.info")["api"] == 1


def test_unknown_method_and_positional_params(m):
    e = _err(m.raw('{"jsonrpc":"2.0","id":5,"method":"axis.fly"}', 5))
    assert e["code"] == -32601 and e["data"] == {"method": "axis.fly"}
    e = _err(m.raw('{"jsonrpc":"2.0","id":6,"method":"axis.status","params":["x"]}', 6))
    assert e["code"] == -32602


def test_batch_answers_in_order_notifications_unanswered(m):
    out = m.raw_batch([
        {"jsonrpc": "2.0", "id": 1, "method": "server.info"},
        {"jsonrpc": "2.0", "method": "server.info"},
        {"jsonrpc": "2.0", "id": 2, "method": "nope"},
    ])
    assert [o["id"] for o in out] == [1, 2]
    assert "result" in out[0] and out[1]["error"]["code"] == -32601


@pytest.mark.parametrize("method, params, code, words", [
    ("axis.move", {"axis": "x", "kind": "fly", "distance": 1.0, "max_vel": 5.0}, -32602,
     "params.kind"),
    ("axis.move", {"axis": "x", "kind": "relative", "distance": "1", "max_vel": 5.0},
     -32602, "params.distance must be a finite number"),
    ("axis.move", {"axis": "x", "kind": "relative", "distance": 1.0}, -32602,
     "params.max_vel is required"),
    ("axis.move", {"axis": "x", "kind": "relative", "distance": 1.0, "max_vel": 5.0,
                   "colour": "red"}, -32602, "params.colour: unknown parameter"),
    ("axis.move", {"axis": "w", "kind": "relative", "distance": 1.0, "max_vel": 5.0},
     -32000, "axis 'w' is unknown"),
    ("axis.move", {"axis": "x", "kind": "relative", "distance": 1.0, "max_vel": 900.0},
     -32000, "max_vel on axis x must be in (0, 500] mm/s"),
    ("axis.move", {"axis": "x", "kind": "relative", "distance": 1.0, "max_vel": 5.0,
                   "tacc": 0}, -32602, "params.tacc must be > 0"),
    ("axis.move", {"axis": "x", "kind": "relative", "distance": 1.0, "max_vel": 5.0},
     -32000, "disabled"),
    ("jog.start", {"axis": "x", "direction": 2}, -32602, "params.direction"),
    ("jog.confirm", {"jog": "jog-999999"}, -32000, "unknown"),
    ("interface.set", {"axis": "x", "changes": {}}, -32602, "params.config_version"),
    ("program.load", {"text": "G1 X1 F100\nG5000\n"}, -32000, "line 2"),
    ("program.run", {}, -32000, "no program loaded"),
    ("scope.configure", {"channels": []}, -32000, "channels"),
    ("status.subscribe", {"rate_hz": 500}, -32602, "params.rate_hz must be <= 50"),
    ("sim.speed", {"factor": 0.5}, -32602, "params.factor"),
    ("machine.load", {"path": "/nonexistent.toml", "config_version": 1}, -32000,
     "nonexistent"),
])
def test_bad_params_name_the_parameter_and_change_nothing(server, m, method, params, code,
                                                          words):
    svc = server[0]
    before = [ax.snapshot() for ax in svc.ctl.axes]
    version = svc.config_version
    with pytest.raises(RemoteError) as e:
        m.call(method, **params)
    assert e.value.code == code, e.value
    assert words in e.value.message
    assert [ax.snapshot() for ax in svc.ctl.axes] == before
    assert svc.config_version == version
    assert m.call("server.info")["api"] == 1


def test_http_routes_and_health(server):
    th = server[1]
    with urllib.request.urlopen(th.url + "/health", timeout=10) as r:
        assert json.loads(r.read()) == {"status": "ok", "api": 1}
    with urllib.request.urlopen(th.url + "/api/scope.csv", timeout=10) as r:
        assert r.headers["Content-Type"].startswith("text/csv")
        assert r.read().decode().startswith("t,")
    req = urllib.request.Request(th.url + "/api/program?name=up.ngc",
                                 data=b"G21 G90\nG1 X1 F100\nM2\n", method="POST")
    with urllib.request.urlopen(req, timeout=20) as r:
        assert json.loads(r.read())["file"] == "up.ngc"
    bad = urllib.request.Request(th.url + "/api/program", data=b"G1 X1 F100\nG5000\n",
                                 method="POST")
    with pytest.raises(urllib.error.HTTPError) as e:
        urllib.request.urlopen(bad, timeout=20)
    assert e.value.code == 400 and "line 2" in json.loads(e.value.read())["error"]["message"]


def test_token_gates_http_and_websocket():
    token = "s3cret-token-0123456789"
    with served(token=token) as (_svc, th):
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(th.url + "/api/scope.csv", timeout=10)
        assert e.value.code == 401
        with urllib.request.urlopen(th.url + "/health", timeout=10) as r:
            assert r.status == 200
        # the front end's static assets carry no secrets: served without the token; the
        # page itself, the API routes and the socket are gated
        for asset in ("/static/js/app.js", "/static/css/creator.css"):
            with urllib.request.urlopen(th.url + asset, timeout=10) as r:
                assert r.status == 200
        for gated in ("/", "/static/../api/scope.csv", "/static/%2e%2e/api/scope.csv"):
            with pytest.raises(urllib.error.HTTPError) as e:
                urllib.request.urlopen(th.url + gated, timeout=10)
            assert e.value.code in (401, 404), gated
        req = urllib.request.Request(th.url + "/api/program", data=b"G0 X0\n", method="POST")
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(req, timeout=10)
        assert e.value.code == 401
        with urllib.request.urlopen(th.url + f"/api/scope.csv?token={token}",
                                    timeout=10) as r:
            assert r.status == 200
        with pytest.raises(Exception, match="cannot connect"):
            client(th)
        with pytest.raises(Exception, match="cannot connect"):
            client(th, token="wrong-token-0123456789")
        with client(th, token=token) as c:
            assert c.call("server.info")["api"] == 1
        from openmotion.remote import connect

        with connect(th.ws_url + f"?token={token}") as c:   # as the browser gives it
            assert c.call("server.info")["api"] == 1


def test_host_needs_a_token():
    from openmotion.errors import MotionError
    from openmotion.remote.server import check_bind

    with pytest.raises(MotionError, match="needs --token"):
        check_bind("0.0.0.0", None)
    with pytest.raises(MotionError, match="at least 16"):
        check_bind("0.0.0.0", "short")
    check_bind("0.0.0.0", "x" * 16)
    check_bind("127.0.0.1", None)


def test_a_frame_past_the_hard_limit_closes_that_connection_only(server):
    from openmotion.remote.server import WS_HARD_LIMIT

    th = server[1]
    with client(th) as bad, client(th) as good:
        with pytest.raises(Exception):  # noqa: B017 - closed by the WebSocket layer (1009)
            bad.raw("x" * (WS_HARD_LIMIT + 10), timeout=20)
        assert good.call("server.info")["api"] == 1
    with client(th) as again:
        assert again.call("server.info")["api"] == 1
