"""G-code front end: RS-274/NGC (LinuxCNC dialect subset) -> canonical commands.

    from openmotion.program import GCodeOptions, compile_text
    cmds = compile_text("G21 G90 G1 X10 F600 M2", GCodeOptions(axes={"X": 0, "Y": 1}))

Parsing (parser.py, expr.py) and interpretation (interp.py: O-word control flow;
modal.py: the modal state machine) validate the whole program before returning; any problem
is a GCodeError naming line, column and word. The commands (canon.py) are in machine
coordinates and machine units, ready for the group runtime. See docs/gcode.md.
"""

from .canon import (
    ArcMove,
    Command,
    Coolant,
    Dwell,
    End,
    Feed,
    Message,
    Pause,
    Rapid,
    SetBlend,
    SetOutput,
    Spindle,
    SyncedFeed,
    ToolChange,
)
from .interp import Interpreter, compile_file, compile_text, interpret
from .options import GCodeOptions
from .parser import Block, Program, parse_program
from .points import PointTable, TablePoint
from .report import RunSummary, format_summary, summarize, write_report
from .runner import ProgramRunner, RunEvent, RunOptions, RunState, run_program
from .source import GCodeError, read_program

__all__ = [
    "PointTable", "ProgramRunner", "RunEvent", "RunOptions", "RunState", "RunSummary",
    "TablePoint", "format_summary", "run_program", "summarize", "write_report",
    "ArcMove",
    "Block",
    "Command",
    "Coolant",
    "Dwell",
    "End",
    "Feed",
    "SyncedFeed",
    "GCodeError",
    "GCodeOptions",
    "Interpreter",
    "Message",
    "Pause",
    "Program",
    "Rapid",
    "SetBlend",
    "SetOutput",
    "Spindle",
    "ToolChange",
    "compile_file",
    "compile_text",
    "interpret",
    "parse_program",
    "read_program",
]
