"""Canonical commands (machine units) -> pulse-space operations for a `Group`.

The runner executes `Op`s; this module builds them and thereby validates the whole program
against the machine (axis scales, speeds, arc geometry in pulses) before anything moves.

Units: a canonical linear position (machine_units, mm or inch) becomes user units of the
axis (mm, inch: converted with 25.4; `pulse` axes take the value as pulses) and then command
pulses with `AxisUnits.to_pulses`; rotary A/B/C positions are degrees.

Feeds (F is units/min in G-code, feed_per_s here): a Group's feed is the vector speed in
PULSE space. `feed_mode="uniform"` (default) uses one factor per program, the smallest
|pulses per unit| of the group's linear axes (rotary axes for rotary-only moves): on a
machine whose linear axes share a scale this is exactly F; otherwise the tool speed is at
most F (equal to F along the finest-scaled axis) and consecutive moves keep the same pulse
feed, so the look-ahead chains them. `feed_mode="exact"` converts every move with its own
factor P/L (pulse length / programmed length): exact F everywhere, but moves in different
directions get different pulse feeds and the group stops between them.

G0 is a straight line (never a dog-leg ptp: predictable clearance) at the highest pulse
feed with which no moving axis exceeds `rapid_ratio` x its maximum speed.

Arcs whose plane axes have equal |pulses per unit| are Group arcs in pulse space (the
direction flips when exactly one plane axis is reversed). Otherwise the circle is an ellipse
in pulses and the arc is sent as chords within `chord_tol` (machine units), all with one
feed so they form one chain.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import MotionError
from ..path import Arc, Direction
from ..units import AxisUnits
from . import canon
from .options import MM_PER_INCH, ROTARY_LETTERS
from .source import GCodeError

#: Blend tolerance (pulses) standing for G64 without P.
UNBOUNDED_BLEND = 1e12


@dataclass(frozen=True)
class Op:
    """One runner operation. kind: line, arc, delay, blend, pause, end, output, action.

    line/arc: `target` (pulses, all group axes), `feed` (pps), `rapid`; arc also `centre`
    (2 plane values, pulses), `plane`, `direction`, `turns`. delay: `seconds`. blend:
    `tolerance` (pulses) or None = exact stop. output: `index`, `level`, `synced`.
    action: `text` (spindle/coolant/tool/message), `outputs` ((index, level), ...),
    `barrier` (wait until the motion before it has ended).
    """

    kind: str
    line: int
    file: str = ""
    target: np.ndarray | None = None
    feed: float = 0.0
    rapid: bool = False
    centre: tuple[float, float] | None = None
    plane: tuple[int, int] = (0, 1)
    direction: Direction = Direction.CCW
    turns: int = 0
    seconds: float = 0.0
    tolerance: float | None = None
    index: int = 0
    level: bool = False
    synced: bool = False
    optional: bool = False
    text: str = ""
    outputs: tuple[tuple[int, bool], ...] = ()
    barrier: bool = False
    source: canon.Command | None = field(default=None, repr=False, compare=False)


@dataclass(frozen=True)
class Scales:
    """Per group axis: effective signed pulses per canonical unit, maximum speed (pps)."""

    ppu: np.ndarray
    vmax: np.ndarray
    rotary: np.ndarray  # bool per axis

    @classmethod
    def build(cls, units: list[AxisUnits], letters: list[str], machine_units: str) -> Scales:
        ppu, vmax, rot = [], [], []
        for u, letter in zip(units, letters, strict=True):
            f = 1.0
            if u.unit in ("mm", "inch") and u.unit != machine_units:
                f = MM_PER_INCH if u.unit == "mm" else 1.0 / MM_PER_INCH
            if u.unit == "pulse":
                f = 1.0 / u.pulses_per_unit
            ppu.append(u.sign * u.pulses_per_unit * f)
            vmax.append(u.max_speed_pps)
            rot.append(letter in ROTARY_LETTERS)
        return cls(np.array(ppu), np.array(vmax), np.array(rot, dtype=bool))

    def to_pulses(self, p: tuple[float, ...]) -> np.ndarray:
        return np.asarray(p, dtype=float) * self.ppu


@dataclass(frozen=True)
class ConvertOptions:
    rapid_ratio: float = 1.0
    feed_mode: str = "uniform"
    chord_tol: float = 0.001

    def __post_init__(self) -> None:
        r = self.rapid_ratio
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not 0.0 < r <= 1.0:
            raise MotionError(f"rapid_ratio must be in (0, 1], got {r!r}")
        if self.feed_mode not in ("uniform", "exact"):
            raise MotionError(f"feed_mode must be 'uniform' or 'exact', got {self.feed_mode!r}")
        c = self.chord_tol
        if isinstance(c, bool) or not isinstance(c, (int, float)) or not c > 0.0 \
                or not math.isfinite(c):
            raise MotionError(f"chord_tol must be a finite number > 0, got {c!r}")


def _fail(cmd: canon.Command, msg: str) -> GCodeError:
    return GCodeError(msg, line=cmd.line, file=cmd.file)


def convert(cmds: list[canon.Command], scales: Scales, start: np.ndarray,
            opts: ConvertOptions) -> list[Op]:
    """Validate and convert a canonical program that starts at `start` (pulses)."""
    lin = ~scales.rotary
    k_lin = float(np.min(np.abs(scales.ppu[lin]))) if lin.any() else 1.0
    k_rot = float(np.min(np.abs(scales.ppu[scales.rotary]))) if scales.rotary.any() else 1.0
    sys_max = float(np.max(scales.vmax))
    ops: list[Op] = []
    pos = np.asarray(start, dtype=float).copy()
    ppu = np.abs(scales.ppu)

    def feed_pps(cmd: canon.Command, delta_units: np.ndarray, length_units: float,
                 pulse_len: float) -> float:
        if cmd.duration is not None:  # G93 inverse time: the whole move in `duration`
            f = pulse_len / cmd.duration
        elif opts.feed_mode == "exact" and length_units > 0.0:
            f = cmd.feed_per_s * pulse_len / length_units
        else:
            moving = np.abs(delta_units) > 0.0
            f = cmd.feed_per_s * (k_lin if (moving & lin).any() else k_rot)
        if not f > 0.0 or not math.isfinite(f):
            raise _fail(cmd, f"feed {cmd.feed_per_s:g} units/s gives no usable pulse speed")
        return min(f, sys_max)  # F above the machine maxima is clamped (as LinuxCNC)

    for cmd in cmds:
        if isinstance(cmd, canon.Rapid | canon.Feed):
            target = scales.to_pulses(cmd.end)
            d = target - pos
            plen = float(np.linalg.norm(d))
            if plen == 0.0:
                continue  # zero-length move: nothing to do
            if isinstance(cmd, canon.Rapid):
                moving = np.abs(d) > 0.0
                f = float(np.min(opts.rapid_ratio * scales.vmax[moving] * plen
                                 / np.abs(d[moving])))
                ops.append(Op("line", cmd.line, cmd.file, target, min(f, sys_max), True,
                              source=cmd))
            else:
                du = d / scales.ppu
                lu = float(np.linalg.norm(du[lin])) if (np.abs(du[lin]) > 0).any() \
                    else float(np.linalg.norm(du))
                ops.append(Op("line", cmd.line, cmd.file, target,
                              feed_pps(cmd, du, lu, plen), source=cmd))
            pos = target
        elif isinstance(cmd, canon.ArcMove):
            pos = _arc(cmd, scales, pos, opts, ops, feed_pps, ppu)
        elif isinstance(cmd, canon.Dwell):
            ops.append(Op("delay", cmd.line, cmd.file, seconds=cmd.seconds, source=cmd))
        elif isinstance(cmd, canon.SetBlend):
            tol = None
            if cmd.mode == "blend":
                # the tolerance in the finest axis's pulses: a deviation of tol pulses is
                # at most tol / min|ppu| machine units on every axis
                # G64 without P (best speed): no bound but the blend's own length limits
                tol = UNBOUNDED_BLEND if cmd.tolerance is None \
                    else cmd.tolerance * float(np.min(ppu))
            ops.append(Op("blend", cmd.line, cmd.file, tolerance=tol, source=cmd))
        elif isinstance(cmd, canon.Pause):
            ops.append(Op("pause", cmd.line, cmd.file, optional=cmd.optional, source=cmd))
        elif isinstance(cmd, canon.End):
            ops.append(Op("end", cmd.line, cmd.file, source=cmd))
        elif isinstance(cmd, canon.SetOutput):
            ops.append(Op("output", cmd.line, cmd.file, index=cmd.index, level=cmd.level,
                          synced=cmd.synced, source=cmd))
        elif isinstance(cmd, canon.Spindle):
            outs = () if cmd.output is None else ((cmd.output, cmd.on),)
            txt = f"spindle {'on' if cmd.on else 'off'} S{cmd.speed:g}"
            ops.append(Op("action", cmd.line, cmd.file, text=txt, outputs=outs, barrier=True,
                          source=cmd))
        elif isinstance(cmd, canon.Coolant):
            outs = tuple((o, lv) for o, lv in ((cmd.mist_output, cmd.mist),
                                               (cmd.flood_output, cmd.flood)) if o is not None)
            ops.append(Op("action", cmd.line, cmd.file, text=f"coolant mist={cmd.mist} "
                          f"flood={cmd.flood}", outputs=outs, barrier=True, source=cmd))
        elif isinstance(cmd, canon.ToolChange):
            ops.append(Op("action", cmd.line, cmd.file, text=f"tool change T{cmd.tool} "
                          "(no changer: ignored)", barrier=True, source=cmd))
        elif isinstance(cmd, canon.Message):
            ops.append(Op("action", cmd.line, cmd.file, text=f"{cmd.kind}: {cmd.text}",
                          source=cmd))
        else:  # pragma: no cover - canon is closed
            raise _fail(cmd, f"unsupported command {type(cmd).__name__}")
    return ops


def _arc(cmd: canon.ArcMove, scales: Scales, pos: np.ndarray, opts: ConvertOptions,
         ops: list[Op], feed_pps, ppu: np.ndarray) -> np.ndarray:
    i, j = cmd.plane
    target = scales.to_pulses(cmd.end)
    centre_p = scales.to_pulses(cmd.centre)
    r_p = cmd.radius * ppu[i]
    lin2 = float(np.sum(((target - pos) ** 2)[[k for k in range(len(pos)) if k not in (i, j)]]))
    direction = cmd.direction
    same = math.isclose(ppu[i], ppu[j], rel_tol=1e-12)
    if same:
        if np.sign(scales.ppu[i]) != np.sign(scales.ppu[j]):
            direction = Direction.CW if direction == Direction.CCW else Direction.CCW
        try:
            Arc(pos, (centre_p[i], centre_p[j]), target, plane=(i, j), direction=direction,
                turns=cmd.turns)
        except MotionError:
            same = False  # a LinuxCNC-tolerated spiral end: send it as chords
    if same:
        plen = math.hypot(r_p * cmd.sweep, math.sqrt(lin2))
        du = (target - pos) / scales.ppu
        f = feed_pps(cmd, du, cmd.length, plen)
        ops.append(Op("arc", cmd.line, cmd.file, target, f, centre=(centre_p[i], centre_p[j]),
                      plane=(i, j), direction=direction, turns=cmd.turns, source=cmd))
        return target
    # chords: n segments of the arc within chord_tol (sagitta r(1-cos(theta/2)) <= tol)
    r = max(cmd.radius, cmd.end_radius)
    half = math.acos(max(-1.0, 1.0 - opts.chord_tol / r)) if opts.chord_tol < r else math.pi
    n = max(2, math.ceil(cmd.sweep / (2.0 * half)))
    if n > 100_000:
        raise _fail(cmd, f"arc needs {n} chords within chord_tol {opts.chord_tol:g}; "
                         "raise chord_tol")
    path = cmd.to_path()
    pts = path.point(np.linspace(0.0, path.length, n + 1))
    pts[-1] = np.asarray(cmd.end, dtype=float)
    pp = pts * scales.ppu
    pp[0] = pos
    seg = np.linalg.norm(np.diff(pp, axis=0), axis=1)
    du_all = np.diff(pts, axis=0)
    # one feed for all chords (the smallest, so no chord exceeds F): one look-ahead chain
    f = min(feed_pps(cmd, du_all[k], float(np.linalg.norm(du_all[k])) * cmd.length
                     / max(path.length, 1e-300), float(seg[k])) if seg[k] > 0 else math.inf
            for k in range(n))
    if cmd.duration is not None:
        f = float(np.sum(seg)) / cmd.duration
    for k in range(1, n + 1):
        if seg[k - 1] > 0.0:
            ops.append(Op("line", cmd.line, cmd.file, pp[k].copy(), f, source=cmd))
    return pp[-1]
