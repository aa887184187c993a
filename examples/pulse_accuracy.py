"""How closely the integer pulse counts follow a path (issue 4, quantization bound).

Runs a line, a full circle and a helix on X, Y, Z of the simulated table with the pulse
record on, once with the default half-pulse rule and once with the floor-rule opt-out, and
prints what `pulse_accuracy` measured at every pulse of every axis.

Run: python examples/pulse_accuracy.py
"""

from __future__ import annotations

from openmotion.control import Controller, pulse_accuracy
from openmotion.control.groups.group import Group, GroupState
from openmotion.path import Arc, Line

R = 2_000.0
PATH = [Line([0, 0, 0], [R, 0, 777]),
        Arc([R, 0, 777], [0, 0], [R, 0, 777]),             # full circle in XY
        Arc([R, 0, 777], [0, 0], [-R, 0, 0], direction="CW")]  # half a helix, Z down


def run(half: bool) -> None:
    ctl = Controller()
    ctl.enable_all()
    ctl.hardware.set_half_pulse(half)
    g = Group(ctl, ["x", "y", "z"], feed=30_000.0, acc_time=0.1)  # pps, s
    ctl.hardware.record_pulses()  # every pulse's exact time from now on
    t0 = ctl.time
    g.line([R, 0, 777])
    g.circle([0, 0])
    g.arc([0, 0], [-R, 0, 0], direction="CW")
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                  and not any(a.is_moving for a in g.axes), 30)
    acc = pulse_accuracy(ctl, ["x", "y", "z"], PATH, t0, ctl.time)
    rule = "half-pulse (default)" if half else "floor (opt-out)"
    print(f"{rule}: {acc.samples} pulse instants checked")
    print("  count - command, per axis (max):", ", ".join(f"{e:.6f}" for e in acc.axis_error))
    print("  command - plan, per axis (max):  ",
          ", ".join(f"{e:.6f}" for e in acc.command_error))
    print(f"  contour error of the counts: {acc.contour_error:.4f} pulses "
          f"at t = {acc.contour_time:.4f} s")


def main() -> None:
    run(True)
    run(False)


if __name__ == "__main__":
    main()
