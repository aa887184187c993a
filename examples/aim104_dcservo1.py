"""DCSERVO1: position control of a DC servo on an emulated AIM104-MOTION-1 (manual,
"Operation" steps 1-7, appendix 1 "Position Control Mode")."""

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary

BASE = 0x180


def setup(lib: MotionLibrary, handle: int, a: int = 0xD8, b: int = 0x00, k: int = 0x10) -> None:
    """Steps 1-4 of the manual's procedure for a DC servo."""
    lib.MOTION_set_board_config_reg(handle, 0x00)       # 1) DC servo motor
    lib.MOTION_controller_reset(handle)                 # 2) initialise the HCTL-1100
    lib.MOTION_program_sample_timer(handle, 0x40)       #    520 us sample time
    lib.MOTION_set_filter_parameters(handle, a, b, k)   # 3) digital filter
    lib.MOTION_enter_idle_mode(handle)
    lib.MOTION_preset_actual_position(handle, 0)        # 4) motor position
    lib.MOTION_set_command_position(handle, 0)


def main() -> dict:
    bus = PC104Bus()
    bus.add(AIM104Board(base=BASE))
    lib = MotionLibrary(bus)
    h = lib.MOTION_boardinit(BASE)
    setup(lib, h)
    lib.MOTION_enter_position_mode(h)                   # 6) position control
    visited = []
    for target in (1000, -250, 4000, 0):                # 7) position commands
        lib.MOTION_set_command_position(h, target)
        lib.delay(0.15)
        visited.append(lib.MOTION_read_actual_position(h))
        print(f"command {target:6d}  actual {visited[-1]:6d}")
    lib.MOTION_boardclose(h)
    return {"targets": [1000, -250, 4000, 0], "actual": visited}


if __name__ == "__main__":
    main()
