"""Soak test (issue #12): random holds, overrides, aborts, moves, paths and jogs on the
simulator, invariants checked every cycle.

The normal run covers 10 simulated seconds (a few seconds of CPU); `--soak-long` (fixture
`soak_long`) runs 45 simulated minutes. Axes x, y form a group (lines, arcs, blends, holds,
continues, overrides, aborts); z runs single-axis T/S moves, velocity moves, S-curve speed
changes and stops; u jogs. Every call that the controller may refuse is allowed to raise
MotionError (a refusal changes nothing); any other exception fails the test.

Invariants, every cycle, from the integer pulse counts the hardware emitted (c_k at the end
of cycle k, period T). The pulse rule puts each count within half a pulse of the planned
position, so the quantisation adds at most 1 pulse to a first difference and at most 2
pulses to a second difference:

- speed: |c_k - c_(k-1)| <= v_max * T + 1 for each axis (v_max its maximum speed);
- acceleration: |c_k - 2 c_(k-1) + c_(k-2)| <= a_max * T**2 + 2, a_max the largest
  acceleration any command of the soak may ask of that axis (below);
- counters consistent with history: |c_k - history position(t_k)| <= 1/2 (+ 1e-6);
- no exception escapes a cycle (`ctl.cycle_errors == 0`), no axis faults;
- memory bounded: the history holds at most `max_records` records per axis, its arrays
  never hold more than `cap_bound` rows (8 times the most records seen live, plus what one
  path window's append can double them by; checked every 100 cycles), and the event log is
  bounded.
"""

from __future__ import annotations

import random

import numpy as np
import pytest

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups import groupexec
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.manual.jog import jog_conti, stop_jog
from openmotion.errors import MotionError

PERIOD = 0.001
FEED_MAX = 40_000.0   # pps of any path (override up to 200 %)
GROUP_ACC = 2e6       # pps^2 cap of each group axis (set_max_pulse_acc, policy "slow")
Z_ACC = 6e6           # z: T/S moves ramp in >= 20 ms to <= 60 kpps (pure S peaks at 2x)
U_ACC = 2e6           # u: jogs ramp in 50 ms to <= 50 kpps (T)
A_MAX = np.array([GROUP_ACC, GROUP_ACC, Z_ACC, U_ACC])


def cap_bound(records_high: int) -> int:
    """Most history rows an axis may hold allocated: its arrays shrink when an eighth is
    live, and one append (a path window of PATH_WINDOW_S / T knots plus its breaks, or a
    move) can double them."""
    return 8 * records_high + 4 * round(groupexec.PATH_WINDOW_S / PERIOD) + 256


def _controller() -> tuple[Controller, Group]:
    cfg = MachineConfig("soak", tuple(AxisConfig(name=n) for n in "xyzu"))
    ctl = Controller(cfg, history_window_s=2.0)
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=20_000.0, acc_time=0.05)
    g.set_axis_limit_policy("slow")
    g.set_max_pulse_acc([GROUP_ACC, GROUP_ACC])
    return ctl, g


def _group_op(rng: random.Random, g: Group) -> None:
    op = rng.random()
    p = g.position
    if op < 0.35:
        g.set_feed(rng.uniform(2_000.0, FEED_MAX / 2))
        tgt = np.clip(p + [rng.uniform(-30_000, 30_000), rng.uniform(-30_000, 30_000)],
                      -200_000, 200_000)
        g.line(list(tgt))
    elif op < 0.5:
        r = rng.uniform(2_000, 20_000)
        ang = rng.uniform(0, 2 * np.pi)
        c = p + r * np.array([np.cos(ang), np.sin(ang)])
        end = c + r * np.array([np.cos(ang + 2.5), np.sin(ang + 2.5)])
        g.set_feed(rng.uniform(2_000.0, FEED_MAX / 2))
        g.arc(list(c), list(end), direction=rng.choice(["CW", "CCW"]))
    elif op < 0.6:
        if rng.random() < 0.5:
            g.enable_blend(rng.uniform(5.0, 200.0))
        else:
            g.disable_blend()
    elif op < 0.72:
        g.set_override(rng.uniform(10.0, 200.0))
    elif op < 0.82:
        if g.state is GroupState.HELD:
            g.cont()
        else:
            g.hold()
    else:
        g.abort()


