"""AIM104-MOTION-1 board emulation, MOTION_* library and the manual's example programs."""

import importlib
import sys
from pathlib import Path

import pytest

from openmotion.compat import hctl1100_regs as R
from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary
from openmotion.errors import MotionError

BASE = 0x180
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def rig(**kw):
    bus = PC104Bus()
    board = bus.add(AIM104Board(base=BASE, **kw))
    lib = MotionLibrary(bus)
    return bus, board, lib, lib.MOTION_boardinit(BASE)


def wait(bus):
    while bus.inb(BASE + 2) & 1:
        pass


# ---------------------------------------------------------------- I/O protocol
def test_write_and_read_by_the_manual_protocol():
    bus, board, _, _ = rig()
    wait(bus)
    bus.outb(BASE, R.R_FILTER_K)
    assert bus.inb(BASE + 2) & 1  # busy right after the address write
    wait(bus)
    bus.outb(BASE + 1, 0x22)
    wait(bus)
    bus.outb(BASE, R.R_FILTER_K)
    bus.inb(BASE)  # dummy read
    wait(bus)
    assert bus.inb(BASE + 1) == 0x22 and board.chip.read(R.R_FILTER_K) == 0x22


def test_protocol_violations_are_named():
    bus, board, _, _ = rig()
    with pytest.raises(MotionError, match="address"):
        bus.outb(BASE + 1, 1)  # no address yet
    bus.outb(BASE, R.R_FILTER_K)
    with pytest.raises(MotionError, match="ready flag"):
        bus.outb(BASE + 1, 1)
    wait(bus)
    with pytest.raises(MotionError, match="dummy read"):
        bus.inb(BASE + 1)
    board.delay_us(2.0)  # the other way to wait
    bus.outb(BASE + 1, 0x33)
    assert board.chip.read(R.R_FILTER_K) == 0x33
    with pytest.raises(MotionError, match="no AIM104"):
        bus.inb(0x300)
    with pytest.raises(MotionError, match="0..255"):
        bus.outb(BASE + 3, 256)


def test_lenient_board_reads_without_dummy():
    bus, board, _, _ = rig(strict=False)
    bus.outb(BASE, R.R_FILTER_A)
    bus.inb(BASE + 2)
    assert bus.inb(BASE + 1) == 0xE5


def test_configuration_register_and_sync_bit():
    bus, board, lib, h = rig()
    lib.MOTION_set_board_config_reg(h, 0xFF)
    assert lib.MOTION_read_board_config_reg(h) == 0x03  # SYNC bit reads back 0
    board.chip.advance(3e-4)
    assert lib.MOTION_read_sample_timer(h) < 0x40
    lib.MOTION_pulse_SYNC(h)
    assert lib.MOTION_read_sample_timer(h) == 0x40


def test_bad_board_arguments():
    with pytest.raises(MotionError, match="base"):
        AIM104Board(base=0x181)
    with pytest.raises(MotionError, match="irq"):
        AIM104Board(irq=6)
    bus = PC104Bus()
    bus.add(AIM104Board(base=BASE))
    with pytest.raises(MotionError, match="in use"):
        bus.add(AIM104Board(base=BASE))
    with pytest.raises(MotionError, match="handle"):
        MotionLibrary(bus).MOTION_read_flag_register(7)


# ---------------------------------------------------------------- status and interrupts
def test_status_flags_latch_until_cleared_and_interrupt():
    bus, board, lib, h = rig()
    seen = []
    board.on_interrupt.append(lambda ev: seen.append(ev.kind))
    assert lib.MOTION_read_board_status_reg(h) & 0x1E == 0x1E  # nothing triggered
    board.set_input("limit2", True)
    board.set_input("limit2", False)
    assert lib.MOTION_read_board_status_reg(h) & 0x04 == 0  # still set (0 = triggered)
    assert board.irq_asserted and seen == ["limit"]
    board.set_input("stop", True)
    lib.MOTION_clear_interrupts(h)
    st = lib.MOTION_read_board_status_reg(h)
    assert st & 0x04 and not st & 0x08  # limit2 cleared, stop re-latched (still active)
    board.set_input("stop", False)
    lib.MOTION_clear_interrupts(h)
    assert lib.MOTION_read_board_status_reg(h) & 0x1E == 0x1E and not board.irq_asserted
    assert lib.MOTION_read_controller_status_reg(h) & 0xC0 == 0xC0


def test_home_halts_only_with_link6():
    bus, board, lib, h = rig()
    lib.MOTION_enter_position_mode(h)
    board.set_input("home", True)
    assert board.chip.mode is R.Mode.POSITION and not lib.MOTION_read_board_status_reg(h) & 0x10
    bus, board, lib, h = rig(link6_home_halts=True)
    lib.MOTION_enter_position_mode(h)
    board.set_input("home", True)
    assert board.chip.mode is R.Mode.INIT_IDLE and [e.kind for e in board.events] == ["home"]
    lib.MOTION_enter_position_mode(h)  # the LIMIT pulse is over: control works again
    assert board.chip.mode is R.Mode.POSITION


