"""Canonical commands (machine units) -> operations for a `Group` in machine units.

The runner executes `Op`s; this module builds them and thereby validates the whole program
against the machine (axis scales, speeds, arc geometry) before anything moves.

Units: a canonical linear position (machine_units, mm or inch) is a coordinate of the
runner's group, which is opened with `units=` (one AxisUnits per axis: signed pulses per
machine unit, from the axis's own unit: mm, inch with 25.4, `pulse` axes 1); rotary A/B/C
positions are degrees. The group plans the path in these units, so the feed is the true
vector speed and an arc is a true arc even when the axes have different pulses per unit
(the XYZU table: x 1000, y 2000 pulses/mm). Each move op carries its end point twice:
`end` (machine units, what the group is given) and `target` (command pulses, what the
compare engine's windows and the report use).

Feeds (F is units/min in G-code, feed_per_s here; the group's feed is units/s):
`feed_mode="uniform"` (default) gives the group F as its vector speed: exact F on every
linear (or rotary-only) move and arc; a move combining linear and rotary axes then has its
tool speed below F (the degrees count in the vector). `feed_mode="exact"` scales such a
mixed move so that its linear part runs at exactly F (as LinuxCNC).

G0 is a straight line (never a dog-leg ptp: predictable clearance) at the highest feed
with which no moving axis exceeds `rapid_ratio` x its maximum speed.

Arcs are group arcs in machine units. An arc whose end is off the circle by more than the
group's Arc accepts (a LinuxCNC-tolerated spiral) is sent as chords within `chord_tol`
(machine units), all at one feed so they form one chain.
"""

from __future__ import annotations

import gc
import math
from dataclasses import dataclass, field, fields

import numpy as np

from ..errors import MotionError
from ..path import Arc, Direction
from ..units import AxisUnits
from . import canon
from .analogout import AnalogOut
from .css import FeedMode, SpindleMode
from .options import MM_PER_INCH, ROTARY_LETTERS
from .orient import Orient
from .overrides import OverrideSwitch
from .probing import Probe, WaitInput
from .rigidtap import RigidTap
from .source import GCodeError
from .splines import SplineFeed
from .usermcodes import UserMCode

#: Blend tolerance (machine units) standing for G64 without P.
UNBOUNDED_BLEND = 1e12


@dataclass(frozen=True)
class Op:
    """One runner operation. kind: line, arc, delay, blend, pause, end, output, action,
    analog (M67/M68; `source` the AnalogOut), wait (M66; `source` the WaitInput), orient
    (M19; `source` the Orient), override (M48-M51; `source` the OverrideSwitch), usermcode
    (M100-M199; `source` the UserMCode). A probe
    move is
    a line whose `source` is a Probe, a spindle-synchronised one (G33/G76) a line whose
    `source` is the SyncedFeed.

    line/arc: `end` (machine units, all group axes), `target` (the same point in command
    pulses), `feed` (machine units/s), `rapid`; arc also `centre` (2 plane values, machine
    units), `plane`, `direction`, `turns`. delay: `seconds`. blend: `tolerance` (machine
    units) or None = exact stop. output: `index`, `level`, `synced`. action: `text`
    (spindle/coolant/tool/message), `outputs` ((index, level), ...), `barrier` (wait until
    the motion before it has ended).
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
    end: np.ndarray | None = None
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

    def to_pulses(self, p: tuple[float, ...] | np.ndarray) -> np.ndarray:
        return np.asarray(p, dtype=float) * self.ppu

    @property
    def vmax_units(self) -> np.ndarray:
        """Maximum speed per axis in machine units (deg for rotary axes) per second."""
        return self.vmax / np.abs(self.ppu)

    def axis_units(self, letters: list[str]) -> list[AxisUnits]:
        """The group's `units=`: one AxisUnits per axis, signed pulses per machine unit."""
        return [AxisUnits(k, "degree" if r else "machine", float(abs(q)),
                          1 if q > 0 else -1, float(v))
                for k, q, r, v in zip(letters, self.ppu, self.rotary, self.vmax_units,
                                      strict=True)]


