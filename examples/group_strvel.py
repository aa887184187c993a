"""StrVel on a group path (HSL-4XMO 4.6): the vector speed jumps from rest to StrVel, ramps
to the feed, ramps down to StrVel and jumps to rest, as a PCL6045 interpolation does. The
same XY contour runs with StrVel 0 (MCCL) and 5 mm/s on the simulated XYZU table.

Run: python examples/group_strvel.py
"""

from __future__ import annotations

import numpy as np

from openmotion.control import Controller
from openmotion.control.group import Group, GroupState


def run(str_vel: float) -> dict:
    """Run the contour with `str_vel` (mm/s); the speeds just after the start and just
    before the end (from the recorded history), the time and the end position."""
    ctl = Controller()
    ctl.enable_all()
    g = Group(ctl, ["x", "y"], feed=20.0, acc_time=0.1, units=True)  # mm/s, s
    g.set_str_vel(str_vel)
    g.enable_blend(0.05)  # mm
    g.line([30.0, 0.0])
    g.line([30.0, 20.0])
    g.arc([20.0, 20.0], [10.0, 20.0], direction="CCW")
    ctl.step()
    ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                  and not any(a.is_moving for a in g.axes), 30)
    ppu = np.array([a.units.pulses_per_unit for a in g.axes])
    rec = [ctl.history.records(a.index) for a in g.axes]
    first = [np.nonzero((r["v0"] != 0.0) | (r["a0"] != 0.0))[0][0] for r in rec]
    t_start = min(float(r["ts"][k]) for r, k in zip(rec, first, strict=True))
    t_end = max(ctl.history.end_time(a.index) for a in g.axes)
    v = np.array([ctl.history.sample(a.index, [t_start, t_end - 1e-9]).v for a in g.axes])
    speed = np.linalg.norm(v / ppu[:, None], axis=0)
    return {"str_vel": str_vel, "start_speed": float(speed[0]), "end_speed": float(speed[1]),
            "time": t_end - t_start, "end": g.position.tolist()}


def main() -> list[dict]:
    out = [run(0.0), run(5.0)]
    for r in out:
        print(f"StrVel {r['str_vel']:4.1f} mm/s: speed after the start {r['start_speed']:.3f}, "
              f"before the end {r['end_speed']:.3f} mm/s, {r['time']:.3f} s, ends at {r['end']}")
    return out


if __name__ == "__main__":
    main()
