"""Jobs jump too: a running group line/arc, a homing sequence, a G-code job and an armed
compare table cross the cycles between the instants they act (control/groups/groupdue.py,
Homing._due, ProgramRunner._due, control/trigger/compare_due.py), with results identical to the
cycle-by-cycle run. Each scenario runs both ways and must jump over most of its cycles."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group
from openmotion.control.home.homing import HomeConfig, home_search
from openmotion.control.trigger.compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    Pulse,
    Toggle,
    WindowJob,
)
from openmotion.program.runner import ProgramRunner
from test_jump_equivalence import observe


def both(run: Callable[[Controller], object], cfg=None) -> tuple[object, int, int]:
    """run(ctl) cycle by cycle and jumping; returns its observation (equal both ways),
    the cycles run and the cycles the jumping run crossed without running them."""
    out = []
    steps = 0
    for jumping in (False, True):
        ctl = Controller(cfg)
        ctl.virtual_jumps = jumping
        ctl.enable_all()
        ctl.hardware.record_pulses(True)
        if jumping:  # count the cycles run one by one (steps and jump landings)
            real = ctl._finish_cycle

            def counting(n, edges, real=real) -> None:  # noqa: ANN001
                nonlocal steps
                steps += 1
                real(n, edges)

            ctl._finish_cycle = counting  # type: ignore[method-assign]
        res = run(ctl)
        out.append((res, observe(ctl)))
        cycles = ctl.cycles
    assert out[0] == out[1]
    print(f"cycles {cycles}, crossed {cycles - steps}")
    return out[0][0], cycles, cycles - steps


def test_a_group_line_and_arc_jump():
    def run(ctl: Controller) -> object:
        g = Group(ctl, [0, 1], feed=30_000.0, acc_time=0.05)
        g.line([20_000.0, 5_000.0])
        g.arc([20_000.0, 15_000.0], [20_000.0, 25_000.0])
        g.delay(0.0123)
        g.line([0.0, 0.0])
        ctl.run_until(lambda: g.state.value == "idle" and g.queue_length == 0, 10.0,
                      event_driven=True)
        return g.state, g.error_code, ctl.time
    res, cycles, crossed = both(run)
    assert res[1] == 0
    assert crossed > 0.8 * cycles


def test_a_streamed_blended_chain_jumps():
    def run(ctl: Controller) -> object:
        g = Group(ctl, [0, 1], feed=40_000.0, acc_time=0.02)
        g.enable_blend(50.0)
        rng = np.random.default_rng(3)
        for _ in range(40):
            g.line(rng.uniform(0.0, 8000.0, 2).tolist())
        ctl.run_until(lambda: g.state.value == "idle" and g.queue_length == 0, 30.0,
                      event_driven=True)
        return g.state, g.error_code, ctl.time
    res, cycles, crossed = both(run)
    assert res[1] == 0
    assert crossed > 0.3 * cycles


def test_homing_jumps():
    def run(ctl: Controller) -> object:
        ctl.axes[0].move_relative(20_000, max_vel=40_000, tacc=0.05)
        ctl.wait_motion_done()
        h = home_search(ctl, 0, HomeConfig(mode=0, str_vel=2000.0, max_vel=20000.0,
                                           tacc=0.05, settle_s=0.0105))
        ctl.run_until(lambda: not h.running, 20.0, event_driven=True)
        return h.status.state, h.status.history, h.status.mark, ctl.axes[0].position
    res, cycles, crossed = both(run)
    assert res[0] == "done"
    assert crossed > 0.8 * cycles


def test_a_gcode_job_jumps():
    prog = ("G21 G90 G17\nG0 X5 Y5\nG1 X20 Y5 F1200\nG2 X30 Y15 I0 J10\nG4 P0.25\n"
            "G1 X5 Y20 F2400\nG3 X5 Y5 I0 J-7.5\nG0 X0 Y0\nM2\n")

    def run(ctl: Controller) -> object:
        r = ProgramRunner(ctl, prog, axes={"X": 0, "Y": 1})
        r.start()
        ctl.run_until(lambda: not r.running, 120.0, event_driven=True)
        t, idx, p = r.trace()
        return (r.state, r.error, list(r.events),
                t.tolist(), idx.tolist(), p.tolist())
    res, cycles, crossed = both(run)
    assert res[0].value == "done" and len(res[3]) > 1000
    assert crossed > 0.5 * cycles


def test_compare_tables_jump():
    def run(ctl: Controller) -> object:
        eng = CompareEngine(ctl)
        lv = LevelJob(AxisSource(0), np.arange(1000.0, 40_000.0, 3000.0), Pulse(0, 0.002))
        win = WindowJob([0, 1], [[10_000.0, 5_000.0], [30_000.0, 15_000.0]], 20.0,
                        Toggle(1))
        eng.add(lv)
        eng.add(win)
        ctl.axes[0].move_relative(40_000, max_vel=20_000, tacc=0.05)
        ctl.axes[1].move_relative(20_000, max_vel=10_000, tacc=0.05)
        ctl.wait_motion_done(timeout=10.0)
        return ({k: v.tolist() for k, v in eng.log.arrays().items()},
                [(e.time, e.kind, e.axis) for e in ctl.events.events()],
                eng.output(0).edges, eng.output(1).edges, lv.hits, win.hits)
    res, cycles, crossed = both(run)
    assert res[4] == 13 and res[5] == 2
    assert crossed > 0.5 * cycles


def test_a_pso_table_with_timer_pulses_stays_identical():
    from helpers import free_axes, start_line
    from openmotion.control.trigger.pso import ZPso

    seed_2d = (0, 0, 50, 50, 100, 100, 50, 150, 0, 200, -50, 150, -100, 100, -50, 50)
    cfg = free_axes(2).config

    def run(ctl: Controller) -> object:
        eng = CompareEngine(ctl)
        z = ZPso(eng)
        z.base(0, 1)
        for a in (0, 1):
            z.set_units(a, 100.0)
            z.source(a, "dpos")  # (MPOS jobs run every cycle: their error model needs it)
        z.table(0, *seed_2d)
        z.hw_timer(2, 2000, 500, 3, 1, 0)        # 3 pulses of 0.5 ms every 2 ms per point
        jid = z.hw_pswitch2(25, 0, 1, 10, 8, 0)  # 2-D points, maxerr 10 pulses
        pts = np.array(seed_2d, float).reshape(8, 2) * 100.0
        for p in [*pts[1:], pts[0]]:
            start = [ctl.axes[i].position for i in (0, 1)]
            # start_line's default line time-scaled by 4 (v, a, j x4, x16, x64: the same
            # path in a quarter of the cycles; a point's 6 ms train ends within its leg)
            if start_line(ctl, start, p, v=80_000.0, a=3.2e6, j=1.28e9):
                assert ctl.wait_motion_done(timeout=30)
            ctl.advance(0.1)  # at rest between the lines
        return ({k: v.tolist() for k, v in eng.log.for_job(jid).items()},
                eng.output(0).edges, z.vector_moved(0) if hasattr(z, "vector_moved") else 0)
    res, cycles, crossed = both(run, cfg)
    assert len(res[0]["index"]) == 8 and len(res[1]) > 8
    # ZPso keeps VECTOR_MOVED of its BASE axes, which the engine accumulates cycle by cycle
    # while they move (every cycle runs then, compare_due.py); the rests between the lines
    # jump, and the results stay identical
    assert crossed > 0.5 * 8 * 100


def test_path_length_jobs_and_finished_mpos_jobs_jump_at_rest():
    from helpers import free_axes, start_line
    from openmotion.control.trigger.compare import VectorSource, every_distance
    from openmotion.control.trigger.pso import ZPso

    cfg = free_axes(2).config

    def run(ctl: Controller) -> object:
        eng = CompareEngine(ctl)
        z = ZPso(eng)
        z.base(0, 1)
        z.table(0, 100.0, 300.0, 900.0, 5000.0)
        z.hw_timer(2, 3000, 1000, 2, 0, 1)
        t3 = z.hw_pswitch2(3, 0, 1, 0, 3)       # VECTOR_MOVED table: toggles do0
        t7 = z.hw_pswitch2(7, 1, 0, 0, 3)       # each point starts the timer on do1
        dist = eng.add(every_distance(VectorSource((0, 1)), 250.0, Pulse(2, 1e-4)))
        mpos = eng.add(LevelJob(AxisSource(0, "mpos"), [400.0, 800.0], Toggle(3)))
        for p in ([1200.0, 0.0], [1200.0, 900.0], [0.0, 0.0]):
            start = [ctl.axes[i].position for i in (0, 1)]
            assert start_line(ctl, start, p, v=30_000.0)
            assert ctl.wait_motion_done(timeout=30)
            ctl.advance(0.3)  # at rest: VECTOR_MOVED stands still, the MPOS job is done
        return ({k: v.tolist() for k, v in eng.log.arrays().items()},
                [eng.output(o).edges for o in range(4)], z.vector_moved(),
                [j in eng.jobs for j in (t3, t7, dist, mpos)], eng.jobs[dist].index)
    res, cycles, crossed = both(run, cfg)
    assert res[3] == [True, True, True, False] and res[4] > 10  # (5000 is out of reach)
    assert len(res[0]["time"]) > 20
    assert crossed > 0.5 * 2 * 300  # the last two rests at least
