"""Compile fast path: plain word lines (N, G0/G1, axis words, F) run without a Block.

CAM programs are almost all lines like `N120 G1 X12.5 Y-3.25 F1200`. Such a line needs no
comment handling, expressions or O-words, so `compile_plain` matches it with one regex on
the raw text and applies exactly what `Modal.execute` would (feed word, motion mode, the
target in machine coordinates, soft limits, a `Rapid` or `Feed` record) straight to the
modal state. Every other line goes through `parse_line` and `Modal.execute` as before, and
whenever anything is unusual (a line the fast path does not cover in the present modal
state, an error, an O-word anywhere in the program) the caller's full path decides: the
result and every error are those of parse_program + interpret, only faster.

The garbage collector is paused while a program compiles: the command list only grows,
and the collections it would trigger rescan every command made so far (O(n) pauses).
"""

from __future__ import annotations

import gc
import re
from collections.abc import Callable, Iterable

from . import canon
from .modal import Modal
from .options import ROTARY_LETTERS, GCodeOptions
from .params import Parameters
from .parser import parse_line

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)"

#: Modal's attributes this module knows. A Modal with others (a dialect feature added
#: later, e.g. cutter compensation) may change what a plain line does: then the fast path
#: stays off until this list and the code below are brought up to date (a test checks it
#: is on for a plain program).
KNOWN_STATE = frozenset((
    "opt", "params", "pos", "machine_mm", "units", "lscale", "ldiv", "incremental",
    "arc_incremental", "plane", "inverse_time", "feed", "motion", "coord", "tool_z",
    "selected_tool", "tool", "spindle_on", "spindle_cw", "speed", "mist", "flood", "ended",
    "letters", "g92", "off"))


def fast_path_available(modal: Modal) -> bool:
    """Whether `modal` holds only the state this module knows (module docstring)."""
    return type(modal) is Modal and set(vars(modal)) <= KNOWN_STATE


def compile_plain(lines: Iterable[str], options: GCodeOptions, file: str,
                  full: Callable[[], list[canon.Command]]) -> list[canon.Command]:
    """Compile the program `lines` (str lines, no line ends) with the fast path; `full()`
    is the general compile of the same program, used for O-words and on any error so that
    the result and the error raised are exactly its own."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        try:
            out = _run(lines, options, file)
        except Exception:  # GCodeError or not: the general path says what is wrong
            out = None
        return full() if out is None else out
    finally:
        if enabled:
            gc.enable()


def _canonical_regex(letters: Iterable[str]) -> re.Pattern[str]:
    """The common CAM layout for the mapped axis `letters`: optional N, G0/G1, each axis
    word at most once in XYZABCUVW order, then F; one group per word."""
    axes = "".join(rf"(?:{L}({_NUM})[ \t]*)?" for L in letters)
    return re.compile(rf"[ \t]*(?:N\d+[ \t]*)?(?:G0*([01])(?![.\d])[ \t]*)?{axes}"
                      rf"(?:F({_NUM})[ \t]*)?\Z")


def _run(lines: Iterable[str], options: GCodeOptions,  # noqa: C901
         file: str) -> list[canon.Command] | None:
    """The fast compile; None where the general path must decide (O-words, limits)."""
    params = Parameters(options.parameters)
    modal = Modal(options, params)
    if not fast_path_available(modal):
        return None
    out: list[canon.Command] = []
    append = out.append
    max_len = options.max_line_length
    limit = options.max_blocks
    skip_deleted = options.block_delete
    soft = options.soft_limits is not None
    letters = modal.letters
    order = [L for L in "XYZABCUVW" if L in letters]
    # (group, machine axis, offset index, linear) per mapped letter, in regex order
    slots = [(gi, letters[L][0], letters[L][1], L not in ROTARY_LETTERS)
             for gi, L in enumerate(order, 1)]
    n_groups = len(order) + 2
    canonical = _canonical_regex(order).match
    Feed, Rapid = canon.Feed, canon.Rapid
    seen_code = False
    running = True
    steps = 0
    feed_key: tuple[float, float, float] | None = None
    feed_per_s = 0.0
    # the modal state a plain line reads, refreshed after every general line
    motion, pos = modal.motion, modal.pos
    incremental, off = modal.incremental, modal.off
    lscale, ldiv, unit = modal.lscale, modal.ldiv, modal.lscale == 1.0 == modal.ldiv
    inverse = modal.inverse_time
    for k, text in enumerate(lines, 1):
        if not running:
            if canonical(text) is None:
                if text.strip() == "%":
                    break
                b = parse_line(text, k, file, max_len)  # parse errors are still errors
                if b is not None and b.oword is not None:
                    return None
            continue
        m = canonical(text) if len(text) <= max_len else None
        if m is not None:
            grp = m.groups()
            g = grp[0]
            f = grp[-1]
            mode = motion if g is None else (0 if g == "0" else 10)
            if f is not None:
                fv = float(f)
                if fv < 0.0:
                    m = None
            if m is not None:
                moving = False
                for gi in range(1, n_groups - 1):
                    if grp[gi] is not None:
                        moving = True
                        break
                if moving and (mode == 0 or (mode == 10 and not inverse)):
                    steps += 1
                    seen_code = True
                    if steps > limit:
                        return None
                    if f is not None:
                        modal.feed = fv
                    motion = mode
                    target = pos[:]
                    for gi, ax, kk, linear in slots:
                        sv = grp[gi]
                        if sv is not None:
                            v = float(sv)
                            if linear and not unit:
                                v = v * lscale / ldiv
                            target[ax] = pos[ax] + v if incremental else v + off[kk]
                    if mode == 10:
                        key = (modal.feed, lscale, ldiv)
                        if key != feed_key:
                            if modal.feed <= 0.0:
                                return None  # the general path's error
                            feed_key = key
                            feed_per_s = modal.lin(modal.feed) / 60.0
                    if soft:
                        modal.check_limits(_FakeBlock, target, target, "", 0)
                    if mode == 10:
                        append(Feed(tuple(target), feed_per_s, k, file, None))
                    else:
                        append(Rapid(tuple(target), k, file))
                    pos = target
                    continue
                if not moving:
                    if f is not None:
                        modal.feed = fv
                    if g is not None:
                        motion = mode
                    if text.strip():
                        seen_code = True
                        steps += 1
                        if steps > limit:
                            return None
                    continue
        # anything else: the general parser and Modal.execute
        if text.strip() == "%":
            if seen_code:
                break
            seen_code = True
            continue
        b = parse_line(text, k, file, max_len)
        if b is None:
            continue
        seen_code = True
        if b.oword is not None:
            return None  # O-word control flow: the general interpreter
        steps += 1
        if steps > limit:
            return None
        if b.delete and skip_deleted:
            continue
        modal.motion, modal.pos = motion, pos
        if not modal.execute(b, out):
            running = False
        motion, pos = modal.motion, modal.pos
        incremental, off = modal.incremental, modal.off
        lscale, ldiv, unit = modal.lscale, modal.ldiv, modal.lscale == 1.0 == modal.ldiv
        inverse = modal.inverse_time
    modal.motion, modal.pos = motion, pos
    return out


class _FakeBlock:
    """Stands in for a Block where a check may raise: any error sends the program to the
    general path, which raises it with the real line and column."""

    @staticmethod
    def error(message: str, pos: int = -1, word: str = "") -> Exception:
        return _Reroute(message)


class _Reroute(Exception):
    pass
