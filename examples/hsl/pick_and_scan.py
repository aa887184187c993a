"""A legacy HSL-4XMO program ported line by line to openmotion (docs/porting-hsl.md).

The C original (shown in the comments) homes X, scans a part with the CCD trigger while
the feeder runs, draws an arc, and handles an alarm on the feeder. Run it with
`python examples/hsl/pick_and_scan.py`; it prints what the legacy program printed.
"""

from __future__ import annotations

import os

from openmotion.compat.hsl import HslLibrary, HslSim
from openmotion.compat.hsl.errors import ERR_AxisState

HERE = os.path.dirname(os.path.abspath(__file__))
X, Y, FEED = 0, 1, 4            # global axis numbers: module 0 CM1/CM2, module 1 CM1


def check(rc: int, what: str) -> None:
    """The C program's `if (rc != 0) { printf(...); exit(1); }`."""
    if rc != 0:
        raise SystemExit(f"{what} failed: {rc} {hsl.HSL_M_get_error_message(rc)}")


hsl = HslLibrary.from_file(os.path.join(HERE, "two_modules.toml"))
sim = HslSim(hsl)               # the machine around the program (switches, alarms)

# HSL_initial(0);
check(hsl.HSL_initial(0), "HSL_initial")
print(f"modules: {hsl.HSL_get_module_count(0)}, scan time "
      f"{hsl.HSL_get_scan_time(0) * 1e6:.1f} us")

# HSL_M_set_el_logic(X, 1); HSL_M_set_home_config(X, 1, 0, 0, 0, 0);
check(hsl.HSL_M_set_el_logic(X, 1), "set_el_logic")        # the table's NC limits
check(hsl.HSL_M_set_el(X, 1), "set_el")                    # decelerate on a limit
check(hsl.HSL_M_set_home_config(X, 0, 0, 0, 0, 0), "set_home_config")

# HSL_M_home_move(X, 500, -20000, 0.1); while (HSL_M_motion_done(X)) ;
hsl.HSL_M_set_command(X, 15000)    # the table starts somewhere to the right
hsl.HSL_M_set_position(X, 15000)
check(hsl.HSL_M_home_move(X, 500, -20000, 0.1), "home_move")
polls = 0
while hsl.HSL_M_motion_done(X):
    polls += 1
hsl.HSL_M_reset_target_pos(X, 0)
print(f"homed after {polls} polls, t = {hsl.HSL_get_time(0):.3f} s, "
      f"command {hsl.HSL_M_get_command(X)}")

# the CCD scan: compare points 1001..35000 every pulse on X, 6000 pps (4.12)
check(hsl.HSL_M_set_trigger_comparator(X, 1, 1, 0.0), "set_trigger_comparator")
check(hsl.HSL_M_build_comp_function(X, 1001, 35000, 1), "build_comp_function")
check(hsl.HSL_M_set_auto_compare(X, 1), "set_auto_compare")
check(hsl.HSL_M_start_ta_move(X, 36000, 0, 6000, 0.05, 0.05), "start_ta_move")
check(hsl.HSL_M_start_tv_move(FEED, 0, 20000, 0.2), "start_tv_move")   # the feeder runs
sim.trip_alarm(FEED, at=hsl.HSL_get_time(0) + 1.0)                     # ...until it alarms
while hsl.HSL_M_motion_done(X):
    io = hsl.HSL_M_get_io_status(FEED)
    if io & (1 << 1):                      # ALM bit: the feeder stopped by itself
        print(f"feeder alarm at t = {hsl.HSL_get_time(0):.3f} s, "
              f"speed {hsl.HSL_M_get_current_speed(FEED):.0f} pps")
        sim.clear_alarm(FEED)
        break
while hsl.HSL_M_motion_done(X):
    pass
print(f"scan done, next compare value {hsl.HSL_M_check_compare_data(X, 5):.0f}")

# a restart of the feeder is refused until the alarm is reset
rc = hsl.HSL_M_start_tv_move(FEED, 0, 20000, 0.2)
print(f"feeder restart: {rc} ({'refused' if rc == ERR_AxisState else 'ok'})")
sim.reset_axis(FEED)
check(hsl.HSL_M_start_tv_move(FEED, 0, 20000, 0.2), "feeder restart after reset")
check(hsl.HSL_M_sd_stop(FEED, 0.1), "sd_stop")

# back to the arc start, then the manual's arc: centre (1000, 0), end (1800, 600)
check(hsl.HSL_M_start_ta_move_xy(0, 0.0, 0.0, 1000.0, 20000.0, 0.1, 0.1), "ta_move_xy")
while hsl.HSL_M_motion_done(X) or hsl.HSL_M_motion_done(Y):
    pass
check(hsl.HSL_M_start_a_arc_xy(0, 1000.0, 0.0, 1800.0, 600.0, 1000.0), "a_arc_xy")
while hsl.HSL_M_motion_done(X):
    pass
print(f"arc end ({hsl.HSL_M_get_command(X)}, {hsl.HSL_M_get_command(Y)}), "
      f"t = {hsl.HSL_get_time(0):.3f} s")
print(f"calls on the wire: {sum(hsl.network.calls.values())}")
check(hsl.HSL_close(0), "HSL_close")
