"""DCSERVO2: trapezoidal profile moves of a DC servo (appendix 1, "Trapezoidal Profile
Mode"): final position, acceleration and maximum velocity, then F0; the chip clears F0 at
the end and stays in position control at the final position."""

from aim104_dcservo1 import BASE, setup

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary


def main() -> dict:
    bus = PC104Bus()
    bus.add(AIM104Board(base=BASE))
    lib = MotionLibrary(bus)
    h = lib.MOTION_boardinit(BASE)
    setup(lib, h)
    lib.MOTION_enter_position_mode(h)
    lib.MOTION_set_acceleration(h, 0x0100)      # 1.0 counts/sample^2
    lib.MOTION_set_max_velocity(h, 40)          # counts/sample
    results = []
    for final in (20000, 5000, 5100):           # trapezoid, trapezoid, triangle (short)
        lib.MOTION_set_final_position(h, final)
        lib.MOTION_execute_trapezoidal_move(h)
        rc = lib.MOTION_wait_until_move_complete(h)
        flags = lib.MOTION_read_flag_register(h)
        lib.delay(0.05)                          # F0 clear is not "motor stopped"
        actual = lib.MOTION_read_actual_position(h)
        results.append({"final": final, "rc": rc, "f0": flags & 1,
                        "command": lib.MOTION_read_command_position(h), "actual": actual})
        print(results[-1])
    lib.MOTION_boardclose(h)
    return {"moves": results}


if __name__ == "__main__":
    main()
