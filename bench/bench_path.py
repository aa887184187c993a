"""Benchmark: path traversal time of the group planner against exact stop and TOPP-RA.

Issue 4, item 7. Four tool paths run through `Group` on the simulated table (1000
pulses/mm, per-axis limits 100 mm/s and 1000 mm/s^2, feed 141 mm/s with the "slow" policy so
the look-ahead slows down to the axis limits):

- a 100-gon of radius 50 mm (the issue's reference case),
- a zig-zag of 200 segments (1 mm pitch, 3 mm amplitude, 143 degree turns),
- a contour: a three-lobed cam outline (150 segments) with a rectangular keyway cut in,
- a shallow zig-zag: 200 segments of 1 mm with 10-30 degree turns (CAM-like).

For each it prints openmotion's blended traversal time, the exact-stop time, TOPP-RA's
time-optimal time for the same waypoints and per-axis limits, the ratios, the blend
tolerance used and openmotion's largest contour deviation (measured on the recorded run)
plus the largest per-axis acceleration over its limit. TOPP-RA follows a cubic spline
through the waypoints (parameterised by chord length), so its own largest distance from the
polyline is printed too: where it is large the comparison is unfair and exact stop is the
reference (the issue says so for zig-zags).

Then, for both zig-zags (issue 4, item 5), the time and the number of sign reversals of the
recorded path acceleration with the minimum cruise ratio off (0), at 0.5 and 0.9, once with the
corners blended within the tolerance and once taken at a corner velocity of 5 mm/s
(junction deviation, `Group.set_corner_velocity`; the largest per-axis velocity step
measured on the run is printed with it).

    python bench/bench_path.py
"""

from __future__ import annotations

import logging
import time

import numpy as np

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupState
from openmotion.control.groups.pathexec import contour_error
from openmotion.path import Line

try:
    import toppra
    import toppra.algorithm
    import toppra.constraint
except ImportError:  # pragma: no cover - toppra is a dev dependency
    toppra = None

PPMM = 1000.0  # pulses per mm
V_MM, A_MM = 100.0, 1000.0  # per-axis limits, mm/s and mm/s^2
V, A = V_MM * PPMM, A_MM * PPMM  # the same in pulses
ORIGIN = 60_000.0  # paths are placed in the positive quadrant (pulses)
RATIOS = (0.0, 0.5, 0.9)  # minimum cruise ratios of the zig-zag table
PERIOD = Controller().period  # servo cycle (s)


def _idle(g: Group) -> bool:
    return g.state is GroupState.IDLE and g.queue_length == 0 and not any(
        a.is_moving for a in g.axes)


def traverse(pts: np.ndarray, tol: float, *, corner_v: float = 0.0,
             ratio: float = 0.0) -> tuple[float, float, float]:
    """(time, largest contour deviation in pulses, largest axis acceleration / limit) of
    one run of the polyline `pts` (pulses) from rest to rest, blended within `tol` pulses
    (0: exact stop), other corners at `corner_v` pps, minimum cruise ratio `ratio`."""
    return _traverse(pts, tol, corner_v, ratio)[:3]


def _traverse(pts: np.ndarray, tol: float, corner_v: float,
              ratio: float) -> tuple[float, float, float, int, float]:
    """traverse() plus the acceleration reversals and the largest per-axis velocity step
    between two servo cycles (pps)."""
    ctl = Controller()
    ctl.enable_all()
    for k in range(len(ctl.axes)):
        ctl.hardware.scenario.remove_switch(k, "mel")
    g = Group(ctl, ["x", "y"], feed=V * np.sqrt(2.0), acc_time=V / A)
    g.set_axis_limit_policy("slow")
    g.set_max_pulse_speed([V, V])
    g.set_max_pulse_acc([A, A])
    if tol > 0.0:
        g.enable_blend(tol)
    g.set_corner_velocity(corner_v)
    g.set_min_cruise_ratio(ratio)
    g.ptp(pts[0])
    ctl.step()
    ctl.run_until(lambda: _idle(g), 60)
    t0 = ctl.time
    for p in pts[1:]:
        g.line(p)
    ctl.step()
    ctl.run_until(lambda: _idle(g), 300)
    t = np.linspace(t0, ctl.time, 50_001)
    smp = [ctl.history.sample(a.index, t) for a in g.axes]
    xy = np.stack([s.p for s in smp], axis=1)
    dev = float(contour_error(xy, _lines(pts)).max())
    acc = max(float(np.abs(s.a).max()) for s in smp) / A
    cyc = t0 + np.arange(int(round((ctl.time - t0) / ctl.period)) + 1) * ctl.period
    per = [ctl.history.sample(a.index, cyc) for a in g.axes]
    step = max(float(np.abs(np.diff(s.v)).max()) for s in per)
    return ctl.time - t0, dev, acc, reversals(per), step


