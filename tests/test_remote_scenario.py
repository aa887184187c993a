"""The browser's scenario through `openmotion.remote`: against a real server and the
controller running in real time on the simulator (the checks wait for states, never for
wall-clock figures)."""

from __future__ import annotations

import time

import pytest

from openmotion.remote import RemoteError
from openmotion.remote.status import only_clock
from remote_kit import at_rest, client, served

WAIT = 20.0   # generous: the CI machine may be loaded; the checks are on states


@pytest.fixture
def machine():
    with served() as (svc, th), client(th) as m:
        m.subscribe(rate_hz=20)
        m.call("axis.servo", axis="x", on=True)
        m.call("axis.servo", axis="y", on=True)
        assert m.wait(lambda s: s["axes"]["x"]["servo"] and s["axes"]["y"]["servo"], WAIT)
        m.server = th   # the tests open more clients on it
        yield svc, m


def test_move_changes_counters_and_lamps(machine):
    svc, m = machine
    x = m.status["axes"]["x"]
    assert x["command"] == 0 and x["io"]["org"] and x["servo"]   # ORG covers 0 .. 3 mm
    res = m.call("axis.move", axis="x", kind="relative", distance=10.0, max_vel=50.0,
                 tacc=0.05)
    assert res["duration"] == pytest.approx(0.25, abs=0.01)
    assert m.wait(lambda s: s["axes"]["x"]["moving"], WAIT)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 10000 and at_rest("x")(s), WAIT)
    x = m.status["axes"]["x"]
    assert x["feedback"] == 10000 and x["target"] == 10000 and x["position"] == 10.0
    assert not x["io"]["org"]
    # absolute back, in user units; then a velocity move changed on the fly and stopped
    m.call("axis.move", axis="x", kind="absolute", position=2.5, max_vel=40.0, shape="S",
           tacc=0.05, vs_acc=5.0, vs_dec=5.0)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 2500 and at_rest("x")(s), WAIT)
    m.call("axis.move", axis="y", kind="velocity", velocity=5.0, tacc=0.05, speed_range=20.0)
    assert m.wait(lambda s: s["axes"]["y"]["state"] == "ContinuousMotion", WAIT)
    m.call("axis.change_speed", axis="y", velocity=8.0, tacc=0.05)
    m.call("axis.stop", axis="y")
    assert m.wait(at_rest("y"), WAIT)
    assert svc.ctl.axis("y").velocity == 0.0
    assert len(m.status["board"]["do"]) == 16 and not any(m.status["board"]["do"])


def test_repeat_between_two_positions_then_stop(machine):
    svc, m = machine
    m.call("axis.repeat", axis="x", p1=1.0, p2=3.0, delay_s=0.05, count=3, max_vel=50.0,
           tacc=0.02)
    assert m.wait(lambda s: s["axes"]["x"]["repeat"], WAIT)
    assert m.wait(lambda s: not s["axes"]["x"]["repeat"] and at_rest("x")(s), WAIT)
    assert m.status["axes"]["x"]["command"] == 1000   # p1, p2, p1
    with pytest.raises(RemoteError, match="delay_s"):
        m.call("axis.repeat", axis="x", p1=1.0, p2=3.0, delay_s=-1, max_vel=50.0)


def test_set_and_reset_positions(machine):
    _svc, m = machine
    st = m.call("axis.set_position", axis="x", position=12.5)
    assert st["command"] == 12500 and st["feedback"] == 12500
    st = m.call("axis.reset_position", axis="x")
    assert st["command"] == st["feedback"] == st["error"] == 0


def test_jog_and_release_stops(machine):
    svc, m = machine
    with m.jog("x", +1, speed=20.0, confirm_s=0.02) as jog_id:
        assert m.wait(lambda s: s["axes"]["x"]["jog"] == jog_id, WAIT)
        time.sleep(0.3)   # longer than the deadman: the confirmations keep it going
        assert svc.ctl.axis("x").state.value == "ContinuousMotion"
    assert m.wait(at_rest("x"), WAIT)
    assert m.call("jog.confirm", jog=jog_id) == {"active": False, "reason": "released"}


