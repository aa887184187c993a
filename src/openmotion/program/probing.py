"""Probing (G38.2-G38.5) and waiting on an input (M66): commands whose result the rest of
the program reads, so interpretation stops there until the machine has answered.

The interpreter (interp.py) pauses after a line that set `Modal.wait_request`; whoever
drives it answers with a `ProbeResult` or an `InputResult`, which `apply_result` turns
into LinuxCNC's parameters (set_probe_data / M66 in interp_convert.cc):

- G38.x: #5061..#5069 = the trip position in program coordinates (offsets removed, the
  rotation undone, program units), #5070 = 1 if the probe tripped; the current position is
  where the axes came to rest. G38.2 / G38.4 without a trip is LinuxCNC's error
  "G38.2 move finished without making contact." ("G38.4 ... breaking contact.").
- M66: #5399 = the input's value (digital 0/1, analog the reading), -1 on a timeout.

Without a machine (`compile_text`), `preview_result` answers as LinuxCNC's standalone
interpreter rs274 (saicanon.cc) does: the probe reaches its end without tripping, #5061..
is that end, #5070 = 0, and the current position backs off 0.254 mm (0.01 in) from it
towards the start along X/Y/Z; M66 reads 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .options import AXIS_LETTERS
from .source import GCodeError
from .words import Word, fmt

if TYPE_CHECKING:
    from .modal import Modal
    from .parser import Block

Point = tuple[float, ...]

#: M66 L: wait modes (LinuxCNC WAIT_MODE_*).
WAIT_MODES = {0: "immediate", 1: "rise", 2: "fall", 3: "high", 4: "low"}
#: G38.x code (x 10) -> (stop on contact (True) or on losing it, error without a trip).
PROBE_CODES = {382: (True, True), 383: (True, False), 384: (False, True), 385: (False, False)}


@dataclass(frozen=True, slots=True)
class Probe:
    """G38.2-G38.5: a straight feed move to `end` that stops when the probe input makes
    contact (`contact` True: G38.2/G38.3) or loses it (False: G38.4/G38.5); `must_trip`
    (G38.2/G38.4): no trip before `end` is an error. `code` is the G-code x 10."""

    end: Point
    feed_per_s: float
    contact: bool
    must_trip: bool
    code: int
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class WaitInput:
    """M66: read digital input `index` (or analog input, `analog`) after the motion before
    it has ended; `mode` (L) 0 reads at once, 1/2 wait for a rising/falling edge, 3/4 for
    a high/low level, at most `timeout` seconds (Q)."""

    index: int
    analog: bool
    mode: int
    timeout: float
    line: int
    file: str = ""


@dataclass(frozen=True, slots=True)
class ProbeResult:
    """What a probe move did: `tripped`; `position` = every machine axis at the trip
    (machine units; the end of the move when it did not trip); `stop` = where the axes
    came to rest. `preview`: an answer without a machine (no "without contact" error)."""

    tripped: bool
    position: Point
    stop: Point
    preview: bool = False


@dataclass(frozen=True, slots=True)
class InputResult:
    """What M66 read: the input's value, or -1.0 when the wait timed out."""

    value: float


Request = Probe | WaitInput
Result = ProbeResult | InputResult


def g38(m: Modal, b: Block, code: int, gpos: int, target: list[float],
        words: dict[str, Word], used: set[str], out: list) -> None:
    """A G38.x line: validate (LinuxCNC's convert_probe) and request the probe move."""
    gword = f"G{code / 10:g}"
    if m.comp.side:
        raise b.error("Cannot probe with cutter radius comp on", gpos, gword)
    if m.inverse_time:
        raise b.error(f"{gword}: cannot probe in inverse time feed mode (G93)", gpos, gword)
    if m.per_rev:
        raise b.error("Cannot probe with feed per rev mode", gpos, gword)
    if m.feed <= 0.0:
        raise b.error("Cannot probe with zero feed rate", gpos, gword)
    contact, must = PROBE_CODES[code]
    if must and target == m.pos:
        raise b.error("Start point too close to probe point", gpos, gword)
    feed, _ = m.feed_rate(b, words, gword, gpos, m._rotary_only(m.pos, target))
    m.check_limits(b, target, target, gword, gpos)
    req = Probe(tuple(target), feed, contact, must, code, b.line, b.file)
    out.append(req)
    m.wait_request = req


