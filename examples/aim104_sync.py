"""Several AIM104-MOTION-1 boards synchronised by SYNC (appendix 3): the boards' SYNC pins
are tied, the master toggles SYNC (configuration bit 2) so all sample timers restart
together, then an X/Y pair runs trapezoidal moves that start in the same sample."""

from openmotion.compat.aim104 import AIM104Board, PC104Bus
from openmotion.compat.aim104_lib import MotionLibrary


def main() -> dict:
    bus = PC104Bus()
    bus.add(AIM104Board(base=0x180, link5_internal_sync=True), tie_sync=True)   # master
    bus.add(AIM104Board(base=0x184, link5_internal_sync=False), tie_sync=True)  # slave
    lib = MotionLibrary(bus)
    hx, hy = lib.MOTION_boardinit(0x180), lib.MOTION_boardinit(0x184)
    for h in (hx, hy):
        lib.MOTION_set_board_config_reg(h, 0x00)
        lib.MOTION_controller_reset(h)
        lib.MOTION_set_filter_parameters(h, 0xD8, 0x00, 0x10)
        lib.MOTION_enter_position_mode(h)
    bus.boards[0x184].chip.advance(1.3e-4)      # the slave's timer runs out of phase
    lib.delay(0.001)
    before = (lib.MOTION_read_sample_timer(hx), lib.MOTION_read_sample_timer(hy))
    lib.MOTION_pulse_SYNC(hx)
    after = (lib.MOTION_read_sample_timer(hx), lib.MOTION_read_sample_timer(hy))
    for h, final in ((hx, 6000), (hy, -3000)):
        lib.MOTION_set_acceleration(h, 0x0080)
        lib.MOTION_set_max_velocity(h, 25)
        lib.MOTION_set_final_position(h, final)
    lib.MOTION_execute_trapezoidal_move(hx)
    lib.MOTION_execute_trapezoidal_move(hy)
    lib.MOTION_wait_until_move_complete(hx)
    lib.MOTION_wait_until_move_complete(hy)
    lib.delay(0.05)
    pos = (lib.MOTION_read_actual_position(hx), lib.MOTION_read_actual_position(hy))
    print(f"sample timers before SYNC {before}, after {after}; positions {pos}")
    return {"timers_before": before, "timers_after": after, "positions": pos}


if __name__ == "__main__":
    main()
