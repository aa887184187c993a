"""ZMotion facade: commands, axis parameters, motion, I/O, and refusals that change nothing."""

import contextlib
import math

import numpy as np
import pytest

from openmotion.compat.zmotion import OFF, ON, ZController
from openmotion.compat.zmotion_params import (
    ZERR_PARAMETER,
    ZERR_STATE,
    ZERR_UNSUPPORTED,
    ZMotionError,
)
from openmotion.errors import MotionError

# Ten times the article's SPEED and ACCEL (100 units/s, 1000 units/s^2): the same ramps
# (SPEED/ACCEL = 0.1 s) and relations in a tenth of the machine time (and of the cycles).
SPEED = 1000.0
ACCEL = 10_000.0


def ctl(speed: float = SPEED, accel: float = ACCEL, **kw) -> ZController:
    c = ZController(**kw)
    c.BASE(0, 1, 2)
    c.UNITS = 100, 100, 100
    c.SPEED = speed, speed, speed
    c.ACCEL = accel, accel, accel
    c.DECEL = accel, accel, accel
    return c


def test_axis_parameters_index_call_and_base_assignment():
    c = ctl()
    assert c.UNITS[1] == 100 and c.UNITS(2) == 100 and list(c.SPEED) == [SPEED] * 3
    c.UNITS[1] = 250
    assert c.UNITS[1] == 250
    c.BASE(1)
    c.SPEED = 10, 20            # BASE(1): axes 1 and 2 (the list extends)
    assert [c.SPEED[a] for a in range(3)] == [SPEED, 10, 20]
    c.MERGE = ON
    assert c.MERGE[1] == 1 and c.MERGE[0] == 0
    c.SRAMP[0] = 50
    assert repr(c.SRAMP) == "SRAMP(50.0, 0.0, 0.0)"
    assert c.base == (1,)


def test_table_call_index_and_slices():
    c = ctl(table_size=32)
    c.TABLE(0, 100, 150, 250)
    assert c.TABLE(1) == 150 and c.TABLE[2] == 250 and len(c.TABLE) == 32
    c.TABLE[4:8] = [1, 2, 3, 4]
    assert c.TABLE[3:8] == [0, 1, 2, 3, 4]
    c.TABLE[10] = -5
    assert c.TABLE(10) == -5


def test_move_runs_at_speed_and_dpos_mpos_follow():
    c = ctl()
    c.BASE(0, 1)
    c.MOVE(300, 400)                     # 500 units at SPEED, ramps of SPEED / ACCEL
    t = c.WAIT_IDLE(0)
    assert t == pytest.approx(500 / SPEED + SPEED / ACCEL, abs=2 * c.ctl.period)
    assert (c.DPOS[0], c.DPOS[1]) == (300, 400) and c.MPOS[1] == pytest.approx(400)
    c.MOVEABS(0, 100)
    c.WAIT_IDLE(0)
    assert (c.DPOS[0], c.DPOS[1]) == (0, 100)
    c.DPOS = 5, 6
    c.MPOS[0] = 7
    assert (c.DPOS[0], c.DPOS[1], c.MPOS[0]) == (5, 6, 7)


def test_single_axis_move_with_sramp():
    c = ctl()
    c.BASE(2)
    c.SRAMP[2] = 50
    t0 = c.ctl.time
    c.MOVE(200)
    t = c.WAIT_IDLE(2) - t0
    # ramp to SPEED at ACCEL smoothed over 50 ms: v/A + Ts = 0.15 s
    assert t == pytest.approx(200 / SPEED + SPEED / ACCEL + 0.05, abs=2 * c.ctl.period)
    assert c.DPOS[2] == 200 and c.ctl.axes[2].position == 20000  # ends on the pulse