def test_profile_flag_and_completion_interrupt():
    bus, board, lib, h = rig()
    lib.MOTION_enter_position_mode(h)
    lib.MOTION_set_acceleration(h, 0x0100)
    lib.MOTION_set_max_velocity(h, 50)
    lib.MOTION_set_final_position(h, -12345)
    lib.MOTION_execute_trapezoidal_move(h)
    assert lib.MOTION_read_board_status_reg(h) & 0x20
    assert lib.MOTION_wait_until_move_complete(h) == 0
    assert lib.MOTION_read_flag_register(h) & 1 == 0
    assert lib.MOTION_read_command_position(h) == -12345
    assert lib.MOTION_read_final_position(h) == -12345
    assert lib.MOTION_read_board_status_reg(h) & 0x20  # latched until cleared
    assert [e.kind for e in board.events] == ["profile_done"]
    lib.MOTION_clear_interrupts(h)
    assert not lib.MOTION_read_board_status_reg(h) & 0x20


def test_wait_until_move_complete_reports_limit_and_timeout():
    bus, board, lib, h = rig()
    lib.MOTION_enter_position_mode(h)
    lib.MOTION_set_acceleration(h, 0x0010)
    lib.MOTION_set_max_velocity(h, 5)
    lib.MOTION_set_final_position(h, 100000)
    lib.MOTION_execute_trapezoidal_move(h)
    assert lib.MOTION_wait_until_move_complete(h, timeout=0.05) == 2
    board.set_input("limit1", True)
    assert lib.MOTION_wait_until_move_complete(h) == 1


def test_library_validates_before_writing():
    bus, board, lib, h = rig()
    with pytest.raises(MotionError, match="velocity"):
        lib.MOTION_set_max_velocity(h, 128)
    with pytest.raises(MotionError, match="command_position"):
        lib.MOTION_set_command_position(h, 1 << 24)
    with pytest.raises(MotionError, match="filter_pole"):
        lib.MOTION_set_filter_parameters(h, 1, 300, 3)
    assert board.chip.read(R.R_FILTER_A) == 0xE5 and board.chip.read(R.R_MAX_VEL) == 0
    lib.MOTION_preset_actual_position(h, -77)
    assert lib.MOTION_read_actual_position(h) == -77


def test_sync_restarts_tied_boards_only():
    bus = PC104Bus()
    a = bus.add(AIM104Board(base=0x180), tie_sync=True)
    b = bus.add(AIM104Board(base=0x184, link5_internal_sync=False), tie_sync=True)
    c = bus.add(AIM104Board(base=0x188))
    b.chip.advance(1e-4)
    bus.advance(2e-4)
    lib = MotionLibrary(bus)
    lib.MOTION_pulse_SYNC(lib.MOTION_boardinit(0x180))
    assert a.chip.read(R.R_SAMPLE_TIMER) == b.chip.read(R.R_SAMPLE_TIMER) == 0x40
    assert c.chip.read(R.R_SAMPLE_TIMER) < 0x40
    before = a.chip.read(R.R_SAMPLE_TIMER)
    lib.MOTION_pulse_SYNC(lib.MOTION_boardinit(0x184))  # a slave does not drive the line
    assert a.chip.read(R.R_SAMPLE_TIMER) == before


# ---------------------------------------------------------------- the manual's examples
@pytest.fixture
def examples():
    sys.path.insert(0, str(EXAMPLES))
    try:
        yield lambda name: importlib.import_module(name).main
    finally:
        sys.path.remove(str(EXAMPLES))


def test_example_dcservo_position(examples):
    r = examples("aim104_dcservo1")()
    assert all(abs(a - t) <= 1 for a, t in zip(r["actual"], r["targets"], strict=True))


def test_example_dcservo_trapezoid_ends_at_final_with_f0_clear(examples):
    for m in examples("aim104_dcservo2")()["moves"]:
        assert m["rc"] == 0 and m["f0"] == 0 and m["command"] == m["final"]
        assert abs(m["actual"] - m["final"]) <= 1


def test_example_dcservo_velocity_modes(examples):
    prop = examples("aim104_dcservo3")()
    assert all(abs(a - c) <= 3 for a, c in zip(prop["actual"], prop["commands"], strict=True))
    integ = examples("aim104_dcservo4")()
    v = integ["measured"]
    assert v[0] == 30 and v[1] == -20 and v[2] == 0 and v[3] == pytest.approx(-20, abs=0.05)
    assert integ["events"] == ["stop"]


def test_example_interrupts_and_limit(examples):
    r = examples("aim104_dcservo5")()
    assert r["interrupts"] == ["profile_done", "limit"]
    assert r["idle_at_limit"] and r["limit_bit_clear"]


def test_example_steppers(examples):
    r = examples("aim104_stepper1")()
    assert r["actual"] == r["targets"]
    r = examples("aim104_stepper2")()
    assert r == {"rc": 0, "f0": 0, "actual": 2000}
    assert examples("aim104_stepper5")() == {"one_phase": 600, "two_phase": 1200}
    assert examples("aim104_stepper6")() == {"forward": 500.0, "back": 300.0}


def test_example_step_response_and_sync(examples, tmp_path):
    r = examples("aim104_step_response")(str(tmp_path / "s.png"))
    assert Path(r["path"]).stat().st_size > 1000
    s = r["summary"]
    assert s["tuned"]["tail_peak_to_peak"] == 0 and s["gain too high"]["tail_peak_to_peak"] > 8
    r = examples("aim104_sync")()
    assert r["timers_after"] == (0x40, 0x40) and r["positions"] == (6000, -3000)
