"""S-curve path chains (issue 4): blended, exact-stop, arc, streamed, overridden, held and
mixed-feed chains on recorded runs (`ctl.history.sample`) and on the executed plans
themselves (`g._run.plan.sprof` holds the exact path motion, so the path jerk and the speed
on each element are checked exactly)."""

from __future__ import annotations

import numpy as np
import pytest

from longrun import size
from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.groups.pathexec import contour_error
from openmotion.path import Arc, Line, plan_speeds, speed_caps, tangential_accels

VMAX, AMAX = 50_000.0, 500_000.0       # per-axis pulse speed and acceleration limits
FEED, ACC_T, JERK = 40_000.0, 0.1, 2.0e7  # path: 400 000 pps^2, window tj = 0.04 s
REL = 1e-9                               # relative slack of every limit check

# line -> line (45 deg) -> line (45 deg) -> line (104 deg)
LL = [("line", [20_000, 0]), ("line", [30_000, 10_000]), ("line", [30_000, 30_000]),
      ("line", [10_000, 35_000])]
# line -> arc (90 deg corner) -> line (45 deg corner)
LAL = [("line", [20_000, 0]), ("arc", [25_000, 0], [30_000, 0], "CW"),
       ("line", [40_000, -10_000])]


class Recorder:
    """Every plan the group executes (a cycle hook after the group's own)."""

    def __init__(self, ctl: Controller, g: Group) -> None:
        self.g = g
        self.plans: list = []
        ctl.add_cycle_hook(self)

    def __call__(self, ctl: Controller, t: float) -> None:
        r = self.g._run
        if r is not None and r.plan is not None and (
                not self.plans or self.plans[-1] is not r.plan):
            self.plans.append(r.plan)

    def path_jerk(self) -> float:
        """Largest |jerk| of every planned path motion s(t) (exact: its segments)."""
        return max(float(np.max(np.abs(p.sprof.j), initial=0.0)) for p in self.plans)

    def executed(self, n: int = 4000):
        """(plan, s, v) samples of each plan over the time it was the one executed."""
        for i, p in enumerate(self.plans):
            end = min(p.t_end, self.plans[i + 1].t0) if i + 1 < len(self.plans) else p.t_end
            if end <= p.t0:
                continue
            smp = p.sprof.sample(np.linspace(0.0, end - p.t0, n))
            yield p, smp.p, smp.v


def make(*, jerk: float | None = JERK, tol: float | None = 40.0, feed: float = FEED,
         acc_t: float = ACC_T, policy: str = "refuse", queue_size: int = 1024):
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=feed, acc_time=acc_t, queue_size=queue_size)
    g.set_max_pulse_speed([VMAX, VMAX])
    g.set_max_pulse_acc([AMAX, AMAX])
    g.set_axis_limit_policy(policy)
    if jerk is not None:
        g.set_path_shape("S", jerk=jerk)
    if tol is not None:
        g.enable_blend(tol)
    return ctl, g, Recorder(ctl, g)


def push(g: Group, prog) -> None:
    for cmd in prog:
        if cmd[0] == "line":
            g.line(cmd[1])
        elif cmd[0] == "arc":
            g.arc(cmd[1], cmd[2], direction=cmd[3])
        else:
            g.set_feed(cmd[1])


def elements(prog, start=(0.0, 0.0)) -> list:
    els, p = [], np.array(start, dtype=float)
    for cmd in prog:
        if cmd[0] == "line":
            els.append(Line(p, cmd[1]))
        elif cmd[0] == "arc":
            els.append(Arc(p, cmd[1], cmd[2], direction=cmd[3]))
        else:
            continue
        p = np.array(els[-1].end, dtype=float)
    return els


def finish(ctl: Controller, g: Group, timeout: float = 60.0) -> float:
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                         and not any(a.is_moving for a in g.axes), timeout)
    return ctl.time


def recorded(ctl: Controller, g: Group, t0: float, t1: float, n: int = 40_001):
    t = np.linspace(t0, t1, n)
    return t, [ctl.history.sample(a.index, t) for a in g.axes]


