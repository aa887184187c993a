"""Benchmark: openmotion's jerk-limited planner against ruckig on random rest-to-rest moves.

Plans the same N seeded random moves (distances 1e-3..1.3e8 pulses, v 1..1e7, a 1..1e9,
j 1..1e12, half of them with a separate deceleration limit) with both libraries and prints
agreement of durations, ruckig's failures, throughputs (CPU time; also with new objects
per move, and three axes synchronised against ruckig 3-DoF, with the goals of issue 14)
and the batch planner's peak memory. Each throughput is the least CPU time of 3 runs,
the planners' runs taken in turn (one under a passing load would skew a ratio); ruckig's
inputs are built before its timed loops, as ours are.

    python bench/bench_profile.py            # N = 100 000, batch of 1 000 000 (< 60 s)
    python bench/bench_profile.py --quick    # a few seconds
"""

from __future__ import annotations

import argparse
import contextlib
import math
import time
import tracemalloc

import numpy as np

from openmotion.profile.batch import jerk_limited_durations
from openmotion.profile.jerk import jerk_limited, jerk_limited_duration, jerk_limited_sync

try:
    import ruckig
except ImportError:  # pragma: no cover - ruckig is a dev dependency
    ruckig = None


def random_moves(n: int, seed: int) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    dist = rng.choice([-1.0, 1.0], n) * np.minimum(10 ** rng.uniform(-3, 8.13, n), 2**27 - 1)
    v = 10 ** rng.uniform(0, 7, n)
    a = 10 ** rng.uniform(0, 9, n)
    j = 10 ** rng.uniform(0, 12, n)
    d = np.where(np.arange(n) % 2 == 0, a, 10 ** rng.uniform(0, 9, n))
    return dist, v, a, j, d


def ruckig_inputs(dist, v, a, j, d) -> list:
    """One InputParameter per move (built outside the timed loop). d_max is the limit
    against the direction of travel, so it maps onto ruckig's min or max acceleration."""
    out = []
    for i in range(dist.size):
        inp = ruckig.InputParameter(1)
        inp.current_position = [0.0]
        inp.target_position = [float(dist[i])]
        inp.max_velocity = [float(v[i])]
        inp.max_jerk = [float(j[i])]
        if dist[i] >= 0:
            inp.max_acceleration, inp.min_acceleration = [float(a[i])], [-float(d[i])]
        else:
            inp.max_acceleration, inp.min_acceleration = [float(d[i])], [-float(a[i])]
        out.append(inp)
    return out


#: Runs of every timed loop; each figure is the least CPU time of its runs.
ROUNDS = 3


def least_times(fns: list, rounds: int) -> list[float]:
    """The least CPU time of each function over `rounds` runs, the functions run in turn
    (a change of load in between affects every planner alike)."""
    best = [math.inf] * len(fns)
    for _ in range(rounds):
        for k, fn in enumerate(fns):
            t0 = time.process_time()
            fn()
            best[k] = min(best[k], time.process_time() - t0)
    return best


