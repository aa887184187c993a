"""What the interpreter needs to know about the machine: `GCodeOptions`.

Axis letters map to machine axis indices; the machine's length unit, start position, soft
limits, stored parameters (work offsets, G28/G30 positions), tool lengths, output numbers for
spindle/coolant and the safety limits of interpretation. Validated on construction.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..errors import MotionError, check_finite, check_int, show
from .parser import MAX_PARAMETER
from .source import MAX_LINE_LENGTH, MAX_PROGRAM_BYTES

#: RS-274/NGC axis letters in parameter order (#5221 = X of G54, #5222 = Y, ...).
AXIS_LETTERS = "XYZABCUVW"
#: Rotary axes: degrees, never scaled by G20/G21.
ROTARY_LETTERS = frozenset("ABC")
MM_PER_INCH = 25.4


def _opt_index(name: str, value: int | None) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise MotionError(f"{name} must be an integer >= 0 or None, got {value!r}")
    return value


@dataclass(frozen=True)
class GCodeOptions:
    """Machine description for the G-code interpreter.

    axes: letter -> machine axis index, e.g. {"X": 0, "Y": 1, "Z": 2, "A": 3}.
    n_axes: number of machine axes (default: highest mapped index + 1).
    machine_units: "mm" or "inch": the unit of canonical positions for linear axes.
    start: machine position at program start (default all zero).
    soft_limits: per machine axis (lo, hi) in machine units, or None for no limit.
    parameters: initial numbered parameters (work offsets #5221.., G28 #5161.., G30 #5181..,
        G92 #5211..), positions in machine units.
    tool_lengths: tool number -> length offset (machine units) applied to Z by G43.
    tool_table: a LinuxCNC tool table (.tbl path, or {number: Tool} from tooltable.py):
        offsets per axis for G43 and diameters for cutter compensation; tool_lengths adds
        Z-only tools not in it.
    n_outputs: M62-M65 P must be in [0, n_outputs).
    n_inputs / n_analog_inputs: M66 P / M66 E must be below them (digital, analog inputs).
    n_analog_outputs: M67/M68 E must be below it (LinuxCNC's default 4 analog outputs).
    spindle_output / mist_output / flood_output: outputs carried by Spindle/Coolant.
    block_delete: skip lines starting with '/' (the block-delete switch is on).
    keep_comments: also emit plain comments as Message(kind="comment").
    require_end: refuse a program that ends without M2, M30 or a closing '%' (LinuxCNC's
        "File ended with no percent sign or program end": a truncated file); off, the end
        of the text ends the program as M2 does. `openmotion run` turns it on.
    max_call_depth: subroutine nesting limit; max_blocks: executed-line limit (loops);
    max_loop_iterations: iterations one while/do/repeat loop may run each time it is entered.
    subroutine_path: folders searched for `O<name> call` subroutines not defined in the
        program, as <name>.ngc (then the program's own folder), like LinuxCNC's
        [RS274NGC]SUBROUTINE_PATH.
    user_m_path: folders searched for the executables of user M-codes M100-M199 (a file
        named M1nn), in LinuxCNC's order [DISPLAY]PROGRAM_PREFIX, then
        [RS274NGC]USER_M_PATH (usermcodes.py); every folder must exist.
    """

    axes: Mapping[str, int]
    n_axes: int | None = None
    machine_units: str = "mm"
    start: Sequence[float] | None = None
    soft_limits: Sequence[tuple[float, float] | None] | None = None
    parameters: Mapping[int, float] = field(default_factory=dict)
    tool_lengths: Mapping[int, float] = field(default_factory=dict)
    n_outputs: int = 16
    n_inputs: int = 16
    n_analog_inputs: int = 4
    n_analog_outputs: int = 4
    spindle_output: int | None = None
    mist_output: int | None = None
    flood_output: int | None = None
    block_delete: bool = True
    keep_comments: bool = False
    require_end: bool = False
    max_call_depth: int = 64
    max_blocks: int = 10_000_000
    max_loop_iterations: int = 1_000_000
    max_line_length: int = MAX_LINE_LENGTH
    max_bytes: int = MAX_PROGRAM_BYTES
    subroutine_path: Sequence[str | os.PathLike[str]] = ()
    user_m_path: Sequence[str | os.PathLike[str]] = ()
    tool_table: Mapping[int, Any] | str | os.PathLike[str] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.axes, Mapping) or not self.axes:
            raise MotionError(f"axes must be a non-empty mapping letter -> index, "
                              f"got {self.axes!r}")
        axes: dict[str, int] = {}
        for letter, idx in self.axes.items():
            up = letter.upper() if isinstance(letter, str) else letter
            if up not in tuple(AXIS_LETTERS):
                raise MotionError(f"axes keys must be letters of {AXIS_LETTERS}, got {letter!r}")
            check_int(f"axes[{letter!r}]", idx, 0)
            if idx in axes.values():
                raise MotionError(f"axes: machine axis {idx} is mapped twice")
            axes[up] = idx
        n = max(axes.values()) + 1
        if self.n_axes is not None:
            if isinstance(self.n_axes, bool) or not isinstance(self.n_axes, int) \
                    or self.n_axes < n:
                raise MotionError(f"n_axes must be an integer >= {n} (highest mapped axis + 1)"
                                  f", got {self.n_axes!r}")
            n = self.n_axes
        if not isinstance(self.machine_units, str) or self.machine_units not in ("mm", "inch"):
            raise MotionError(f"machine_units must be 'mm' or 'inch', got "
                              f"{self.machine_units!r}")
        if self.start is not None and (isinstance(self.start, (str, bytes, Mapping))
                                       or not isinstance(self.start, Iterable)
                                       or getattr(self.start, "ndim", 1) != 1):
            raise MotionError(f"start must be a sequence of {n} numbers (one per machine "
                              f"axis) or None, got {show(self.start)}")
        start = tuple(0.0 for _ in range(n)) if self.start is None else tuple(
            check_finite(f"start[{k}]", v) for k, v in enumerate(self.start))
        if len(start) != n:
            raise MotionError(f"start must have {n} values (one per machine axis), "
                              f"got {len(start)}")
        limits: tuple[tuple[float, float] | None, ...] | None = None
        if self.soft_limits is not None:
            if isinstance(self.soft_limits, str | bytes) or not hasattr(self.soft_limits,
                                                                         "__len__"):
                raise MotionError(f"soft_limits must be a sequence of {n} (lo, hi) or None "
                                  f"entries, got {self.soft_limits!r}")
            if len(self.soft_limits) != n:
                raise MotionError(f"soft_limits must have {n} entries (one per machine axis),"
                                  f" got {len(self.soft_limits)}")
            out = []
            for k, lim in enumerate(self.soft_limits):
                if lim is None:
                    out.append(None)
                    continue
                try:
                    lo_raw, hi_raw = lim
                except (TypeError, ValueError):
                    raise MotionError(f"soft_limits[{k}] must be (lo, hi) or None, "
                                      f"got {lim!r}") from None
                lo = -math.inf if lo_raw is None else float(lo_raw)
                hi = math.inf if hi_raw is None else float(hi_raw)
                if math.isnan(lo) or math.isnan(hi) or lo > hi:
                    raise MotionError(f"soft_limits[{k}] must satisfy lo <= hi, got {lim!r}")
                if not lo <= start[k] <= hi:
                    raise MotionError(f"start[{k}] = {start[k]:g} is outside soft_limits[{k}]"
                                      f" = {lim!r}")
                out.append((lo, hi))
            limits = tuple(out)
        for name in ("parameters", "tool_lengths"):
            if not isinstance(getattr(self, name), Mapping):
                raise MotionError(f"{name} must be a mapping number -> value, got "
                                  f"{show(getattr(self, name))}")
        for key, v in self.parameters.items():
            if isinstance(key, bool) or not isinstance(key, int) \
                    or not 1 <= key <= MAX_PARAMETER:
                raise MotionError(f"parameters keys must be integers in [1, {MAX_PARAMETER}],"
                                  f" got {key!r}")
            check_finite(f"parameters[{key}]", v)
        for key, v in self.tool_lengths.items():
            if isinstance(key, bool) or not isinstance(key, int) or key < 0:
                raise MotionError(f"tool_lengths keys must be integers >= 0, got {key!r}")
            check_finite(f"tool_lengths[{key}]", v)
        check_int("n_outputs", self.n_outputs, 0)
        check_int("n_inputs", self.n_inputs, 0)
        check_int("n_analog_inputs", self.n_analog_inputs, 0)
        check_int("n_analog_outputs", self.n_analog_outputs, 0)
        for name in ("spindle_output", "mist_output", "flood_output"):
            _opt_index(name, getattr(self, name))
        for name, lo in (("max_call_depth", 1), ("max_blocks", 1),
                         ("max_loop_iterations", 1), ("max_line_length", 16),
                         ("max_bytes", 1)):
            check_int(name, getattr(self, name), lo)
        for name in ("block_delete", "keep_comments", "require_end"):
            if not isinstance(getattr(self, name), bool):
                raise MotionError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if isinstance(self.subroutine_path, (str, bytes)) or not isinstance(
                self.subroutine_path, Iterable) or not all(
                isinstance(d, (str, os.PathLike)) for d in self.subroutine_path):
            raise MotionError(f"subroutine_path must be a sequence of folder names, got "
                              f"{self.subroutine_path!r}")
        object.__setattr__(self, "subroutine_path", tuple(os.fspath(d)
                                                          for d in self.subroutine_path))
        from .usermcodes import check_folders

        object.__setattr__(self, "user_m_path", check_folders("user_m_path",
                                                              self.user_m_path))
        object.__setattr__(self, "tool_table", self._tools())
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "n_axes", n)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "soft_limits", limits)

    def _tools(self) -> dict[int, Any]:
        """The tool table as {number: Tool}, tool_lengths merged in as Z-only tools."""
        from .tooltable import Tool, read_tool_table

        table = self.tool_table
        if table is None:
            tools: dict[int, Tool] = {}
        elif isinstance(table, (str, os.PathLike)):
            try:
                tools = read_tool_table(table)
            except MotionError as e:  # the file's own message, said to be the tool table
                raise MotionError(f"tool_table: {e}") from None
        elif isinstance(table, Mapping):
            tools = {}
            for key, t in table.items():
                if not isinstance(t, Tool) or t.number != key:
                    raise MotionError(f"tool_table[{key!r}] must be a Tool with number "
                                      f"{key!r}, got {t!r}")
                tools[key] = t
        else:
            raise MotionError(f"tool_table must be a .tbl path or a mapping number -> Tool,"
                              f" got {table!r}")
        for key, length in self.tool_lengths.items():
            if key in tools:
                raise MotionError(f"tool {key} is in both tool_table and tool_lengths")
            if key > 0:
                tools[key] = Tool(key, key, (0.0, 0.0, float(length)) + (0.0,) * 6)
        return tools
