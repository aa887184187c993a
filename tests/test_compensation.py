"""Backlash, vibration suppression and pitch-error compensation (control.loops.compensation)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import DriveConfig, default_machine
from openmotion.control import Controller
from openmotion.control.core.axis import Axis
from openmotion.control.loops.compensation import (
    BACKLASH_COMPENSATING,
    Compensation,
    PitchCompTable,
)
from openmotion.errors import MotionError

SEED_TABLE = (22, 20, 15, 11, 0, 10, 12, 15)  # MCCL 2.10.1, home index 4, interval 10000
# Sim lead-screw error (pulses) at z = k * 10000 (one screw revolution of axis x).
SCREW_ERR = (0.0, 3.0, 7.5, 12.0, 9.0, 4.0, -2.0, -6.5, -3.0, 1.0, 5.0)


def _machine(backlash: float = 0.0, pitch: tuple[float, ...] = ()) -> Controller:
    cfg = default_machine()
    x = dataclasses.replace(cfg.axes[0], drive=DriveConfig(backlash=backlash,
                                                           pitch_error=pitch))
    ctl = Controller(dataclasses.replace(cfg, axes=(x, *cfg.axes[1:])))
    ctl.axis("x").enable()
    return ctl


def _with_backlash(backlash: int, pitch: tuple[float, ...] = (),
                   **comp_kw: float) -> tuple[Controller, Axis, Compensation]:
    """Axis x with `backlash` pulses of play on its drive and a Compensation correcting
    exactly that much (max_accel 5e6 unless `comp_kw` says otherwise)."""
    ctl = _machine(backlash=float(backlash), pitch=pitch)
    ax = ctl.axis("x")
    comp = Compensation(ax, **{"max_accel": 5e6, **comp_kw})
    comp.backlash_comp(backlash)
    return ctl, ax, comp


def _record(ctl: Controller, axis: int = 0) -> list:
    """Every AxisCommand the controller hands the hardware for `axis`."""
    cmds: list = []
    orig = ctl.hardware.command

    def command(i, cmd):
        if i == axis:
            cmds.append(cmd)
        orig(i, cmd)

    ctl.hardware.command = command  # type: ignore[method-assign]
    return cmds


def _move_to(ctl: Controller, target: int, vmax: float = 60000.0) -> None:
    ax = ctl.axis("x")
    ax.move_relative(target - ax.position, max_vel=vmax, tacc=0.03)
    assert ctl.wait_motion_done(timeout=10.0)


def _load_error(ctl: Controller) -> float:
    """Encoder (load) position minus planned position, in counts (1 count = 1 pulse)."""
    ax = ctl.axis("x")
    return ax.counters.feedback - ax.position


# ---------------------------------------------------------------------- the seed example
def test_seed_table_value_at_15000_is_11():
    t = PitchCompTable.make(10000, 4, SEED_TABLE)
    assert t.value(15000, +1) == 11
    assert t.span == (-40000, 30000)
    assert [t.value((k - 4) * 10000, 1) for k in range(8)] == list(SEED_TABLE)


def test_seed_move_of_15000_outputs_15011_pulses():
    ctl = _machine()
    ax = ctl.axis("x")
    comp = Compensation(ax, max_accel=5e6)
    comp.set_pitch_table(10000, 4, SEED_TABLE, stroke=(-40000, 30000))
    _move_to(ctl, 15000)
    assert ctl.hardware.read_axis(0).pulses_out == 15011      # pulses out: planned + 11
    assert ctl.hardware.command_position(0) == 15011.0
    assert ax.counters.command == 15000                        # command counter: planned
    assert ax.position == 15000.0
    assert comp.offset == 11.0


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-500, 500), min_size=3, max_size=12), st.data())
def test_table_interpolation_between_neighbours(vals, data):
    home = data.draw(st.integers(0, len(vals) - 1))
    vals[home] = 0
    for k in range(len(vals) - 1):  # keep |step| < interval
        vals[k + 1] = max(min(vals[k + 1], vals[k] + 999), vals[k] - 999)
    t = PitchCompTable.make(1000, home, vals, [v - 3 if k != home else 0
                                               for k, v in enumerate(vals)])
    x = data.draw(st.floats(-home * 1000.0, (len(vals) - 1 - home) * 1000.0))
    k = min(int(x / 1000 + home), len(vals) - 2)
    lo, hi = sorted((vals[k], vals[k + 1]))
    assert lo <= t.value(x, 1) <= hi
    exact = vals[k] + (x / 1000 + home - k) * (vals[k + 1] - vals[k])
    assert abs(t.value(x, 1) - exact) <= 0.5 + 1e-9
    if k != home and k + 1 != home:
        assert t.value(x, -1) == t.value(x, 1) - 3  # backward table in negative travel


# ---------------------------------------------------------------------- backlash
def test_backlash_compensation_reduces_final_error_to_one_count():
    targets = (20000, 8000, 15000, -3000, 2000, 1000)
    errs = {}
    for on in (False, True):
        ctl = _machine(backlash=37.0)
        comp = Compensation(ctl.axis("x"), max_accel=5e6)
        comp.backlash_comp(37 if on else 0)
        e = []
        for tg in targets:
            _move_to(ctl, tg)
            e.append(_load_error(ctl))
        errs[on] = e
    assert max(abs(v) for v in errs[False]) == 37          # the mechanism is really there
    assert all(abs(v) <= 1 for v in errs[True])


def test_backlash_counters_and_direction():
    ctl, ax, comp = _with_backlash(50)
    _move_to(ctl, 10000)
    assert comp.offset == 0.0 and comp.direction == 1
    _move_to(ctl, 4000)
    assert comp.direction == -1 and comp.offset == -50.0
    assert ax.counters.command == 4000                      # planned
    assert ctl.hardware.read_axis(0).pulses_out == 3950     # planned + offset
    assert abs(ax.counters.error) <= 1                      # planned vs load
    comp.backlash_comp(50, mode=0)                          # off: ramps back out
    ctl.advance(0.2)
    assert comp.offset == 0.0 and ctl.hardware.read_axis(0).pulses_out == 4000


def test_motion_done_reports_compensating_until_offset_settles():
    ctl, ax, comp = _with_backlash(400, comp_accel=2e5)
    _move_to(ctl, 5000)
    ax.move_relative(-10, max_vel=1000, tacc=0.01)
    codes = []
    while ax.motion_done != 0:
        codes.append(ax.motion_done)
        ctl.step()
    assert BACKLASH_COMPENSATING in codes
    assert comp.settled and comp.offset == -400.0
    assert abs(_load_error(ctl)) <= 1


# ---------------------------------------------------------------------- pitch error
def _table_from_screw() -> tuple[int, ...]:
    # measured on a laser: the load is e(x) too far, so command -e(x); home index 1 at x=0
    # and one point below so the table covers the stroke (MEL -5000 .. PEL 305000).
    pts = [-round(SCREW_ERR[0])] + [-round(e) for e in SCREW_ERR]
    pts += [pts[-1]] * (33 - len(pts))
    pts[1] = 0
    return tuple(pts)


def test_pitch_compensation_reduces_final_error_to_one_count():
    targets = (15000, 42000, 27500, 61234, 88000, 33333, 5000, 99000)
    worst = {}
    for on in (False, True):
        ctl = _machine(pitch=SCREW_ERR)
        comp = Compensation(ctl.axis("x"), max_accel=5e6)
        if on:
            comp.set_pitch_table(10000, 1, _table_from_screw())
        e = []
        for tg in targets:
            _move_to(ctl, tg, vmax=200000.0)
            e.append(_load_error(ctl))
        worst[on] = max(abs(v) for v in e)
    assert worst[False] >= 8
    assert worst[True] <= 1


def test_backlash_and_pitch_together():
    ctl, _, comp = _with_backlash(25, pitch=SCREW_ERR)
    comp.set_pitch_table(10000, 1, _table_from_screw())
    for tg in (30000, 12000, 47000, 20500, 81000, 64000):
        _move_to(ctl, tg, vmax=150000.0)
        assert abs(_load_error(ctl)) <= 1


# ---------------------------------------------------------------------- limits
def _sup_each(cmds: list) -> tuple[np.ndarray, np.ndarray]:
    """Per command: sup |v| and sup |a| of its cubic, sampled on 41 points."""
    s = np.linspace(0.0, 1.0, 41)
    dt = np.array([c.dt for c in cmds])[:, None] * s
    v0, a0, j = (np.array([getattr(c, f) for c in cmds])[:, None] for f in ("v0", "a0", "j"))
    return np.abs(v0 + a0 * dt + j * dt * dt / 2).max(axis=1), np.abs(a0 + j * dt).max(axis=1)


def _sup(cmds: list) -> tuple[float, float]:
    v, a = _sup_each(cmds)
    return float(v.max()), float(a.max())


def _record_planned(ax) -> list:
    """The planned pieces, before the compensation transform changes them."""
    planned: list = []

    def rec(_ax, cmd):
        planned.append(cmd)
        return cmd

    ax.command_transforms.insert(0, rec)
    return planned


@settings(max_examples=8, deadline=None)
@given(st.lists(st.integers(-40000, 40000).filter(lambda d: abs(d) > 50), min_size=2,
                max_size=4), st.integers(20, 3000))
def test_output_never_exceeds_axis_limits(moves, backlash):
    """Planned moves at up to 80 % of V and A; the compensation uses the rest and never
    more: each cycle's output stays within the limits (or, where the planned piece alone
    already exceeds them - Hermite pieces of very short moves - adds nothing to it)."""
    V, A = 100000.0, 4e6
    ctl, ax, comp = _with_backlash(backlash, pitch=SCREW_ERR, max_accel=A, max_vel=V)
    comp.set_pitch_table(10000, 1, _table_from_screw())
    cmds = _record(ctl)
    planned = _record_planned(ax)
    _move_to(ctl, 50000, vmax=0.8 * V)
    for d in moves:
        ax.move_relative(d, max_vel=0.8 * V, tacc=0.8 * V / (0.8 * A))
        ctl.advance(0.01)  # a reversal mid-move leaves little budget
        if ax.motion is not None:
            ax.stop(0.02)
        assert ctl.wait_motion_done(timeout=10.0)
    _move_to(ctl, 40000, vmax=0.8 * V)  # stops end between pulses; end on a whole one
    assert comp.settled
    assert len(cmds) == len(planned)
    vo, ao = _sup_each(cmds)
    vp, ap = _sup_each(planned)
    assert np.all(vo <= np.maximum(V, vp) * (1 + 1e-9))
    assert np.all(ao <= np.maximum(A, ap) * (1 + 1e-9))
    assert abs(_load_error(ctl)) <= 1


def test_compensation_uses_the_budget_left_by_a_move():
    V, A = 100000.0, 4e6
    ctl, ax, comp = _with_backlash(2000, max_accel=A, max_vel=V)
    _move_to(ctl, 40000, vmax=0.5 * V)
    cmds = _record(ctl)
    ax.move_relative(-30000, max_vel=0.5 * V, tacc=0.05)
    assert ctl.wait_motion_done(timeout=10.0)
    vmax, amax = _sup(cmds)
    assert 0.5 * V * 1.01 < vmax <= V * (1 + 1e-9)   # the offset ran during the move
    assert amax <= A * (1 + 1e-9)


# ---------------------------------------------------------------------- vibration suppression
def test_vibration_suppression_reverse_then_forward_pulse():
    ctl = _machine()
    ax = ctl.axis("x")
    comp = Compensation(ax, max_accel=5e6)
    comp.suppress_vibration(0.005, 0.004)
    ax.move_relative(3000, max_vel=30000, tacc=0.02)
    t_end = ax.motion.t_end
    trace = []
    while ax.motion_done != 0:
        ctl.step()
        trace.append((ctl.time, ctl.hardware.read_axis(0).pulses_out))
    outs = [p for t, p in trace if t > t_end]
    assert min(outs) == 2999 and outs[-1] == 3000
    t_rev = next(t for t, p in trace if t > t_end and p == 2999)
    t_fwd = next(t for t, p in trace if t > t_rev and p == 3000)
    assert t_rev >= t_end + 0.005 - 1e-9
    assert t_fwd - t_rev >= 0.004 - 1e-9
    assert ax.counters.command == 3000


# ---------------------------------------------------------------------- safety and refusals
def test_offset_frozen_in_error_stop():
    ctl, ax, comp = _with_backlash(300, comp_accel=1e5)
    _move_to(ctl, 5000)
    ax.move_relative(-100, max_vel=5000, tacc=0.01)
    ctl.advance(0.05)
    ctl.emergency_stop()
    o = comp.offset
    pos = ctl.hardware.command_position(0)
    ctl.advance(0.1)
    assert comp.offset == o and ctl.hardware.command_position(0) == pos


def test_remove_only_at_zero_offset():
    ctl, ax, comp = _with_backlash(40)
    _move_to(ctl, 5000)
    _move_to(ctl, 1000)
    with pytest.raises(MotionError, match="ramp to 0"):
        comp.remove()
    comp.backlash_comp(0)
    ctl.advance(0.1)
    comp.remove()
    assert ax.command_transforms == [] and ax.done_gates == []
    with pytest.raises(MotionError, match="already"):
        Compensation(ax, max_accel=1e6), Compensation(ax, max_accel=1e6)


@pytest.mark.parametrize("args, kwargs, match", [
    ((10000, 0, (0,)), {}, "2..256"),
    ((10000, 0, tuple([0] * 257)), {}, "2..256"),
    ((10000, 0, (0, 1, 2)), {"backward": (0, 1)}, "as many points"),
    ((10000, 3, (0, 1, 2)), {}, "home_index"),
    ((10000, -1, (0, 1, 2)), {}, "home_index"),
    ((10000, 0, (5, 1, 2)), {}, "home point"),
    ((0, 0, (0, 1, 2)), {}, "interval"),
    ((10000, 0, (0, 1.5, 2)), {}, "whole number"),
    ((10000, 0, (0, float("nan"), 2)), {}, "finite"),
    ((10, 0, (0, 20, 2)), {}, "monotonic"),
    ((10000, 0, "012"), {}, "sequence"),
    ((10000, 0, (0, 1, 2)), {}, "cover"),                 # 0..20000 vs MEL..PEL
    ((10000, 4, SEED_TABLE), {"stroke": (-50000, 0)}, "cover"),
    ((10000, 4, SEED_TABLE), {"stroke": (5, 1)}, "lo < hi"),
])
def test_bad_tables_refused_state_unchanged(args, kwargs, match):
    ctl = _machine()
    ax = ctl.axis("x")
    comp = Compensation(ax, max_accel=5e6)
    good = comp.set_pitch_table(10000, 4, SEED_TABLE, stroke=(-40000, 30000))
    _move_to(ctl, 15000)
    before = (comp._table, comp.offset, ax.snapshot())
    with pytest.raises(MotionError, match=match):
        comp.set_pitch_table(*args, **kwargs)
    ctl.advance(0.05)
    assert (comp._table, comp.offset, ax.snapshot()) == before and comp._table is good


def test_bad_settings_refused():
    ctl = _machine()
    ax = ctl.axis("x")
    for kw in ({"max_accel": 0.0}, {"max_accel": float("nan")},
               {"max_accel": 1e6, "max_vel": 1e9}, {"max_accel": 1e6, "comp_accel": 2e6},
               {"max_accel": 1e6, "comp_vel": -1.0}):
        with pytest.raises(MotionError):
            Compensation(ax, **kw)
    assert ax.command_transforms == []
    comp = Compensation(ax, max_accel=1e6)
    comp.backlash_comp(10)
    for a in ((-1,), (40000,), (1.5,), (10, 2), (None,)):
        with pytest.raises(MotionError):
            comp.backlash_comp(*a)
    for a in ((-0.1, 0.0), (float("inf"), 0.0), (0.0, 2.0)):
        with pytest.raises(MotionError):
            comp.suppress_vibration(*a)
    assert comp._backlash == 10 and comp._vib is None


def test_no_switches_needs_a_stroke():
    ctl = _machine()
    comp = Compensation(ctl.axis("u"), max_accel=1e6)
    with pytest.raises(MotionError, match="stroke"):
        comp.set_pitch_table(1000, 0, (0, 1, 2))
    comp.set_pitch_table(1000, 0, (0, 1, 2), stroke=(0, 2000))
