"""M67 / M68: analog outputs (LinuxCNC's motion.analog-out-NN).

`M67 E- Q-` sets analog output E to Q where the next motion starts (synchronised with
motion, as M62/M63), `M68 E- Q-` sets it at once once the motion before it has ended
(LinuxCNC's task waits for motion before an immediate output).
Both become one `AnalogOut` record; the runner writes it through the control layer's
`AnalogOutputs` (control/trigger/analog.py), which checks the value against the board's
range when the program is bound to the machine (before anything moves).

LinuxCNC's texts: "Invalid analog index with M67" for a missing or negative E. rs274 also
accepts a missing Q (value -1) and rounds a fractional E; openmotion refuses both, and an
E at or above `GCodeOptions.n_analog_outputs` (the running LinuxCNC's motion module refuses
it then).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block


@dataclass(frozen=True, slots=True)
class AnalogOut:
    """M67 (synced: where the next motion starts) / M68: output `index` to `value`."""

    index: int
    value: float
    synced: bool
    line: int
    file: str = ""


def m67_m68(m: Modal, b: Block, code: int, pos: int, words: dict[str, Word],
            used: set[str], out: list) -> None:
    """Execute M67/M68 E Q (module docstring)."""
    mw = f"M{code}"
    e, q = words.get("E"), words.get("Q")
    if e is None or e.value < 0:
        raise b.error(f"Invalid analog index with {mw}", e.pos if e else pos,
                      fmt("E", e.value) if e else mw)
    n = round(e.value)
    if abs(e.value - n) > 1e-6:
        raise b.error(f"{mw} E (the analog output) must be an integer, got {e.value:g}",
                      e.pos, fmt("E", e.value))
    if n >= m.opt.n_analog_outputs:
        raise b.error(f"{mw} E must be below {m.opt.n_analog_outputs} (the analog outputs), "
                      f"got {n}", e.pos, fmt("E", e.value))
    if q is None:
        raise b.error(f"{mw} needs Q (the value to set)", pos, mw)
    used.update("EQ")
    out.append(AnalogOut(int(n), q.value, code == 67, b.line, b.file))