def check_axes(sx, sy) -> None:
    """Per-axis speed and acceleration within the limits at every sample."""
    for s in (sx, sy):
        assert np.abs(s.v).max() <= VMAX * (1 + REL)
        assert np.abs(s.a).max() <= AMAX * (1 + REL)


def speed(sx, sy) -> np.ndarray:
    return np.hypot(sx.v, sy.v)


def min_cruise_speed(sx, sy, feed: float = FEED) -> float:
    """Smallest speed between the first and the last instant above half the feed: a stop
    anywhere inside the chain shows as ~0."""
    v = speed(sx, sy)
    fast = np.nonzero(v > 0.5 * feed)[0]
    return float(v[fast[0]:fast[-1] + 1].min())


def caps_held(rec: Recorder, scale: float | None = None) -> float:
    """Largest ratio of the executed path speed to the speed cap (feed, axis speeds,
    centripetal share on arcs) of the element it is on, over every executed plan (with the
    feed override `scale` instead of each plan's own: a lower override is reached by a
    deceleration, not at once)."""
    worst = 0.0
    for p, s, v in rec.executed():
        ch, lim = p.chain, p.limits
        feeds = np.minimum(ch.feeds * (scale or lim.scale), lim.feed)
        caps, _ = speed_caps(list(ch.elements), feeds.tolist(), ch.accels.tolist(),
                             axis_vmax=lim.axis_vmax, axis_amax=lim.axis_amax)
        k = np.clip(np.searchsorted(ch.cum, s, side="right") - 1, 0, len(ch.elements) - 1)
        worst = max(worst, float(np.max(v / np.asarray(caps)[k])))
    return worst


def run_prog(prog, **kw):
    ctl, g, rec = make(**kw)
    t0 = ctl.time
    push(g, prog)
    t1 = finish(ctl, g)
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    return t1 - t0, g, rec, t, sx, sy


