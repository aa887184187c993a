"""MCCL.h for `openmotion.compat.mccl`: return codes, constants and the structures.

Return codes and constants are the header's (seed-facts 5). The structures are dataclasses
with the manual's field names (HIWIN PCI-4P motion library user's manual, 2.4-2.10); fixed
C arrays are lists of the C length. The run-time error codes `MCC_GetErrorCode` returns
are in the separate reference manual, which we do not have: the values below are ours
(seed-facts 5 asks the spec to define them), one per error the user's manual names.
"""

from __future__ import annotations

from dataclasses import dataclass, field

# ---------------------------------------------------------------------- return codes
NO_ERR = 0
INITIAL_MOTION_ERR = -1
COMMAND_BUFFER_FULL_ERR = -2
COMMAND_NOTACCEPTED_ERR = -3
COMMAND_NOTFINISHED_ERR = -4
PARAMETER_ERR = -5
GROUP_PARAMETER_ERR = -6
FEED_RATE_ERR = -7
BLEND_COMMAND_NOTCALLED_ERR = -8
VOLTAGE_COMMAND_CHANNEL_ERR = -9
HOME_COMMAND_NOTCALLED_ERR = -10
HOLD_ILLEGAL_ERR = -11
CONTI_ILLEGAL_ERR = -12
ABORT_ILLEGAL_ERR = -13
RUN_TIME_ERR = -14
ABORT_NOT_FINISH_ERR = -15
GROUP_RAN_OUT_ERR = -16

# ---------------------------------------------------------------------- motion status
GMS_RUNNING = 0
GMS_STOP = 1
GMS_HOLD = 2
GMS_DELAYING = 3

# ---------------------------------------------------------------------- other constants
CIR_CW = 0
CIR_CCW = 1
IPM_ONETIME_BLOCK = 0
IPM_ONETIME_UNBLOCK = 1
IPM_SETTLE_BLOCK = 2
IPM_SETTLE_UNBLOCK = 3
MAX_COMP_POINT = 256
DDA_FMT_NO, DDA_FMT_PD, DDA_FMT_CW, DDA_FMT_AB = 0, 1, 2, 3
NORMAL_MODE, HOME_ONLY_MODE, INDEX_ONLY_MODE = 0, 1, 2
UNIT_MM, UNIT_INCH = 0, 1
COORD_ABSOLUTE, COORD_INCREASE = 0, 1
MAX_CARD = 12
MAX_GROUP = 72
CHANNELS_PER_CARD = 4
GROUP_AXES = 6            # x, y, z, u, v, w arguments (v, w are not used on the PCI-4P)
CARD_TYPE_PCI_4P = 2
#: MCC_GetCurCommand nType
CMD_PTP, CMD_LINE, CMD_CW, CMD_CCW = 0, 1, 2, 3
CMD_DELAY = 4             # ours: a delay is executing (the manual lists types 0-3 only)

# ---------------------------------------------------------------------- run-time errors
#: MCC_GetErrorCode values (ours; see the module doc).
ERROR_NONE = 0
ERROR_LIMIT_SWITCH = 101      # a limit switch was reached
ERROR_SOFT_LIMIT = 102        # the software limit (working interval) was reached
ERROR_OVER_SPEED = 201        # a command needed more than the maximum pulse speed
ERROR_OVER_ACC = 202          # ... more than the maximum pulse acceleration
ERROR_ARC = 203               # arc command error
ERROR_INPOS_TIMEOUT = 301     # in-position check time passed (core INPOS_TIMEOUT)
ERROR_AXIS_FAULT = 401        # an axis faulted (servo alarm, stop refused, ...)
ERROR_EMERGENCY = 402         # emergency stop input


# ---------------------------------------------------------------------- structures
@dataclass
class HOME_CONFIG:
    """Homing parameters (2.4): wType 0 NORMAL / 1 HOME_ONLY / 2 INDEX_ONLY; phase
    directions 0 positive / 1 negative; wSensorMode 0 NO / 1 NC; dfOffset (mm) from the
    mechanism origin to the logical home."""

    wType: int = NORMAL_MODE
    wPhase0Dir: int = 1
    wPhase1Dir: int = 0
    wSensorMode: int = 0
    dfOffset: float = 0.0


