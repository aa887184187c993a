"""Cutter radius compensation G41/G42/G41.1/G42.1 and G40, as LinuxCNC's interpreter does it.

The tool centre runs at the tool radius left (G41) or right (G42) of the programmed XY path.
- Entry: the first XY move after G41/G42 must be a straight line longer than the radius;
  it ends at the programmed end point moved by the radius perpendicular to the move.
- Corners: a convex corner (turn away from the tool by more than 0.05 rad) gets an arc
  around the programmed corner (G1; a straight move for G0); a concave corner moves the end
  of the previous move back to where the tool touches both elements. Moves whose end is
  moved are held in a queue until the next XY move decides it; moving an end so far back
  that the move would run backwards (or an arc would grow) is a gouge: an error naming
  the line. Tangent joins (within 0.05 rad) pass straight through.
- Arcs are offset by the radius (inside arcs must be larger than the tool).
- G40: the queue is flushed where the tool is; the next move (the exit) is a straight
  line from the compensated point to the programmed one; an arc right after G40 is refused.
Work in machine coordinates of the plane: X/Y in G17, Z/X in G18 (lathes; the tool table's
X/Z offsets place the nose, its orientation only matters for LinuxCNC's arc entry, which is
refused here). Offsets are translations and units scale uniformly, so distances hold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from ..path import Direction
from . import canon
from .arcgeom import arc_extent, sweep_angle
from .parser import Block

if TYPE_CHECKING:
    from .modal import Modal

#: LinuxCNC TOLERANCE_CONCAVE_CORNER (rad): corners below it are tangent.
SMALL = 0.05
HALF_PI = 0.5 * math.pi


def signed_sweep(sx: float, sy: float, cx: float, cy: float, turn: int, ex: float,
                 ey: float) -> float:
    """Signed angle (rad) of an arc from s to e about c: > 0 CCW; |turn| counts circles."""
    if turn == 0:
        return 0.0
    a0 = math.atan2(sy - cy, sx - cx)
    a1 = math.atan2(ey - cy, ex - cx)
    if turn > 0:
        d = (a1 - a0) % (2 * math.pi)
        if d <= 0.0:
            d += 2 * math.pi
        return d + 2 * math.pi * (turn - 1)
    d = (a0 - a1) % (2 * math.pi)
    if d <= 0.0:
        d += 2 * math.pi
    return -(d + 2 * math.pi * (-turn - 1))


@dataclass
class _Queued:
    """A motion in the output whose XY end may still move (`index` into the output)."""

    index: int
    dx: float = 0.0  # straight moves: the direction checked against backing up
    dy: float = 0.0
    turn: int = 0  # arcs: signed turns
    sweep: float = 0.0  # arcs: signed sweep when queued (0: never checked)
    centre: tuple[float, float] = (0.0, 0.0)


@dataclass
class CutterComp:
    """Compensation state of one program run."""

    side: str = ""  # "left", "right" or "" (off)
    radius: float = 0.0  # machine units, > 0 when active
    orientation: int = 0  # lathe tool orientation (G18): where the tip is from the nose
    first_move: bool = True
    arc_not_allowed: bool = False
    prog: tuple[float, float] = (0.0, 0.0)  # programmed XY where the tool is (machine)
    queue: list[_Queued] = field(default_factory=list)
    endpoint: tuple[float, float] | None = None

    @property
    def active(self) -> bool:
        return bool(self.side) and self.radius > 0.0

    def code(self) -> int:
        return {"left": 410, "right": 420}.get(self.side, 400)


def comp_on(m: Modal, b: Block, code: int, gpos: int, words: dict, used: set[str]) -> None:
    """G41/G42 [D tool] or G41.1/G42.1 D diameter [L orientation]."""
    cc = m.comp
    gword = f"G{code / 10:g}"
    if m.plane not in (170, 180):
        raise b.error(f"{gword}: cutter compensation needs the XY (G17) or XZ (G18) plane",
                      gpos, gword)
    for L in ("X", "Y") if m.plane == 170 else ("Z", "X"):
        if L not in m.letters:
            raise b.error(f"{gword} needs a machine axis for {L}", gpos, gword)
    if cc.side:
        raise b.error(f"{gword}: cutter compensation is already on (G40 first)", gpos, gword)
    side = "left" if code in (410, 411) else "right"
    d = words.get("D")
    if code in (411, 421):
        if d is None:
            raise b.error(f"{gword} needs D (the tool diameter)", gpos, gword)
        used.add("D")
        radius = m.lin(d.value) / 2.0
        orientation = 0
        if "L" in words:
            if m.plane != 180:
                raise b.error(f"{gword} L (lathe orientation) needs G18", words["L"].pos,
                              "L")
            used.add("L")
            orientation = m.int_word(b, "L", words["L"], 0)
            if orientation > 9:
                raise b.error(f"{gword} L (orientation) must be 0..9, got {orientation}",
                              words["L"].pos, f"L{orientation}")
    else:
        tool = m.tool
        if d is not None:
            used.add("D")
            tool = m.int_word(b, "D", d, 0)
        t = m.tools.get(tool)
        if t is None and tool != 0:
            raise b.error(f"{gword}: tool {tool} is not in the tool table", d.pos if d else
                          gpos, f"D{tool}" if d else gword)
        radius = t.radius if t is not None else 0.0
        orientation = t.orientation if t is not None else 0
        if t is not None and t.orientation not in (0, 9) and m.plane != 180:
            raise b.error(f"{gword} with a lathe tool (orientation {t.orientation}) needs "
                          "G18", gpos, gword)
    if radius < 0:
        radius = -radius
        side = "left" if side == "right" else "right"
    cc.side, cc.radius, cc.first_move = side, radius, True
    cc.orientation = orientation if m.plane == 180 else 0
    cc.queue.clear()
    cc.endpoint = None


def comp_off(m: Modal) -> None:
    """G40: flush where the tool is; the next move is the exit move."""
    cc = m.comp
    if cc.active and not cc.first_move:
        cc.queue.clear()
        cc.arc_not_allowed = True
        # LinuxCNC: the programmed point becomes the current point (the exit move runs
        # from where the tool is to the next programmed point)
        ax, ay = plane_axes(m)
        p = list(m.pos)
        p[ax], p[ay] = cc.prog
        m.pos = p
    cc.side = ""
    cc.first_move = True
    cc.endpoint = None


class _Emit:
    """Output helpers for one block: records in machine coordinates."""

    def __init__(self, m: Modal, b: Block, out: list[canon.Command], gword: str, gpos: int,
                 feed: float) -> None:
        self.m, self.b, self.out, self.gword, self.gpos, self.feed = m, b, out, gword, gpos, feed
        self.ax, self.ay = plane_axes(m)

    def point(self, x: float, y: float, rest: list[float] | None = None) -> list[float]:
        p = list(self.m.pos if rest is None else rest)
        p[self.ax], p[self.ay] = x, y
        return p

    def straight(self, rapid: bool, end: list[float]) -> int:
        shown = shifted(self.m, end)
        self.m.check_limits(self.b, shown, shown, self.gword, self.gpos)
        rec: canon.Command
        if rapid:
            rec = canon.Rapid(tuple(shown), self.b.line, self.b.file)
        else:
            rec = canon.Feed(tuple(shown), self.feed, self.b.line, self.b.file)
        self.out.append(rec)
        self.m.pos = end
        return len(self.out) - 1

    def arc(self, end: list[float], cx: float, cy: float, turn: int) -> int:
        d1, d2 = lathe_shift(self.m)
        self.out.append(make_arc(self.m, self.b, tuple(shifted(self.m, self.m.pos)),
                                 shifted(self.m, end), cx + d1, cy + d2, turn, self.feed,
                                 self.gword, self.gpos))
        self.m.pos = end
        return len(self.out) - 1


def make_arc(m: Modal, b: Block, start: tuple[float, ...], end: list[float], cx: float,
             cy: float, turn: int, feed: float, gword: str, gpos: int) -> canon.ArcMove:
    ax, ay = plane_axes(m)
    sx, sy, ex, ey = start[ax], start[ay], end[ax], end[ay]
    ccw = turn > 0
    turns = abs(turn) - 1
    r1 = math.hypot(sx - cx, sy - cy)
    r2 = math.hypot(ex - cx, ey - cy)
    if r1 <= 0.0 or r2 <= 0.0:
        raise b.error("cutter compensation made a zero-radius arc", gpos, gword)
    sweep = sweep_angle(sx, sy, ex, ey, cx, cy, ccw, turns)
    if m.opt.soft_limits is not None:
        a0 = math.atan2(sy - cy, sx - cx)
        amin, amax, bmin, bmax = arc_extent(cx, cy, max(r1, r2), a0, sweep, ccw, sx, sy, ex,
                                            ey)
        lo = [min(p, q) for p, q in zip(start, end, strict=True)]
        hi = [max(p, q) for p, q in zip(start, end, strict=True)]
        lo[ax], hi[ax], lo[ay], hi[ay] = amin, amax, bmin, bmax
        m.check_limits(b, lo, hi, gword, gpos)
    centre = list(start)
    centre[ax], centre[ay] = cx, cy
    return canon.ArcMove(tuple(start), tuple(end), tuple(centre), (ax, ay),
                         Direction.CCW if ccw else Direction.CW, turns, sweep, r1, r2, feed,
                         b.line, b.file)


def plane_axes(m: Modal) -> tuple[int, int]:
    """Machine axes of the compensation plane, first then second: X, Y in G17; Z, X in G18
    (the lathe plane, as LinuxCNC's XZ compensation)."""
    if m.plane == 180:
        return m.letters["Z"][0], m.letters["X"][0]
    return m.letters["X"][0], m.letters["Y"][0]


def lathe_shift(m: Modal) -> tuple[float, float]:
    """Offset (first, second plane axis) from the nose centre that compensation steers to
    the lathe tool's control point, by orientation (LinuxCNC latheorigin_x/_z); 0 for
    mills, orientation 0 and 9."""
    cc = m.comp
    o, r = cc.orientation, cc.radius
    if m.plane != 180 or o in (0, 9):
        return 0.0, 0.0
    dx = -r if o in (1, 2, 6) else r if o in (3, 4, 8) else 0.0
    dz = -r if o in (2, 3, 7) else r if o in (1, 4, 5) else 0.0
    return dz, dx


def shifted(m: Modal, p: list[float]) -> list[float]:
    """A compensated point as output: nose centre -> control point (lathe tools)."""
    d1, d2 = lathe_shift(m)
    if d1 == 0.0 and d2 == 0.0:
        return list(p)
    ax, ay = plane_axes(m)
    q = list(p)
    q[ax] += d1
    q[ay] += d2
    return q


def _tool_inside(side: str, turn: int) -> bool:
    return (side == "left" and turn > 0) or (side == "right" and turn < 0)


def _move_endpoint_and_flush(m: Modal, b: Block, out: list[canon.Command], x: float,
                             y: float, gword: str, gpos: int) -> None:
    """Move the XY end of every queued motion to (x, y), checking for gouges; flush."""
    cc = m.comp
    ax, ay = plane_axes(m)
    tol = 0.0254 if m.units == "mm" else 0.001
    ep = cc.endpoint
    d1, d2 = lathe_shift(m)
    for q in cc.queue:
        rec = out[q.index]
        end = list(rec.end)  # type: ignore[union-attr]
        end[ax], end[ay] = x + d1, y + d2
        if isinstance(rec, canon.ArcMove):
            cx, cy = q.centre
            if ep is not None and q.sweep != 0.0:
                new = signed_sweep(ep[0], ep[1], cx, cy, q.turn, x, y)
                if abs(new) > abs(q.sweep) + tol:
                    raise b.error("arc move in a concave corner cannot be reached by the tool "
                                  "without gouging", gpos, gword)
            out[q.index] = make_arc(m, b, rec.start, end, cx + d1, cy + d2, q.turn,
                                    rec.feed_per_s, gword, gpos)
        else:
            if ep is not None and q.dx * (x - ep[0]) + q.dy * (y - ep[1]) < 0:
                kind = "traverse" if isinstance(rec, canon.Rapid) else "feed"
                raise b.error(f"straight {kind} in a concave corner cannot be reached by the "
                              "tool without gouging", gpos, gword)
            m.check_limits(b, end, end, gword, gpos)
            out[q.index] = replace(rec, end=tuple(end))  # type: ignore[type-var]
        # the next queued motion starts where this one now ends
        if q.index + 1 < len(out):
            nxt = out[q.index + 1]
            if isinstance(nxt, canon.ArcMove):
                s = list(nxt.start)
                s[ax], s[ay] = x + d1, y + d2
                out[q.index + 1] = replace(nxt, start=tuple(s))
    cc.queue.clear()
    p = list(m.pos)
    p[ax], p[ay] = x, y
    m.pos = p
    cc.endpoint = (x, y)


def comp_straight(m: Modal, b: Block, mode: int, target: list[float], feed: float,
                  out: list[canon.Command], gword: str, gpos: int) -> None:
    """A G0/G1 under compensation (LinuxCNC convert_straight_comp1/comp2)."""
    cc = m.comp
    e = _Emit(m, b, out, gword, gpos, feed)
    ax, ay = e.ax, e.ay
    px, py = target[ax], target[ay]
    cx, cy = m.pos[ax], m.pos[ay]
    r = cc.radius
    rapid = mode == 0
    if cc.first_move:
        dist = math.hypot(px - cx, py - cy)
        if dist <= r:
            raise b.error(f"cutter compensation entry move ({dist:.6g}) is not longer than "
                          f"the tool radius ({r:.6g})", gpos, gword)
        alpha = math.atan2(py - cy, px - cx) + (HALF_PI if cc.side == "left" else -HALF_PI)
        cc.endpoint = (cx, cy)
        idx = e.straight(rapid, e.point(px + r * math.cos(alpha), py + r * math.sin(alpha),
                                        target))
        cc.queue.append(_Queued(idx, math.cos(alpha), math.sin(alpha)))
        cc.first_move = False
        cc.prog = (px, py)
        return
    opx, opy = cc.prog
    if px == opx and py == opy:  # no XY motion: stays where the tool is, queued
        idx = e.straight(rapid, e.point(cx, cy, target))
        cc.queue.append(_Queued(idx))
        return
    theta = math.atan2(cy - opy, cx - opx)
    alpha = math.atan2(py - opy, px - opx)
    if cc.side == "left":
        if theta < alpha:
            theta += 2 * math.pi
        beta = theta - alpha - HALF_PI
        gamma = HALF_PI
    else:
        if alpha < theta:
            alpha += 2 * math.pi
        beta = alpha - theta - HALF_PI
        gamma = -HALF_PI
    ex, ey = px + r * math.cos(alpha + gamma), py + r * math.sin(alpha + gamma)
    midx, midy = opx + r * math.cos(alpha + gamma), opy + r * math.sin(alpha + gamma)
    front = _front_arc(m, out)
    concave = beta < -SMALL or beta > math.pi + SMALL or (
        beta > math.pi - SMALL and front is not None and (
            (cc.side == "right" and front.turn > 0) or (cc.side == "left" and front.turn < 0)))
    if not concave and beta > SMALL:  # convex: go round the corner
        _move_endpoint_and_flush(m, b, out, cx, cy, gword, gpos)
        if rapid:
            e.straight(True, e.point(midx, midy))
        else:
            e.arc(e.point(midx, midy), opx, opy, -1 if cc.side == "left" else 1)
        cc.endpoint = (midx, midy)
    elif concave:
        if front is None:
            half = 0.5 * (beta + math.pi)
            if half == 0.0:
                raise b.error("a zero-degree inside corner cannot be compensated", gpos,
                              gword)
            retreat = r / math.tan(half)
            mx = cx + retreat * math.cos(theta + gamma)
            my = cy + retreat * math.sin(theta + gamma)
        else:
            mx, my = _arc_to_line_corner(m, b, out, front, px, py, opx, opy, gword, gpos)
        _move_endpoint_and_flush(m, b, out, mx, my, gword, gpos)
    else:
        cc.queue.clear()
        cc.endpoint = (cx, cy)
    idx = e.straight(rapid, e.point(ex, ey, target))
    cc.queue.append(_Queued(idx, px - opx, py - opy))
    cc.prog = (px, py)


def _front_arc(m: Modal, out: list[canon.Command]) -> _Queued | None:
    q = m.comp.queue
    if q and isinstance(out[q[0].index], canon.ArcMove):
        return q[0]
    return None


def _arc_to_line_corner(m: Modal, b: Block, out: list[canon.Command], prev: _Queued,
                        px: float, py: float, opx: float, opy: float, gword: str,
                        gpos: int) -> tuple[float, float]:
    """Where the tool leaves a compensated arc to start the next compensated line."""
    cc = m.comp
    r = cc.radius
    arc = out[prev.index]
    ax, ay = plane_axes(m)
    c1, c2 = prev.centre
    oldrad = math.hypot(c2 - arc.end[ay], c1 - arc.end[ax])
    base = math.atan2(py - opy, px - opx)
    theta = base + HALF_PI if prev.turn > 0 else base - HALF_PI
    phi = math.atan2(c2 - opy, c1 - opx)
    inside = _tool_inside(cc.side, prev.turn)
    uncomp = oldrad + r if inside else oldrad - r
    d = uncomp * math.cos(theta - phi)
    ell = (d - r) / oldrad if inside else (d + r) / oldrad
    if not -1.0 <= ell <= 1.0:
        raise b.error("arc to straight motion makes a corner the compensated tool cannot "
                      "fit in without gouging", gpos, gword)
    if inside:
        ang = (-math.acos(ell) if prev.turn > 0 else math.acos(ell)) + theta + math.pi
    else:
        ang = (math.acos(ell) if prev.turn > 0 else -math.acos(ell)) + theta + math.pi
    return c1 + oldrad * math.cos(ang), c2 + oldrad * math.sin(ang)


def _entry_arc(m: Modal, b: Block, e: _Emit, target: list[float], pcx: float, pcy: float,
               turn: int, gword: str, gpos: int) -> None:
    """The first move after G41/G42 is an arc (LinuxCNC convert_arc_comp1): it ends at the
    radius from the programmed end, on a circle through the current point."""
    cc = m.comp
    r = cc.radius
    ax, ay = e.ax, e.ay
    cx, cy = m.pos[ax], m.pos[ay]
    ex, ey = target[ax], target[ay]
    if math.hypot(ex - cx, ey - cy) <= r:
        raise b.error("the cutter compensation entry arc is not longer than the tool radius",
                      gpos, gword)
    inside = _tool_inside(cc.side, turn)
    if inside and math.hypot(pcx - cx, pcy - cy) <= r:
        raise b.error(f"{gword}: the tool radius is not less than the arc radius", gpos,
                      gword)
    gamma = math.atan2(pcy - ey, pcx - ex) if inside else math.atan2(ey - pcy, ex - pcx)
    nex, ney = ex + r * math.cos(gamma), ey + r * math.sin(gamma)
    half = math.hypot(cy - ney, cx - nex) / 2.0
    ab = math.atan2(pcy - ney, pcx - nex)
    a_ang = math.atan2(cy - ney, cx - nex) - ab
    if abs(math.cos(a_ang)) < 1e-6:
        raise b.error(f"{gword}: the tool radius is not less than the arc radius", gpos,
                      gword)
    c_len = half / math.cos(a_ang)
    ncx, ncy = nex + c_len * math.cos(ab), ney + c_len * math.sin(ab)
    cc.first_move = False
    cc.prog = (ex, ey)
    cc.endpoint = (cx, cy)
    idx = e.arc(e.point(nex, ney, target), ncx, ncy, turn)
    cc.queue.append(_Queued(idx, turn=turn, sweep=signed_sweep(cx, cy, ncx, ncy, turn, nex,
                                                                ney), centre=(ncx, ncy)))


def comp_arc(m: Modal, b: Block, mode: int, target: list[float], pcx: float, pcy: float,
             turn: int, feed: float, out: list[canon.Command], gword: str,
             gpos: int) -> None:
    """A G2/G3 under compensation (LinuxCNC convert_arc_comp2); (pcx, pcy) is the
    programmed centre, `turn` the signed turns."""
    cc = m.comp
    e = _Emit(m, b, out, gword, gpos, feed)
    ax, ay = e.ax, e.ay
    if cc.first_move:
        _entry_arc(m, b, e, target, pcx, pcy, turn, gword, gpos)
        return
    r = cc.radius
    opx, opy = cc.prog
    cx, cy = m.pos[ax], m.pos[ay]
    ex0, ey0 = target[ax], target[ay]
    arc_r = math.hypot(pcx - ex0, pcy - ey0)
    theta = math.atan2(cy - opy, cx - opx)
    theta = theta - HALF_PI if cc.side == "left" else theta + HALF_PI
    delta = math.atan2(pcy - opy, pcx - opx)
    alpha = delta - HALF_PI if mode == 30 else delta + HALF_PI
    beta = theta - alpha if cc.side == "left" else alpha - theta
    if beta > 1.5 * math.pi:
        beta -= 2 * math.pi
    elif beta < -HALF_PI:
        beta += 2 * math.pi
    inside = _tool_inside(cc.side, turn)
    if inside:
        gamma = math.atan2(pcy - ey0, pcx - ex0)
        if arc_r <= r:
            raise b.error(f"{gword}: the tool radius ({r:.6g}) is not less than the radius "
                          f"of the arc it cuts inside ({arc_r:.6g})", gpos, gword)
    else:
        gamma = math.atan2(ey0 - pcy, ex0 - pcx)
        delta += math.pi
    nex, ney = ex0 + r * math.cos(gamma), ey0 + r * math.sin(gamma)
    front = _front_arc(m, out)
    if beta < -SMALL or beta > math.pi + SMALL or (abs(beta - math.pi) < SMALL
                                                    and not inside):
        if front is None:
            h = arc_r * math.sin(beta - HALF_PI)
            if inside:
                dist = arc_r - r
                ell = (h + r) / dist
                if not -1.0 <= ell <= 1.0:
                    raise b.error("arc move in a concave corner cannot be reached by the tool "
                                  "without gouging", gpos, gword)
                ang = theta + math.asin(ell) if turn > 0 else theta - math.asin(ell)
            else:
                dist = arc_r + r
                ell = (h - r) / dist
                if not -1.0 <= ell <= 1.0:
                    raise b.error("arc move in a concave corner cannot be reached by the tool "
                                  "without gouging", gpos, gword)
                ang = (theta + math.pi - math.asin(ell) if turn > 0
                       else theta + math.pi + math.asin(ell))
            mx, my = pcx + dist * math.cos(ang), pcy + dist * math.sin(ang)
        else:
            prev_rec = out[front.index]
            c1, c2 = front.centre
            oldrad = math.hypot(c2 - prev_rec.end[ay], c1 - prev_rec.end[ax])  # type: ignore
            newrad = arc_r - r if inside else arc_r + r
            dcc = math.hypot(c2 - pcy, c1 - pcx)
            if oldrad == 0 or dcc == 0:
                raise b.error("arc to arc motion is invalid because the arcs have the same "
                              "centre", gpos, gword)
            a = (oldrad ** 2 + dcc ** 2 - newrad ** 2) / (2 * oldrad * dcc)
            if not -1.0 <= a <= 1.0:
                raise b.error("arc to arc motion makes a corner the compensated tool cannot "
                              "fit in without gouging", gpos, gword)
            pull = math.acos(a)
            cdir = math.atan2(pcy - c2, pcx - c1)
            if _tool_inside(cc.side, front.turn):
                d = cdir + pull if turn > 0 else cdir - pull
            else:
                d = cdir - pull if turn > 0 else cdir + pull
            mx, my = c1 + oldrad * math.cos(d), c2 + oldrad * math.sin(d)
        _move_endpoint_and_flush(m, b, out, mx, my, gword, gpos)
    elif beta > SMALL:  # convex: an arc round the corner first
        midx, midy = opx + r * math.cos(delta), opy + r * math.sin(delta)
        cc.queue.clear()
        e.arc(e.point(midx, midy), opx, opy, -1 if cc.side == "left" else 1)
        cc.endpoint = (midx, midy)
    else:
        cc.queue.clear()
        cc.endpoint = (cx, cy)
    end = e.point(nex, ney, target)
    sw = signed_sweep(opx, opy, pcx, pcy, turn, ex0, ey0)
    idx = e.arc(end, pcx, pcy, turn)
    cc.queue.append(_Queued(idx, turn=turn, sweep=sw, centre=(pcx, pcy)))
    cc.prog = (ex0, ey0)