def test_merge_blends_within_one_pulse_of_the_corner():
    c = ctl(speed=100.0, accel=1000.0)  # the article's: the 1 ms scope sample bound below
    c.BASE(0, 1)
    c.MERGE = ON, ON
    c.TRIGGER()
    t0 = c.ctl.time
    c.MOVEABS(100, 0)
    c.MOVEABS(100, 100)
    t_merge = c.WAIT_IDLE(0) - t0
    pos = c.scope.arrays()["dpos"][:, :2]
    d = np.min(np.hypot(pos[:, 0] - 100, pos[:, 1]))
    # within 1 pulse (0.01 units) of the corner, plus what one 1 ms sample can miss at the
    # corner's speed
    assert d <= 0.015
    c.MERGE = OFF, OFF
    t1 = c.ctl.time
    c.MOVEABS(0, 100)
    c.MOVEABS(0, 0)
    assert c.WAIT_IDLE(0) - t1 > t_merge  # exact stop at the corner takes longer


def test_rapidstop_2_stops_on_the_path_3_at_once():
    c = ctl()
    c.BASE(0, 1)
    c.MOVE(300, 400)
    c.MOVE(100, 0)
    c.run(0.2)                            # 150 units along the first line
    c.RAPIDSTOP(2)
    c.WAIT_IDLE(0)
    x, y = c.DPOS[0], c.DPOS[1]
    assert 0 < x < 300 and y == pytest.approx(x * 4 / 3, abs=0.02)  # on the line
    assert c.IDLE(0) and c.IDLE(1)
    c.MOVE(100, 100)
    c.run(0.05)
    assert c.ctl.axes[0].is_moving
    c.RAPIDSTOP(3)
    assert c.IDLE(0) and not c.ctl.axes[0].is_moving


def test_op_drives_pso_and_plain_outputs():
    c = ctl()
    c.OP(0, ON)
    c.OP(9, 1)
    c.run(0.01)
    assert c.OP(0) is True and c.OP(9) is True
    assert c.ctl.hardware.read_output(None, "do0")
    c.OP(0, OFF)
    c.run(0.01)
    assert c.OP(0) is False and not c.ctl.hardware.read_output(None, "do0")


def test_atype_4_compares_mpos():
    c = ctl()
    c.BASE(0)
    c.ATYPE[0] = 4
    assert c.pso.kind(0) == "mpos" and c.ATYPE[0] == 4
    c.TABLE(0, 10, 20)
    job = c.HW_PSWITCH2(1, 0, 1, 0, 1, 1)
    c.MOVE(30)
    c.WAIT_IDLE(0)
    log = c.engine.log.for_job(job)
    assert log["state"].tolist() == [1, 0]
    np.testing.assert_allclose(log["positions"][:, 0] / 100, [10, 20], atol=0.011)


def test_vector_moved_and_buffer_query():
    c = ctl()
    c.BASE(0, 1)
    c.MOVE(30, 40)
    c.WAIT_IDLE(0)
    assert c.VECTOR_MOVED[0] == pytest.approx(50, abs=1e-6)
    c.VECTOR_MOVED[0] = 0
    assert c.VECTOR_MOVED[0] == 0
    free = c.HW_PSWITCH2_FREE()
    c.TABLE(0, 10, 20, 30)
    c.HW_PSWITCH2(3, 0, 1, 0, 2)
    assert c.HW_PSWITCH2_FREE() == free - 3
    c.HW_PSWITCH2(2)
    assert c.HW_PSWITCH2_FREE() == free


def test_scope_records_positions_and_exact_output_edges():
    c = ctl()
    c.BASE(0)
    c.TABLE(0, 10)
    c.HW_TIMER(2, 1000, 50, 3, OFF, 0)        # 3 pulses of 50 us, 1 ms apart
    c.HW_PSWITCH2(7, 0, 1, 0, 0)
    sc = c.TRIGGER()
    c.MOVE(20)
    c.WAIT_IDLE(0)
    a = sc.arrays()
    assert a["time"][0] == 0.0 and a["dpos"].shape[1] == 3
    assert a["dpos"][-1, 0] == pytest.approx(20)
    np.testing.assert_allclose(sc.pulse_widths(0), [50e-6] * 3, atol=1e-12)
    t, lv = sc.level_trace(0)
    assert t[0] == 0 and lv.max() == 1 and lv[-1] == 0


