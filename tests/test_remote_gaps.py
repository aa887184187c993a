"""Gaps the browser half found in the server (issue #20), each driven through the client:
the software E-stop in `status.estop`, the SVON lamp, homing's state and counters in one
push, `home.get {mode}`, refusals in the user's units, the working folder of file paths."""

from __future__ import annotations

import pytest

from openmotion.remote import RemoteError
from remote_kit import at_rest, client, served

WAIT = 20.0   # generous: the checks are on states, never on wall-clock figures


@pytest.fixture
def machine():
    with served() as (svc, th), client(th) as m:
        m.subscribe(rate_hz=50)
        yield svc, m


def test_software_estop_is_reported_until_reset(machine):
    svc, m = machine
    m.call("axis.servo", axis="x", on=True)
    assert m.wait(lambda s: s["axes"]["x"]["servo"] and not s["estop"], WAIT)
    m.call("machine.estop", reason="test")
    assert m.wait(lambda s: s["estop"] and s["axes"]["x"]["state"] == "ErrorStop", WAIT)
    assert m.call("status.get")["estop"]
    with pytest.raises(RemoteError, match="latched"):
        m.call("axis.reset", axis="x")
    assert m.call("status.get")["axes"]["x"]["state"] == "ErrorStop"
    m.call("machine.reset")
    assert m.wait(lambda s: not s["estop"] and s["axes"]["x"]["state"] != "ErrorStop", WAIT)


def test_svon_lamp_follows_servo_on(machine):
    svc, m = machine
    assert not m.status["axes"]["x"]["io"]["svon"]
    m.call("axis.servo", axis="x", on=True)
    assert m.wait(lambda s: s["axes"]["x"]["io"]["svon"] and s["axes"]["x"]["servo"], WAIT)
    m.call("axis.servo", axis="x", on=False)
    assert m.wait(lambda s: not s["axes"]["x"]["io"]["svon"], WAIT)


def test_homing_done_arrives_with_the_counters_cleared(machine):
    """No push shows homing `done` before the counters read their home values: the state
    and the counters change in one cycle under the controller's lock, one snapshot. The
    target recorder too: the UI's Home resets it (the HSL library leaves it to the
    application, manual 4.4), while a Homing run by the library alone keeps it."""
    svc, m = machine
    m.call("axis.servo", axis="x", on=True)
    m.call("axis.move", axis="x", kind="absolute", position=20.0, max_vel=100.0, tacc=0.05)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 20000 and at_rest("x")(s), WAIT)
    info = m.call("machine.info")
    m.call("home.set", axis="x", config_version=info["config_version"],
           changes={"max_vel": 40.0, "str_vel": 4.0, "direction": -1})
    m.notifications.clear()
    m.call("home.start", axis="x")
    assert m.wait(lambda s: s["axes"]["x"]["homing"]["state"] == "done", WAIT)
    view: dict = {}
    for msg in list(m.notifications):
        if msg.get("method") != "notify_status_update":
            continue
        d = msg["params"][0].get("axes", {}).get("x", {})
        view.update({k: v for k, v in d.items() if k in ("command", "error", "target")})
        if d.get("homing", {}).get("state") == "done":
            assert view.get("command") == 0 and view.get("error", 0) == 0, d
            assert view.get("target") == 0, d
            break
    else:
        raise AssertionError("no push carried homing done")
    assert svc.ctl.axis("x").counters.target == 0.0


def test_the_library_homing_alone_keeps_the_target_recorder():
    from openmotion.config import default_machine
    from openmotion.control import Controller
    from openmotion.control.home.homing import Homing
    from openmotion.control.home.homing_modes import HomeConfig

    ctl = Controller(default_machine())
    ax = ctl.axis("x")
    ax.enable()
    ax.move_relative(20000, max_vel=50000, tacc=0.05)
    ctl.run_until(lambda: not ax.is_moving, timeout=20.0)
    h = Homing(ctl, "x", HomeConfig(mode=0, direction=-1, str_vel=4000.0, max_vel=40000.0))
    h.start()
    ctl.run_until(lambda: not h.running, timeout=60.0)
    assert h.done and ax.counters.command == 0
    assert ax.counters.target != 0.0     # HSL: "the target position recorder will not"


def test_home_get_draws_another_mode_without_applying_it(machine):
    svc, m = machine
    saved = m.call("home.get", axis="x")
    assert saved["config"]["mode"] == 0
    other = m.call("home.get", axis="x", mode=11)
    assert other["config"]["mode"] == 11 and other["sequence"] != saved["sequence"]
    assert other["config"]["max_vel"] == saved["config"]["max_vel"]   # the rest as saved
    assert m.call("home.get", axis="x")["config"]["mode"] == 0        # nothing applied
    assert svc.homes["x"].mode == 0
    with pytest.raises(RemoteError) as e:
        m.call("home.get", axis="x", mode=99)
    assert "mode" in e.value.message


