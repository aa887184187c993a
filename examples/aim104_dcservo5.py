"""DCSERVO5: interrupts on status change (manual, link 8): a callback per event, LIMIT
halting the motor (Init/Idle), then backing off the switch open loop through R09H."""

from aim104_dcservo1 import BASE, setup

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary


def write_reg(bus: PC104Bus, base: int, reg: int, value: int) -> None:
    """Raw register write by the manual's protocol: ready, address, ready, data."""
    while bus.inb(base + 2) & 0x01:
        pass
    bus.outb(base, reg)
    while bus.inb(base + 2) & 0x01:
        pass
    bus.outb(base + 1, value & 0xFF)


def main() -> dict:
    bus = PC104Bus()
    board = bus.add(AIM104Board(base=BASE, irq=5))
    lib = MotionLibrary(bus)
    h = lib.MOTION_boardinit(BASE)
    seen = []
    board.on_interrupt.append(lambda ev: seen.append((round(ev.time, 4), ev.kind)))
    setup(lib, h)
    lib.MOTION_enter_position_mode(h)
    lib.MOTION_set_acceleration(h, 0x0080)
    lib.MOTION_set_max_velocity(h, 30)
    lib.MOTION_set_final_position(h, 8000)
    lib.MOTION_execute_trapezoidal_move(h)
    lib.MOTION_wait_until_move_complete(h)
    lib.MOTION_clear_interrupts(h)
    lib.MOTION_set_final_position(h, 30000)
    lib.MOTION_execute_trapezoidal_move(h)
    lib.delay(0.1)
    board.set_input("limit1", True)             # hits the limit switch mid-move
    halted_status = lib.MOTION_read_controller_status_reg(h)
    lib.delay(0.05)
    lib.MOTION_enter_position_mode(h)           # ignored while LIMIT is active
    still_idle = bool(lib.MOTION_read_flag_register(h) & 0x02)
    lib.MOTION_set_board_config_reg(h, 0x00)
    write_reg(bus, BASE, 0x09, -20)             # back off open loop: R09H in Init/Idle
    lib.delay(0.05)
    board.set_input("limit1", False)
    write_reg(bus, BASE, 0x09, 0)
    lib.MOTION_clear_interrupts(h)
    at = lib.MOTION_read_actual_position(h)
    lib.MOTION_set_command_position(h, at)
    lib.MOTION_enter_position_mode(h)
    print("interrupts:", seen, " status at limit:", hex(halted_status))
    result = {"interrupts": [k for _, k in seen], "idle_at_limit": still_idle,
              "limit_bit_clear": bool(lib.MOTION_read_controller_status_reg(h) & 0x80)}
    lib.MOTION_boardclose(h)
    return result


if __name__ == "__main__":
    main()