def reversals(smp: list) -> int:
    """Sign changes of the recorded path acceleration v.a/|v| (a dead band of 0.1 % of the
    axis acceleration limit ignores rounding while cruising)."""
    v = np.stack([s.v for s in smp], axis=1)
    a = np.stack([s.a for s in smp], axis=1)
    tang = (v * a).sum(axis=1) / np.maximum(np.linalg.norm(v, axis=1), 1e-9)
    sign = np.sign(tang[np.abs(tang) > 1e-3 * A])
    return int(np.count_nonzero(sign[1:] != sign[:-1]))


def _lines(pts: np.ndarray) -> list[Line]:
    return [Line(a, b) for a, b in zip(pts[:-1], pts[1:], strict=True)]


def topp_ra(pts_mm: np.ndarray) -> tuple[float, float]:
    """(TOPP-RA's time-optimal duration in s, its spline's largest distance from the
    polyline in mm) for the waypoints `pts_mm` and the per-axis limits V_MM, A_MM."""
    ss = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts_mm, axis=0), axis=1))])
    path = toppra.SplineInterpolator(ss, pts_mm)
    d = pts_mm.shape[1]
    vel = toppra.constraint.JointVelocityConstraint(np.array([[-V_MM, V_MM]] * d))
    acc = toppra.constraint.JointAccelerationConstraint(np.array([[-A_MM, A_MM]] * d))
    grid = np.linspace(0.0, ss[-1], 20 * len(ss))
    inst = toppra.algorithm.TOPPRA([vel, acc], path, gridpoints=grid,
                                   parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0.0, 0.0)
    if traj is None:  # pragma: no cover - infeasible would be a toppra failure here
        return float("nan"), float("nan")
    spline = path(np.linspace(0.0, ss[-1], 20_001))
    stray = float(contour_error(spline, _lines(pts_mm)).max())
    return float(traj.duration), stray


def polygon(n: int = 100, r_mm: float = 50.0) -> tuple[np.ndarray, float]:
    """Regular n-gon inscribed in a circle (closed), and its chord deviation (pulses)."""
    ang = np.linspace(0.0, 2.0 * np.pi, n + 1)
    r = r_mm * PPMM
    pts = np.stack([ORIGIN + r * np.cos(ang), ORIGIN + r * np.sin(ang)], axis=1)
    return pts, r * (1.0 - np.cos(np.pi / n))


def zigzag(n: int = 200) -> np.ndarray:
    """n segments, 1 mm pitch, 3 mm amplitude: 143 degree turns at every vertex."""
    k = np.arange(n + 1)
    return np.stack([1000.0 + 1000.0 * k, 1000.0 + 3000.0 * (k % 2)], axis=1)


def shallow_zigzag(n: int = 200) -> np.ndarray:
    """n segments of 1 mm; the heading alternates +-turn/2 about x with turns of 10-30
    degrees (golden-ratio sequence): a CAM-like wavy line."""
    turn = np.radians(10.0 + 20.0 * ((0.618034 * np.arange(n)) % 1.0))
    head = np.where(np.arange(n) % 2 == 0, 0.5, -0.5) * turn
    steps = PPMM * np.stack([np.cos(head), np.sin(head)], axis=1)
    return np.concatenate([[[0.0, 0.0]], np.cumsum(steps, axis=0)]) + [1000.0, ORIGIN]


