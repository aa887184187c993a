"""Compile fast path: plain word lines (N, G0/G1, axis words, F) run without a Block.

CAM programs are almost all lines like `N120 G1 X12.5 Y-3.25 F1200`. Such a line needs no
comment handling, expressions or O-words, so `plain_commands` matches it with one regex on
the raw text and applies exactly what `Modal.execute` would (F with feed_lin/feed_ang,
motion mode, motion_prev, the end of a canned-cycle series, the target through the work,
G92 and tool offsets, soft limits, a `Rapid` or `Feed` record) straight to the modal state.

It does so only while the modal state is one whose effect on a plain line it models
(`_plain_modes`): no cutter compensation, no rotated coordinate system, no G7 diameter
mode, a G0/G1 motion mode; feed moves also need G94 (not G93/G95). In any other state, and
for every other line, the line goes through `parse_line` and `Modal.execute` as before; a
plain line the fast code cannot finish (soft limit, zero feed) is re-run that way too, so
its error is the general path's own. A program with an O-word, an M98/M99 request or more
lines than `max_blocks` is handed whole to the general interpreter (`_Defer`). The result
and every error are those of parse_program + interpret, only faster.

The garbage collector is paused while a program compiles: the command list only grows,
and the collections it would trigger rescan every command made so far (O(n) pauses).
"""

from __future__ import annotations

import gc
import re
from collections.abc import Callable, Iterable, Iterator, Sequence

from . import canon
from .cuttercomp import CutterComp
from .cycles import CycleState
from .modal import Modal
from .options import ROTARY_LETTERS, GCodeOptions
from .params import Parameters
from .parser import parse_line
from .progunits import CompiledProgram, program_units

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)"

#: Modal's attributes this module knows. A Modal with others (a dialect feature added
#: later) may change what a plain line does: then the fast path stays off until this list
#: and `_plain_modes` are brought up to date (a test checks it is on for a plain program).
KNOWN_STATE = frozenset((
    "opt", "params", "pos", "machine_mm", "units", "lscale", "ldiv", "incremental",
    "arc_incremental", "plane", "inverse_time", "feed", "feed_lin", "feed_ang", "motion",
    "motion_prev", "cycle", "polar_inc", "comp", "saved_states", "blend", "coord", "tools",
    "has_tool_table", "selected_tool", "tool", "spindle_on", "spindle_cw", "speed", "mist",
    "flood", "ended",
    "flow_request", "letters", "g92", "off", "work", "rot", "rotated", "tool_offset", "line",
    "per_rev", "css", "retract_old_z", "diameter_mode", "wait_request", "unit_log", "out_at",
    "feed_override_on", "speed_override_on", "feed_hold_on", "adaptive_feed_on"))


class _Defer(Exception):
    """The program needs the general interpreter (O-words, M98/M99, max_blocks)."""


def fast_path_available(modal: Modal) -> bool:
    """Whether `modal` holds only the state this module knows (module docstring)."""
    return (type(modal) is Modal and set(vars(modal)) <= KNOWN_STATE
            and type(modal.comp) is CutterComp and type(modal.cycle) is CycleState)


def _plain_modes(modal: Modal) -> tuple[bool, bool]:
    """(plain rapids and motion-mode words allowed, plain feed moves allowed)."""
    moves = (not modal.comp.side and not modal.rotated and not modal.diameter_mode
             and modal.flow_request is None)
    return moves, moves and not modal.inverse_time and not modal.per_rev