def m66(m: Modal, b: Block, pos: int, words: dict[str, Word], used: set[str],
        out: list) -> None:
    """An M66 line: validate (LinuxCNC's convert_m) and request the input read."""
    p, e, lw, q = (words.get(k) for k in "PELQ")
    used.update(k for k in "PELQ" if k in words)
    if p is not None and e is not None:
        raise b.error("Invalid to select both a digital and an analog input with M66",
                      e.pos, fmt("E", e.value))
    mode = 0 if lw is None else round(lw.value)
    if lw is not None and (abs(lw.value - mode) > 1e-4 or mode not in WAIT_MODES):
        raise b.error(f"M66 L must be one of 0 (immediate), 1 (rise), 2 (fall), 3 (high), "
                      f"4 (low), got {lw.value:g}", lw.pos, fmt("L", lw.value))
    timeout = q.value if q is not None and q.value > 0 else 0.0
    if mode > 0 and timeout <= 0.0:
        raise b.error("Zero timeout with wait type != immediate return (M66 L1-L4 "
                      "need Q > 0 seconds)", pos, "M66")
    if e is not None and mode != 0:
        raise b.error("Can't select analog input with wait type != immediate return "
                      "(M66 E needs L0)", lw.pos,
                      fmt("L", lw.value))  # type: ignore[union-attr]
    w = p if p is not None else e
    if w is None:
        raise b.error("Need to have either a valid P or a valid E word with M66", pos, "M66")
    n = round(w.value)
    letter = "P" if p is not None else "E"
    if n < 0 or abs(w.value - n) > 1e-4:
        raise b.error(f"M66 {letter} must be an integer >= 0, got {w.value:g}", w.pos,
                      fmt(letter, w.value))
    if m.comp.side:
        kind = "digital" if p is not None else "analog"
        raise b.error(f"Cannot wait for {kind} input with cutter radius compensation on",
                      pos, "M66")
    count = m.opt.n_inputs if p is not None else m.opt.n_analog_inputs
    if n >= count:
        what = "digital" if p is not None else "analog"
        raise b.error(f"M66 {letter}{n}: {what} input number must be < {count} (the "
                      f"machine's {what} inputs)", w.pos, fmt(letter, w.value))
    req = WaitInput(int(n), e is not None, mode, timeout, b.line, b.file)
    out.append(req)
    m.wait_request = req


def preview_result(m: Modal, req: Request) -> Result:
    """LinuxCNC rs274's answer without a machine (module docstring)."""
    if isinstance(req, WaitInput):
        return InputResult(0.0)
    end = list(req.end)
    start = m.pos
    xyz = [m.letters[L][0] for L in "XYZ" if L in m.letters]
    dist = math.sqrt(sum((start[a] - end[a]) ** 2 for a in xyz))
    stop = end[:]
    if dist > 0.0:
        back = m.lin(0.254 if m.units == "mm" else 0.01)
        for a in xyz:
            stop[a] = end[a] + back * (start[a] - end[a]) / dist
    return ProbeResult(False, tuple(end), tuple(stop), preview=True)


def apply_result(m: Modal, req: Request, result: Result) -> None:
    """Store a request's answer in the parameters (and the position) as LinuxCNC does;
    G38.2/G38.4 without a trip raise its error, naming the line."""
    if isinstance(req, WaitInput):
        if not isinstance(result, InputResult):
            raise GCodeError(f"M66 needs an InputResult, got {type(result).__name__}",
                             req.line, 0, "M66", req.file)
        m.params.set_number(5399, float(result.value))
        return
    if not isinstance(result, ProbeResult):
        raise GCodeError(f"G38 needs a ProbeResult, got {type(result).__name__}", req.line,
                         0, "G38", req.file)
    n = len(m.pos)
    for name in ("position", "stop"):
        pt = getattr(result, name)
        if len(pt) != n or not all(math.isfinite(v) for v in pt):
            raise GCodeError(f"ProbeResult.{name} must hold {n} finite values, got {pt!r}",
                             req.line, 0, "G38", req.file)
    gword = f"G{req.code / 10:g}"
    if req.must_trip and not result.tripped and not result.preview:
        what = "making" if req.contact else "breaking"
        raise GCodeError(f"{gword} move finished without {what} contact.", req.line,
                         0, gword, req.file)
    trip = program_point(m, result.position)
    for k in range(len(AXIS_LETTERS)):
        m.params.set_number(5061 + k, trip[k])
    m.params.set_number(5070, 1.0 if result.tripped else 0.0)
    m.pos = list(result.stop)


def program_point(m: Modal, point: Point) -> list[float]:
    """A machine point in program coordinates (X..W), as #<_x>.. would read there."""
    saved = m.pos
    m.pos = list(point)
    try:
        return [m.program_position(k) for k in range(len(AXIS_LETTERS))]
    finally:
        m.pos = saved
