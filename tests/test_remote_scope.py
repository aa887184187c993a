"""The server's scope in virtual time (no server, deterministic): ring buffer, reading on
from a sample number, trigger window, derived acceleration, decimation, CSV, bad setups."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.remote.scope import Scope, Trigger


@pytest.fixture
def ctl():
    c = Controller()
    c.enable_all()
    return c


def _attach(ctl, scope):
    ctl.add_cycle_hook(lambda c, t: scope.sample(t))


def test_ring_keeps_the_newest_samples_and_reads_on(ctl):
    sc = Scope(ctl, ["x.command", "x.state"], 1, 1.0)
    _attach(ctl, sc)
    ref = []
    ctl.axis("x").move_relative(50_000, max_vel=20_000, tacc=0.1)
    for _ in range(2500):
        ctl.step()
        ref.append((round(ctl.time, 9), round(ctl.axis("x").position / 1000, 9)))
    d = sc.data(-1, 10**6)
    assert (d["first"], d["next"]) == (1500, 2500)
    assert list(zip(d["t"], d["columns"]["x.command"], strict=True)) == ref[1500:]
    d2 = sc.data(2400, 10**6)
    assert d2["start"] == 2400 and len(d2["t"]) == 100
    assert sc.data(10, 10)["start"] == 1500   # older than the history: from its first


def test_rising_trigger_keeps_pre_s_and_stops_when_full(ctl):
    sc = Scope(ctl, ["x.velocity", "x.acceleration"], 1, 1.0,
               Trigger("x.velocity", "rising", 10.0, 0.2))
    _attach(ctl, sc)
    ctl.advance(0.3)                          # pre-trigger history fills
    t_move = ctl.time
    ctl.axis("x").move_velocity(20_000, tacc=0.1)   # 20 mm/s, crosses 10 mm/s at 0.05 s
    ctl.advance(1.5)
    d = sc.data(-1, 10**6)
    assert not sc.running
    t0 = d["triggered_at"]
    assert t0 == pytest.approx(t_move + 0.05, abs=0.0011)
    assert d["t"][0] == pytest.approx(t0 - 0.2, abs=0.0011)
    assert len(d["t"]) == sc.cap
    acc = d["columns"]["x.acceleration"]
    assert max(acc) == pytest.approx(200.0, rel=1e-6)   # 20 mm/s in 0.1 s


def test_level_trigger_and_arm(ctl):
    sc = Scope(ctl, ["x.command"], 2, 1.0, Trigger("x.command", "level", 1.0, 0.0))
    _attach(ctl, sc)
    assert sc.dt == pytest.approx(0.002)
    ctl.axis("x").move_relative(2000, max_vel=10_000, tacc=0.05)
    ctl.advance(2.0)
    assert sc.triggered_at is not None and not sc.running
    first = sc.data(-1, 10**6)["columns"]["x.command"][0]
    assert first >= 1.0 - 1e-9
    sc.arm()
    assert sc.running and sc.triggered_at is None and sc.info()["samples"] == 0


def test_decimation_keeps_the_peaks(ctl):
    sc = Scope(ctl, ["x.velocity"], 1, 5.0)
    _attach(ctl, sc)
    ctl.axis("x").move_relative(3000, max_vel=30_000, tacc=0.05)
    ctl.advance(2.0)
    full = sc.data(-1, 10**6)["columns"]["x.velocity"]
    small = sc.data(-1, 100)
    assert len(small["t"]) <= 100
    assert max(small["columns"]["x.velocity"]) == max(full)
    assert small["t"] == sorted(small["t"])


def test_csv_and_io_channels(ctl):
    sc = Scope(ctl, ["x.command", "x.io.org", "x.feedback", "x.error"], 1, 2.0)
    _attach(ctl, sc)
    ctl.axis("x").move_relative(5000, max_vel=20_000, tacc=0.05)
    ctl.advance(1.0)
    lines = sc.csv().splitlines()
    assert lines[0] == "t,x.command,x.io.org,x.feedback,x.error"
    org = [float(r.split(",")[2]) for r in lines[1:]]
    assert org[0] == 1.0 and org[-1] == 0.0          # ORG covers 0 .. 3 mm
    last = lines[-1].split(",")
    assert float(last[1]) == pytest.approx(5.0) and float(last[3]) == pytest.approx(5.0)
    part = sc.csv(start=0.5, end=0.6).splitlines()
    assert 95 <= len(part) - 1 <= 101


@pytest.mark.parametrize("kw, words", [
    ({"channels": []}, "1..16"),
    ({"channels": ["x.command", "x.command"]}, "repeat"),
    ({"channels": ["w.command"]}, "unknown"),
    ({"channels": ["x.jerk"]}, "quantity"),
    ({"channels": ["x.io.foo"]}, "quantity"),
    ({"channels": ["x.command"], "divider": 0}, "divider"),
    ({"channels": ["x.command"], "seconds": 0.5}, "seconds"),
    ({"channels": ["x.command"], "trigger": Trigger("y.command", "rising")}, "trigger.channel"),
    ({"channels": ["x.command"], "trigger": Trigger("x.command", "sideways")}, "trigger.mode"),
    ({"channels": ["x.command"], "trigger": Trigger("x.command", "level", 0.0, 9.0)},
     "pre_s"),
])
def test_bad_setups_are_refused_and_the_old_one_stays(ctl, kw, words):
    sc = Scope(ctl, ["y.command"], 1, 3.0)
    args = {"channels": ["x.command"], "divider": 1, "seconds": 3.0, "trigger": Trigger(),
            **kw}
    with pytest.raises(MotionError, match=words):
        sc.configure(args["channels"], args["divider"], args["seconds"], args["trigger"])
    assert sc.channels == ["y.command"] and sc.version == 1


def test_board_lines_are_channels(ctl):
    sc = Scope(ctl, ["di.3", "do.5", "x.io.svon"], 1, 1.0,
               Trigger("do.5", "rising", 0.5, 0.08))
    _attach(ctl, sc)
    ctl.advance(0.05)
    ctl.hardware.scenario.set_input("di3", True)
    ctl.advance(0.05)
    t_out = ctl.time
    ctl.hardware.write_output(None, "do5", True)
    ctl.advance(0.05)
    d = sc.data(-1, 10**6)
    di, do = d["columns"]["di.3"], d["columns"]["do.5"]
    assert set(di) == {0.0, 1.0} and di[0] == 0.0 and di[-1] == 1.0
    assert do[0] == 0.0 and do[-1] == 1.0
    assert d["triggered_at"] == pytest.approx(t_out + ctl.period, abs=1e-9)
    names = {c["name"] for c in __import__("openmotion.remote.scope", fromlist=["x"])
             .channel_names(ctl)}
    assert {"di.0", "di.15", "do.0", "do.15"} <= names
    for bad, why in (("di.16", r"di line must be a number in \[0, 15\]"),
                     ("do.x", "do line must be a number"), ("di.-1", "di line")):
        with pytest.raises(MotionError, match=why):
            Scope(ctl, [bad], 1, 1.0)


class _CycleBetweenSlices:
    """A lock that lets one control cycle's sample run each time a read releases it: what
    the real-time thread does when it waits on the scope's lock. Counts the holds."""

    def __init__(self, scope, ctl):
        import threading

        self._lock = threading.Lock()
        self.scope, self.ctl = scope, ctl
        self.holds = 0
        self.reading = False
        self.cycles = 0

    def __enter__(self):
        self._lock.acquire()
        self.holds += 1

    def __exit__(self, *exc):
        self._lock.release()
        if self.reading:          # the cycle gets the lock between two slices of the read
            self.reading = False
            self.ctl._time_for_test = getattr(self.ctl, "_time_for_test", 1000.0) + 0.001
            self.scope.sample(self.ctl._time_for_test)
            self.cycles += 1
            self.reading = True