SYS_HOME_CONFIG = HOME_CONFIG


@dataclass
class ENCODER_CONFIG:
    """Encoder format (2.4): wType 0 A/B, 1 CW/CCW, 2 Pulse/Direction; inversions 0/1;
    wABSwap 1 swaps A and B (the manual's table reads "0 Swap, 1 Not Swap", but its own
    example sets 0 for a normal encoder: we take 0 = not swapped)."""

    wType: int = 0
    wAInverse: int = 0
    wBInverse: int = 0
    wCInverse: int = 0
    wABSwap: int = 0
    wPaddle: list[int] = field(default_factory=lambda: [0, 0, 0])


SYS_ENCODER_CONFIG = ENCODER_CONFIG


@dataclass
class SYS_MACH_PARAM:
    """Mechanism parameters of one axis (2.4; the manual's example values as defaults
    where it gives them). Lengths in mm, speeds from wRPM."""

    wPosToEncoderDir: int = 0
    wRPM: int = 3000
    dwPPR: int = 500
    dfPitch: float = 1.0
    dfGearRatio: float = 1.0
    dfHighLimit: float = 50000.0
    dfLowLimit: float = -50000.0
    dfHighLimitOffset: float = 5.0
    dfLowLimitOffset: float = 5.0
    wPulseMode: int = 0
    wPulseWidth: int = 100
    wCommandMode: int = 0
    wPaddle: int = 0
    stHome: HOME_CONFIG = field(default_factory=HOME_CONFIG)
    stEncoder: ENCODER_CONFIG = field(default_factory=ENCODER_CONFIG)
    wOverTravelUpSensorMode: int = 2
    wOverTravelDownSensorMode: int = 2


@dataclass
class SYS_GROUP_INFO:
    """A group's card and the channel of each of its axes x, y, z, u (-1: not used;
    nChannel[4] and [5] must be -1)."""

    nCardIndex: int = 0
    nChannel: list[int] = field(default_factory=lambda: [-1] * 6)


@dataclass
class SYS_GROUP_CONFIG:
    """Groups (2.5.1): nGroupUsed[g] == 0 uses group g (the manual's example marks the
    others -1); stGroupInfo[g] dispatches its axes."""

    nGroupUsed: list[int] = field(default_factory=lambda: [-1] * MAX_GROUP)
    stGroupInfo: list[SYS_GROUP_INFO] = field(
        default_factory=lambda: [SYS_GROUP_INFO() for _ in range(MAX_GROUP)])


@dataclass
class SYS_CARD_CONFIG:
    """A card (2.5.1): wCardType 2 for the PCI-4P; address and IRQ are not used."""

    wCardType: int = CARD_TYPE_PCI_4P
    wCardAddress: int = 0
    wIRQ_No: int = 0
    wPaddle: int = 0


@dataclass
class SYS_COMP_PARAM:
    """Pitch/backlash compensation of one axis (2.10.1): dwInterval (pulses, <= 0
    disables), wHome_No (the home point), the forward and backward tables (pulses)."""

    dwInterval: int = 0
    wHome_No: int = 0
    wPaddle: int = 0
    nForwardTable: list[int] = field(default_factory=lambda: [0] * MAX_COMP_POINT)
    nBackwardTable: list[int] = field(default_factory=lambda: [0] * MAX_COMP_POINT)


@dataclass
class COMMAND_INFO:
    """The executing command (2.6.5): nType 0 PtP, 1 line, 2 CW arc/circle, 3 CCW
    arc/circle (4: a delay, ours); dfFeedSpeed is the feed (PtP: the speed ratio);
    dfPos the target (dfPos[4], [5] not used)."""

    nType: int = 0
    nCommandIndex: int = -1
    dfFeedSpeed: float = 0.0
    dfPos: list[float] = field(default_factory=lambda: [0.0] * 6)
