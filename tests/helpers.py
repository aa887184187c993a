"""Machines and moves several test files share (pytest puts tests/ on sys.path).

Each helper builds something a test then asserts on; none asserts more than "the motion
finished", so a failure still points at the test that called it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.guard.safety import Safety
from openmotion.hw.interface import Hardware
from openmotion.profile.jerk import jerk_limited
from openmotion.profile.segments import Profile, State


def free_axes(n: int = 3, period: float | None = None,
              hardware: Callable[[MachineConfig], Hardware] | None = None,
              **axis_kw: object) -> Controller:
    """An enabled controller on `n` default axes x, y, z, u (no switches: free travel;
    1000 pulses/mm, 500 mm/s). `hardware(cfg)` replaces the simulator."""
    cfg = MachineConfig("t", tuple(AxisConfig(name=c, **axis_kw) for c in "xyzu"[:n]))
    c = Controller(cfg, hardware(cfg) if hardware else None, period=period)
    c.enable_all()
    return c


def with_own_safety(cfg: MachineConfig) -> tuple[Controller, Safety]:
    """An enabled controller on `cfg` with a Safety the test holds (safety=False, then
    attached explicitly, so the test can reach its settings)."""
    ctl = Controller(cfg, safety=False)
    safety = Safety(ctl)
    ctl.enable_all()
    return ctl, safety


def table_without_mel(*, safety: bool = True) -> Controller:
    """The enabled default XYZU table with its -EL switches (just below 0) removed, so
    paths may run to either side of the origin."""
    ctl = Controller(safety=safety)
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    return ctl


def finish_group(ctl: Controller, g: Group, timeout: float = 30.0) -> float:
    """Run until the group is idle with an empty queue and no axis moving; the end time.
    The condition is an end state: virtual time jumps to it (the same end as stepping)."""
    ctl.step()
    assert ctl.run_until(lambda: g.state is GroupState.IDLE and g.queue_length == 0
                         and not any(a.is_moving for a in g.axes), timeout,
                         event_driven=True)
    return ctl.time


def start_line(c: Controller, start: Sequence[float], end: Sequence[float],
               v: float = 20_000.0, a: float = 2e5, j: float = 2e7) -> bool:
    """Start a synchronised straight line from `start` to `end` (pulses, axes 0..k-1):
    each axis runs a scaled copy of one jerk-limited profile and ends exactly on its
    target. False (nothing started) for a zero-length line."""
    p_start, p_end = np.asarray(start, float), np.asarray(end, float)
    d = p_end - p_start
    length = float(np.linalg.norm(d))
    if length == 0.0:
        return False
    ref = jerk_limited(length, v, a, j)
    for ax, (p0, dk) in enumerate(zip(p_start, d, strict=True)):
        k = dk / length
        prof = Profile(ref.t0, p0 + k * ref.p0, k * ref.v0, k * ref.a0, k * ref.j,
                       ref.duration, State(p0), State(p0 + dk), ref.labels, ref.dt)
        c.axes[ax].run_profile(prof, stop_accel=a, stop_jerk=j)
    return True


def segment_profile(segs: Sequence[tuple[float, float, float, bool]], v0: float,
                    p0: float = 0.0) -> Profile:
    """A profile from drawn (duration, jerk, start acceleration, dwell) segments: a dwell
    stops on the spot (dwell and arrival semantics), the others are jerk segments."""
    from openmotion.profile.segments import ProfileBuilder

    b = ProfileBuilder(p0, v0, v_before=v0)
    for dur, jerk, accel, dwell in segs:
        if dwell:
            b.set_velocity(0.0)
            b.segment(dur, 0.0, accel=0.0)
        else:
            b.segment(dur, jerk, accel=accel)
    return b.build()

