"""M48-M53: the program switches the operator's overrides and the feed-stop switch on and
off (LinuxCNC modal group 9, run after the spindle and coolant words of the line).

M48 / M49: feed and spindle overrides on / off. M50 [P1] / M50 P0: the feed override on /
off. M51 [P1] / M51 P0: the spindle-speed override. While an override is off the program
runs at 100 % whatever the operator set; switched on again, the operator's setting applies
(ProgramRunner.set_feed_override / set_spindle_override, `openmotion run
--feed-override`). Both are on at the start of every pass and after M2/M30 (LinuxCNC's M2).
#<_feed_override> / #<_speed_override> read the switches.
M52 [P1] / M52 P0: adaptive feed on / off (LinuxCNC's motion.adaptive-feed: the feed is
scaled live by an analog input, RunOptions.adaptive_feed_input, runoverride.py); off at the
start of every pass; #<_adaptive_feed> reads it. M53 [P1] / M53 P0: the feed-stop switch
(RunOptions.feed_hold_input, a board input: while it is active the path holds,
decelerating along it, and goes on when it is released) is obeyed / ignored; on at the
start of every pass; #<_feed_hold> reads it. Without a feed_hold_input there is no switch
and M53 changes nothing (ProgramRunner.pause() always holds, as LinuxCNC's pause does).
The runner applies a switch where the next motion command starts (LinuxCNC queues the
enables with the motion segment), without stopping a blended path. As in LinuxCNC, none of
them may be used with cutter compensation on.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block

#: The override M-codes (modal group 9).
OVERRIDE_CODES = (48, 49, 50, 51, 52, 53)


@dataclass(frozen=True, slots=True)
class OverrideSwitch:
    """M48-M53: the feed / spindle override, the feed-stop switch and adaptive feed on
    (True), off (False) or unchanged (None)."""

    feed: bool | None
    spindle: bool | None
    line: int
    file: str = ""
    feed_hold: bool | None = None  # M53: the feed-stop switch on / off
    adaptive: bool | None = None   # M52: adaptive feed on / off

    @property
    def text(self) -> str:
        parts = [f"{name} {'on' if on else 'off'}"
                 for name, on in (("feed override", self.feed),
                                  ("spindle override", self.spindle),
                                  ("feed stop switch", self.feed_hold),
                                  ("adaptive feed", self.adaptive))
                 if on is not None]
        return ", ".join(parts)


def _switch(b: Block, code: int, pos: int, p: Word | None) -> bool:
    if p is None:
        return True
    if p.value not in (0.0, 1.0):
        raise b.error(f"M{code} P must be 0 (off) or 1 (on), got {p.value:g}", p.pos,
                      fmt("P", p.value))
    return p.value == 1.0


def m48_m53(m: Modal, b: Block, code: int, pos: int, words: dict[str, Word],
            used: set[str], out: list) -> None:
    """One override M-code of a line (module doc)."""
    p = words.get("P") if code in (50, 51, 52, 53) else None
    if p is not None:
        used.add("P")
    on = _switch(b, code, pos, p)
    if m.comp.side:  # LinuxCNC: "Cannot enable/disable overrides with cutter comp on"
        raise b.error(f"M{code} cannot be used with cutter compensation on (G40 first)", pos,
                      f"M{code}")
    if code == 52:
        m.adaptive_feed_on = on
        out.append(OverrideSwitch(None, None, b.line, b.file, adaptive=on))
        return
    if code == 53:
        m.feed_hold_on = on
        out.append(OverrideSwitch(None, None, b.line, b.file, feed_hold=on))
        return
    if code in (48, 49):
        sw = OverrideSwitch(code == 48, code == 48, b.line, b.file)
    elif code == 50:
        sw = OverrideSwitch(on, None, b.line, b.file)
    else:
        sw = OverrideSwitch(None, on, b.line, b.file)
    if sw.feed is not None:
        m.feed_override_on = sw.feed
    if sw.spindle is not None:
        m.speed_override_on = sw.spindle
    out.append(sw)