def contour(n: int = 150, keyway: bool = True) -> tuple[np.ndarray, float]:
    """A three-lobed cam outline r = 40 + 6 cos(3 theta) mm sampled into n chords, with a
    6 mm wide, 5 mm deep keyway at theta = 0 (four sharp corners) unless `keyway` is
    False; closed. Also the largest chord deviation of the sampled outline (pulses)."""
    th = np.linspace(0.0, 2.0 * np.pi, n + 1)
    dth = float(th[1] - th[0])
    rho = 46.0 * 46.0 / (46.0 + 9.0 * 6.0) * PPMM  # (r^2)^1.5 / (r^2 - r r'') at a tip
    # chord deviation at the lobe tips (smallest radius of curvature): sagitta
    # L^2 / (8 rho) of the chord L = r dtheta there (r' = 0 at a tip)
    sag = (46.0 * PPMM * dth) ** 2 / (8.0 * rho)
    if not keyway:
        r = (40.0 + 6.0 * np.cos(3.0 * th)) * PPMM
        return np.stack([r * np.cos(th), r * np.sin(th)], axis=1) + ORIGIN, sag
    half = np.arcsin(3.0 / 46.0)  # keyway half-width 3 mm at r ~ 46 mm
    th = th[(th > half) & (th < 2.0 * np.pi - half)]
    th = np.concatenate([[half], th, [2.0 * np.pi - half]])
    r = (40.0 + 6.0 * np.cos(3.0 * th)) * PPMM
    outline = np.stack([r * np.cos(th), r * np.sin(th)], axis=1)
    depth = 5.0 * PPMM
    a, b = outline[-1], outline[0]
    key = np.array([a - [depth, 0.0], b - [depth, 0.0]])
    pts = np.concatenate([key[1:], outline, key[:1], key[1:]]) + ORIGIN
    return pts, sag


def main() -> None:
    logging.disable(logging.WARNING)  # toppra logs every solve
    poly, poly_tol = polygon()
    cam, cam_tol = contour()
    lobes, _ = contour(keyway=False)
    cases = (
        ("100-gon r=50mm", poly, poly_tol),
        ("zig-zag 200 seg", zigzag(), 50.0),
        ("cam outline 150 seg", lobes, cam_tol),
        (f"cam + keyway {len(cam) - 1} seg", cam, cam_tol),
        ("shallow zig-zag 200 seg", shallow_zigzag(), 50.0),
    )
    print(f"per-axis limits {V_MM:g} mm/s, {A_MM:g} mm/s^2; {PPMM:g} pulses/mm; "
          f"feed {V_MM * np.sqrt(2):.0f} mm/s, policy 'slow'")
    for name, pts, tol in cases:
        w0 = time.perf_counter()
        te, _, _ = traverse(pts, 0.0)
        tb, dev, acc = traverse(pts, tol)
        line = (f"{name}: openmotion {tb:.3f} s (tolerance {tol:.1f} pulses = "
                f"{tol / PPMM * 1000:.1f} um), exact stop {te:.3f} s, "
                f"ratio to exact stop {tb / te:.3f}")
        if toppra is not None:
            tt, stray = topp_ra(pts / PPMM)
            fair = stray * PPMM <= 1.5 * tol  # the spline is the polyline's path, nearly
            line += (f", TOPP-RA {tt:.3f} s (its spline strays {stray * 1000:.1f} um from "
                     f"the polyline{'' if fair else ': not a fair reference'}), "
                     f"ratio to TOPP-RA {tb / tt:.3f}")
        else:  # pragma: no cover
            line += ", TOPP-RA not installed (pip install toppra)"
        line += (f"; max contour deviation {dev:.2f} pulses, max axis accel "
                 f"{acc:.12f} x limit [{time.perf_counter() - w0:.1f} s wall]")
        print(line)
    cruise_table(cases[1][1], cases[-1][1])


def cruise_table(zz: np.ndarray, shallow: np.ndarray) -> None:
    """Time and acceleration reversals with the minimum cruise ratio off, 0.5 and 0.9."""
    corner_v = 5.0 * PPMM
    print("minimum cruise ratio: time and sign reversals of the recorded path acceleration")
    for name, pts in (("zig-zag 200 seg", zz), ("shallow zig-zag 200 seg", shallow)):
        te = _traverse(pts, 0.0, 0.0, 0.0)[0]
        for label, tol, cv in (("blend 50 pulses", 50.0, 0.0),
                               (f"corner velocity {corner_v / PPMM:g} mm/s", 0.0, corner_v)):
            runs = [_traverse(pts, tol, cv, r) for r in RATIOS]
            line = f"{name}, {label}: exact stop {te:.3f} s; " + "; ".join(
                f"ratio {r:g}: {x[0]:.3f} s, {x[3]} reversals"
                for r, x in zip(RATIOS, runs, strict=True))
            if cv > 0.0:
                line += (f"; largest axis velocity change in one cycle "
                         f"{max(x[4] for x in runs) / PPMM:.2f} mm/s (bound: corner velocity "
                         f"+ axis accel x cycle = {(cv + A * PERIOD) / PPMM:.2f})")
            print(line)


if __name__ == "__main__":
    main()