def _state(c: ZController) -> tuple:
    return (tuple(repr(c._params[k]) for k in sorted(c._params)), tuple(c.TABLE[0:20]),
            tuple(c.engine.jobs), c.pso.timer.mode, c.pso.timer.cycle, c.OP(0), c.base,
            tuple((k, g.queue_length) for k, g in c._groups.items()), c.ctl.time)


BAD = [
    ("UNITS", "UNITS(1)", lambda c: setattr(c, "UNITS", (100, -1))),
    ("UNITS", "values", lambda c: setattr(c, "UNITS", (1, 2, 3, 4))),
    ("SPEED", "SPEED(0)", lambda c: c.SPEED.__setitem__(0, 0)),
    ("SRAMP", "SRAMP(0)", lambda c: c.SRAMP.__setitem__(0, 300)),
    ("MERGE", "MERGE(0)", lambda c: c.MERGE.__setitem__(0, 2)),
    ("ATYPE", "ATYPE(0)", lambda c: c.ATYPE.__setitem__(0, 65)),
    ("DPOS", "DPOS(0)", lambda c: c.DPOS.__setitem__(0, math.nan)),
    ("UNITS", "axis", lambda c: c.UNITS.__getitem__(7)),
    ("BASE", "axes", lambda c: c.BASE(0, 0)),
    ("TABLE", "values[1]", lambda c: c.TABLE(0, 1, math.inf)),
    ("TABLE", "values", lambda c: c.TABLE.__setitem__(slice(0, 3), [1, 2])),
    ("TABLE", "index", lambda c: c.TABLE(10**9)),
    ("OP", "number", lambda c: c.OP(99, 1)),
    ("OP", "state", lambda c: c.OP(0, 5)),
    ("HW_PSWITCH2", "maxerr", lambda c: c.HW_PSWITCH2(25, 0, 1, 0, 8, 0)),
    ("HW_PSWITCH2", "mode", lambda c: c.HW_PSWITCH2(8, 0, 1, 0, 2)),
    ("HW_PSWITCH2", "opnum", lambda c: c.HW_PSWITCH2(3, 9, 1, 0, 2)),
    ("HW_TIMER", "on_us", lambda c: c.HW_TIMER(2, 1000, 2000, 1, OFF, 0)),
    ("HW_TIMER", "opstate", lambda c: c.HW_TIMER(2, 1000, 200, 1, 3, 0)),
    ("MOVE", "value[1]", lambda c: c.MOVE(1, math.nan)),
    ("MOVE", "distance", lambda c: c.MOVE()),
    ("MOVEABS", "axes", lambda c: c.MOVEABS(1, 2, 3, 4)),
    ("RAPIDSTOP", "mode", lambda c: c.RAPIDSTOP(7)),
    ("WAIT IDLE", "axis", lambda c: c.WAIT_IDLE(5)),
]


@pytest.mark.parametrize("command,parameter,call", BAD, ids=[b[0] + ":" + b[1] for b in BAD])
def test_bad_commands_raise_naming_command_and_parameter_and_change_nothing(command, parameter,
                                                                             call):
    c = ctl()
    c.TABLE(0, 1, 2, 3)
    c.BASE(0)
    c.HW_PSWITCH2(1, 0, 1, 0, 2, 1)
    c.BASE(0, 1)
    before = _state(c)
    with pytest.raises(ZMotionError) as e:
        call(c)
    assert isinstance(e.value, MotionError)
    assert e.value.command == command and e.value.parameter == parameter
    assert str(e.value).startswith(command) and e.value.code > 0
    assert _state(c) == before


