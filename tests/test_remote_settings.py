"""Settings through the API: interface I/O and homing validated, saved to the machine file
(responses and homing in its own tables) and loaded back, an old UI sidecar migrated; two
clients, commands serialised, and the refusal of a command carrying an outdated
config_version."""

from __future__ import annotations

import threading

import pytest

from openmotion.config import load_machine
from openmotion.config_toml import load_machine_settings
from openmotion.remote import ReloadError, RemoteError
from openmotion.remote.interface import sidecar_path
from openmotion.remote.service import MachineService
from remote_kit import at_rest, client, machine_file, served

WAIT = 20.0


def test_interface_change_is_validated_saved_and_loaded_back(tmp_path):
    path = machine_file(tmp_path)
    with served(file=path) as (svc, th), client(th) as m:
        info = m.call("machine.info")
        assert info["file"] == str(path) and info["config_version"] == 1
        before = path.read_text()
        cur = m.call("interface.get", axis="x")
        assert cur["logic"]["pel"] == "nc" and cur["responses"]["el"] == "immediate"
        assert "cw_ccw" in cur["choices"]["pulse_mode"]
        # a bad value: refused naming the field, nothing saved, version unchanged
        with pytest.raises(RemoteError, match=r"axes\.x\.pulse_mode must be one of"):
            m.call("interface.set", axis="x", config_version=1,
                   changes={"pulse_mode": "bogus"})
        with pytest.raises(RemoteError, match=r"erc_width_s must be a number in \[0, 1\]"):
            m.call("interface.set", axis="x", config_version=1,
                   changes={"responses": {"erc_width_s": -1}})
        with pytest.raises(RemoteError, match=r"changes.colour: unknown key"):
            m.call("interface.set", axis="x", config_version=1, changes={"colour": 1})
        assert path.read_text() == before and svc.config_version == 1
        # a good change: applied, saved, version bumped
        res = m.call("interface.set", axis="x", config_version=1, changes={
            "pulse_mode": "cw_ccw", "move_ratio": 2.0, "logic": {"org": "nc"},
            "responses": {"el": "decel", "sd": {"enabled": True}, "erc_width_s": 0.01}})
        assert res["saved"] == str(path) and res["config_version"] == 2
        assert res["interface"]["pulse_mode"] == "cw_ccw"
        ax = load_machine(path).axis("x")
        assert (ax.pulse_mode, ax.move_ratio, ax.logic["org"]) == ("cw_ccw", 2.0, "nc")
        saved = load_machine_settings(path)["x"]["responses"]   # in the machine file itself
        assert saved["el"] == "decel" and saved["sd"]["enabled"] is True
        assert "[axes.x.responses]" in path.read_text()
        assert not sidecar_path(path).exists()
        assert svc.ctl.safety.settings("x").el_decelerate
        # responses only: applied live, no rebuild
        ctl = svc.ctl
        m.call("interface.set", axis="y", config_version=2, changes={
            "responses": {"alm": "decel"}})
        assert svc.ctl is ctl and svc.ctl.axis("y").alarm_decelerate
        m.call("home.set", axis="x", config_version=3, changes={"mode": 2, "max_vel": 30.0})
        home = load_machine_settings(path)["x"]["home"]
        assert home["mode"] == 2 and home["max_vel"] == pytest.approx(30.0)
    # a new server on the same file has every setting back
    svc2 = MachineService(file=path)
    try:
        assert svc2.config.axis("x").pulse_mode == "cw_ccw"
        assert svc2.ctl.safety.settings("x").el_decelerate
        assert svc2.ctl.axis("y").alarm_decelerate
        assert svc2.homes["x"].mode == 2
        assert svc2.homes["x"].max_vel == pytest.approx(30.0 * 1000)
    finally:
        svc2.shutdown()


def test_an_old_ui_sidecar_is_read_and_folded_into_the_machine_file(tmp_path):
    path = machine_file(tmp_path)
    side = sidecar_path(path)
    side.write_text('[interface.x]\nel = "decel"\n[home.x]\nmode = 3\nmax_vel = 25.0\n')
    with served(file=path) as (svc, th), client(th) as m:
        assert svc.ctl.safety.settings("x").el_decelerate and svc.homes["x"].mode == 3
        assert m.call("interface.get", axis="x")["responses"]["el"] == "decel"
        m.call("machine.save")
        assert not side.exists()
        saved = load_machine_settings(path)["x"]
        assert saved["responses"]["el"] == "decel" and saved["home"]["mode"] == 3
    svc2 = MachineService(file=path)
    try:
        assert svc2.ctl.safety.settings("x").el_decelerate and svc2.homes["x"].mode == 3
    finally:
        svc2.shutdown()