# ------------------------------------------------------------------ 1. blended chains
@pytest.mark.parametrize("prog", [LL, LAL], ids=["line-line", "line-arc-line"])
def test_blended_chain_runs_through_within_limits(prog):
    tol = 40.0
    els = elements(prog)
    t_t, *_ = run_prog(prog, jerk=None, tol=tol)
    t_s, g, rec, t, sx, sy = run_prog(prog, tol=tol)
    assert g.position.tolist() == list(els[-1].end)  # exact end
    assert min_cruise_speed(sx, sy) > 1000.0  # no stop inside the chain
    err = contour_error(np.stack([sx.p, sy.p], axis=1), els)
    assert 0.5 * tol < err.max() <= tol * (1 + 1e-6)  # corners rounded within T
    check_axes(sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    assert caps_held(rec) <= 1 + REL
    # the smoothing adds about one window per chain, not one per corner
    assert t_t < t_s < t_t + 0.2


# ------------------------------------------------------------------ 2. exact-stop corners
ZIGZAG = [("line", [10_000.0 * (k + 1), 6_000.0 * (k % 2 == 0)]) for k in range(6)]


def test_exact_stop_zigzag_passes_each_corner_at_rest():
    els = elements(ZIGZAG)
    _, g, rec, t, sx, sy = run_prog(ZIGZAG, tol=None)  # blending off: exact stops
    assert g.position.tolist() == [60_000.0, 0.0]
    check_axes(sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    xy = np.stack([sx.p, sy.p], axis=1)
    assert contour_error(xy, els).max() < 1e-6  # the path is followed exactly
    dt = t[1] - t[0]
    for el in els[:-1]:  # the recorded motion is at rest at each corner instant
        i = int(np.argmin(np.linalg.norm(xy - el.end, axis=1)))
        assert np.linalg.norm(xy[i] - el.end) < 1e-3
        assert speed(sx, sy)[i] < 1e-3 * FEED
        assert np.hypot(sx.a[i], sy.a[i]) < JERK * 2 * dt
    # no acceleration spike: every axis acceleration is continuous (jerk-bounded steps),
    # where a T path flips -A*u1 -> +A*u2 at the corner
    for s in (sx, sy):
        assert np.abs(np.diff(s.a)).max() <= JERK * dt * (1 + 1e-6)
    _, _, _, _, tx, ty = run_prog(ZIGZAG, tol=None, jerk=None)
    assert np.abs(np.diff(tx.a)).max() > 0.5 * AMAX  # (the T path does spike)


# ------------------------------------------------------------------ 3. arcs at high feed
@pytest.mark.parametrize("radius", [1_000.0, 3_000.0])
def test_arc_centripetal_share_held_at_high_feed(radius):
    """Feed 50 000 pps, path acceleration = the axis limit: the arc's centripetal cap
    sqrt(sqrt(3)/2 * A * R) binds. A short line from rest accelerates into it, so the
    smoothing window holds raw motion of both (the guard keeps the arc's cap and tangential
    share there); the recorded axis accelerations stay within the limit, also where the
    curvature steps at the arc's ends (knots at the element boundaries)."""
    r = radius
    prog = [("line", [1_000, 0]), ("arc", [1_000, r], [1_000 + r, r], "CCW"),
            ("line", [1_000 + r, r + 5_000])]
    _, g, rec, t, sx, sy = run_prog(prog, jerk=5e6, tol=None, feed=50_000.0, acc_t=0.1,
                                    policy="slow")
    assert g.position.tolist() == [1_000 + r, r + 5_000]
    check_axes(sx, sy)
    assert caps_held(rec) <= 1 + REL  # the speed on the arc within its centripetal cap
    assert rec.path_jerk() <= 5e6 * (1 + REL)
    xy = np.stack([sx.p, sy.p], axis=1)
    on_arc = np.abs(np.hypot(xy[:, 0] - 1_000, xy[:, 1] - r) - r) < 1e-6
    on_arc &= xy[:, 0] > 1_000 + 1e-6
    a_n = speed(sx, sy)[on_arc] ** 2 / r
    assert a_n.max() <= np.sqrt(0.75) * AMAX * (1 + 1e-6)  # recorded (Hermite error 1e-6)
    assert a_n.max() > 0.9 * np.sqrt(0.75) * AMAX  # the cap is reached: the test binds


# ------------------------------------------------------------------ 4. streaming
def _raw_state(g: Group, t: float):
    p = g._run.plan
    return p.raw.state_at(t - p.raw_t0), p


def _check_stream(ctl, g, rec, t0, els, tol):
    t1 = finish(ctl, g)
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    assert g.position.tolist() == list(els[-1].end)
    check_axes(sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    assert caps_held(rec) <= 1 + REL
    err = contour_error(np.stack([sx.p, sy.p], axis=1), els)
    assert err.max() <= tol * (1 + 1e-6)
    return t, sx, sy


def test_commands_pushed_while_running_join_and_blend():
    ctl, g, rec = make()
    t0 = ctl.time
    for k, cmd in enumerate(LAL):
        push(g, [cmd])
        if k < len(LAL) - 1:
            ctl.advance(0.08)  # the rest joins the running chain
    _, sx, sy = _check_stream(ctl, g, rec, t0, elements(LAL), 40.0)
    assert min_cruise_speed(sx, sy) > 1000.0  # joined and blended: no stop
    assert len({p.chain.owners[-1] for p in rec.plans}) == 3  # three joins/starts


def test_push_after_raw_motion_ended_joins_at_rest():
    """The raw motion has ended (it rests at the chain's end) while the smoothed one still
    moves: the next command joins (a re-plan with a lead of tj), the corner is passed at
    rest and no limit is exceeded."""
    ctl, g, rec = make()
    t0 = ctl.time
    g.line([10_000, 0])
    ctl.step()
    plan = g._run.plan
    t_raw_end = plan.raw_t0 + plan.raw.duration
    assert ctl.run_until(lambda: ctl.time > t_raw_end + 0.01, 5)
    assert g._run is not None and ctl.time < g._run.plan.t_end  # still moving
    assert g.axes[0].velocity > 0.0
    g.line([10_000, 10_000])
    assert g._run.plan.chain.owners[-1] == 1  # joined the running chain at once
    g.line([0, 10_000])
    els = elements([("line", [10_000, 0]), ("line", [10_000, 10_000]), ("line", [0, 10_000])])
    t, sx, sy = _check_stream(ctl, g, rec, t0, els, 40.0)
    _at_rest_without_spike(t, sx, sy, [10_000, 0])  # the corner the raw motion stopped at


def _at_rest_without_spike(t, sx, sy, corner) -> None:
    """The motion passes `corner` at rest, its axis accelerations continuous around it
    (the next corner may be blended: a blend's curvature step is not checked here)."""
    xy = np.stack([sx.p, sy.p], axis=1)
    i = int(np.argmin(np.linalg.norm(xy - corner, axis=1)))
    assert np.linalg.norm(xy[i] - corner) < 1e-3
    assert speed(sx, sy)[i] < 1e-3 * FEED
    near = slice(max(0, i - 2000), i + 2000)
    for s in (sx, sy):
        assert np.abs(np.diff(s.a[near])).max() <= JERK * (t[1] - t[0]) * (1 + 1e-6)


def test_late_push_while_braking_keeps_limits():
    """A command pushed while the chain brakes for its end, too late for a blend: it joins
    with an exact stop (or starts after the chain), within every limit."""
    ctl, g, rec = make()
    t0 = ctl.time
    g.line([20_000, 0])
    ctl.step()

    def braking() -> bool:
        rs, p = _raw_state(g, ctl.time)
        return rs.a < 0.0 and p.chain.length - rs.p < 1_000.0
    assert ctl.run_until(braking, 5)
    g.line([20_000, 10_000])
    g.line([30_000, 20_000])
    els = elements([("line", [20_000, 0]), ("line", [20_000, 10_000]),
                    ("line", [30_000, 20_000])])
    t, sx, sy = _check_stream(ctl, g, rec, t0, els, 40.0)
    _at_rest_without_spike(t, sx, sy, [20_000, 0])


def cam_polyline(n: int, seg: float, seed: int = 1) -> np.ndarray:
    """n short segments turning 1.5-4 deg at each corner, the turn changing side every 150
    segments (a CAM contour: S-bends of polylines), rounded to 1e-3 pulse."""
    rng = np.random.default_rng(seed)
    turn = rng.uniform(1.5, 4.0, n) * np.where((np.arange(n) // 150) % 2, 1.0, -1.0)
    head = np.cumsum(np.deg2rad(turn))
    return np.round(np.cumsum(np.stack([np.cos(head), np.sin(head)], axis=1) * seg, axis=0), 3)


def test_long_stream_keeps_a_short_chain_and_never_stops():
    n, tol = size(600, 2000), 20.0
    pts = cam_polyline(n, 300.0)
    ctl, g, rec = make(tol=tol)
    todo = iter(pts.tolist())
    sizes: list[int] = []

    def feeder(c: Controller, t: float) -> None:  # a CAM sender keeping 200 queued
        while g.queue_length < 200:
            nxt = next(todo, None)
            if nxt is None:
                return
            g.line(nxt)
        if g._run is not None and g._run.plan is not None:
            sizes.append(len(g._run.plan.chain.elements))
    ctl.add_cycle_hook(feeder)
    t0 = ctl.time
    t1 = finish(ctl, g, 120.0)
    assert g.position.tolist() == pts[-1].tolist()
    assert len(sizes) > n // 2 and max(sizes) <= 150  # of 2n elements: the look-ahead reach
    t, (sx, sy) = recorded(ctl, g, t0, t1, 100_001)
    inner = (t > t0 + 0.2) & (t < t1 - 0.2)  # past the start's and before the end's ramp
    assert speed(sx, sy)[inner].min() > 0.5 * FEED  # never stops, never crawls
    check_axes(sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    els = elements([("line", p) for p in pts])
    xy = np.stack([sx.p, sy.p], axis=1)[::20]
    assert contour_error(xy, els).max() <= tol * (1 + 1e-6)


# ------------------------------------------------------------------ 5. override, hold, abort
LONG = [("line", [40_000, 0]), ("line", [60_000, 20_000]), ("line", [60_000, 60_000]),
        ("line", [20_000, 70_000])]


def _smooth_run(t, sx, sy) -> None:
    """No velocity jump (each step within the acceleration limit) and no acceleration jump
    on the lines (each step within the path jerk)."""
    dt = t[1] - t[0]
    for s in (sx, sy):
        assert np.abs(np.diff(s.v)).max() <= AMAX * dt * (1 + 1e-6)


def test_feed_override_up_and_down_mid_chain_is_smooth():
    ctl, g, rec = make()
    t0 = ctl.time
    push(g, LONG)
    ctl.advance(0.4)
    g.set_override(150)   # faster (the axes' 50 000 pps cap the diagonal)
    ctl.advance(0.5)
    g.set_override(40)    # slower: decelerates to the new feed along the plan
    ctl.advance(0.5)
    g.set_override(100)
    t1 = finish(ctl, g)
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    assert g.position.tolist() == [20_000.0, 70_000.0]
    assert len(rec.plans) >= 4
    check_axes(sx, sy)
    _smooth_run(t, sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    assert caps_held(rec, 1.5) <= 1 + REL
    v = speed(sx, sy)
    assert v[(t > t0 + 0.85) & (t < t0 + 0.9)].max() > 1.2 * FEED  # the override took
    assert v[(t > t0 + 1.3) & (t < t0 + 1.4)].max() < 0.41 * FEED
    assert contour_error(np.stack([sx.p, sy.p], axis=1), elements(LONG)).max() <= 40.0



def test_override_while_resting_at_an_exact_stop_keeps_the_rest():
    """An override re-plans from the raw state; at an exact-stop corner the raw motion is
    resting out its tj. The re-plan completes that rest, so the corner is still passed at
    rest (it used to leave at once: a 3 422 pps velocity step at the corner)."""
    ctl, g, rec = make(tol=None)
    t0 = ctl.time
    g.line([10_000, 0])
    g.line([10_000, 10_000])
    ctl.step()

    def resting() -> bool:
        rs, _ = _raw_state(g, ctl.time)
        return rs.v == 0.0 and rs.p > 5_000.0
    assert ctl.run_until(resting, 5)
    ctl.advance(0.003)
    g.set_override(120)
    t1 = finish(ctl, g)
    assert g.position.tolist() == [10_000.0, 10_000.0]
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    check_axes(sx, sy)
    _smooth_run(t, sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    _at_rest_without_spike(t, sx, sy, [10_000, 0])


def _uninterrupted_end() -> list[float]:
    return elements(LONG)[-1].end.tolist()


def test_hold_stops_on_the_path_and_continue_ends_exactly():
    ctl, g, rec = make()
    t0 = ctl.time
    push(g, LONG)
    ctl.advance(0.7)
    g.hold()
    assert ctl.run_until(lambda: g.state is GroupState.HELD, 5)
    t_held = ctl.time
    assert not any(a.is_moving for a in g.axes)
    t, (sx, sy) = recorded(ctl, g, t0, t_held)
    check_axes(sx, sy)
    _smooth_run(t, sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    held = g.position.copy()
    assert contour_error(held[None, :], elements(LONG))[0] <= 40.0  # on the path
    assert 0.0 < held[0] < 60_000.0
    ctl.advance(0.2)
    g.cont()
    t1 = finish(ctl, g)
    assert g.position.tolist() == _uninterrupted_end()
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    check_axes(sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    assert contour_error(np.stack([sx.p, sy.p], axis=1), elements(LONG)).max() <= 40.0


def test_abort_stops_on_the_path_and_takes_new_commands():
    ctl, g, rec = make()
    t0 = ctl.time
    push(g, LONG)
    ctl.advance(1.0)
    g.abort()
    assert g.queue_length == 0
    assert ctl.run_until(lambda: g.state is GroupState.IDLE
                         and not any(a.is_moving for a in g.axes), 5)
    t, (sx, sy) = recorded(ctl, g, t0, ctl.time)
    check_axes(sx, sy)
    _smooth_run(t, sx, sy)
    assert rec.path_jerk() <= JERK * (1 + REL)
    stop = g.position.copy()
    assert contour_error(stop[None, :], elements(LONG))[0] <= 40.0
    assert stop.tolist() != _uninterrupted_end()
    g.line([0, 0])
    finish(ctl, g)
    assert g.position.tolist() == [0.0, 0.0]


# ------------------------------------------------------------------ 6. mixed commands
FEEDS = [("line", [20_000, 0]), ("feed", 15_000.0), ("line", [30_000, 8_000]),
         ("line", [40_000, 8_000]), ("feed", 40_000.0), ("line", [60_000, 20_000])]


@pytest.mark.parametrize("jerk", [None, JERK], ids=["T", "S"])
def test_per_command_feeds_blend_in_one_chain(jerk):
    """A program changing F keeps blending: one chain, each element within its own feed
    (the slower command's cap reaches tj*F/2 into its neighbours on an S path)."""
    els = elements(FEEDS)
    _, g, rec, t, sx, sy = run_prog(FEEDS, jerk=jerk, tol=40.0)
    assert g.position.tolist() == [60_000.0, 20_000.0]
    assert speed(sx, sy)[(t > t[0] + 0.2) & (t < t[-1] - 0.2)].min() > 5_000.0  # no stop
    assert any(len(set(p.chain.feeds)) > 1 for p in rec.plans)  # mixed feeds in a chain
    assert caps_held(rec) <= 1 + REL   # each element's own feed
    check_axes(sx, sy)
    err = contour_error(np.stack([sx.p, sy.p], axis=1), els)
    assert 20.0 < err.max() <= 40.0 * (1 + 1e-6)
    if jerk:
        assert rec.path_jerk() <= JERK * (1 + REL)


def _element_jerk_ratio(rec: Recorder, jerk_of: dict[int, float]) -> float:
    """Largest |path jerk| / the jerk limit of the command owning the element the executed
    position is on."""
    worst = 0.0
    for i, p in enumerate(rec.plans):
        end = min(p.t_end, rec.plans[i + 1].t0) if i + 1 < len(rec.plans) else p.t_end
        smp = p.sprof.sample(np.linspace(0.0, max(0.0, end - p.t0), 4000))
        k = np.clip(np.searchsorted(p.chain.cum, smp.p, side="right") - 1, 0,
                    len(p.chain.elements) - 1)
        lim = np.array([jerk_of[p.chain.owners[q]] for q in k])
        worst = max(worst, float(np.max(np.abs(smp.j) / lim)))
    return worst


def test_command_with_a_smaller_window_joins_and_keeps_each_jerk():
    """Command 1 has twice the acceleration and four times the jerk (half the window): it
    joins the chain; the guard keeps the other commands' accelerations near it, so every
    element keeps its own command's jerk limit."""
    ctl, g, rec = make(tol=40.0, policy="slow")
    t0 = ctl.time
    g.line([20_000, 0])
    g.set_acc_time(ACC_T / 2)
    g.set_path_shape("S", jerk=4 * JERK)
    g.line([30_000, 10_000])
    g.set_acc_time(ACC_T)
    g.set_path_shape("S", jerk=JERK)
    g.line([30_000, 30_000])
    t1 = finish(ctl, g)
    assert g.position.tolist() == [30_000.0, 30_000.0]
    assert any(len(p.chain.owners) and set(p.chain.owners) >= {0, 1} for p in rec.plans)
    assert _element_jerk_ratio(rec, {0: JERK, 1: 4 * JERK, 2: JERK}) <= 1 + REL
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    check_axes(sx, sy)
    assert speed(sx, sy)[(t > t0 + 0.2) & (t < t1 - 0.2)].min() > 1_000.0


def test_command_with_a_larger_window_starts_a_new_chain():
    """A lower jerk (a window longer than the running chain's) must not join: the chain
    stops exactly at the corner and the command runs as a new chain with its own window."""
    ctl, g, rec = make(tol=40.0)
    t0 = ctl.time
    g.line([20_000, 0])
    g.line([30_000, 10_000])
    g.set_path_shape("S", jerk=JERK / 4)
    g.line([30_000, 30_000])
    t1 = finish(ctl, g)
    assert g.position.tolist() == [30_000.0, 30_000.0]
    for p in rec.plans:  # never both windows in one chain
        assert not {1, 2} <= set(p.chain.owners)
    assert {round(p.tj, 9) for p in rec.plans} == {0.04, 0.16}
    assert _element_jerk_ratio(rec, {0: JERK, 1: JERK, 2: JERK / 4}) <= 1 + REL
    t, (sx, sy) = recorded(ctl, g, t0, t1)
    check_axes(sx, sy)
    xy = np.stack([sx.p, sy.p], axis=1)
    i = int(np.argmin(np.linalg.norm(xy - [30_000, 10_000], axis=1)))
    assert speed(sx, sy)[i] < 1e-3 * FEED  # exact stop between the chains
    assert np.linalg.norm(xy[i] - [30_000, 10_000]) < 1e-3


def test_higher_acceleration_next_to_a_short_move_keeps_its_jerk():
    """Two short collinear moves: 200 000 pps^2 and jerk 1e7, then 400 000 pps^2 and jerk
    4e7 (window 0.02 s <= 0.04 s: it joins). The second's raw motion accelerates and brakes
    within one window of the first's executed position: without the acceleration guard its
    jerk would reach 1.5 times the first command's limit."""
    ctl, g, rec = make(tol=None)
    g.set_acc_time(0.2)
    g.set_path_shape("S", jerk=1e7)
    g.line([300, 0])
    g.set_acc_time(0.1)
    g.set_path_shape("S", jerk=4e7)
    g.line([800, 0])
    finish(ctl, g)
    assert g.position.tolist() == [800.0, 0.0]
    assert [p.chain.owners for p in rec.plans] == [(0, 1)]
    assert _element_jerk_ratio(rec, {0: 1e7, 1: 4e7}) <= 1 + REL


# ------------------------------------------------------------------ the guard itself
def _limits(feed: float = FEED, accel: float = 400_000.0):
    from openmotion.control.groups.pathexec import Limits
    return Limits(feed, accel, np.array([VMAX, VMAX]), np.array([AMAX, AMAX]))


def test_guard_zone_is_half_a_window_of_the_cap():
    """A line into an arc of cap c: the line's last c*tj/2 runs at c (and at the arc's
    tangential acceleration), the rest at the feed; the arc keeps its own cap."""
    from openmotion.control.groups.pathexec import guarded
    tj = 0.04
    arc = Arc([10_000, 0], [10_000, 1_000], [11_000, 1_000], direction="CCW")
    els = [Line([0, 0], [10_000, 0]), arc]
    caps, _ = speed_caps(els, FEED, 400_000.0, axis_vmax=[VMAX, VMAX],
                         axis_amax=[AMAX, AMAX])
    c = caps[1]
    assert c < FEED
    out, feeds, accels = guarded(els, FEED, 400_000.0, _limits(), tj)
    assert [round(e.length, 6) for e in out] == [round(10_000 - c * tj / 2, 6),
                                                 round(c * tj / 2, 6), round(arc.length, 6)]
    assert feeds == [FEED, pytest.approx(c), pytest.approx(c)]
    assert accels[0] == 400_000.0
    assert accels[1] == pytest.approx(tangential_accels([arc], 400_000.0,
                                                        axis_amax=[AMAX, AMAX])[0])


def test_guard_does_not_cross_an_exact_stop():
    """An exact-stop corner (junction speed 0) is a barrier: neither side is slowed for the
    other, and no element gets a 0 feed (which used to crash the join)."""
    from openmotion.control.groups.pathexec import guarded
    els = [Line([0, 0], [10_000, 0]), Line([10_000, 0], [10_000, 10_000])]
    out, feeds, _ = guarded(els, [FEED, 10_000.0], [400_000.0, 400_000.0], _limits(), 0.04)
    assert len(out) == 2 and feeds == [FEED, 10_000.0]


def test_tangential_accels_match_the_look_ahead():
    els = [Line([0, 0], [3, 4]), Arc([3, 4], [3, 6], [3, 8], direction="CW"),
           Line([3, 8], [3, 20])]
    sp = plan_speeds(els, 100.0, [50.0, 80.0, 90.0], axis_amax=[40.0, 60.0])
    assert tangential_accels(els, [50.0, 80.0, 90.0], axis_amax=[40.0, 60.0]) == \
        [x.accel for x in sp]
