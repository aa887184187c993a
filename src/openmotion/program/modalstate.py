"""M70-M73: save and restore the modal state (LinuxCNC's save_settings/restore_settings).

M70 saves the state in the current call level, M72 restores it, M71 forgets it, M73 saves
it and restores it automatically when the subroutine returns (endsub, return, M99). The
state: units (restored first), plane, distance and arc-distance modes, feed mode and F,
coordinate system, G43/G49, retract mode G98/G99, G96/G97, G7/G8, G92 on/off, path control
G61/G61.1/G64 with P/Q, S, spindle M3/M4/M5, mist and flood. Motion mode and cutter
compensation are not restored (as LinuxCNC). Restoring emits the Spindle, Coolant and
SetBlend records of whatever changed, so the runtime follows.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from . import canon
from .css import FeedMode, SpindleMode
from .parser import Block

if TYPE_CHECKING:
    from .modal import Modal

_FIELDS = ("plane", "incremental", "arc_incremental", "inverse_time", "per_rev", "feed",
           "feed_lin", "feed_ang", "coord", "retract_old_z", "css", "diameter_mode",
           "speed", "spindle_on", "spindle_cw", "mist", "flood", "blend")


@dataclass
class SavedState:
    """One M70/M73 snapshot; `auto` = restore on return (M73)."""

    units: str
    values: dict[str, object]
    tool_offset: list[float]
    g92_on: bool
    auto: bool


def save(m: Modal, auto: bool) -> SavedState:
    return SavedState(m.units, {f: getattr(m, f) for f in _FIELDS}, list(m.tool_offset),
                      m.params.numbers[5210] != 0.0, auto)


def restore(m: Modal, s: SavedState, b: Block, out: list[canon.Command]) -> None:
    """Put a snapshot back, emitting the records of the machine state that changed."""
    before = {f: getattr(m, f) for f in _FIELDS}
    if s.units != m.units:
        m._set_units(s.units)
    for f, v in s.values.items():
        setattr(m, f, v)
    m.tool_offset = list(s.tool_offset)
    if s.g92_on != (m.params.numbers[5210] != 0.0):
        if s.g92_on:
            m.g92 = [m.params.numbers[5211 + k] for k in range(9)]
        else:
            m.g92 = [0.0] * 9
        m.params.set_number(5210, 1.0 if s.g92_on else 0.0)
    m.params.set_number(5220, float(m.coord))
    m.update_offsets()
    line, file = b.line, b.file
    if before["css"] != m.css:  # G96/G97 restored: the runner's spindle follows it
        if isinstance(m.css, SpindleMode):
            out.append(replace(m.css, line=line, file=file))
        else:
            x = m.letters.get("X")
            out.append(SpindleMode(0.0, 0.0, x[0] if x else 0, 0.0, line, file))
    if before["per_rev"] != m.per_rev:
        out.append(FeedMode(bool(m.per_rev), line, file))
    if any(before[f] != s.values[f] for f in ("spindle_on", "spindle_cw", "speed")):
        out.append(canon.Spindle(m.spindle_on, m.spindle_cw, m.speed, m.opt.spindle_output,
                                 line, file))
    if before["mist"] != m.mist or before["flood"] != m.flood:
        out.append(canon.Coolant(m.mist, m.flood, m.opt.mist_output, m.opt.flood_output,
                                 line, file))
    if before["blend"] != m.blend and m.blend is not None:
        mode, tol, cam = m.blend
        out.append(canon.SetBlend(mode, tol, line, file, cam))


def state_word(m: Modal, b: Block, code: int, pos: int, out: list[canon.Command]) -> None:
    """Execute M70 / M71 / M72 / M73 at the current call level."""
    level = m.params.depth
    if code in (70, 73):
        m.saved_states[level] = save(m, auto=code == 73)
    elif code == 71:
        m.saved_states.pop(level, None)
    else:
        s = m.saved_states.get(level)
        if s is None:
            raise b.error("M72: no state saved with M70/M73 at this call level", pos, "M72")
        restore(m, s, b, out)


def on_return(m: Modal, level: int, b: Block, out: list[canon.Command]) -> None:
    """A subroutine at call level `level` returns: auto-restore (M73), forget its saves."""
    s = m.saved_states.pop(level, None)
    if s is not None and s.auto:
        restore(m, s, b, out)