@pytest.mark.parametrize(("method", "params", "quoted"), [
    ("axis.move", {"kind": "velocity", "velocity": 1e6}, "500 mm/s"),
    ("axis.move", {"kind": "velocity", "velocity": 1.0, "str_vel": 5.0}, "5 mm/s"),
    ("axis.move", {"kind": "relative", "distance": 5.0, "max_vel": 1e6}, "500] mm/s"),
    ("home.set", {"changes": {"max_vel": 1e6}}, "500 mm/s"),
    ("home.set", {"changes": {"str_vel": 50.0, "max_vel": 40.0}}, "(40 mm/s), got 50 mm/s"),
])
def test_refusals_quote_the_users_units(machine, method, params, quoted):
    svc, m = machine
    m.call("axis.servo", axis="x", on=True)
    if method == "home.set":
        params = {**params, "config_version": m.call("machine.info")["config_version"]}
    before = m.call("home.get", axis="x")["config"]
    with pytest.raises(RemoteError) as e:
        m.call(method, axis="x", **params)
    assert quoted in e.value.message and "pps" not in e.value.message, e.value.message
    assert m.call("home.get", axis="x")["config"] == before
    assert not m.call("status.get")["axes"]["x"]["moving"]


def test_change_speed_refusal_in_mm_per_s(machine):
    svc, m = machine
    m.call("axis.servo", axis="x", on=True)
    m.call("axis.move", axis="x", kind="velocity", velocity=10.0)
    try:
        with pytest.raises(RemoteError) as e:
            m.call("axis.change_speed", axis="x", velocity=50.0)
        assert "speed range 10 mm/s" in e.value.message, e.value.message
        assert e.value.data["param"] == "velocity"
    finally:
        m.call("axis.stop", axis="x", mode="immediate")


def test_file_paths_stay_in_the_working_folder(tmp_path):
    from openmotion.remote.workdir import WorkFolder
    from remote_kit import machine_file

    work = tmp_path / "work"
    work.mkdir()
    outside = tmp_path / "secret.ngc"
    outside.write_text("G0 X1\nM2\n")
    (work / "part.ngc").write_text("G0 X1\nM2\n")
    (work / "link.ngc").symlink_to(outside)
    mf = machine_file(work)
    with served(file=mf, workdir=WorkFolder(work.resolve(), True)) as (svc, th), \
            client(th) as m:
        assert m.call("program.load", path="part.ngc")["lines"] == 2        # relative
        assert m.call("program.load", path=str(work / "part.ngc"))["lines"] == 2
        for bad in (str(outside), "../secret.ngc", "link.ngc", "/etc/passwd"):
            with pytest.raises(RemoteError) as e:
                m.call("program.load", path=bad)
            assert e.value.code == -32000 and "must lie in the working folder" in e.value.message
            assert e.value.data["param"] == "path"
        v = m.call("machine.info")["config_version"]
        with pytest.raises(RemoteError, match="must lie in the working folder"):
            m.call("machine.save", path=str(tmp_path / "other.toml"))
        assert not (tmp_path / "other.toml").exists()
        with pytest.raises(RemoteError, match="must lie in the working folder"):
            m.call("machine.load", path=str(tmp_path / "other.toml"), config_version=v)
        assert m.call("machine.save", path="copy.toml")["file"] == str(work.resolve() /
                                                                      "copy.toml")
        assert mf.exists()   # the server's own machine file: written without a path
        assert m.call("machine.save")["file"].endswith("copy.toml")   # the new machine file


def test_working_folder_of_the_command_line(tmp_path):
    from openmotion.errors import MotionError
    from openmotion.remote.workdir import WorkFolder

    assert not WorkFolder.for_server("127.0.0.1", None, None).restricted
    wf = WorkFolder.for_server("0.0.0.0", None, str(tmp_path / "m.toml"))
    assert wf.restricted and wf.folder == tmp_path.resolve()
    assert WorkFolder.for_server("127.0.0.1", str(tmp_path), None).folder == tmp_path.resolve()
    with pytest.raises(MotionError, match="--workdir"):
        WorkFolder.for_server("0.0.0.0", str(tmp_path / "nope"), None)
    none = WorkFolder.for_server("0.0.0.0", None, None)
    with pytest.raises(MotionError, match="no working folder"):
        none.resolve("path", "a.ngc")
