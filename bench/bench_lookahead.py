"""Benchmark: blended look-ahead segments per second against Klipper's LookAheadQueue.

Two polylines, planned from rest to rest at feed 100 mm/s and 1000 mm/s^2:

- the 100-gon of radius 50 mm (bench_path's reference case, 3.6 degree turns),
- a 90-degree zig-zag of 200 segments (points (k, k mod 2) mm).

openmotion rounds every corner within a tolerance and plans the speeds along lines and arcs
(`path.plan_polyline`, one vectorised pass; also the per-corner object path
`blend_corner` + `plan_speeds` it replaces, for the record). Klipper takes the corners at
its junction-deviation speed (square_corner_velocity 5 mm/s, minimum_cruise_ratio 0, no
blending). Each prints segments/s (CPU time) and the path time; the ratio is
openmotion / Klipper, then the ratio of the path times ("same or shorter" within 0.1 %,
see SAME_TIME; the goal of issue 14: >= 1.0x at the same or shorter path time).

Klipper is read from a checkout given by `--klipper PATH` or the KLIPPER_PATH environment
variable (its klippy/toolhead.py `Move` and `LookAheadQueue`, with the modules it imports
for the printer, mcu, chelper and kinematics.extruder, stubbed as empty modules). Nothing of
Klipper is part of openmotion; without a checkout the bench says so and prints ours alone.

    python bench/bench_lookahead.py [--klipper PATH] [--seconds S]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import types
from collections.abc import Callable
from typing import Any

from openmotion.path import Line, blend_corner, plan_speeds
from openmotion.path.polyline import plan_polyline

FEED, ACCEL = 100.0, 1000.0  # mm/s, mm/s^2
SCV = 5.0                    # Klipper's square_corner_velocity, mm/s


def gon(n: int = 100, r: float = 50.0) -> list[tuple[float, float]]:
    pts = [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n))
           for k in range(n)]
    return pts + [pts[0]]


def zigzag(n: int = 200) -> list[tuple[float, float]]:
    return [(float(k), float(k % 2)) for k in range(n + 1)]


#: (name, points, blend tolerance in mm). 0.006 mm lets the 100-gon's blend arcs run at the
#: feed (radius >= F**2/a_n); 0.1 mm lets the zig-zag's corners beat Klipper's 5 mm/s.
CASES = (("100-gon r=50", gon(), 0.006), ("zig-zag 90 deg", zigzag(), 0.1))
#: Path times within this fraction of Klipper's count as the same: a blend arc shares its
#: acceleration budget with the centripetal part (arc_tangential_ratio 0.5), so ramping up
#: through arcs is a little slower than through Klipper's corners, which step the velocity.
SAME_TIME = 1e-3


def rate(fn: Callable[[], Any], segments: int, seconds: float) -> tuple[float, Any]:
    """Segments per CPU second of fn (best of 3 runs of about seconds/3 each)."""
    out = fn()  # warm up
    best = math.inf
    for _ in range(3):
        n, t0 = 0, time.process_time()
        while True:
            out = fn()
            n += 1
            dt = time.process_time() - t0
            if dt >= seconds / 3:
                break
        best = min(best, dt / n)
    return segments / best, out


def ours(pts: list[tuple[float, float]], tol: float) -> Callable[[], Any]:
    return lambda: plan_polyline(pts, FEED, ACCEL, tolerance=tol)


def ours_objects(pts: list[tuple[float, float]], tol: float) -> Callable[[], Any]:
    """The per-corner object path: Line per segment, blend_corner per corner, plan_speeds."""
    def run() -> float:
        lines = [Line(pts[k], pts[k + 1]) for k in range(len(pts) - 1)]
        els: list[Any] = []
        prev: Any = lines[0]
        for nxt in lines[1:]:
            b = blend_corner(prev, nxt, tol)
            if b is None:
                els.append(prev)
                prev = nxt
            else:
                els += [b.first, b.arc]
                prev = b.second
        els.append(prev)
        return sum(s.duration for s in plan_speeds(els, FEED, ACCEL))
    return run


def load_klipper(path: str) -> Any:
    """klippy/toolhead.py from a Klipper checkout, its hardware imports stubbed."""
    klippy = os.path.join(path, "klippy")
    if not os.path.isfile(os.path.join(klippy, "toolhead.py")):
        raise SystemExit(f"no klippy/toolhead.py under {path!r}")
    for name in ("mcu", "chelper", "kinematics", "kinematics.extruder"):
        sys.modules.setdefault(name, types.ModuleType(name))
    sys.path.insert(0, klippy)
    import toolhead  # type: ignore[import-not-found]
    return toolhead


def klipper(th: Any, pts: list[tuple[float, float]]) -> Callable[[], Any]:
    head = types.SimpleNamespace(max_accel=ACCEL, max_velocity=FEED, extra_axes=[],
                                 junction_deviation=SCV * SCV * (math.sqrt(2.0) - 1.0) / ACCEL,
                                 mcr_pseudo_accel=ACCEL)
    p4 = [(x, y, 0.0, 0.0) for x, y in pts]

    def run() -> float:
        q = th.LookAheadQueue()
        for k in range(len(p4) - 1):
            q.add_move(th.Move(head, p4[k], p4[k + 1], FEED))
        return sum(m.accel_t + m.cruise_t + m.decel_t for m in q.flush())
    return run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--klipper", default=os.environ.get("KLIPPER_PATH"),
                    help="path of a Klipper checkout (default: $KLIPPER_PATH)")
    ap.add_argument("--seconds", type=float, default=1.5, help="CPU seconds per figure")
    args = ap.parse_args()
    th = load_klipper(args.klipper) if args.klipper else None
    if th is None:
        print("no Klipper checkout given (--klipper PATH or KLIPPER_PATH): openmotion alone")
    print(f"feed {FEED:g} mm/s, accel {ACCEL:g} mm/s^2; Klipper square_corner_velocity "
          f"{SCV:g} mm/s, minimum_cruise_ratio 0")
    for name, pts, tol in CASES:
        n = len(pts) - 1
        r_new, plan = rate(ours(pts, tol), n, args.seconds)
        r_obj, t_obj = rate(ours_objects(pts, tol), n, min(args.seconds, 1.0))
        line = (f"{name} ({n} segments, blend {tol:g} mm): openmotion plan_polyline "
                f"{r_new:,.0f} seg/s, path {plan.duration:.4f} s (object path blend_corner + "
                f"plan_speeds {r_obj:,.0f} seg/s, path {t_obj:.4f} s)")
        if th is not None:
            r_k, t_k = rate(klipper(th, pts), n, args.seconds)
            ok = plan.duration <= t_k * (1.0 + SAME_TIME)
            line += (f"; Klipper LookAheadQueue {r_k:,.0f} seg/s, path {t_k:.4f} s; ratio "
                     f"{r_new / r_k:.2f}x, path time ratio {plan.duration / t_k:.4f} "
                     f"({'same or shorter' if ok else 'LONGER'}); goal >= 1.0x: "
                     f"{'met' if r_new >= r_k and ok else 'not met'}")
        print(line)


if __name__ == "__main__":
    main()
