"""The PLCopen single-axis state machine (seed-facts 6.1) and HSL motion-done codes (2.5).

Every state change of an `Axis` goes through `transition`, which refuses anything the table
does not list, so an illegal sequence is a loud MotionError rather than a silent mess.
SynchronizedMotion (cam/gear) is not modelled yet.
"""

from __future__ import annotations

from enum import Enum

from ...errors import MotionError


class AxisState(Enum):
    """PLCopen Motion Control Part 1 axis states."""

    DISABLED = "Disabled"
    STANDSTILL = "Standstill"
    HOMING = "Homing"
    DISCRETE_MOTION = "DiscreteMotion"
    CONTINUOUS_MOTION = "ContinuousMotion"
    STOPPING = "Stopping"
    ERROR_STOP = "ErrorStop"


S = AxisState
MOTION_STATES = frozenset({S.HOMING, S.DISCRETE_MOTION, S.CONTINUOUS_MOTION, S.STOPPING})

#: Allowed transitions. Any state may go to ErrorStop (a fault) and to Disabled (power off);
#: those two are added below rather than repeated in every row.
TRANSITIONS: dict[AxisState, frozenset[AxisState]] = {
    S.DISABLED: frozenset({S.STANDSTILL}),
    S.STANDSTILL: frozenset({S.HOMING, S.DISCRETE_MOTION, S.CONTINUOUS_MOTION, S.STOPPING}),
    S.HOMING: frozenset({S.STANDSTILL, S.STOPPING}),
    # A motion may be replaced by the other kind (a velocity move becomes a positioning one).
    S.DISCRETE_MOTION: frozenset({S.STANDSTILL, S.DISCRETE_MOTION, S.CONTINUOUS_MOTION,
                                  S.STOPPING}),
    S.CONTINUOUS_MOTION: frozenset({S.STANDSTILL, S.DISCRETE_MOTION, S.CONTINUOUS_MOTION,
                                    S.STOPPING}),
    # Stopping cannot be aborted by motion; it ends in Standstill (or a fault / power off).
    S.STOPPING: frozenset({S.STANDSTILL, S.STOPPING}),
    # MC_Reset: to Standstill when powered, to Disabled otherwise.
    S.ERROR_STOP: frozenset({S.STANDSTILL}),
}
TRANSITIONS = {
    k: v | {S.ERROR_STOP, S.DISABLED} for k, v in TRANSITIONS.items()
}


def can_transition(src: AxisState, dst: AxisState) -> bool:
    """Whether the table allows src -> dst."""
    return dst in TRANSITIONS[src]


def transition(src: AxisState, dst: AxisState, axis_name: str = "axis") -> AxisState:
    """Return dst if the table allows src -> dst, else raise MotionError."""
    if dst not in TRANSITIONS[src]:
        raise MotionError(
            f"{axis_name}: state transition {src.value} -> {dst.value} is not allowed"
        )
    return dst


class MotionDone:
    """`motion_done` status codes of the PCL6045 main status (seed-facts 2.5)."""

    STOPPED = 0
    HOMING = 9  # home special-speed motion: between the moves of a home sequence
    AT_STRVEL = 10
    ACCELERATING = 11
    AT_MAXVEL = 12
    DECELERATING = 13
    WAITING_INP = 14