def test_deadman_timeout_stops_a_jog_nobody_confirms(machine):
    svc, m = machine
    jog = m.call("jog.start", axis="x", direction=1, speed=10.0)
    assert jog["deadman_ms"] == 250 and jog["confirm_ms"] == 100
    assert m.wait(lambda s: s["axes"]["x"]["jog"] == jog["jog"], WAIT)
    assert m.wait(lambda s: s["axes"]["x"]["jog"] is None and at_rest("x")(s), WAIT)
    res = m.call("jog.confirm", jog=jog["jog"])
    assert res["active"] is False and "deadman" in res["reason"]
    # a dead id never restarts motion
    assert svc.ctl.axis("x").motion is None


def test_lost_connection_stops_its_jog(machine):
    svc, m = machine
    other = client(m.server)
    other.call("jog.start", axis="y", direction=1, speed=10.0)
    assert m.wait(lambda s: s["axes"]["y"]["state"] == "ContinuousMotion", WAIT)
    other.close()
    assert m.wait(at_rest("y"), WAIT)


def test_home(machine):
    svc, m = machine
    m.call("axis.move", axis="x", kind="absolute", position=20.0, max_vel=100.0, tacc=0.05)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 20000 and at_rest("x")(s), WAIT)
    info = m.call("machine.info")
    home = m.call("home.get", axis="x")
    assert home["config"]["mode"] == 0 and home["sequence"]
    m.call("home.set", axis="x", config_version=info["config_version"],
           changes={"max_vel": 40.0, "str_vel": 4.0, "direction": -1})
    m.call("home.start", axis="x")
    assert m.wait(lambda s: s["axes"]["x"]["homing"]["state"] == "done", WAIT)
    assert m.wait(at_rest("x"), WAIT)
    assert m.status["axes"]["x"]["command"] == 0


PROGRAM = """G21 G90 G17 G94
G0 X0 Y0
G1 X5 F600
G1 Y5
G1 X0
G1 Y0
M2
"""


def test_program_runs_and_the_current_line_advances(machine):
    svc, m = machine
    for ax in ("z", "u"):
        m.call("axis.servo", axis=ax, on=True)
    res = m.call("program.load", text=PROGRAM, name="square.ngc")
    assert res["lines"] == 7 and res["moves"] >= 5
    prev = m.call("program.preview", max_points=100)
    assert len(prev["points"]) >= 5 and not prev["decimated"]
    assert m.call("program.lines", first=3, count=2)["lines"] == ["G1 X5 F600", "G1 Y5"]
    m.call("program.run", feed_override=100.0)
    lines = []
    t_end = time.monotonic() + 60
    while time.monotonic() < t_end:
        p = m.status["program"]
        if p["state"] == "running" and (not lines or lines[-1] != p["line"]):
            lines.append(p["line"])
        if p["state"] in ("done", "error", "aborted"):
            break
        time.sleep(0.005)
    assert m.status["program"]["state"] == "done", m.status["program"]
    # the current line advances through the program, never back
    assert lines == sorted(lines) and len(set(lines) & {2, 3, 4, 5, 6}) >= 3, lines
    path = m.call("path.get", since=0, max_points=100000)
    assert path["axes"].startswith("XY") and len(path["points"]) > 10
    speeds = path["speed"]
    # the G1 square runs at F600 = 10 mm/s (the G0 to the start at the rapid feed)
    assert sum(1 for v in speeds if abs(v - 10.0) < 0.5) > len(speeds) // 4