def test_unsupported_and_state_refusals_have_their_codes():
    c = ctl()
    with pytest.raises(ZMotionError) as e:
        c.RAPIDSTOP(1)
    assert e.value.code == ZERR_UNSUPPORTED
    with pytest.raises(ZMotionError) as e:
        c.ATYPE[0] = 0
    assert e.value.code == ZERR_UNSUPPORTED
    c.BASE(0, 1)
    c.MOVE(100, 100)
    c.run(0.1)
    before = _state(c)
    for call in (lambda: c.DPOS.__setitem__(0, 0), lambda: c.UNITS.__setitem__(1, 5)):
        with pytest.raises(ZMotionError) as e:
            call()
        assert e.value.code == ZERR_STATE
    c.BASE(1, 2)
    with pytest.raises(ZMotionError) as e:
        c.MOVE(5, 5)                      # axis 1 is in the running (0, 1) interpolation
    assert e.value.code == ZERR_STATE and e.value.command == "MOVE"
    c.BASE(0, 1)
    assert _state(c) == before
    c.WAIT_IDLE(0)
    c.BASE(1, 2)
    c.MOVE(5, 5)                          # idle now: the new interpolation takes the axes
    c.WAIT_IDLE(1)
    assert (c.DPOS[1], c.DPOS[2]) == (105, 5)
    assert e.value.code != ZERR_PARAMETER


def test_decel_different_from_accel():
    c = ctl()
    c.BASE(0, 1)
    c.DECEL = ACCEL / 2, ACCEL / 2
    c.MOVE(10, 10)
    g = c._group((0, 1), "MOVE")
    assert g.dec_time == pytest.approx(2 * g.acc_time)   # DECEL half of ACCEL: twice the time
    c.WAIT_IDLE(0)
    assert c.DPOS[0] == 10
    c.BASE(2)                             # a single axis has its own deceleration
    c.DECEL[2] = ACCEL / 2
    c.MOVE(10)
    c.WAIT_IDLE(2)
    assert c.DPOS[2] == 10


ODD = [None, "x", [1], (), object(), math.nan, -1, 1e300, True, np.array([1.0, 2.0])]


def test_odd_values_only_ever_raise_zmotion_errors():
    c = ctl()
    before = _state(c)
    calls = []
    for name in ("ATYPE", "UNITS", "SPEED", "ACCEL", "DECEL", "MERGE", "SRAMP", "DPOS", "MPOS",
                 "VECTOR_MOVED"):
        calls += [lambda v, n=name: getattr(c, n).__setitem__(0, v),
                  lambda v, n=name: getattr(c, n).__getitem__(v)]
    calls += [lambda v: c.BASE(v), lambda v: c.TABLE(0, v), lambda v: c.TABLE(v),
              lambda v: c.OP(0, v), lambda v: c.OP(v), lambda v: c.MOVE(v, 1),
              lambda v: c.HW_PSWITCH2(v), lambda v: c.HW_PSWITCH2(25, 0, 1, v, 8, 0),
              lambda v: c.HW_TIMER(2, v, 100, 1, 0, 0), lambda v: c.RAPIDSTOP(v),
              lambda v: c.WAIT_IDLE(v), lambda v: c.IDLE(v)]
    for call in calls:
        for v in ODD:
            with contextlib.suppress(ZMotionError):  # anything else fails the test
                call(v)
            c.RAPIDSTOP(3)
            c.WAIT_IDLE(0)
            for a in range(3):
                c.DPOS[a] = 0
                c.MPOS[a] = 0
            c.VECTOR_MOVED[0] = 0
            c.UNITS = 100, 100, 100
            c.SPEED = 100, 100, 100
            c.ATYPE = 1, 1, 1
            c.MERGE = 0, 0, 0
            c.SRAMP = 0, 0, 0
            c.BASE(0, 1, 2)
            c.OP(0, OFF)
            c.HW_PSWITCH2(2)
            c.HW_TIMER(0, 10000, 6000, 1, OFF, 0)
            c.TABLE[0:20] = [0.0] * 20
    assert _state(c)[1:3] == before[1:3]