def _z_op(rng: random.Random, ctl: Controller) -> None:
    z = ctl["z"]
    op = rng.random()
    shape = rng.choice("TS")
    v = rng.uniform(5_000.0, 60_000.0)
    tacc = rng.uniform(0.02, 0.2)
    if op < 0.3:
        d = rng.uniform(-40_000, 40_000)
        if abs(z.position + d) < 400_000:
            z.move_relative(d, max_vel=v, tacc=tacc, shape=shape)
    elif op < 0.5:
        z.move_velocity(rng.choice([-1, 1]) * v, tacc=tacc, shape=shape)
    elif op < 0.75:
        z.change_speed(min(v, z.motion.spec.max_vel if z.motion and z.motion.spec else v),
                       tacc)
    else:
        z.stop()


def _u_op(rng: random.Random, ctl: Controller) -> None:
    u = ctl["u"]
    if u.is_moving:
        stop_jog(ctl, "u")
    else:
        jog_conti(ctl, "u", rng.choice([0, 1]), rng.uniform(1.0, 10.0))  # <= 50 kpps


def _keep_in_travel(ctl: Controller) -> None:
    """Velocity moves and jogs run until changed: turn them back before 400 000 pulses."""
    for name in ("z", "u"):
        ax = ctl[name]
        if abs(ax.position) > 300_000 and ax.is_moving and ax.position * ax.velocity > 0:
            ax.stop()


def soak(seconds: float, seed: int) -> dict[str, float]:
    rng = random.Random(seed)
    ctl, g = _controller()
    hist = ctl.history
    n_ax = len(ctl.axes)
    vmax = np.array([a.max_speed for a in ctl.axes])
    v_tol = vmax * PERIOD + 1.0
    a_tol = A_MAX * PERIOD**2 + 2.0
    prev = np.zeros(n_ax)
    prev2 = np.zeros(n_ax)
    n_cycles = round(seconds / PERIOD)
    next_op = 0
    refusals = ops = 0
    worst_v = worst_a = worst_h = 0.0
    rec_high = 0
    cap_high = 0
    for k in range(n_cycles):
        if k >= next_op:
            ops += 1
            try:
                which = rng.random()
                if which < 0.5:
                    _group_op(rng, g)
                elif which < 0.8:
                    _z_op(rng, ctl)
                else:
                    _u_op(rng, ctl)
            except MotionError:
                refusals += 1
            next_op = k + rng.randint(5, 120)
        _keep_in_travel(ctl)
        ctl.step()
        t = ctl.time
        c = np.empty(n_ax)
        for i, ax in enumerate(ctl.axes):
            c[i] = ctl.hardware.read_axis(i).pulses_out - ax.counters.out_offset
            h = abs(c[i] - hist.state_at(i, t).p)
            worst_h = max(worst_h, h)
            assert h <= 0.5 + 1e-6, f"cycle {k}: axis {ax.name} count {c[i]} vs history"
        if k >= 1:
            dv = np.abs(c - prev)
            worst_v = max(worst_v, float(np.max(dv / v_tol)))
            assert np.all(dv <= v_tol), f"cycle {k}: speed {dv / PERIOD} pps"
        if k >= 2:
            da = np.abs(c - 2 * prev + prev2)
            worst_a = max(worst_a, float(np.max(da / a_tol)))
            assert np.all(da <= a_tol), f"cycle {k}: acceleration {da / PERIOD**2} pps^2"
        prev2, prev = prev, c
        assert ctl.cycle_errors == 0
        if k % 100 == 0:
            rec_high = max(rec_high, *(hist.n_records(i) for i in range(n_ax)))
            cap = max(hist.capacity(i) for i in range(n_ax))
            cap_high = max(cap_high, cap)
            assert cap <= cap_bound(rec_high), (cap, rec_high)
    assert not any(a.fault for a in ctl.axes), [a.fault for a in ctl.axes]
    assert g.error_code == 0, g.error_message
    for i in range(n_ax):
        assert hist.n_records(i) <= hist.max_records
    assert len(ctl.events.events()) <= 10_000
    return {"cycles": n_cycles, "ops": ops, "refusals": refusals, "worst_speed": worst_v,
            "worst_acc": worst_a, "worst_history": worst_h, "records_high": rec_high,
            "capacity_high": cap_high}


@pytest.mark.parametrize("seed", [1, 2])
def test_soak(seed: int, soak_long: bool) -> None:
    seconds = 45 * 60.0 if soak_long else 5.0
    figures = soak(seconds, seed)
    assert figures["ops"] > 10 and figures["refusals"] < figures["ops"]
    print(f"soak seed {seed}: {figures}")
