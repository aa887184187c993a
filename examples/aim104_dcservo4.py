"""DCSERVO4: integral velocity control of a DC servo (appendix 1): velocity profiling
through position control, so the velocity has zero steady-state error; STOP decelerates to
zero and holds until the flag is cleared."""

from aim104_dcservo1 import BASE, setup

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary


def measure(lib: MotionLibrary, h: int, samples: int = 200) -> float:
    """Mean velocity (counts/sample) over `samples` samples from actual position reads."""
    p0 = lib.MOTION_read_actual_position(h)
    lib.delay(samples * 520e-6)
    return (lib.MOTION_read_actual_position(h) - p0) / samples


def main() -> dict:
    bus = PC104Bus()
    board = bus.add(AIM104Board(base=BASE))
    lib = MotionLibrary(bus)
    h = lib.MOTION_boardinit(BASE)
    setup(lib, h)
    lib.MOTION_enter_position_mode(h)
    lib.MOTION_set_acceleration(h, 0x0040)      # 0.25 counts/sample^2
    lib.MOTION_set_integral_velocity(h, 30)
    lib.MOTION_execute_integral_velocity(h)
    lib.delay(0.2)
    v1 = measure(lib, h)
    lib.MOTION_set_integral_velocity(h, -20)
    lib.delay(0.2)
    v2 = measure(lib, h)
    board.set_input("stop", True)               # emergency STOP: ramp to zero and hold
    lib.delay(0.2)
    v3 = measure(lib, h)
    board.set_input("stop", False)
    lib.MOTION_clear_interrupts(h)              # clears the latched STOP flag
    lib.delay(0.2)
    v4 = measure(lib, h)
    lib.MOTION_end_integral_velocity(h)
    print(f"30 -> {v1:.3f}, -20 -> {v2:.3f}, stopped -> {v3:.3f}, resumed -> {v4:.3f}")
    lib.MOTION_boardclose(h)
    return {"measured": [v1, v2, v3, v4], "events": [e.kind for e in board.events]}


if __name__ == "__main__":
    main()