def test_a_bad_home_table_in_the_machine_file_is_refused_naming_it(tmp_path):
    from openmotion.errors import MotionError

    path = machine_file(tmp_path)
    path.write_text(path.read_text() + "\n[axes.x.home]\nmode = 99\n")
    with pytest.raises(MotionError, match=r"axes\.x\.home: mode must be 0\.\.12"):
        MachineService(file=path)


def test_machine_save_gives_the_in_memory_machine_a_file(tmp_path):
    with served() as (_svc, th), client(th) as m:
        assert m.call("machine.info")["file"] is None
        with pytest.raises(RemoteError, match="path is required"):
            m.call("machine.save")
        res = m.call("machine.save", path=str(tmp_path / "new.toml"))
        assert load_machine(res["file"]).name == "xyzu"
        info = m.call("machine.info")
        assert info["file"] == str(tmp_path / "new.toml")
        # loading it again rebuilds the controller; config_version goes up
        out = m.call("machine.load", path=res["file"], config_version=info["config_version"])
        assert out["config_version"] == info["config_version"] + 1


def test_a_stale_config_version_is_refused_with_reload(tmp_path):
    path = machine_file(tmp_path)
    with served(file=path) as (svc, th), client(th) as a, client(th) as b:
        va = a.call("machine.info")["config_version"]
        vb = b.call("machine.info")["config_version"]
        assert va == vb == 1
        b.subscribe(rate_hz=20)
        a.call("interface.set", axis="x", config_version=va,
               changes={"responses": {"inp": True}})
        # b is told at once, and a command of b on the old version is refused
        assert b.wait(lambda s: b.config_version == 2, WAIT)
        with pytest.raises(ReloadError) as e:
            b.call("interface.set", axis="x", config_version=vb,
                   changes={"responses": {"inp": False}})
        assert e.value.code == -32001 and e.value.data == {"config_version": 2}
        with pytest.raises(ReloadError):
            b.call("axis.servo", axis="x", on=True, config_version=vb)
        assert not svc.ctl.axis("x").powered
        # after a reload it goes through
        vb = b.call("machine.info")["config_version"]
        b.call("axis.servo", axis="x", on=True, config_version=vb)
        assert svc.ctl.axis("x").powered


def test_two_clients_commands_are_serialised():
    with served() as (svc, th), client(th) as a, client(th) as b:
        a.call("axis.servo", axis="x", on=True)
        results: list[object] = []

        def move(c):
            try:
                c.call("axis.move", axis="x", kind="relative", distance=5.0, max_vel=20.0)
                results.append("moved")
            except RemoteError as exc:
                results.append(exc.message)

        threads = [threading.Thread(target=move, args=(c,)) for c in (a, b)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        # one command ran first and started the move; the other found it running
        assert results.count("moved") == 1, results
        assert any("a motion is running" in str(r) for r in results), results
        a.subscribe(rate_hz=20)
        assert a.wait(lambda s: s["axes"]["x"]["command"] == 5000 and at_rest("x")(s), WAIT)
        assert a.call("server.info")["clients"] == 2


def test_stops_do_not_wait_behind_a_long_command():
    with served() as (svc, th), client(th) as m:
        m.call("axis.servo", axis="x", on=True)
        m.call("axis.move", axis="x", kind="velocity", velocity=10.0)
        release = threading.Event()
        th.server._commands.submit(release.wait, 30)   # a command that takes its time
        try:
            m.call("machine.estop", timeout=10)          # answered while it still runs
            assert svc.ctl.axis("x").state.value == "ErrorStop"
            m.call("axis.stop", timeout=10)
            with pytest.raises(Exception, match="no answer"):
                m.call("axis.reset", axis="x", timeout=0.5)   # a command: it waits
        finally:
            release.set()


def test_a_slow_query_does_not_hold_up_the_next_request_on_its_connection():
    import json
    import time

    from openmotion.remote.methods import Method

    with served() as (svc, th), client(th) as m:
        release = threading.Event()

        def slow(ctx, p):
            p.done()
            release.wait(20)
            return {"slow": True}

        th.server.methods = {**th.server.methods, "test.slow": Method(slow, command=False)}
        m._send(json.dumps({"jsonrpc": "2.0", "id": "s", "method": "test.slow"}))
        # answered while the slow query still waits, on the same connection
        assert m.call("server.info", timeout=10)["api"] == 1
        m.call("axis.servo", axis="x", on=True, timeout=10)
        jog = m.call("jog.start", axis="x", direction=1, timeout=10)["jog"]
        assert m.call("jog.confirm", jog=jog, timeout=10)["active"]
        m.call("jog.stop", jog=jog, timeout=10)
        release.set()
        t_end = time.monotonic() + 10
        while "s" not in m._pending and time.monotonic() < t_end:
            time.sleep(0.01)
        assert m._pending["s"][0]["result"] == {"slow": True}