def test_a_long_read_is_copied_in_slices_and_lets_the_cycle_run(ctl):
    from openmotion.remote import scope as scope_mod

    sc = Scope(ctl, [f"x.{q}" for q in ("command", "velocity", "error", "state")] +
               [f"di.{k}" for k in range(12)], 1, 600.0)
    cap = sc.cap
    assert cap == 600_000 and len(sc.channels) == 16
    # a full 600 s history, written straight into the ring (filling it cycle by cycle
    # would take minutes): sample k at time k ms, every column = k
    k = np.arange(cap, dtype=float)
    sc._t[:] = k * 0.001
    sc._buf[:] = k[:, None]
    sc.n = cap
    lock = _CycleBetweenSlices(sc, ctl)
    sc._lock = lock
    lock.reading = True
    d = sc.data(-1, 10**7)
    lock.reading = False
    slices = -(-cap // scope_mod.SLICE_ROWS)
    assert lock.holds >= slices           # never the whole ring under one hold
    assert lock.cycles >= slices - 1      # and a cycle ran between every two slices
    t = np.array(d["t"])
    assert np.all(np.diff(t) > 0)         # still one consistent, ordered history
    # the cycles overwrote the oldest rows while the read went on: those were copied first
    col = np.array(d["columns"]["x.command"])
    assert len(col) == d["next"] - d["start"]
    assert col[0] * 1000 == pytest.approx(d["start"], abs=1e-6)
    assert d["next"] == cap               # the end the read started from