def test_program_pause_resume_abort_and_override(machine):
    svc, m = machine
    for ax in ("z", "u"):
        m.call("axis.servo", axis=ax, on=True)
    # relative moves: the program's X0 is the G54 origin at mid-travel, 150 mm away from where
    # the machine starts; the second move is long enough to be aborted while it runs
    m.call("program.load", text="G21 G91\nM64 P3\nG1 X5 F300\nM0\nG1 X20\nM2\n")
    m.call("program.run", feed_override=50.0)
    assert m.wait(lambda s: s["program"]["state"] == "running", WAIT)
    m.call("program.feed_override", percent=150.0)
    assert m.wait(lambda s: s["program"]["state"] == "paused", 60)   # M0
    assert m.status["program"]["line"] == 4
    assert m.wait(lambda s: s["board"]["do"][3], WAIT)               # M64 P3
    m.call("program.resume")
    assert m.wait(lambda s: s["program"]["state"] == "running", WAIT)
    m.call("program.abort")
    assert m.wait(lambda s: s["program"]["state"] == "aborted", WAIT)
    with pytest.raises(RemoteError, match="percent"):
        m.call("program.feed_override", percent=500)


def test_estop_stops_everything(machine):
    svc, m = machine
    m.call("axis.move", axis="x", kind="velocity", velocity=20.0)
    jog = m.call("jog.start", axis="y", direction=1, speed=10.0)
    assert m.wait(lambda s: s["axes"]["x"]["moving"] and s["axes"]["y"]["moving"], WAIT)
    m.call("sim.estop", pressed=True)
    assert m.wait(lambda s: s["estop"] and all(
        a["state"] in ("ErrorStop", "Disabled") for a in s["axes"].values()), WAIT)
    assert all(ax.velocity == 0.0 for ax in svc.ctl.axes)
    assert m.call("jog.confirm", jog=jog["jog"])["active"] is False
    with pytest.raises(RemoteError, match="E-stop"):
        m.call("machine.reset")
    with pytest.raises(RemoteError):
        m.call("axis.move", axis="x", kind="relative", distance=1.0, max_vel=10.0)
    m.call("sim.estop", pressed=False)
    assert m.wait(lambda s: not s["estop"], WAIT)
    m.call("machine.reset")
    assert m.wait(at_rest("x"), WAIT)
    # the software E-stop
    m.call("axis.move", axis="x", kind="velocity", velocity=20.0)
    m.call("machine.estop")
    assert m.wait(lambda s: s["axes"]["x"]["state"] == "ErrorStop", WAIT)
    assert any(e["kind"] == "estop" for e in m.call("machine.events")["events"])
    # the events were pushed too (notify_event), as they happened
    assert m.wait(lambda s: any(e["kind"] == "estop" and e["axis"] == "x" for e in m.events),
                  WAIT)


def test_tripped_limit_stops_the_axis(machine):
    svc, m = machine
    m.call("axis.move", axis="x", kind="velocity", velocity=10.0)
    assert m.wait(lambda s: s["axes"]["x"]["state"] == "ContinuousMotion", WAIT)
    m.call("sim.trip_limit", axis="x", signal="pel", active=True)
    assert m.wait(lambda s: s["axes"]["x"]["state"] == "ErrorStop", WAIT)
    assert m.status["axes"]["x"]["fault"] == "+EL" and m.status["axes"]["x"]["io"]["pel"]
    m.call("sim.trip_limit", axis="x", signal="pel", active=False)
    assert m.wait(lambda s: not s["axes"]["x"]["io"]["pel"], WAIT)
    m.call("sim.alarm", axis="y", active=True)
    assert m.wait(lambda s: s["axes"]["y"]["io"]["alm"], WAIT)
    m.call("sim.alarm", axis="y", active=False)
    m.call("sim.input", index=2, level=True)
    assert m.wait(lambda s: s["board"]["di"][2], WAIT)
    with pytest.raises(RemoteError, match="index must be in"):
        m.call("sim.input", index=99, level=True)
    assert m.call("sim.speed", factor=4)["speed"] == 4.0
    assert svc.running


