"""STEPPER6: open-loop stepping in half-step mode (no encoder needed): the commutator is
held (F4) and its offset moved one half step at a time while R09H drives the windings."""

from aim104_stepper1 import HALF_STEP, make, setup_stepper


def main() -> dict:
    bus, board, lib, h = make()
    setup_stepper(lib, h, HALF_STEP, 5, 5)
    lib.MOTION_open_loop_stepper(h, 100, 0.002)         # 100 half steps forward
    fwd = board.plant.position
    lib.MOTION_open_loop_stepper(h, -40, 0.002)
    back = board.plant.position
    print(f"after +100 half steps: {fwd} counts, after -40: {back} counts")
    lib.MOTION_boardclose(h)
    return {"forward": fwd, "back": back}


if __name__ == "__main__":
    main()
