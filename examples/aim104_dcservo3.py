"""DCSERVO3: proportional velocity control of a DC servo (appendix 1): the command is 12.4
fixed point (x16) in counts/sample, MC = (K/4)(Vcmd - Vact); a steady-state error remains."""

from aim104_dcservo1 import BASE, setup

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary


def main() -> dict:
    bus = PC104Bus()
    bus.add(AIM104Board(base=BASE))
    lib = MotionLibrary(bus)
    h = lib.MOTION_boardinit(BASE)
    setup(lib, h, k=0x40)
    lib.MOTION_enter_position_mode(h)
    speeds = []
    for v in (10.0, -25.5):
        lib.MOTION_set_proportional_velocity(h, round(v * 16))
        lib.MOTION_execute_proportional_velocity(h)
        lib.delay(0.3)
        speeds.append(lib.MOTION_read_actual_velocity(h))
        print(f"command {v:6.2f} counts/sample  actual {speeds[-1]} counts/sample")
    lib.MOTION_end_proportional_velocity(h)     # back to position control
    lib.MOTION_boardclose(h)
    return {"commands": [10.0, -25.5], "actual": speeds}


if __name__ == "__main__":
    main()