def test_scope_records_on_the_server_with_trigger_and_csv(machine):
    svc, m = machine
    chans = ["x.command", "x.feedback", "x.velocity", "x.acceleration", "x.error",
             "x.state", "x.io.org", "y.command"]
    m.call("scope.configure", channels=chans, seconds=5.0,
           trigger={"channel": "x.velocity", "mode": "rising", "level": 5.0, "pre_s": 0.1})
    # armed only once the pre-trigger history is full (0.1 s of control time)
    assert m.wait(lambda s: svc.scope.n > 150, WAIT)
    m.call("axis.move", axis="x", kind="relative", distance=5.0, max_vel=20.0, tacc=0.05)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 5000 and at_rest("x")(s), WAIT)
    data = m.call("scope.data", since=-1, max_points=100000)
    assert data["triggered_at"] is not None
    assert set(data["columns"]) == set(chans)
    v = data["columns"]["x.velocity"]
    assert max(v) == pytest.approx(20.0, rel=1e-6)
    t0 = data["triggered_at"]
    before = [t for t in data["t"] if t < t0]
    assert before and t0 - before[0] == pytest.approx(0.1, abs=0.002)
    # a second client (a reload, another tab) sees the same history
    with client(m.server) as other:
        again = other.call("scope.data", since=-1, max_points=100000)
    assert again["t"][:len(data["t"])] == data["t"]
    # live pushes: only new samples, numbered on from the history
    sub = m.call("scope.subscribe", rate_hz=20)
    m.call("scope.configure", channels=["x.command"], seconds=2.0)
    assert m.wait(lambda s: len(m.scope_pushes) >= 3, WAIT)
    pushes = [p for p in list(m.scope_pushes) if p["scope_version"] == svc.scope.version]
    assert all(a["next"] == b["start"] for a, b in zip(pushes, pushes[1:], strict=False))
    m.call("unsubscribe", subscription=sub["subscription"])
    with pytest.raises(RemoteError, match="unknown"):
        m.call("unsubscribe", subscription=sub["subscription"])
    m.call("scope.configure", channels=chans, seconds=5.0)
    m.call("axis.move", axis="x", kind="relative", distance=1.0, max_vel=20.0, tacc=0.05)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 6000 and at_rest("x")(s), WAIT)
    csv = m.call("scope.csv")["csv"].splitlines()
    assert csv[0] == "t," + ",".join(chans) and len(csv) > 10
    with pytest.raises(RemoteError, match="quantity"):
        m.call("scope.configure", channels=["x.nonsense"])


def test_at_rest_the_pushes_slow_to_idle_hz_and_a_change_still_comes(machine):
    svc, m = machine
    with client(m.server) as c:
        t0 = time.monotonic()
        c.subscribe(rate_hz=50, idle_hz=1)
        time.sleep(1.5)
        with c._cond:
            pushes = [n["params"][0] for n in c.notifications
                      if n["method"] == "notify_status_update"]
        # only the clock moved: one push a second at most (50 a second without idle_hz),
        # each with nothing but the clock
        assert len(pushes) <= (time.monotonic() - t0) / 0.99 + 1, len(pushes)
        assert all(only_clock(d) for d in pushes), pushes
        c.call("axis.servo", axis="z", on=True)
        assert c.wait(lambda s: s["axes"]["z"]["servo"], WAIT)
        # the merged diffs give the server's status (the skipped ones held only the clock)
        assert c.wait(lambda s: s["axes"] == m.call("status.get")["axes"], WAIT)
    with pytest.raises(RemoteError, match="idle_hz must be <= 20"):
        m.call("status.subscribe", rate_hz=20, idle_hz=30)


def test_only_clock_tells_a_diff_of_the_clock_from_a_change():
    assert only_clock({"time": 1.0, "cycles": 1000, "scope": {"next": 1000},
                       "cycle": {"busy_us": 30.0}})
    assert only_clock({})
    assert not only_clock({"time": 1.0, "axes": {"x": {"command": 1}}})
    assert not only_clock({"time": 1.0, "scope": {"next": 5, "running": False}})
    assert not only_clock({"program": {"line": 3}})
