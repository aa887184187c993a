"""The controller runtime: clock and cycle loop, axes (PLCopen states, HSL counters),
single-axis motion execution. Public positions are pulses; see Axis for unit-aware calls."""

from .core.axis import Axis
from .core.clock import CycleStats
from .core.controller import Controller, register_attachment, set_default_hardware
from .core.counters import COUNTER_MAX, COUNTER_MIN, Counters, wrap28
from .core.events import EventLog, MotionEvent
from .core.motion import ActiveMotion
from .core.states import AxisState, MotionDone
from .groups.accuracy import PulseAccuracy, count_accuracy, pulse_accuracy
from .groups.group import Group
from .groups.groupexec import GroupError, GroupState
from .guard.inposition import INPOS_TIMEOUT, InPositionControl
from .guard.safety import IO_STATUS_BITS, Safety, StopRecord, io_status
from .home.homing import Homing, escape_home, home_move, home_search
from .home.homing_modes import HomeConfig, HomeStatus
from .home.homing_sequence import HomeSequence
from .home.latch import Latch, LatchData, TouchProbe
from .loops.compensation import BACKLASH_COMPENSATING, Compensation, PitchCompTable
from .loops.servo import PIDFF, Compensator, FollowingErrorMonitor, FollowingErrorResult, LeadFilter
from .loops.servoloop import ServoLoop, attach_servo_loops
from .manual.jog import jog_conti, jog_pulse, jog_space, stop_jog
from .trigger.analog import AnalogInputs, AnalogOutputs
from .trigger.compare import CompareEngine
from .trigger.compare_io import EventLog as CompareLog
from .trigger.compare_io import plot_firings
from .trigger.compare_jobs import (
    AxisSource,
    LevelJob,
    LevelSeq,
    Pulse,
    SetLevel,
    Toggle,
    VectorSource,
    WindowJob,
    every_distance,
)
from .trigger.hsl_trigger import HslTrigger
from .trigger.pso import PulseTimer, ZPso


# -- composition: the core (controller) imports no capability and no back end; this
# package, one level up, chooses the default back end and what every controller gets.
def _simulator(config):  # noqa: ANN001, ANN202 - the default back end, imported when used
    from ..hw.sim import SimMachine

    return SimMachine(config)


set_default_hardware(_simulator)
register_attachment("servo_loops", lambda ctl, wanted: attach_servo_loops(ctl))
register_attachment("safety", lambda ctl, wanted: Safety(ctl) if wanted else None)

__all__ = [
    "COUNTER_MAX", "COUNTER_MIN", "ActiveMotion", "Axis", "AxisState", "Controller",
    "Counters", "CycleStats", "MotionDone", "wrap28", "AnalogOutputs", "AnalogInputs",
    "PIDFF", "Compensator", "FollowingErrorMonitor", "FollowingErrorResult", "LeadFilter",
    "ServoLoop", "BACKLASH_COMPENSATING", "Compensation", "PitchCompTable", "INPOS_TIMEOUT",
    "InPositionControl", "Group", "GroupError", "GroupState", "jog_conti", "jog_pulse",
    "jog_space", "stop_jog", "IO_STATUS_BITS", "Safety", "StopRecord", "io_status",
    "CompareEngine", "CompareLog", "plot_firings", "AxisSource", "LevelJob", "LevelSeq",
    "Pulse", "SetLevel", "Toggle", "VectorSource", "WindowJob", "every_distance", "EventLog",
    "MotionEvent", "Homing", "escape_home", "home_move", "home_search", "HomeConfig",
    "HomeStatus", "HomeSequence", "HslTrigger", "Latch", "LatchData", "TouchProbe",
    "PulseTimer", "ZPso", "PulseAccuracy", "count_accuracy", "pulse_accuracy",
]
