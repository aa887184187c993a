"""The program's length unit (G20 inch / G21 mm) as the interpreter saw it, for the report.

Canonical commands are in machine units and carry no unit; the interpreter's modal state
logs every unit change (`Modal.unit_log`: commands output before the block, line, unit), and
`program_units` reads from it the unit in force at the program's first motion and whether
the program changed unit after it. compile_text returns a `CompiledProgram` (a list of
commands) holding it; the run report draws in that unit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from . import canon


@dataclass(frozen=True)
class ProgramUnits:
    """`units` ("mm" or "inch"): in force at the first motion (or at the end when nothing
    moves); `switched`: the program changes to the other unit after its first motion."""
    units: str = "mm"
    switched: bool = False


class CompiledProgram(list):  # type: ignore[type-arg]
    """compile_text's command list, with the program's `units` (ProgramUnits)."""

    def __init__(self, cmds: Sequence[canon.Command] = (), units: ProgramUnits | None = None):
        super().__init__(cmds)
        self.units = units if units is not None else ProgramUnits()


_MOTION = (canon.Rapid, canon.Feed, canon.ArcMove, canon.SyncedFeed)


def program_units(cmds: Sequence[object], log: Sequence[tuple[int, int, str]], initial: str,
                  by_line: bool = False) -> ProgramUnits:
    """The unit at the first motion of `cmds` from the modal `log` of unit changes
    ((commands output before the block, line, unit), in execution order); `initial`: the
    unit before any change. `by_line`: place a change by its line (the fast path, whose
    lines run once, in order) instead of by its output position."""
    first = next((k for k, c in enumerate(cmds) if isinstance(c, _MOTION)), None)
    if first is None:
        return ProgramUnits(log[-1][2] if log else initial, False)
    where = getattr(cmds[first], "line", 0) if by_line else first
    units, switched = initial, False
    for at, line, u in log:
        if (line if by_line else at) <= where:
            units = u
        elif u != units:
            switched = True
    return ProgramUnits(units, switched)
