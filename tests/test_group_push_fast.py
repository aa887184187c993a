"""The program runner's push path (Group._queue_line) against the public set_feed + line.

The runner hands the group the lines the G-code compiler made through an internal entry
that skips re-validating what cannot fail; it must make the same commands (bit for bit),
leave the same state and refuse exactly what the public calls refuse, with their errors.
The whole runs are compared cycle by cycle with the entry replaced by the public calls.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupError
from openmotion.control.guard.safety import Safety
from openmotion.program.runjob import work_origin
from openmotion.program.runner import ProgramRunner, RunState

ROOT = Path(__file__).resolve().parents[1]
MIXED = """G21 G90 G64 P0.01 F1200
G1 X10 Y0
G1 X10 Y10
G2 X20 Y10 I5 J0
G1 X30 Y5 F3000
G0 X0 Y0
G4 P0.1
G61
G1 X5 Y5
G1 X6 Y5
M62 P1
G1 X8 Y8
G64
G1 X1 Y1
G1 X2 Y3
M2
"""


def _public(self: Group, end: np.ndarray, feed: float, line: object = None) -> int:
    return self._queue_line_public(end, feed)


def _run(text: str, stepping: bool) -> tuple[str, int, float]:
    """(digest of every cycle's axis positions and command index and of the events,
    cycles, end time) of a program run on the default table."""
    h = hashlib.sha256()
    ctl = Controller()
    ctl.enable_all()
    run = ProgramRunner(ctl, text, gcode={"parameters": work_origin(ctl)})
    run.start()
    if stepping:
        while run.state is RunState.RUNNING:
            ctl.step()
            assert run.group is not None
            h.update(np.array([a.position for a in ctl.axes] + [run.group.current_index],
                              dtype=float).tobytes())
    else:
        ctl.run_until(lambda: run.state is not RunState.RUNNING, 1e5, event_driven=True)
        for x in run.trace():
            h.update(np.asarray(x, dtype=float).tobytes())
    assert run.state is RunState.DONE, run.error
    for e in run.events:
        h.update(repr((e.t, e.kind, e.line, e.text)).encode())
    return h.hexdigest(), ctl.cycles, ctl.time


@pytest.mark.parametrize("name", ["mixed", "laser_contour.ngc", "cam_rose.ngc"])
def test_runs_equal_the_public_calls(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    text = MIXED if name == "mixed" else (ROOT / "examples" / "programs" / name).read_text()
    # the short mixed program cycle by cycle (every axis, every cycle); the long ones
    # event-driven: the runner's trace still holds every cycle's command index and positions
    stepping = name == "mixed"
    fast = _run(text, stepping)
    monkeypatch.setattr(Group, "_queue_line", _public)
    assert _run(text, stepping) == fast


def _group(n: int = 3) -> tuple[Controller, Group]:
    ctl = Controller()
    ctl.enable_all()
    g = Group(ctl, ["x", "y", "z"][:n], units=True, feed=20.0, queue_size=8)
    g.set_axis_limit_policy("slow")
    g.enable_blend(0.01)
    return ctl, g


def _state(g: Group) -> tuple:
    cmds = []
    for c in g._queue:
        el = c.elements[0]
        cmds.append((c.index, c.kind, c.feed, c.accel, c.decel, c.jerk, c.str_vel, c.move,
                     el.start.tobytes(), el.end.tobytes(), el.length, el.direction.tobytes(),
                     el.max_abs_tangent.tobytes(), type(el)))
    tail = None if g._tail is None else g._tail.tobytes()
    return tuple(cmds), tail, g._feed, g._next_index, g.state


def _apply(g: Group, calls: list[tuple[list[float], float]], fast: bool) -> list:
    out: list = []
    for end, feed in calls:
        try:
            if fast:
                out.append(g._queue_line(np.array(end, dtype=float), feed))
            else:
                g.set_feed(feed)
                out.append(g.line(np.array(end, dtype=float)))
        except GroupError as e:
            out.append((type(e), e.code, str(e)))
        out.append(_state(g))
    return out


CALLS = [([1.0, 2.0, 0.5], 20.0), ([1.0, 2.0, 0.5], 20.0),  # zero length: refused
         ([1.5, 2.5, 0.5], 30.0), ([np.nan, 1.0, 0.0], 20.0), ([1.0, 1.0], 20.0),
         ([3e12, 0.0, 0.0], 20.0), ([2.0, 2.0, 1.0], 1e9), ([2.0, 2.0, 1.0], -1.0),
         ([2.0, 2.0, 1.0], np.float64(25.0)), ([2.5, 2.0, 1.0], 0.0),
         ([1e-300, 2.0, 1.0], 20.0), ([4.0, 3.0, 1.0], 20.0)] + \
    [([5.0 + 0.1 * k, 3.0, 1.0], 20.0) for k in range(8)]  # the queue fills (8)


def test_commands_and_refusals_equal_the_public_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    outs = []
    for fast in (False, True):
        _, g = _group()
        outs.append(_apply(g, CALLS, fast))
    assert outs[0] == outs[1]
    refused = sum(isinstance(x, tuple) and x[0] is GroupError for x in outs[1])
    assert refused == 12
    public = Group._queue_line_public
    calls = []

    def counted(self: Group, end: np.ndarray, feed: float) -> int:
        calls.append(1)
        return public(self, end, feed)

    monkeypatch.setattr(Group, "_queue_line_public", counted)
    _, g = _group()
    _apply(g, CALLS, True)
    assert len(calls) == refused  # every accepted line took the fast path


def test_soft_limits_and_error_state_equal_the_public_calls() -> None:
    outs = []
    for fast in (False, True):
        ctl, g = _group()
        safety = Safety.of(ctl) or Safety(ctl)
        k = float(g._k[0])
        safety.soft.set("x", 10.0 * k, -10.0 * k)
        safety.soft.enable("x")
        out = _apply(g, [([5.0, 0.0, 0.0], 20.0), ([10.0, 0.0, 0.0], 20.0),
                         ([10.5, 0.0, 0.0], 20.0), ([-10.0, 1.0, 0.0], 20.0),
                         ([-10.01, 1.0, 0.0], 20.0)], fast)
        safety.soft.disable("x")
        out += _apply(g, [([11.0, 0.0, 0.0], 20.0)], fast)
        g._state = type(g.state).ERROR  # (as a fault leaves it)
        out += _apply(g, [([12.0, 0.0, 0.0], 20.0)], fast)
        outs.append(out)
    assert outs[0] == outs[1]
    assert sum(isinstance(x, tuple) and x[0] is GroupError for x in outs[1]) == 3


def test_first_line_starts_where_the_axes_are() -> None:
    outs = []
    for fast in (False, True):
        ctl, g = _group(2)
        ax = ctl.axis("x")
        ax.move_absolute(1234.0, max_vel=20000.0)
        ctl.run_until(lambda ax=ax: not ax.is_moving, 5.0)
        outs.append(_apply(g, [([3.0, 4.0], 20.0), ([3.0, 5.0], 20.0)], fast))
    assert outs[0] == outs[1]


def test_chain_of_equals_between_bit_for_bit() -> None:
    from openmotion.path.geometry import Line

    rng = np.random.default_rng(7)
    for dim in (2, 3, 4, 6, 17):
        for scale in (1e-9, 0.05, 1e3):
            pts = rng.normal(size=(300, dim)) * scale + rng.normal(size=dim) * 100.0
            pts[5] = pts[4]  # a zero-length line
            pts[7, 0] = pts[6, 0]
            lines = Line.chain_of(pts.copy())
            for k, got in enumerate(lines):
                a, b = pts[k].copy(), pts[k + 1].copy()
                a.flags.writeable = b.flags.writeable = False
                want = Line.between(a, b)
                assert got.length == want.length
                for x, y in ((got.start, a), (got.end, b), (got.direction, want.direction),
                             (got.max_abs_tangent, want.max_abs_tangent)):
                    assert x.tobytes() == y.tobytes() and not x.flags.writeable
                assert got.end is lines[k + 1].start if k + 1 < len(lines) else True


def test_runner_takes_the_prepared_lines(monkeypatch: pytest.MonkeyPatch) -> None:
    """cam_rose's lines come from the stretches prepared ahead (one line of each made by
    the group itself), and the queue holds the same commands as with the public calls."""
    from openmotion.path.geometry import Line
    from openmotion.program.runner import RunOptions

    text = (ROOT / "examples" / "programs" / "cam_rose.ngc").read_text()
    queues = []
    for public in (False, True):
        made = []
        between = Line.between.__func__  # type: ignore[attr-defined]

        def counted(cls: type, a: np.ndarray, b: np.ndarray,
                    made: list = made, between=between) -> Line:  # noqa: ANN001
            made.append(1)
            return between(cls, a, b)

        with monkeypatch.context() as m:
            m.setattr(Line, "between", classmethod(counted))
            if public:
                m.setattr(Group, "_queue_line", _public)
            ctl = Controller()
            ctl.enable_all()
            run = ProgramRunner(ctl, text, gcode={"parameters": work_origin(ctl)},
                                options=RunOptions(window=5000))
            run.start()
            assert run.group is not None
            run._feed(run.group)
            queues.append(_state(run.group))
            if not public:
                assert len(made) <= 4000 // 256 + 2
    assert queues[0] == queues[1]
