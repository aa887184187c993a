"""STEPPER1: position control of a stepper in half-step mode (appendix 1 "Align", appendix
2 commutator). A 200-step motor with a 500-line encoder: 2000 quadrature counts/rev, so
Ring = 2000 / (200/4) = 40 counts, and half step needs X = Y = Ring/8 = 5."""

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary
from openmotion.compat.hctl1100_commutator import IdealStepper

BASE = 0x180
HALF_STEP, FULL_ONE_PHASE = 0x03, 0x01


def setup_stepper(lib: MotionLibrary, h: int, drive: int, x: int, y: int) -> None:
    """Configure, reset, filter, commutator, zero positions and align (manual order)."""
    lib.MOTION_set_board_config_reg(h, drive)
    lib.MOTION_controller_reset(h)
    lib.MOTION_program_sample_timer(h, 0x40)
    lib.MOTION_set_filter_parameters(h, 0xE5, 0x40, 0x40)
    lib.MOTION_set_controller_status_reg(h, 0x02)       # 4 phase, quadrature counts
    lib.MOTION_program_commutator(h, 40, x, y, 0, 0, 0)
    lib.MOTION_preset_actual_position(h, 0)
    lib.MOTION_set_command_position(h, 0)
    lib.MOTION_enter_align_mode(h)
    lib.delay(2 * 2048 * 520e-6 + 0.01)                 # PHA then PHD, 2048 samples each


def make(position: float = 3.0) -> tuple[PC104Bus, AIM104Board, MotionLibrary, int]:
    motor = IdealStepper(200, 2000)
    motor.position = position                           # unknown phase at power-on
    bus = PC104Bus()
    board = bus.add(AIM104Board(motor, base=BASE))
    lib = MotionLibrary(bus)
    return bus, board, lib, lib.MOTION_boardinit(BASE)


def main() -> dict:
    bus, board, lib, h = make()
    setup_stepper(lib, h, HALF_STEP, 5, 5)
    out = []
    for target in (400, 405, -1000):                    # 405: a half step (5 counts) on
        lib.MOTION_set_command_position(h, target)
        lib.delay(0.3)
        out.append(lib.MOTION_read_actual_position(h))
        print(f"command {target:6d}  actual {out[-1]:6d}")
    lib.MOTION_boardclose(h)
    return {"targets": [400, 405, -1000], "actual": out}


if __name__ == "__main__":
    main()
