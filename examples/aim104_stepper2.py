"""STEPPER2: trapezoidal profile control of a stepper in half-step mode."""

from aim104_stepper1 import HALF_STEP, make, setup_stepper


def main() -> dict:
    bus, board, lib, h = make()
    setup_stepper(lib, h, HALF_STEP, 5, 5)
    lib.MOTION_set_acceleration(h, 0x0010)              # 1/16 counts/sample^2
    lib.MOTION_set_max_velocity(h, 4)
    lib.MOTION_set_final_position(h, 2000)              # one revolution
    lib.MOTION_execute_trapezoidal_move(h)
    rc = lib.MOTION_wait_until_move_complete(h)
    lib.delay(0.1)
    res = {"rc": rc, "f0": lib.MOTION_read_flag_register(h) & 1,
           "actual": lib.MOTION_read_actual_position(h)}
    print(res)
    lib.MOTION_boardclose(h)
    return res


if __name__ == "__main__":
    main()