def compile_plain(lines: Iterable[str], options: GCodeOptions, file: str,
                  full: Callable[[], list[canon.Command]]) -> list[canon.Command]:
    """Compile the program `lines` (str lines, no line ends) with the fast path; `full()`
    is the general compile of the same program, used when the program needs it and on
    any error, so that the result and the error raised are exactly its own."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        state: list[Modal] = []
        try:
            out = list(plain_commands(lines, options, file, state))
        except Exception:  # GCodeError or _Defer: the general path says what is wrong
            out = None
        if out is None:
            return full()
        m = state[0]
        return CompiledProgram(out, program_units(out, m.unit_log, options.machine_units,
                                                  by_line=True))
    finally:
        if enabled:
            gc.enable()


def _canonical_regex(letters: Iterable[str]) -> re.Pattern[str]:
    """The common CAM layout for the mapped axis `letters`: optional N, G0/G1, each axis
    word at most once in XYZABCUVW order, then F; one group per word."""
    axes = "".join(rf"(?:{L}({_NUM})[ \t]*)?" for L in letters)
    return re.compile(rf"[ \t]*(?:N\d+[ \t]*)?(?:G0*([01])(?![.\d])[ \t]*)?{axes}"
                      rf"(?:F({_NUM})[ \t]*)?\Z")


def plain_commands(lines: Iterable[str], options: GCodeOptions,  # noqa: C901
                   file: str, state: list[Modal] | None = None) -> Iterator[canon.Command]:
    """The commands of a program without O-words, line by line (module docstring).

    Raises the general path's GCodeError for a line that is wrong, and `_Defer` where the
    whole program must go to the interpreter. Lines are read one at a time, so `lines`
    may be a file being read.
    """
    params = Parameters(options.parameters)
    modal = Modal(options, params)
    if state is not None:  # the caller reads the modal state after (its unit_log)
        state.append(modal)
    if not fast_path_available(modal):
        raise _Defer("modal state unknown to the fast path")
    general: list[canon.Command] = []
    max_len = options.max_line_length
    limit = options.max_blocks
    skip_deleted = options.block_delete
    soft = options.soft_limits is not None
    # Modal.check_limits's bounds for a plain line (lo = hi = its target), the same floats
    bounds = _soft_bounds(options.soft_limits, len(modal.pos)) if soft else None
    letters = modal.letters
    order = [L for L in "XYZABCUVW" if L in letters]
    # (group, machine axis, offset index, linear) per mapped letter, in regex order
    slots = [(gi, letters[L][0], letters[L][1], L not in ROTARY_LETTERS)
             for gi, L in enumerate(order, 1)]
    n_groups = len(order) + 2
    no_words = (None,) * (n_groups - 2)
    xy_groups = [gi for gi, L in enumerate(order, 1) if L in "XY"]
    # Modal._rotary_only: (machine axis, rotary) of every mapped letter, in its order
    movers = [(ax, L in ROTARY_LETTERS) for L, (ax, _k) in letters.items()]
    any_rotary = any(rot for _ax, rot in movers)
    canonical = _canonical_regex(order).match
    Feed, Rapid = canon.Feed, canon.Rapid
    comp, cycle = modal.comp, modal.cycle
    seen_code = False
    running = True
    steps = 0
    # the modal state a plain line reads, refreshed after every general line
    motion, pos = modal.motion, modal.pos
    incremental, off = modal.incremental, modal.off
    lscale, ldiv = modal.lscale, modal.ldiv
    unit = lscale == 1.0 == ldiv
    moves_ok, feeds_ok = _plain_modes(modal)
    # written back to the modal state before a general line and at the end
    feed, f_lin, f_ang = modal.feed, modal.feed_lin, modal.feed_ang
    motion_prev = modal.motion_prev
    cycle_set = True  # cycle.initial may be set: the next plain line clears it
    for k, text in enumerate(lines, 1):
        if not running:  # after M2/M30: later lines are still parsed (their errors count)
            if len(text) > max_len or canonical(text) is None:
                if text.strip() == "%":
                    break
                b = parse_line(text, k, file, max_len)
                if b is not None and b.oword is not None:
                    raise _Defer("O-word")
            continue
        m = canonical(text) if moves_ok and len(text) <= max_len else None
        if m is not None:
            grp = m.groups()
            g = grp[0]
            f = grp[-1]
            mode = motion if g is None else (0 if g == "0" else 10)
            fv = 0.0
            if f is not None:
                fv = float(f)
                if fv < 0.0:
                    m = None  # the general path's error
            moving = grp[1:-1] != no_words
            if m is not None and moving and (mode == 0 or (mode == 10 and feeds_ok)):
                steps += 1
                seen_code = True
                if steps > limit:
                    raise _Defer("max_blocks")
                if f is not None:
                    n_feed, n_lin, n_ang = fv, fv * lscale / ldiv, fv
                else:
                    n_feed, n_lin, n_ang = feed, f_lin, f_ang
                target = pos[:]
                if unit and not incremental:
                    for gi, ax, kk, _linear in slots:
                        sv = grp[gi]
                        if sv is not None:
                            target[ax] = float(sv) + off[kk]
                else:
                    for gi, ax, kk, linear in slots:
                        sv = grp[gi]
                        if sv is not None:
                            v = float(sv)
                            if linear and not unit:
                                v = v * lscale / ldiv
                            target[ax] = pos[ax] + v if incremental else v + off[kk]
                per_s = 0.0
                if mode == 10:
                    if n_feed <= 0.0:
                        m = None  # "feed rate is zero or not set": the general path
                    else:
                        rotary_only = False
                        if any_rotary:
                            moved = [rot for ax, rot in movers if target[ax] != pos[ax]]
                            rotary_only = bool(moved) and all(moved)
                        per_s = (n_ang if rotary_only else n_lin) / 60.0
                if m is not None and soft:
                    if bounds is None:
                        try:
                            modal.check_limits(_FakeBlock, target, target, "", 0)
                        except _Reroute:
                            m = None
                    else:
                        for ax, lo_b, hi_b in bounds:
                            t = target[ax]
                            if t < lo_b or t > hi_b:
                                m = None  # the general path raises its error
                                break
                if m is not None:
                    feed, f_lin, f_ang = n_feed, n_lin, n_ang
                    motion_prev = motion
                    motion = mode
                    if cycle_set:
                        cycle.initial = None
                        cycle_set = False
                    if comp.arc_not_allowed:
                        for gi in xy_groups:
                            if grp[gi] is not None:
                                comp.arc_not_allowed = False
                    if mode == 10:
                        yield Feed(tuple(target), per_s, k, file, None)
                    else:
                        yield Rapid(tuple(target), k, file)
                    pos = target
                    continue
                steps -= 1  # the general path below counts the line again
            elif m is not None and not moving:
                if f is not None:
                    feed, f_lin, f_ang = fv, fv * lscale / ldiv, fv
                if g is not None:
                    motion_prev = motion
                    motion = mode
                    if cycle_set:
                        cycle.initial = None
                        cycle_set = False
                if text.strip():
                    seen_code = True
                    steps += 1
                    if steps > limit:
                        raise _Defer("max_blocks")
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
            raise _Defer("O-word")
        steps += 1
        if steps > limit:
            raise _Defer("max_blocks")
        if b.delete and skip_deleted:
            continue
        modal.motion, modal.pos, modal.motion_prev = motion, pos, motion_prev
        modal.feed, modal.feed_lin, modal.feed_ang = feed, f_lin, f_ang
        running = modal.execute(b, general)
        if modal.flow_request is not None:
            raise _Defer("M98/M99")
        if modal.wait_request is not None:  # G38.x / M66: the interpreter answers it
            raise _Defer("probe or input wait")
        if general and not comp.side and not comp.queue:
            # cutter compensation edits the moves it queued (indices into this list):
            # they leave only once it is off
            yield from general
            general.clear()
        motion, pos = modal.motion, modal.pos
        incremental, off = modal.incremental, modal.off
        lscale, ldiv = modal.lscale, modal.ldiv
        unit = lscale == 1.0 == ldiv
        moves_ok, feeds_ok = _plain_modes(modal)
        feed, f_lin, f_ang = modal.feed, modal.feed_lin, modal.feed_ang
        motion_prev = modal.motion_prev
        cycle_set = True
    modal.motion, modal.pos, modal.motion_prev = motion, pos, motion_prev
    modal.feed, modal.feed_lin, modal.feed_ang = feed, f_lin, f_ang
    yield from general


def _soft_bounds(limits: Sequence[tuple[float, float] | None],
                 n_axes: int) -> list[tuple[int, float, float]] | None:
    """(machine axis, lowest, highest) position `Modal.check_limits` lets a point reach on
    every limited axis (its own tolerance, computed the same way), or None when the limits
    name more axes than the machine has (that call then runs as it is)."""
    if len(limits) > n_axes:
        return None
    return [(ax, lim[0] - 1e-9 * max(1.0, abs(lim[0])), lim[1] + 1e-9 * max(1.0, abs(lim[1])))
            for ax, lim in enumerate(limits) if lim is not None]


class _FakeBlock:
    """Stands in for a Block where a check may raise: the line then runs through the
    general path, which raises the error with the real line and column."""

    @staticmethod
    def error(message: str, pos: int = -1, word: str = "") -> Exception:
        return _Reroute(message)


class _Reroute(Exception):
    pass
