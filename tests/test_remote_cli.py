"""`openmotion ui`: refuses a network bind without a token, serves and stops on Ctrl-C;
the front end's routes; a large program's preview stays within its point budget."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from openmotion.cli import main
from remote_kit import client, served

SRC = str(Path(__file__).resolve().parent.parent / "src")


def test_host_without_token_is_refused(capsys):
    assert main(["ui", "--host", "0.0.0.0"]) == 2
    assert "--host 0.0.0.0 needs --token" in capsys.readouterr().err
    assert main(["ui", "--port", "70000"]) == 2
    assert main(["ui", "--speed", "50"]) == 2
    assert "speed must be a number in [1, 20]" in capsys.readouterr().err
    assert main(["ui", "--machine", "/nonexistent.toml"]) == 2


def test_ui_serves_and_stops_on_ctrl_c(tmp_path):
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.Popen([sys.executable, "-m", "openmotion", "ui", "--port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)
    try:
        line = proc.stdout.readline()
        assert line.startswith("openmotion ui: http://127.0.0.1:"), line
        url = line.split(": ", 1)[1].strip().rstrip("/")
        with urllib.request.urlopen(url + "/health", timeout=20) as r:
            assert json.loads(r.read())["status"] == "ok"
        from openmotion.remote import connect

        ws = url.replace("http://", "ws://") + "/ws"
        with connect(ws, timeout=20) as m:
            assert m.call("machine.info")["name"] == "xyzu"
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            # a guard against a hang only: with the CPU shared 13 ways the interpreter's
            # exit alone took 8-10 s here (0.25 s of CPU), a loaded CI machine more
            rc = proc.wait(timeout=90)
        except subprocess.TimeoutExpired:
            proc.kill()
            raise
    assert rc == 0, proc.stderr.read()


def test_front_end_routes_without_and_with_the_static_files(tmp_path):
    from openmotion.remote.server import RemoteServer, ServerThread
    from openmotion.remote.service import MachineService

    (tmp_path / "index.html").write_text("<html>creator</html>")
    (tmp_path / "app.js").write_text("console.log(1)")
    svc = MachineService()
    th = ServerThread(RemoteServer(svc, static_dir=tmp_path)).start()
    try:
        with urllib.request.urlopen(th.url + "/", timeout=10) as r:
            assert "creator" in r.read().decode()
        with urllib.request.urlopen(th.url + "/static/app.js", timeout=10) as r:
            assert r.read() == b"console.log(1)"
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(th.url + "/static/../../etc/passwd", timeout=10)
        assert e.value.code == 404
    finally:
        th.stop()
        svc.shutdown()
    empty = tmp_path / "none"
    svc = MachineService()
    th = ServerThread(RemoteServer(svc, static_dir=empty)).start()
    try:
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(th.url + "/", timeout=10)
        assert e.value.code == 404 and b"front end is not installed" in e.value.read()
    finally:
        th.stop()
        svc.shutdown()


def test_large_program_preview_is_decimated():
    lines = ["G21 G90 G17", "G0 X0 Y0"]
    for i in range(4000):
        lines.append(f"G1 X{(i % 40) * 0.5:.1f} Y{(i // 40) * 0.5:.1f} F3000")
        if i % 500 == 0:
            lines.append("G2 I1 J0")
    lines.append("M2")
    text = "\n".join(lines) + "\n"
    with served() as (_svc, th), client(th) as m:
        t0 = time.process_time()
        res = m.call("program.load", text=text, name="big.ngc", timeout=120)
        assert res["lines"] == len(lines)
        prev = m.call("program.preview", max_points=1000)
        assert prev["decimated"] and prev["total"] > 4000
        assert 500 <= len(prev["points"]) <= 1300
        assert prev["line"] == sorted(prev["line"])   # in program order
        # machine coordinates: program zero sits mid-travel (x 150 mm), as `openmotion run`
        assert prev["bounds"]["max"][0] == pytest.approx(150.0 + 19.5)
        assert time.process_time() - t0 < 120


def test_the_commissioning_example_runs_against_a_server():
    import importlib.util

    path = Path(__file__).resolve().parent.parent / "examples" / "remote_commission.py"
    spec = importlib.util.spec_from_file_location("remote_commission", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    with served() as (_svc, th):
        out = mod.commission(th.ws_url, None)
    assert out["position"] == pytest.approx(20.0)
    assert out["peak_velocity"] == pytest.approx(40.0, rel=1e-6)
