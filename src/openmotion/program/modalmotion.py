"""Modal's motion: a line's motion mode handed to the module that runs it, and feeds.

A mixin of `modal.Modal` (the state lives there): the last step of a line's order of
execution dispatches G0/G1 (here), G2/G3 (arcmove.py), G5.x splines, canned and lathe
cycles, G33/G33.1/G76, G38.x and moves under cutter compensation, and turns the F number
into a speed (G93 inverse time, G94, G95 per revolution). modal.py keeps the order itself.
"""

from __future__ import annotations

import math
from typing import Any

from . import canon
from .arcmove import arc_move
from .compmove import comp_motion
from .css import nominal_rpm
from .cycles import CYCLES, canned_cycle
from .latheprofile import LATHE_CYCLES, lathe_cycle
from .options import ROTARY_LETTERS
from .parser import Block
from .probing import PROBE_CODES, g38
from .rigidtap import g33_1
from .splines import SPLINE_CODES, open_block_error, spline_move
from .threading import g33, g76
from .words import Word, feed_length, fmt


class ModalMotion:
    """Mixin of `Modal`: the motion-mode dispatch of one line and its feed rate."""

    pos: list[float]
    letters: dict[str, tuple[int, int]]
    motion: int | None
    incremental: bool
    inverse_time: bool
    feed: float
    feed_lin: float
    feed_ang: float
    per_rev: bool
    spindle_on: bool
    speed: float
    comp: Any

    def feed_rate(self, b: Block, words: dict[str, Word], gword: str, gpos: int,
                  rotary_only: bool = False) -> tuple[float, float | None]:
        """(feed_per_s, duration) for a feed move; errors when F is missing. A move of
        rotary axes only runs at the F number in degrees per minute (never unit-scaled)."""
        if self.inverse_time:
            f = words.get("F")
            if f is None or f.value <= 0:
                raise b.error("inverse time feed (G93) needs F > 0 on every G1/G2/G3 line",
                              gpos, gword)
            return 0.0, 60.0 / f.value
        if self.feed <= 0.0:
            raise b.error("feed rate is zero or not set: give F before or with "
                          f"{gword}", gpos, gword)
        return self.per_second(self.feed_ang if rotary_only else self.feed_lin, b, gword,
                               gpos), None

    def per_second(self, f: float, b: Block, gword: str, gpos: int) -> float:
        """A feed F (per minute, or per revolution in G95) in units per second; G95 uses the
        commanded spindle speed S (no spindle feedback on this path)."""
        if not self.per_rev:
            return f / 60.0
        rpm = nominal_rpm(self)
        if not self.spindle_on or self.speed <= 0.0 or not math.isfinite(rpm):
            raise b.error(f"{gword} in G95 (feed per revolution) needs the spindle turning "
                          "at S > 0" + (" (G96 at X0 without D: no rpm limit)"
                                        if not math.isfinite(rpm) else ""), gpos, gword)
        return f * rpm / 60.0

    def _rotary_only(self, start: list[float], end: list[float]) -> bool:
        """True when only rotary axes move (LinuxCNC then feeds at the angular rate)."""
        moved = [L for L, (ax, _k) in self.letters.items() if end[ax] != start[ax]]
        return bool(moved) and all(L in ROTARY_LETTERS for L in moved)

    def _motion(self, b: Block, gs: dict[int, tuple[int, int]], axes: dict[str, Word],
                words: dict[str, Word], used: set[str], out: list[canon.Command],
                machine: bool) -> None:
        mode = self.motion
        gpos = gs[1][1] if 1 in gs else (axes[next(iter(axes))].pos if axes else 0)
        if mode is None:
            if 1 in gs:
                raise b.error("axis words cannot be used with G80", gs[1][1], "G80")
            w = next(iter(axes.values()))
            raise b.error("axis words without a motion mode (G0, G1, G2 or G3)", w.pos,
                          fmt(next(iter(axes)), w.value))
        gword = f"G{mode / 10:g}"
        if mode not in (52, 53):
            open_block_error(self, b, gpos, gword)
        if mode in SPLINE_CODES:
            if machine:
                raise b.error("G53 needs G0 or G1", gs[0][1], "G53")
            spline_move(self, b, mode, gpos, axes, words, used, out)
            return
        if machine:
            if mode not in (0, 10):
                raise b.error("G53 needs G0 or G1", gs[0][1], "G53")
            if self.incremental:
                raise b.error("G53 cannot be used in incremental mode (G91)", gs[0][1], "G53")
        if mode in CYCLES:
            if self.comp.side:
                raise b.error("canned cycles cannot be used with cutter compensation on",
                              gpos, gword)
            canned_cycle(self, b, mode, gpos, axes, words, used, out)
            return
        if mode in LATHE_CYCLES:
            lathe_cycle(self, b, mode, gpos, axes, words, used, out)
            return
        if mode == 331:
            g33_1(self, b, gpos, axes, words, used, out)
            return
        if mode in (330, 760):
            if self.comp.side:
                raise b.error(f"{gword} cannot be used with cutter compensation on", gpos,
                              gword)
            if mode == 760:
                g76(self, b, gpos, axes, words, used, out)
            else:
                g33(self, b, gpos, self.target_position(b, axes), words, used, out)
            return
        if mode in PROBE_CODES:
            target = self.target_position(b, axes)
            g38(self, b, mode, gpos, target, words, used, out)
            return
        if mode in (20, 30) and self.comp.arc_not_allowed:
            raise b.error("the move just after cutter compensation ends (G40) must be a "
                          "straight line", gpos, gword)
        if self.comp.active:
            comp_motion(self, b, mode, gpos, gword, axes, words, used, out, machine)
            return
        if mode in (0, 10) and any(L in axes for L in "XY"):
            self.comp.arc_not_allowed = False
        target = self.target_position(b, axes, machine=machine)
        if mode == 0:
            self.check_limits(b, target, target, gword, gpos)
            out.append(canon.Rapid(tuple(target), b.line, b.file))
        elif mode == 10:
            feed, duration = self.feed_rate(b, words, gword, gpos,
                                            self._rotary_only(self.pos, target))
            if duration is not None:
                feed = feed_length(self.pos, target, self.letters) / duration
            self.check_limits(b, target, target, gword, gpos)
            out.append(canon.Feed(tuple(target), feed, b.line, b.file, duration))
        else:
            out.append(arc_move(self, b, mode, gpos, target, words, used))
        self.pos = target