@dataclass(frozen=True)
class ConvertOptions:
    rapid_ratio: float = 1.0
    feed_mode: str = "uniform"
    chord_tol: float = 0.001

    def __post_init__(self) -> None:
        r = self.rapid_ratio
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not 0.0 < r <= 1.0:
            raise MotionError(f"rapid_ratio must be in (0, 1], got {r!r}")
        if not isinstance(self.feed_mode, str) or self.feed_mode not in ("uniform", "exact"):
            raise MotionError(f"feed_mode must be 'uniform' or 'exact', got {self.feed_mode!r}")
        c = self.chord_tol
        if isinstance(c, bool) or not isinstance(c, (int, float)) or not c > 0.0 \
                or not math.isfinite(c):
            raise MotionError(f"chord_tol must be a finite number > 0, got {c!r}")


def _fail(cmd: canon.Command, msg: str) -> GCodeError:
    return GCodeError(msg, line=cmd.line, file=cmd.file)


def convert(cmds: list[canon.Command], scales: Scales, start: np.ndarray,
            opts: ConvertOptions, rpm: float = 0.0) -> list[Op]:
    """Validate and convert a canonical program that starts at `start` (pulses); `rpm`:
    the spindle speed commanded before it (a program continued after a probe).

    G38.x (`probing.Probe`) becomes a feed line whose `source` is the Probe record (the
    runner arms the probe input for it), M66 (`probing.WaitInput`) an op "wait". The
    garbage collector is paused meanwhile, as for the compile (fastpath.py): the op list
    only grows, and the collections it would trigger rescan every op made so far.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _convert(cmds, scales, start, opts, rpm)
    finally:
        if enabled:
            gc.enable()


def _convert(cmds: list[canon.Command], scales: Scales, start: np.ndarray,
             opts: ConvertOptions, rpm: float) -> list[Op]:
    lin = ~scales.rotary
    vmax = scales.vmax_units
    sys_max = float(np.max(vmax))
    ops: list[Op] = []
    pos = np.asarray(start, dtype=float) / scales.ppu  # machine units
    css: SpindleMode | None = None  # G96 in force
    s_word = rpm  # the S number (G96: the surface speed)

    def rpm_now() -> float:
        """Commanded rpm at the current point (G96: from X)."""
        if css is None or rpm == 0.0:
            return rpm
        return css.rpm(s_word, float(pos[css.x_axis])) if css.x_axis < len(pos) else rpm

    def feed_of(cmd: canon.Command, delta: np.ndarray, length: float) -> float:
        """Group feed (units/s) for a move of `length` (vector of all axes) by `delta`."""
        if cmd.duration is not None:  # G93 inverse time: the whole move in `duration`
            f = length / cmd.duration
        else:
            f = cmd.feed_per_s
            moving = np.abs(delta) > 0.0
            if opts.feed_mode == "exact" and (moving & lin).any() and \
                    (moving & ~lin).any():
                # F applies to the linear part (RS-274): scale by total / linear length
                f *= length / float(np.linalg.norm(delta[lin]))
        if not f > 0.0 or not math.isfinite(f):
            raise _fail(cmd, f"feed {cmd.feed_per_s:g} units/s gives no usable speed")
        return min(f, sys_max)  # F above the machine maxima is clamped (as LinuxCNC)

    ppu = scales.ppu
    uniform = opts.feed_mode == "uniform"
    for cmd in cmds:
        kind = type(cmd)
        if kind is _FEED or kind is _RAPID or isinstance(cmd, _FEED | _RAPID):
            # G0/G1, the bulk of a program, first (no other command is one of these)
            rapid = kind is _RAPID or (kind is not _FEED and isinstance(cmd, _RAPID))
            end = np.asarray(cmd.end, dtype=float)
            d = end - pos
            # = float(np.linalg.norm(d)): a 1-D norm is sqrt(d.dot(d)), correctly rounded
            length = math.sqrt(d.dot(d)) if d.ndim == 1 else float(np.linalg.norm(d))
            if length == 0.0:
                continue  # zero-length move: nothing to do
            if rapid:
                moving = np.abs(d) > 0.0
                f = min(float(np.min(opts.rapid_ratio * vmax[moving] * length
                                     / np.abs(d[moving]))), sys_max)
            elif uniform and cmd.duration is None:  # feed_of's uniform F, inline
                f = cmd.feed_per_s
                if not f > 0.0 or not math.isfinite(f):
                    raise _fail(cmd, f"feed {cmd.feed_per_s:g} units/s gives no usable speed")
                f = min(f, sys_max)
            else:
                f = feed_of(cmd, d, length)
            ops.append(_line_op(cmd.line, cmd.file, end * ppu, f, rapid, end, cmd))
            pos = end
        elif isinstance(cmd, Probe):
            end = np.asarray(cmd.end, dtype=float)
            f = min(cmd.feed_per_s, sys_max) if cmd.feed_per_s > 0 else sys_max
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(end), f, end=end,
                          source=cmd))
            pos = end
        elif isinstance(cmd, Orient):
            ops.append(Op("orient", cmd.line, cmd.file, seconds=cmd.timeout or 0.0,
                          text=f"M19 R{cmd.angle:g} P{cmd.mode}", barrier=True, source=cmd))
        elif isinstance(cmd, UserMCode):  # after the motion before it (usermcodes.py)
            ops.append(Op("usermcode", cmd.line, cmd.file, text=" ".join(
                [f"M{cmd.code}", *cmd.args[1:]]), barrier=True, source=cmd))
        elif isinstance(cmd, OverrideSwitch):  # where the next motion starts
            ops.append(Op("override", cmd.line, cmd.file, text=cmd.text, source=cmd))
        elif isinstance(cmd, AnalogOut):
            ops.append(Op("analog", cmd.line, cmd.file, index=cmd.index, synced=cmd.synced,
                          text=f"ao{cmd.index} = {cmd.value:g}", source=cmd))
        elif isinstance(cmd, WaitInput):
            ops.append(Op("wait", cmd.line, cmd.file, index=cmd.index, seconds=cmd.timeout,
                          source=cmd))
        elif isinstance(cmd, canon.SyncedFeed):
            end = np.asarray(cmd.end, dtype=float)
            length = float(np.linalg.norm(end - pos))
            if length == 0.0:
                continue
            if rpm <= 0.0 or not math.isfinite(rpm_now()):
                raise _fail(cmd, "a synchronised move (G33/G76) needs the spindle turning "
                                 "at S > 0")
            # no spindle feedback on this path: the nominal speed pitch x S
            f = cmd.pitch * rpm_now() / 60.0
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(end), min(f, sys_max),
                          end=end, source=cmd))
            pos = end
        elif isinstance(cmd, RigidTap):
            if rpm <= 0.0 or not math.isfinite(rpm_now()):
                raise _fail(cmd, "G33.1 needs the spindle turning at S > 0")
            # without spindle feedback: in at K x S, out at K x S x I (the runner with a
            # spindle axis replaces both by the synchronised tap, rigidtap_run.py)
            start, end = np.asarray(cmd.start, dtype=float), np.asarray(cmd.end, dtype=float)
            f = cmd.pitch * rpm_now() / 60.0
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(end), min(f, sys_max),
                          end=end, source=cmd))
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(start),
                          min(f * cmd.return_scale, sys_max), end=start, source=cmd))
            pos = start
        elif isinstance(cmd, canon.ArcMove):
            pos = _arc(cmd, scales, pos, opts, ops, feed_of)
        elif isinstance(cmd, SplineFeed):
            pos = _spline(cmd, scales, pos, opts, ops, feed_of)
        elif isinstance(cmd, canon.Dwell):
            ops.append(Op("delay", cmd.line, cmd.file, seconds=cmd.seconds, source=cmd))
        elif isinstance(cmd, canon.SetBlend):
            tol = None
            if cmd.mode == "blend":
                # G64 without P (best speed): no bound but the blend's own length limits
                tol = UNBOUNDED_BLEND if cmd.tolerance is None else float(cmd.tolerance)
            ops.append(Op("blend", cmd.line, cmd.file, tolerance=tol, source=cmd))
        elif isinstance(cmd, canon.Pause):
            ops.append(Op("pause", cmd.line, cmd.file, optional=cmd.optional, source=cmd))
        elif isinstance(cmd, canon.End):
            ops.append(Op("end", cmd.line, cmd.file, source=cmd))
        elif isinstance(cmd, canon.SetOutput):
            ops.append(Op("output", cmd.line, cmd.file, index=cmd.index, level=cmd.level,
                          synced=cmd.synced, source=cmd))
        elif isinstance(cmd, SpindleMode):
            css = cmd if cmd.per_s_unit > 0.0 else None
            ops.append(Op("action", cmd.line, cmd.file, text="G96 constant surface speed"
                          if css else "G97 rpm mode", barrier=True, source=cmd))
        elif isinstance(cmd, FeedMode):
            ops.append(Op("feedmode", cmd.line, cmd.file, synced=cmd.per_rev, source=cmd))
        elif isinstance(cmd, canon.Spindle):
            rpm = cmd.speed if cmd.on else 0.0
            s_word = cmd.speed
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


_FEED, _RAPID = canon.Feed, canon.Rapid
#: An Op's fields after `kind` as `Op(...)` sets them (the defaults), for `_line_op`.
_LINE_FIELDS = {f.name: f.default for f in fields(Op)[1:]}


def _line_op(line: int, file: str, target: np.ndarray, feed: float, rapid: bool,
             end: np.ndarray, source: canon.Command) -> Op:
    """`Op("line", line, file, target, feed, rapid, end=end, source=source)`, the same
    object (the same attributes in the same order) made without the frozen dataclass's
    field-by-field `__init__` (a program has one per line). The keys go in one by one in
    the class's order (`kind` first: an update of an empty dict would copy the template's
    table), so the dict stays a key-sharing one: 328 bytes an op, not 528 (264 by
    `__init__`, whose values are not in a dict object)."""
    op = _new(Op)
    d = op.__dict__
    d["kind"] = "line"
    d.update(_LINE_FIELDS)
    d["line"], d["file"], d["target"], d["feed"] = line, file, target, feed
    d["rapid"], d["end"], d["source"] = rapid, end, source
    return op


_new = object.__new__


def _spline(cmd: SplineFeed, scales: Scales, pos: np.ndarray, opts: ConvertOptions,
            ops: list[Op], feed_of) -> np.ndarray:
    """G5/G5.1/G5.2: chords within chord_tol, all at one feed (one look-ahead chain)."""
    try:
        pts = cmd.polyline(opts.chord_tol)
    except ValueError as exc:
        raise _fail(cmd, f"{exc}; raise chord_tol") from None
    pts[0] = pos
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    end = pts[-1]
    f = feed_of(cmd, end - pos, float(np.sum(seg)))
    for k in range(1, len(pts)):
        if seg[k - 1] > 0.0:
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(pts[k]), f,
                          end=pts[k].copy(), source=cmd))
    return end.copy()


def _arc(cmd: canon.ArcMove, scales: Scales, pos: np.ndarray, opts: ConvertOptions,
         ops: list[Op], feed_of) -> np.ndarray:
    i, j = cmd.plane
    end = np.asarray(cmd.end, dtype=float)
    centre = (float(cmd.centre[i]), float(cmd.centre[j]))
    try:
        Arc(pos, centre, end, plane=(i, j), direction=cmd.direction, turns=cmd.turns)
        exact = True
    except MotionError:
        exact = False  # a LinuxCNC-tolerated spiral end: send it as chords
    if exact:
        f = feed_of(cmd, end - pos, cmd.length)
        ops.append(Op("arc", cmd.line, cmd.file, scales.to_pulses(end), f, centre=centre,
                      plane=(i, j), direction=cmd.direction, turns=cmd.turns, end=end,
                      source=cmd))
        return end
    # chords: n segments of the arc within chord_tol (sagitta r(1-cos(theta/2)) <= tol)
    r = max(cmd.radius, cmd.end_radius)
    half = math.acos(max(-1.0, 1.0 - opts.chord_tol / r)) if opts.chord_tol < r else math.pi
    n = max(2, math.ceil(cmd.sweep / (2.0 * half)))
    if n > 100_000:
        raise _fail(cmd, f"arc needs {n} chords within chord_tol {opts.chord_tol:g}; "
                         "raise chord_tol")
    path = cmd.to_path()
    pts = path.point(np.linspace(0.0, path.length, n + 1))
    pts[0] = pos
    pts[-1] = end
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    # one feed for all chords (F; G93: the whole arc in `duration`): one look-ahead chain
    f = feed_of(cmd, end - pos, float(np.sum(seg)))
    for k in range(1, n + 1):
        if seg[k - 1] > 0.0:
            ops.append(Op("line", cmd.line, cmd.file, scales.to_pulses(pts[k]), f,
                          end=pts[k].copy(), source=cmd))
    return end
