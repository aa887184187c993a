"""Predefined read-only named parameters (#<_x>, #<_metric>, #<_vmajor>, ...).

The names and values of LinuxCNC 2.9 (interp_namedparams.cc): modal state as G-code numbers
times ten (#<_plane> = 170 for G17, #<_coord_system> = 540 for G54, 591 for G59.1,
#<_motion_mode> = 10 for G1, 800 for G80), flags as 1/0, positions in program coordinates
(#<_x>) or in machine coordinates in program units (#<_abs_x>). A program may not assign
them; a user global of the same name (set with #<_x> = ...) is refused by the caller.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from .options import AXIS_LETTERS, ROTARY_LETTERS

if TYPE_CHECKING:
    from .modal import Modal

#: The dialect's version as LinuxCNC reports it: "2.9" and "0.0" (M.N and 0.m).
VMAJOR, VMINOR = 2.9, 0.0


def _flag(x: bool) -> float:
    return 1.0 if x else 0.0


def _coord(m: Modal) -> float:
    return float(530 + 10 * m.coord) if m.coord < 7 else float(584 + m.coord)


def _abs(k: int) -> Callable[[Modal], float]:
    def get(m: Modal) -> float:
        letter = AXIS_LETTERS[k]
        info = m.letters.get(letter)
        if info is None:
            return 0.0
        v = m.pos[info[0]]
        return v if letter in ROTARY_LETTERS else v * m.ldiv / m.lscale
    return get


def _pos(k: int) -> Callable[[Modal], float]:
    return lambda m: m.program_position(k)


_TABLE: dict[str, Callable[[Modal], float]] = {
    "_VMAJOR": lambda m: VMAJOR,
    "_VMINOR": lambda m: VMINOR,
    "_METRIC_MACHINE": lambda m: _flag(m.machine_mm),
    "_LINE": lambda m: float(m.line),
    "_MOTION_MODE": lambda m: float(800 if m.motion is None else m.motion),
    "_PLANE": lambda m: float(m.plane),
    "_CCOMP": lambda m: float(m.ccomp_code()),
    "_METRIC": lambda m: _flag(m.units == "mm"),
    "_IMPERIAL": lambda m: _flag(m.units == "inch"),
    "_ABSOLUTE": lambda m: _flag(not m.incremental),
    "_INCREMENTAL": lambda m: _flag(m.incremental),
    "_INVERSE_TIME": lambda m: _flag(m.inverse_time),
    "_UNITS_PER_MINUTE": lambda m: _flag(not m.inverse_time and not m.per_rev),
    "_UNITS_PER_REV": lambda m: _flag(m.per_rev),
    "_COORD_SYSTEM": _coord,
    "_TOOL_OFFSET": lambda m: _flag(any(m.tool_offset)),
    "_RETRACT_R_PLANE": lambda m: _flag(not m.retract_old_z),
    "_RETRACT_OLD_Z": lambda m: _flag(m.retract_old_z),
    "_SPINDLE_RPM_MODE": lambda m: _flag(not m.css),
    "_SPINDLE_CSS_MODE": lambda m: _flag(m.css),
    "_IJK_ABSOLUTE_MODE": lambda m: _flag(not m.arc_incremental),
    "_LATHE_DIAMETER_MODE": lambda m: _flag(m.diameter_mode),
    "_LATHE_RADIUS_MODE": lambda m: _flag(not m.diameter_mode),
    "_SPINDLE_ON": lambda m: _flag(m.spindle_on),
    "_SPINDLE_CW": lambda m: _flag(m.spindle_on and m.spindle_cw),
    "_MIST": lambda m: _flag(m.mist),
    "_FLOOD": lambda m: _flag(m.flood),
    "_SPEED_OVERRIDE": lambda m: _flag(m.speed_override_on),
    "_FEED_OVERRIDE": lambda m: _flag(m.feed_override_on),
    "_ADAPTIVE_FEED": lambda m: _flag(m.adaptive_feed_on),
    "_FEED_HOLD": lambda m: _flag(m.feed_hold_on),
    "_FEED": lambda m: m.feed_program_units(),
    "_RPM": lambda m: abs(m.speed),
    "_CURRENT_TOOL": lambda m: float(m.tool),
    "_SELECTED_TOOL": lambda m: float(m.selected_tool),
    "_CURRENT_POCKET": lambda m: float(m.pocket_of(m.tool)),
    "_SELECTED_POCKET": lambda m: float(m.pocket_of(m.selected_tool)),
    "_VALUE": lambda m: 0.0,
    "_VALUE_RETURNED": lambda m: 0.0,
    "_TASK": lambda m: 1.0,
    "_CALL_LEVEL": lambda m: float(m.params.depth),
    "_REMAP_LEVEL": lambda m: 0.0,
}
for _k, _L in enumerate(AXIS_LETTERS):
    _TABLE["_" + _L] = _pos(_k)
    _TABLE["_ABS_" + _L] = _abs(_k)

#: Names a program may read but not assign.
READ_ONLY = frozenset(_TABLE) - {"_VALUE", "_VALUE_RETURNED"}


def predefined(m: Modal, name: str) -> float | None:
    """The value of predefined parameter `name` (upper case, leading '_'), else None."""
    get = _TABLE.get(name)
    return None if get is None else get(m)
