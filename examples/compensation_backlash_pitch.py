"""Backlash and pitch-error compensation on the simulated X axis, with in-position checks.

The simulated X axis has 30 pulses of backlash and a lead-screw error of up to 12 pulses.
Move to a few targets without compensation, then with it, and print the load error
(encoder minus target) after each move. Run: python examples/compensation_backlash_pitch.py
"""

from __future__ import annotations

import dataclasses

from openmotion.config import DriveConfig, default_machine
from openmotion.control import Controller
from openmotion.control.guard.inposition import InPositionControl
from openmotion.control.loops.compensation import Compensation

SCREW_ERR = (0.0, 3.0, 7.5, 12.0, 9.0, 4.0, -2.0, -6.5, -3.0, 1.0, 5.0)  # per revolution
BACKLASH = 30
TARGETS = (15000, 42000, 27500, 61234, 33333, 5000)


def make_controller() -> Controller:
    cfg = default_machine()
    x = dataclasses.replace(cfg.axes[0], drive=DriveConfig(backlash=BACKLASH,
                                                           pitch_error=SCREW_ERR))
    ctl = Controller(dataclasses.replace(cfg, axes=(x, *cfg.axes[1:])))
    ctl.axis("x").enable()
    return ctl


def comp_table() -> list[int]:
    """The laser measurement turned into an MCCL table: 10000-pulse interval, home index
    1 (one point below home so the table covers MEL at -5000), 33 points up to PEL."""
    pts = [0, 0] + [-round(e) for e in SCREW_ERR[1:]]
    return pts + [pts[-1]] * (33 - len(pts))


def run(compensate: bool) -> list[float]:
    ctl = make_controller()
    ax = ctl.axis("x")
    comp = Compensation(ax, max_accel=5e6)
    ip = InPositionControl(ctl)
    ip.set_tolerance("x", 1)
    ip.set_check_time("x", 1.0)
    ip.enable(["x"])  # uncompensated, the first reversal fails this check (error 301)
    if compensate:
        comp.backlash_comp(BACKLASH)
        comp.set_pitch_table(10000, 1, comp_table())
    errors = []
    for target in TARGETS:
        if ip.error_code:
            break
        ip.queue(lambda t=target: ax.move_relative(t - ax.position, max_vel=100000,
                                                   tacc=0.05))
        ctl.run_until(lambda: ip.pending == 0 and ax.motion_done == 0, 10.0)
        errors.append(ax.counters.feedback - ax.position)
    if ip.error_code:
        print(f"  in-position error {ip.error_code} on axis {ip.error_axis}: {ax.fault}")
    return errors


if __name__ == "__main__":
    for on in (False, True):
        print(f"compensation {'on ' if on else 'off'}: load error after each move (counts):",
              run(on))
