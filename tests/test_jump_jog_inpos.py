"""A continuous jog and in-position control jump too (control/manual/jog.py `_due`,
control/guard/inposition.py `InPositionControl._due`): each scenario runs cycle by cycle
and jumping with identical results, and the jumping run must cross most of its cycles."""

from __future__ import annotations

import dataclasses

import pytest

from openmotion.config import DriveConfig, default_machine
from openmotion.control import Controller
from openmotion.control.guard.inposition import InPositionControl
from openmotion.control.manual.jog import jog_conti, stop_jog
from test_jump_equivalence import observe


def both(run, cfg=None, *, safety: bool = True) -> tuple[object, int, int]:  # noqa: ANN001
    """run(ctl) cycle by cycle and jumping (as test_jump_jobs.both, with `safety`): the
    observation must be equal; returns the result, the cycles run and those crossed."""
    out = []
    steps = [0]
    for jumping in (False, True):
        ctl = Controller(cfg, safety=safety)
        ctl.virtual_jumps = jumping
        ctl.enable_all()
        ctl.hardware.record_pulses(True)
        if jumping:  # count the cycles run one by one (steps and jump landings)
            real = ctl._finish_cycle

            def counting(n, edges, real=real) -> None:  # noqa: ANN001
                steps[0] += 1
                real(n, edges)

            ctl._finish_cycle = counting  # type: ignore[method-assign]
        res = run(ctl)
        out.append((res, observe(ctl)))
    assert out[0] == out[1]
    return out[0][0], ctl.cycles, ctl.cycles - steps[0]


@pytest.mark.parametrize("safety", [True, False])
def test_a_continuous_jog_into_its_limit_jumps(safety):
    """Without Safety only the jog's own edge declaration makes the PEL edge land."""
    def run(ctl: Controller) -> object:
        ctl.hardware.scenario.place_switch(0, "pel", 20_000.0, 1000.0)
        jog_conti(ctl, "x", 0, 4)  # 20 000 pps, stops at the PEL ahead
        jog_conti(ctl, "y", 1, 3)
        ctl.advance(0.3)
        stop_jog(ctl, "y")
        ctl.run_until(lambda: not any(a.is_moving for a in ctl.axes), 5.0,
                      event_driven=True)
        return tuple((a.state, a.position) for a in ctl.axes), ctl.time

    res, cycles, crossed = both(run, safety=safety)
    (_, xp), (_, yp) = res[0][0], res[0][1]
    assert 19_990 <= xp < 21_000 and yp < 0  # (Safety stops at the PEL edge itself)
    assert crossed > 0.8 * cycles


def test_a_jog_started_on_its_active_limit_stops_in_the_first_cycle():
    def run(ctl: Controller) -> object:
        ctl.hardware.scenario.place_switch(0, "pel", -100.0, 1000.0)  # active already
        ctl.advance(0.01)
        try:
            jog_conti(ctl, "x", 0, 4)
        except Exception as exc:  # noqa: BLE001 - a refusal is a result too
            return type(exc).__name__
        ctl.run_until(lambda: not ctl.axis("x").is_moving, 2.0, event_driven=True)
        return ctl.axis("x").state, ctl.axis("x").position, ctl.time
    both(run)


def _servo(cfg=None):  # noqa: ANN001, ANN202
    cfg = default_machine()
    servo = DriveConfig(type="servo", bandwidth_hz=5.0, inp_band=1.0)
    return dataclasses.replace(cfg, axes=tuple(
        dataclasses.replace(a, drive=servo) if a.name == "x" else a for a in cfg.axes))


def test_queued_moves_under_in_position_control_jump():
    def run(ctl: Controller) -> object:
        ip = InPositionControl(ctl)
        ip.set_tolerance("x", 3)
        ip.set_check_time("x", 2.0)
        ip.enable(["x"])
        x, z = ctl.axis("x"), ctl.axis("z")
        log: list = []
        ip.queue(lambda: z.move_relative(30_000, max_vel=40_000, tacc=0.05))
        ip.queue(lambda: log.append((ctl.time, z.position)))
        ip.queue(lambda: x.move_relative(10_000, max_vel=50_000, tacc=0.05))
        ip.queue(lambda: log.append((ctl.time, x.counters.error)))
        ip.queue(lambda: z.move_relative(-30_000, max_vel=40_000, tacc=0.05))
        ctl.run_until(lambda: ip.pending == 0 and all(a.motion_done == 0 for a in ctl.axes),
                      10.0, event_driven=True)
        return tuple(log), ip.error_code, ctl.time
    res, cycles, crossed = both(run, _servo())
    log, code, _ = res
    assert code == 0 and len(log) == 2
    assert crossed > 0.3 * cycles  # the servo's settling runs every cycle (waiting INP)


def test_an_in_position_timeout_lands_on_its_cycle():
    def run(ctl: Controller) -> object:
        ip = InPositionControl(ctl)
        ip.set_tolerance("x", 0)
        ip.set_check_time("x", 0.0123)
        ip.enable(["x"])
        x = ctl.axis("x")
        ip.queue(lambda: x.move_relative(10_000, max_vel=50_000, tacc=0.05))
        ip.queue(lambda: ctl.axis("z").move_relative(100, max_vel=10_000, tacc=0.01))
        ctl.advance(1.0)
        return ip.error_code, ip.error_axis, ip.pending, x.state, x.fault, ctl.time
    res, cycles, crossed = both(run, _servo())
    assert res[0] != 0 and res[1] == 0 and res[2] == 0
    assert crossed > 0
