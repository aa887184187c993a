"""PSO / compare jobs through the API and their firings on the path view: exact positions
for a single-axis move, firings on the path of a program, bad setups refused with nothing
started, clear."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from openmotion.remote import RemoteError
from remote_kit import at_rest, client, served

WAIT = 20.0


@pytest.fixture
def machine():
    with served() as (svc, th), client(th) as m:
        m.subscribe(rate_hz=50)
        yield svc, m


def _path_until(m, pred, timeout=WAIT):
    t_end = time.monotonic() + timeout
    while True:
        d = m.call("path.get", since=0, max_points=100_000)
        if pred(d) or time.monotonic() > t_end:
            return d
        time.sleep(0.05)


def test_distance_job_fires_at_exact_positions_of_a_move(machine):
    svc, m = machine
    m.call("axis.servo", axis="x", on=True)
    r = m.call("pso.set", kind="distance", axes=["x"], output=2, every=5.0, pulse_s=0.002)
    assert r["job"]["kind"] == "distance" and r["job"]["active"] and r["firings"] == 0
    m.call("axis.move", axis="x", kind="relative", distance=22.0, max_vel=100.0, tacc=0.05)
    assert m.wait(lambda s: s["axes"]["x"]["command"] == 22000 and at_rest("x")(s), WAIT)
    d = _path_until(m, lambda d: len(d["firings"]) >= 4 and d["points"][-1][0] == 22.0)
    assert d["axes"] == ["x"]
    pso = [f for f in d["firings"] if f["kind"] == "PSO"]
    assert [f["point"][0] for f in pso] == pytest.approx([5.0, 10.0, 15.0, 20.0], abs=1e-6)
    assert all(f["output"] == 2 for f in pso)
    assert m.call("pso.get")["firings"] == 4
    # reading on from `next` gives no firing twice
    assert m.call("path.get", since=d["next"])["firings"] == []
    m.call("pso.clear")
    assert m.call("pso.get")["jobs"] == []


def test_points_job_and_program_firings_lie_on_the_programs_path(machine):
    svc, m = machine
    for ax in ("x", "y", "z", "u"):
        m.call("axis.servo", axis=ax, on=True)
    m.call("program.load", text="G21 G90\nG0 X0 Y0\nG1 X10 F1200\nG1 Y10\nG1 X0\nM2\n")
    every = 3.0
    m.call("pso.set", kind="distance", axes=["x", "y"], output=1, every=every)
    m.call("program.run", feed_override=100.0)
    assert m.wait(lambda s: s["program"]["state"] == "done", 60.0), m.status["program"]
    d = _path_until(m, lambda d: d["points"] and not any(
        a["moving"] for a in m.status["axes"].values()))
    pts = np.array(d["points"])[:, :2]
    length = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
    pso = [f for f in d["firings"] if f["kind"] == "PSO"]
    # every `every` of XY path length since the run began (the job counted the G0 too)
    assert abs(len(pso) - math.floor(length / every)) <= 1, (len(pso), length)
    for f in pso:      # each firing lies on the travelled polyline
        p = np.array(f["point"][:2])
        a, b = pts[:-1], pts[1:]
        ab = b - a
        tt = np.clip(((p - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-18), 0, 1)
        assert np.min(np.linalg.norm(a + ab * tt[:, None] - p, axis=1)) < 0.02, f


@pytest.mark.parametrize(("params", "message"), [
    ({"kind": "spiral", "axes": ["x"], "output": 0}, "kind"),
    ({"kind": "distance", "axes": ["x"], "output": 99, "every": 1.0},
     r"output must be in \[0, 15\]"),
    ({"kind": "distance", "axes": ["x"], "output": 0, "every": 0.0}, "every must be > 0 mm"),
    ({"kind": "distance", "axes": ["x"], "output": 0}, "every must be > 0"),
    ({"kind": "distance", "axes": ["x", "x"], "output": 0, "every": 1.0}, "1 to 3 different"),
    ({"kind": "distance", "axes": ["q"], "output": 0, "every": 1.0}, "q"),
    ({"kind": "distance", "axes": ["x"], "output": 0, "every": 1.0, "pulse_s": 5.0}, "pulse_s"),
    ({"kind": "points", "axes": ["x", "y"], "output": 0, "points": [[1.0]], "window": 1.0},
     r"points\[0\] must be a list of 2"),
    ({"kind": "points", "axes": ["x", "y"], "output": 0, "points": [[1.0, 2.0]]}, "window"),
    ({"kind": "distance", "axes": ["x"], "output": 0, "every": 1.0, "colour": 1}, "colour"),
])
def test_bad_pso_setups_are_refused_and_start_nothing(machine, params, message):
    svc, m = machine
    with pytest.raises(RemoteError, match=message):
        m.call("pso.set", **params)
    assert m.call("pso.get") == {"jobs": [], "firings": 0, "dropped": []}


def test_points_job_fires_once_per_point_within_its_window(machine):
    svc, m = machine
    m.call("axis.servo", axis="y", on=True)
    here = m.status["axes"]["y"]["position"]
    pts = [[here + 5.0], [here + 10.0]]
    r = m.call("pso.set", kind="points", axes=["y"], output=4, points=pts, window=0.5)
    assert r["job"]["remaining"] == 2
    m.call("axis.move", axis="y", kind="relative", distance=15.0, max_vel=50.0, tacc=0.05)
    d = _path_until(m, lambda d: len([f for f in d["firings"] if f["kind"] == "PSO"]) >= 2
                    and not m.status["axes"]["y"]["moving"])
    pso = [f for f in d["firings"] if f["kind"] == "PSO"]
    assert len(pso) == 2 and all(f["output"] == 4 for f in pso)
    for f, p in zip(pso, pts, strict=True):
        assert abs(f["point"][0] - p[0]) <= 0.5 + 1e-6
    assert m.call("pso.get")["jobs"][0]["remaining"] == 0


def test_hsl_comparator_firings_are_marked_on_a_programs_path(machine):
    """A general comparator (HSL CMP, safety.cmp) set by a script on the controller: its
    firing appears on the path at the exact crossing, as kind CMP."""
    svc, m = machine
    for ax in ("x", "y", "z", "u"):
        m.call("axis.servo", axis=ax, on=True)
    start = m.status["axes"]["x"]["command"]
    level = start + 50_000 if start < 100_000 else start - 50_000
    with svc.ctl.lock:
        svc.ctl.safety.cmp.set_general_comparator("x", "command",
                                                  ">" if level > start else "<", "event",
                                                  float(level))
    m.call("program.load", text="G21 G90\nG0 X0 Y0\nG1 X10 F1200\nM2\n")
    m.call("program.run", feed_override=100.0)
    assert m.wait(lambda s: s["program"]["state"] == "done", 60.0), m.status["program"]
    d = _path_until(m, lambda d: any(f["kind"] == "CMP" for f in d["firings"]))
    cmp = [f for f in d["firings"] if f["kind"] == "CMP"]
    assert len(cmp) >= 1
    assert cmp[0]["point"][0] == pytest.approx(level / 1000.0, abs=0.01)   # 1000 pulses/mm
    with svc.ctl.lock:
        svc.ctl.safety.cmp.clear_general_comparator("x")
