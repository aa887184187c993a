"""Benchmark: jerk-limited re-planning from any state, against ruckig, failure counts.

N random cases (seeded): a state (p, v, a) with a != 0 and v anywhere in +-v_max (one case
in ten up to 3 v_max: braking from above the limit), limits log-uniform (v 1..1e4, a
1..1e5, j 1..1e7, half the cases with a deceleration d_max set apart, 0.1..10 a_max), a
target 1e-2..1e4 away on either side. Each case is planned by `profile.retarget` (to rest
on the target) and, one case in four, also by `retarget_velocity` (to a target velocity);
ruckig plans the same (position or velocity interface, 1 DoF). Counted:

- failures: ours = an exception or a profile that breaks a limit, jumps, or does not end
  exactly on the target at rest (the target velocity); ruckig's = an error result;
- durations where both succeed: within 1e-9 relative, within 1e-6, ours longer beyond
  1e-9 and by which case class (the a_max > d_max gap where ours stops and comes back,
  a start above v_max), the largest difference;
- the same on the same problem only: ruckig's limits are signed (given here in the frame
  of our final approach), ours hold in the frame of the final approach; where ruckig's
  own plan arrives from the other side, it solved a different problem (it brakes harder
  than our limits allow for that approach: the a_max > d_max gap);
- CPU time per case of each planner (ruckig with reused objects).

    python bench/bench_retarget.py [N] [--seed S]      (default N = 100000; the issue's
                                                         goal is stated for 1e6)
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass, field

import numpy as np

from openmotion.profile.retarget import retarget, retarget_velocity
from openmotion.profile.segments import Profile, State

REL = 1e-9


@dataclass
class Case:
    state: State
    target: float
    v_max: float
    a_max: float
    j_max: float
    d_max: float | None
    v_target: float | None  # velocity mode (None: to rest on the target)


def cases(n: int, seed: int) -> list[Case]:
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        v, a, j = 10 ** rng.uniform(0, 4), 10 ** rng.uniform(0, 5), 10 ** rng.uniform(0, 7)
        d = a * 10 ** rng.uniform(-1, 1) if k % 2 else None
        acc = rng.uniform(-1, 1) * min(a, d or a, math.sqrt(j * v))
        spread = 3.0 if k % 10 == 3 else 1.0
        v0 = rng.uniform(-spread, spread) * v - acc * abs(acc) / (2 * j)
        p = rng.uniform(-100, 100)
        target = p + rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-2, 4)
        vt = float(rng.uniform(-1, 1) * v) if k % 4 == 1 else None
        out.append(Case(State(p, v0, acc), target, v, a, j, d, vt))
    return out


def invalid(prof: Profile, c: Case) -> str:
    """Why `prof` is not a valid plan for c ('' if it is): limits (widened by what the
    start state forces), continuity of p/v/a, the exact end."""
    s = c.state
    if c.v_target is None:
        if prof.end.p != c.target or prof.end.v != 0.0:
            return "end"
        d_max = c.a_max if c.d_max is None else c.d_max
        a_big = max(c.a_max, d_max, abs(s.a))
    else:
        if prof.end.v != c.v_target:
            return "end"
        a_big = max(c.a_max, abs(s.a))
    if prof.n_segments == 0:
        return ""
    t0, p0, v0, a0, jj = prof.t0, prof.p0, prof.v0, prof.a0, prof.j
    dt = np.diff(np.append(t0, prof.duration))
    if np.any(dt < -1e-15 * max(1.0, prof.duration)):
        return "time"
    pe = p0 + dt * (v0 + dt * (a0 / 2 + dt * jj / 6))
    ve = v0 + dt * (a0 + dt * jj / 2)
    ae = a0 + dt * jj
    t_ulp = 4.0 * math.ulp(max(prof.duration, 1e-300))
    v_big = max(c.v_max, abs(s.v) + s.a * s.a / (2 * c.j_max), abs(c.v_target or 0.0))
    scale = max(abs(c.target - s.p), float(np.abs(p0 - s.p).max()),
                abs(s.v) * prof.duration) + 1.0
    a_tol = REL * a_big + c.j_max * t_ulp
    v_tol = REL * v_big + a_big * t_ulp
    if np.any(np.abs(jj) > c.j_max * (1 + 1e-12)):
        return "jerk"
    if np.any(np.abs(a0) > a_big + a_tol) or np.any(np.abs(ae) > a_big + a_tol):
        return "accel"
    # speed inside a segment: the extreme of v at t* = -a0/j
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(jj != 0.0, -a0 / jj, -1.0)
    inside = (ts > 0) & (ts < dt)
    vs = np.where(inside, v0 + ts * (a0 + ts * jj / 2), 0.0)
    if max(float(np.abs(v0).max()), float(np.abs(ve).max()),
           float(np.abs(vs).max())) > v_big + v_tol:
        return "speed"
    nxt_p = np.append(p0[1:], prof.end.p)
    nxt_v = np.append(v0[1:], prof.end.v)
    nxt_a = np.append(a0[1:], 0.0)
    if np.any(np.abs(pe - nxt_p) > REL * scale) or np.any(np.abs(ve - nxt_v) > v_tol) or \
            np.any(np.abs(ae - nxt_a) > a_tol):
        return "jump"
    if abs(p0[0] - s.p) > REL * scale or abs(v0[0] - s.v) > REL * v_big or \
            abs(a0[0] - s.a) > REL * a_big:
        return "start"
    return ""


def ours(c: Case) -> Profile:
    if c.v_target is None:
        return retarget(c.state, c.target, c.v_max, c.a_max, c.j_max, d_max=c.d_max)
    return retarget_velocity(c.state, c.v_target, c.a_max, c.j_max)


def approach_frame(prof: Profile) -> float:
    if prof.n_segments == 0:
        return 1.0
    mid = 0.5 * (prof.t0[-1] + prof.duration)
    return 1.0 if prof.sample([mid]).v[0] >= 0.0 else -1.0


class Ruckig:
    """ruckig 1-DoF with reused objects."""

    def __init__(self) -> None:
        import ruckig

        self.mod = ruckig
        self.otg = ruckig.Ruckig(1)
        self.inp = ruckig.InputParameter(1)
        self.traj = ruckig.Trajectory(1)

    def approach(self) -> float:
        """Side the last calculated plan arrives from (+1/-1; 0: it does not move)."""
        p = self.traj.profiles[0][0]
        moving = [k for k in range(7) if p.t[k] > 0.0]
        if not moving:
            return 0.0
        dp = p.p[moving[-1] + 1] - p.p[moving[-1]]
        return 1.0 if dp > 0.0 else -1.0 if dp < 0.0 else 0.0

    def duration(self, c: Case, frame: float) -> float | None:
        r, inp = self.mod, self.inp
        inp.current_position, inp.current_velocity = [c.state.p], [c.state.v]
        inp.current_acceleration = [c.state.a]
        inp.max_velocity, inp.max_jerk = [c.v_max], [c.j_max]
        if c.v_target is None:
            inp.control_interface = r.ControlInterface.Position
            inp.target_position, inp.target_velocity = [c.target], [0.0]
            d = c.a_max if c.d_max is None else c.d_max
            inp.max_acceleration, inp.min_acceleration = \
                ([c.a_max], [-d]) if frame > 0 else ([d], [-c.a_max])
        else:
            inp.control_interface = r.ControlInterface.Velocity
            inp.target_velocity = [c.v_target]
            inp.max_acceleration, inp.min_acceleration = [c.a_max], [-c.a_max]
        inp.target_acceleration = [0.0]
        try:
            res = self.otg.calculate(inp, self.traj)
        except r.RuckigError:
            return None
        if res not in (r.Result.Working, r.Result.Finished):
            return None
        return float(self.traj.duration)


@dataclass
class Stats:
    n: int = 0
    our_fail: dict[str, int] = field(default_factory=dict)
    ruckig_fail: int = 0
    compared: int = 0
    within_1e9: int = 0
    within_1e6: int = 0
    longer: dict[str, int] = field(default_factory=dict)
    shorter: dict[str, int] = field(default_factory=dict)
    other_side: int = 0  # ruckig's plan arrives from the other side: a different problem
    same: int = 0  # compared on the same problem
    same_1e9: int = 0
    same_longer: int = 0
    max_rel: float = 0.0
    worst: Case | None = None
    t_ours: float = 0.0
    t_ruckig: float = 0.0


def run(n: int, seed: int = 1, with_ruckig: bool = True) -> Stats:
    st = Stats(n=n)
    rk = Ruckig() if with_ruckig else None
    for c in cases(n, seed):
        t0 = time.process_time()
        try:
            prof = ours(c)
        except Exception as exc:  # noqa: BLE001 - every exception is a failure here
            st.t_ours += time.process_time() - t0
            key = f"exception {type(exc).__name__}"
            st.our_fail[key] = st.our_fail.get(key, 0) + 1
            continue
        st.t_ours += time.process_time() - t0
        why = invalid(prof, c)
        if why:
            st.our_fail[why] = st.our_fail.get(why, 0) + 1
            continue
        if rk is None:
            continue
        frame = approach_frame(prof) if c.v_target is None else 1.0
        t0 = time.process_time()
        ref = rk.duration(c, frame)
        st.t_ruckig += time.process_time() - t0
        if ref is None:
            st.ruckig_fail += 1
            continue
        st.compared += 1
        r = (prof.duration - ref) / ref if ref > 0 else prof.duration
        arrives = rk.approach() if c.v_target is None else frame
        if arrives not in (0.0, frame):
            st.other_side += 1
        else:
            st.same += 1
            st.same_1e9 += abs(r) <= 1e-9
            st.same_longer += r > 1e-9
        if abs(r) <= 1e-9:
            st.within_1e9 += 1
        if abs(r) <= 1e-6:
            st.within_1e6 += 1
        if abs(r) > 1e-9:
            if c.v_target is None and any(lb.startswith("stop") for lb in prof.labels):
                key = "a_max > d_max gap (stop, come back)"
            elif abs(c.state.v) > c.v_max:
                key = "start above v_max"
            elif c.v_target is not None:
                key = "velocity"
            else:
                key = "other"
            side = st.longer if r > 0 else st.shorter
            side[key] = side.get(key, 0) + 1
        if abs(r) > st.max_rel:
            st.max_rel, st.worst = abs(r), c
    return st


def report(st: Stats) -> None:
    print(f"{st.n} cases (to rest on a target; one in four to a target velocity)")
    fails = sum(st.our_fail.values())
    print(f"  failures: openmotion {fails} {dict(st.our_fail) or ''}  ruckig {st.ruckig_fail}"
          f"  (goal: 0 of ours)")
    if st.compared:
        print(f"  durations, {st.compared} cases both planned: within 1e-9 relative "
              f"{st.within_1e9} ({100 * st.within_1e9 / st.compared:.3f} %), within 1e-6 "
              f"{st.within_1e6}; ours longer > 1e-9: {sum(st.longer.values())} "
              f"{dict(st.longer) or ''}; ours shorter < -1e-9: {sum(st.shorter.values())} "
              f"{dict(st.shorter) or ''}; "
              f"max |rel diff| {st.max_rel:.2e}")
        print(f"  same problem (ruckig's plan arrives from our approach side; {st.other_side} "
              f"where it arrives from the other, a different problem): {st.same} cases, "
              f"within 1e-9 {st.same_1e9} ({100 * st.same_1e9 / max(1, st.same):.3f} %), "
              f"ours longer > 1e-9: {st.same_longer}")
        ours_us = 1e6 * st.t_ours / st.n
        ruckig_us = 1e6 * st.t_ruckig / max(1, st.compared + st.ruckig_fail)
        print(f"  CPU per case: openmotion {ours_us:.1f} us, ruckig {ruckig_us:.1f} us "
              f"(reused objects); ratio {ruckig_us / ours_us:.2f}x")
        ok = fails == 0 and st.within_1e9 == st.compared
        print(f"  goal (0 failures, every duration within 1e-9 of ruckig's): "
              f"{'met' if ok else 'not met'}; on the same problem: 0 failures and never "
              f"longer than ruckig: {'met' if fails == 0 and st.same_longer == 0 else 'not met'}"
              f", within 1e-9: {'met' if st.same_1e9 == st.same else 'not met'}")
        if st.worst is not None:
            print(f"  largest difference at {st.worst}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", nargs="?", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    try:
        import ruckig  # noqa: F401
        have = True
    except ImportError:
        print("ruckig is not installed: openmotion's failure count alone")
        have = False
    report(run(args.n, args.seed, have))


if __name__ == "__main__":
    main()
