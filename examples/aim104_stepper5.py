"""STEPPER5: position control of a stepper in full-step mode (one phase on): Y = 0,
X = Ring/4 = 10. Switching to two-phases-on needs only the configuration register."""

from aim104_stepper1 import FULL_ONE_PHASE, make, setup_stepper


def main() -> dict:
    bus, board, lib, h = make()
    setup_stepper(lib, h, FULL_ONE_PHASE, 10, 0)
    lib.MOTION_set_command_position(h, 600)
    lib.delay(0.3)
    one = lib.MOTION_read_actual_position(h)
    lib.MOTION_set_board_config_reg(h, 0x02)            # full step, two phases on
    lib.MOTION_set_command_position(h, 1200)
    lib.delay(0.3)
    two = lib.MOTION_read_actual_position(h)
    print(f"one phase on: {one}   two phases on: {two}")
    lib.MOTION_boardclose(h)
    return {"one_phase": one, "two_phase": two}


if __name__ == "__main__":
    main()
