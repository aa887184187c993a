"""HCTL-1100 register map, flag codes, modes and number formats (AIM104 manual, app. 1-2).

Pure constants and conversions; the chip itself is in `hctl1100.py`.
"""

from __future__ import annotations

from enum import Enum

from openmotion.errors import MotionError

# --- register addresses (AIM104 appendix 2, "Register Reference Table") ---
R_FLAG = 0x00
R_PROGRAM = 0x05
R_STATUS = 0x07
R_PWM = 0x09
R_CMD_POS_MSB, R_CMD_POS_MID, R_CMD_POS_LSB = 0x0C, 0x0D, 0x0E
R_SAMPLE_TIMER = 0x0F
R_ACT_POS_MSB, R_ACT_POS_MID, R_ACT_POS_LSB = 0x12, 0x13, 0x14
R_PRESET_MSB, R_PRESET_MID, R_PRESET_LSB = 0x15, 0x16, 0x17
R_COMM_RING = 0x18
R_COMM_VEL_TIMER = 0x19
R_COMM_X = 0x1A
R_COMM_Y = 0x1B
R_COMM_OFFSET = 0x1C
R_COMM_ADVANCE = 0x1F
R_FILTER_A, R_FILTER_B, R_FILTER_K = 0x20, 0x21, 0x22
R_PROP_VEL_LSB, R_PROP_VEL_MSB = 0x23, 0x24
R_ACCEL_LSB, R_ACCEL_MSB = 0x26, 0x27
R_MAX_VEL = 0x28
R_FINAL_LSB, R_FINAL_MID, R_FINAL_MSB = 0x29, 0x2A, 0x2B
R_ACT_VEL_LSB, R_ACT_VEL_MSB = 0x34, 0x35
R_INT_VEL = 0x3C

#: Registers the user may read / write (anything else is refused by the Python API).
READABLE = frozenset({
    R_FLAG, R_STATUS, R_PWM, R_CMD_POS_MSB, R_CMD_POS_MID, R_CMD_POS_LSB, R_SAMPLE_TIMER,
    R_ACT_POS_MSB, R_ACT_POS_MID, R_ACT_POS_LSB, R_COMM_RING, R_COMM_X, R_COMM_Y,
    R_COMM_OFFSET, R_COMM_ADVANCE, R_FILTER_A, R_FILTER_B, R_FILTER_K, R_PROP_VEL_LSB,
    R_PROP_VEL_MSB, R_ACCEL_LSB, R_ACCEL_MSB, R_MAX_VEL, R_FINAL_LSB, R_FINAL_MID,
    R_FINAL_MSB, R_ACT_VEL_LSB, R_ACT_VEL_MSB, R_INT_VEL,
})
WRITABLE = frozenset({
    R_FLAG, R_PROGRAM, R_STATUS, R_PWM, R_CMD_POS_MSB, R_CMD_POS_MID, R_CMD_POS_LSB,
    R_SAMPLE_TIMER, R_ACT_POS_MID, R_PRESET_MSB, R_PRESET_MID, R_PRESET_LSB, R_COMM_RING,
    R_COMM_VEL_TIMER, R_COMM_X, R_COMM_Y, R_COMM_OFFSET, R_COMM_ADVANCE, R_FILTER_A,
    R_FILTER_B, R_FILTER_K, R_PROP_VEL_LSB, R_PROP_VEL_MSB, R_ACCEL_LSB, R_ACCEL_MSB,
    R_MAX_VEL, R_FINAL_LSB, R_FINAL_MID, R_FINAL_MSB, R_INT_VEL,
})

# --- program counter commands (R05H) ---
PC_RESET, PC_INIT_IDLE, PC_ALIGN, PC_CONTROL = 0x00, 0x01, 0x02, 0x03

# --- flag register codes (R00H): bits 0-2 flag address, bit 3 set(1)/clear(0) ---
F0, F1, F2, F3, F4, F5 = range(6)
FLAG_SET = 0x08

# --- status register (R07H) bits ---
ST_SIGN_INHIBIT = 0x01
ST_FOUR_PHASE = 0x02
ST_FULL_COUNTS = 0x04
ST_RESERVED = 0x08
ST_PROFILE = 0x10
ST_INIT = 0x20
ST_STOP_CLEAR = 0x40   # 0 = STOP triggered
ST_LIMIT_CLEAR = 0x80  # 0 = LIMIT triggered

# --- soft-reset defaults (appendix 1, "Reset") ---
DEFAULT_A, DEFAULT_B, DEFAULT_K = 0xE5, 0x40, 0x40
DEFAULT_SAMPLE_TIMER = 0x40
#: Chip clock assumed by the manual's sample-time formula (t = 16(T+1)/fclk).
CLOCK_HZ = 2.0e6
#: Align energises each of PHA and PHD for this many samples.
ALIGN_SAMPLES = 2048


class Mode(Enum):
    """Setup routines and control modes (appendix 1)."""

    INIT_IDLE = "init/idle"
    ALIGN = "align"
    POSITION = "position control"
    PROP_VELOCITY = "proportional velocity"
    INTEGRAL_VELOCITY = "integral velocity"
    TRAPEZOID = "trapezoidal profile"


#: Minimum sample timer value per control mode (appendix 2, "Sample Timer Register").
MIN_SAMPLE_TIMER = {
    Mode.POSITION: 0x07,
    Mode.PROP_VELOCITY: 0x07,
    Mode.TRAPEZOID: 0x0F,
    Mode.INTEGRAL_VELOCITY: 0x0F,
    Mode.INIT_IDLE: 0x00,
    Mode.ALIGN: 0x07,  # not in the manual: align runs the position-mode commutator [low]
}


def sample_time(t_reg: int, clock_hz: float = CLOCK_HZ) -> float:
    """Sample period in seconds for sample timer value T: 16(T+1)/fclk (eq. [6])."""
    return 16.0 * (t_reg + 1) / clock_hz


def check_register(name: str, reg: int, allowed: frozenset[int]) -> int:
    """A register address the chip accepts for this access."""
    if isinstance(reg, bool) or not isinstance(reg, int):
        raise MotionError(f"{name} must be an int register address, got {reg!r}")
    if reg not in allowed:
        raise MotionError(f"{name} {reg:#04x} is not a register the HCTL-1100 allows here")
    return reg


def check_byte(name: str, value: int) -> int:
    """An 8-bit register value 0..255 (0x00..0xFF)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise MotionError(f"{name} must be an int in 0..255, got {value!r}")
    if not 0 <= value <= 0xFF:
        raise MotionError(f"{name} must be in 0..255, got {value!r}")
    return value


def wrap24(x: int) -> int:
    """Signed value of the low 24 bits (two's complement, -2**23 .. 2**23 - 1)."""
    x &= 0xFFFFFF
    return x - 0x1000000 if x & 0x800000 else x


def signed8(x: int) -> int:
    x &= 0xFF
    return x - 0x100 if x & 0x80 else x


def signed16(x: int) -> int:
    x &= 0xFFFF
    return x - 0x10000 if x & 0x8000 else x


def split24(x: int) -> tuple[int, int, int]:
    """(MSB, middle, LSB) bytes of a 24-bit two's-complement value."""
    x &= 0xFFFFFF
    return (x >> 16) & 0xFF, (x >> 8) & 0xFF, x & 0xFF


def join24(msb: int, mid: int, lsb: int) -> int:
    return wrap24((msb << 16) | (mid << 8) | lsb)