def rate(n: int, seconds: float) -> float:
    return n / seconds if seconds > 0 else float("inf")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, a few seconds")
    ap.add_argument("--n", type=int, default=None, help="moves compared one by one")
    ap.add_argument("--batch", type=int, default=None, help="moves in the batch run")
    ap.add_argument("--seed", type=int, default=2026)
    args = ap.parse_args(argv)
    n = args.n or (5_000 if args.quick else 100_000)
    n_batch = args.batch or (100_000 if args.quick else 1_000_000)
    if ruckig is None:
        raise SystemExit("ruckig is not installed (pip install ruckig)")

    dist, v, a, j, d = random_moves(n, args.seed)
    inputs = ruckig_inputs(dist, v, a, j, d)
    otg, traj = ruckig.Ruckig(1), ruckig.Trajectory(1)

    # correctness pass: durations, and which cases ruckig rejects
    ref = np.full(n, np.nan)
    for i, inp in enumerate(inputs):
        try:
            otg.calculate(inp, traj)
            ref[i] = traj.duration
        except ruckig.RuckigError:
            pass
    ours = np.array([jerk_limited_duration(dist[i], v[i], a[i], j[i], d_max=d[i])
                     for i in range(n)])
    batch = jerk_limited_durations(dist, v, a, j, d)
    ok = np.isfinite(ref)
    rel = np.abs(ours[ok] - ref[ok]) / ref[ok]
    rel_batch = np.abs(batch - ours) / ours
    ours_valid = np.isfinite(ours) & (ours > 0)

    # throughput: every figure is the least CPU time of ROUNDS runs, the runs of all the
    # planners taken in turn, so a change of the machine's load hits each of them alike
    solvable = [inp for inp, good in zip(inputs, ok, strict=True) if good]

    def ruckig_reused() -> None:  # ruckig on the cases it solves (no exceptions)
        for inp in solvable:
            otg.calculate(inp, traj)

    # the same with one reused InputParameter whose fields are set per move (a user's loop)
    one = ruckig.InputParameter(1)
    one.current_position = [0.0]
    fields = [(inp.target_position, inp.max_velocity, inp.max_acceleration,
               inp.min_acceleration, inp.max_jerk) for inp in solvable]

    def ruckig_set() -> None:
        for tp, mv, ma, mi, mj in fields:
            one.target_position, one.max_velocity, one.max_acceleration = tp, mv, ma
            one.min_acceleration, one.max_jerk = mi, mj
            otg.calculate(one, traj)

    args_list = list(zip(dist.tolist(), v.tolist(), a.tolist(), j.tolist(), d.tolist(),
                         strict=True))

    def ours_profile() -> None:
        for dd, vv, aa, jj, de in args_list:
            jerk_limited(dd, vv, aa, jj, d_max=de)

    def ours_duration() -> None:
        for dd, vv, aa, jj, de in args_list:
            jerk_limited_duration(dd, vv, aa, jj, d_max=de)

    # new objects per move (what a caller without a planner object pays), ruckig's cases
    m = min(len(solvable), 20_000)
    new_args = [(inp.target_position, inp.max_velocity, inp.max_acceleration,
                 inp.min_acceleration, inp.max_jerk) for inp in solvable[:m]]

    def ruckig_new() -> None:
        for tp, mv, ma, mi, mj in new_args:
            otg1, inp1, tr1 = ruckig.Ruckig(1), ruckig.InputParameter(1), ruckig.Trajectory(1)
            inp1.current_position = [0.0]
            inp1.target_position, inp1.max_velocity, inp1.max_acceleration = tp, mv, ma
            inp1.min_acceleration, inp1.max_jerk = mi, mj
            otg1.calculate(inp1, tr1)

    ok_idx = np.flatnonzero(ok)[:m]
    ours_args = [args_list[i] for i in ok_idx.tolist()]

    def ours_new() -> None:
        for dd, vv, aa, jj, de in ours_args:
            jerk_limited(dd, vv, aa, jj, d_max=de)

    # three axes synchronised, new objects per move (moves of 3 consecutive random cases)
    k3 = (m // 3) * 3
    tri = [ok_idx[i:i + 3] for i in range(0, k3, 3)]
    tri_in = [([abs(float(dist[i])) for i in idx], [float(v[i]) for i in idx],
               [float(a[i]) for i in idx], [-float(d[i]) for i in idx],
               [float(j[i]) for i in idx]) for idx in tri]

    def ruckig3() -> None:
        for tp, mv, ma, mi, mj in tri_in:
            otg3, inp3, tr3 = ruckig.Ruckig(3), ruckig.InputParameter(3), ruckig.Trajectory(3)
            inp3.current_position = [0.0, 0.0, 0.0]
            inp3.target_position, inp3.max_velocity = tp, mv
            inp3.max_acceleration, inp3.min_acceleration, inp3.max_jerk = ma, mi, mj
            with contextlib.suppress(ruckig.RuckigError, ValueError):  # its failures
                otg3.calculate(inp3, tr3)

    sync_args = [([abs(float(dist[i])) for i in idx], [float(v[i]) for i in idx],
                  [float(a[i]) for i in idx], [float(j[i]) for i in idx],
                  [float(d[i]) for i in idx]) for idx in tri]

    def ours_sync() -> None:
        for dd, vv, aa, jj, de in sync_args:
            jerk_limited_sync(dd, vv, aa, jj, d_max=de)

    bd, bv, ba, bj, bdd = random_moves(n_batch, args.seed + 1)
    jerk_limited_durations(bd[:1000], bv[:1000], ba[:1000], bj[:1000], bdd[:1000])  # warm-up

    def ours_batch() -> None:
        jerk_limited_durations(bd, bv, ba, bj, bdd)

    (t_ruckig, t_ruckig_set, t_profile, t_duration, t_ruckig_new, t_profile_new,
     t_ruckig3, t_sync, t_batch) = least_times(
        [ruckig_reused, ruckig_set, ours_profile, ours_duration, ruckig_new, ours_new,
         ruckig3, ours_sync, ours_batch], 1 if args.quick else ROUNDS)
    tracemalloc.start()
    jerk_limited_durations(bd, bv, ba, bj, bdd)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()

    r_ruckig = rate(len(solvable), t_ruckig)
    r_ruckig_set = rate(len(solvable), t_ruckig_set)
    r_profile = rate(n, t_profile)
    r_duration = rate(n, t_duration)
    r_batch = rate(n_batch, t_batch)
    print(f"jerk-limited rest-to-rest, N = {n} random moves (seed {args.seed}), "
          f"batch of {n_batch}")
    print("-" * 78)
    print(f"{'cases ruckig solves':44s} {ok.sum():>12d} ({100 * ok.mean():.2f} %)")
    print(f"{'cases ruckig failed, openmotion solved':44s} {(~ok & ours_valid).sum():>12d}")
    print(f"{'cases openmotion failed':44s} {(~ours_valid).sum():>12d}")
    print(f"{'max rel. duration diff vs ruckig':44s} {rel.max():>12.2e}")
    print(f"{'median rel. duration diff vs ruckig':44s} {np.median(rel):>12.2e}")
    print(f"{'max rel. diff batch vs scalar':44s} {rel_batch.max():>12.2e}")
    print("-" * 78)
    print(f"{'planner':44s} {'profiles/s':>12s} {'vs ruckig':>12s}")
    print(f"{'ruckig calculate() (reused objects)':44s} {r_ruckig:>12.0f} {1.0:>12.2f}")
    print(f"{'ruckig, setting fields of one InputParameter':44s} {r_ruckig_set:>12.0f} "
          f"{r_ruckig_set / r_ruckig:>12.3f}")
    print(f"{'openmotion jerk_limited -> Profile':44s} {r_profile:>12.0f} "
          f"{r_profile / r_ruckig:>12.3f}")
    print(f"{'openmotion jerk_limited_duration (scalar)':44s} {r_duration:>12.0f} "
          f"{r_duration / r_ruckig:>12.3f}")
    print(f"{'openmotion jerk_limited_durations (batch)':44s} {r_batch:>12.0f} "
          f"{r_batch / r_ruckig:>12.3f}")
    r_new, r_prof_new = rate(m, t_ruckig_new), rate(m, t_profile_new)
    r3, r_sync = rate(len(tri), t_ruckig3), rate(len(tri), t_sync)
    print(f"{'ruckig new objects per move':44s} {r_new:>12.0f}")
    print(f"{'openmotion jerk_limited (same moves)':44s} {r_prof_new:>12.0f} "
          f"{r_prof_new / r_new:>12.3f}  goal >= 0.5: "
          f"{'met' if r_prof_new >= 0.5 * r_new else 'not met'}")
    print(f"{'ruckig 3-DoF, new objects per move':44s} {r3:>12.0f}")
    print(f"{'openmotion jerk_limited_sync, 3 axes':44s} {r_sync:>12.0f} {r_sync / r3:>12.3f}"
          f"  goal >= 0.5: {'met' if r_sync >= 0.5 * r3 else 'not met'}")
    print(f"{'batch vs ruckig reused objects':44s} {'':>12s} {r_batch / r_ruckig:>12.3f}"
          f"  goal >= 3: {'met' if r_batch >= 3 * r_ruckig else 'not met'}")
    print("-" * 78)
    print(f"{'batch peak memory (tracemalloc)':44s} {peak / 2**20:>9.1f} MiB "
          f"({peak / n_batch:.0f} B/move)")


if __name__ == "__main__":
    main()
