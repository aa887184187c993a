"""The AIM104-MOTION-1 'motion.h' library (manual, "Library Functions") over the I/O map.

Every MOTION_* call goes through the board's four I/O bytes with the manual's protocol
(wait ready, address, dummy read, wait ready, data), exactly as the C library on the
utility disk does, so the examples exercise the same paths a real program would. Names,
argument order and meaning follow the manual; Python differences:

- positions are returned as signed 24-bit values (the C functions return the raw
  `unsigned long` register contents) and accepted as signed or 24-bit unsigned ints;
- waiting is in virtual time: `delay(seconds)` and the `wait_until_*` calls advance the bus;
- two functions whose names the seed text lost are reconstructed and so marked:
  `MOTION_program_commutator` and `MOTION_open_loop_stepper`.
"""

from __future__ import annotations

import math

from openmotion.errors import MotionError, check_nonnegative, check_positive

from . import hctl1100_regs as R
from .aim104 import ST_BUSY, PC104Bus


def _int_in(name: str, value: int, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise MotionError(f"{name} must be an int in {lo}..{hi}, got {value!r}")
    return value


class MotionLibrary:
    """The MOTION_* functions for the boards on one `PC104Bus`."""

    def __init__(self, bus: PC104Bus) -> None:
        if not isinstance(bus, PC104Bus):
            raise MotionError(f"bus must be a PC104Bus, got {type(bus).__name__}")
        self.bus = bus
        self._handles: dict[int, int] = {}
        self._next = 1

    # ------------------------------------------------------------------ plumbing
    def _base(self, handle: int) -> int:
        base = self._handles.get(handle) if isinstance(handle, int) else None
        if base is None:
            raise MotionError(f"handle {handle!r} is not an open AIM104-MOTION-1 handle")
        return base

    def _write(self, base: int, reg: int, value: int) -> None:
        self._wait_base(base)
        self.bus.outb(base, reg)
        self._wait_base(base)
        self.bus.outb(base + 1, value & 0xFF)

    def _read(self, base: int, reg: int) -> int:
        self._wait_base(base)
        self.bus.outb(base, reg)
        self.bus.inb(base)  # the essential dummy read
        self._wait_base(base)
        return self.bus.inb(base + 1)

    def _wait_base(self, base: int) -> None:
        for _ in range(1000):
            if not self.bus.inb(base + 2) & ST_BUSY:
                return
        raise MotionError(f"board at {base:#x} stays busy")  # cannot happen in emulation

    def delay(self, seconds: float) -> None:
        """Let virtual time pass for every board on the bus."""
        self.bus.advance(check_nonnegative("seconds", seconds))

    # ------------------------------------------------------------------ board
    def MOTION_boardinit(self, baseaddr: int) -> int:
        """Open the board at `baseaddr`; returns a handle for the other calls."""
        board = self.bus.board_at(baseaddr)
        if board.base != baseaddr:
            raise MotionError(f"baseaddr must be the board's base {board.base:#x}, "
                              f"got {baseaddr:#x}")
        h = self._next
        self._next += 1
        self._handles[h] = baseaddr
        return h

    def MOTION_boardclose(self, handle: int) -> int:
        self._base(handle)
        del self._handles[handle]
        return 0

    def MOTION_wait_until_ready(self, handle: int) -> None:
        self._wait_base(self._base(handle))

    def MOTION_set_board_config_reg(self, handle: int, config_value: int) -> None:
        self.bus.outb(self._base(handle) + 3, _int_in("config_value", config_value, 0, 255))

    def MOTION_read_board_config_reg(self, handle: int) -> int:
        return self.bus.inb(self._base(handle) + 3)

    def MOTION_pulse_SYNC(self, handle: int) -> None:
        base = self._base(handle)
        self.bus.outb(base + 3, self.bus.inb(base + 3) | 0x04)

    def MOTION_read_board_status_reg(self, handle: int) -> int:
        return self.bus.inb(self._base(handle) + 2)

    def MOTION_clear_interrupts(self, handle: int) -> None:
        """Clear the IRQ line, the board status latches and the chip's LIMIT/STOP latches."""
        base = self._base(handle)
        self.bus.outb(base + 2, 0)
        self._write(base, R.R_STATUS, self._read(base, R.R_STATUS) & 0x07)

    # ------------------------------------------------------------------ chip setup
    def MOTION_set_controller_status_reg(self, handle: int, status: int) -> None:
        self._write(self._base(handle), R.R_STATUS, _int_in("status", status, 0, 255))

    def MOTION_read_controller_status_reg(self, handle: int) -> int:
        return self._read(self._base(handle), R.R_STATUS)

    def MOTION_read_flag_register(self, handle: int) -> int:
        return self._read(self._base(handle), R.R_FLAG)

    def MOTION_program_sample_timer(self, handle: int, period: int) -> None:
        """Sample timer T (R0FH): t = 16(T+1)/2 MHz, i.e. (T+1) x 8 us."""
        self._write(self._base(handle), R.R_SAMPLE_TIMER, _int_in("period", period, 0, 255))

    def MOTION_read_sample_timer(self, handle: int) -> int:
        return self._read(self._base(handle), R.R_SAMPLE_TIMER)

    def MOTION_set_filter_parameters(self, handle: int, filter_zero: int, filter_pole: int,
                                     filter_gain: int) -> None:
        base = self._base(handle)
        vals = [_int_in(n, v, 0, 255) for n, v in (("filter_zero", filter_zero),
                                                   ("filter_pole", filter_pole),
                                                   ("filter_gain", filter_gain))]
        for reg, v in zip((R.R_FILTER_A, R.R_FILTER_B, R.R_FILTER_K), vals, strict=True):
            self._write(base, reg, v)

    def MOTION_program_commutator(self, handle: int, ring: int, x: int, y: int,
                                  offset: int = 0, velocity_timer: int = 0,
                                  phase_advance: int = 0) -> None:
        """[reconstructed name] Commutator ring, X, Y, offset, velocity timer, advance."""
        base = self._base(handle)
        args = (("ring", ring, 0, 127), ("x", x, 0, 127), ("y", y, 0, 127),
                ("offset", offset, -128, 127), ("velocity_timer", velocity_timer, 0, 255),
                ("phase_advance", phase_advance, 0, 127))
        vals = [_int_in(n, v, lo, hi) for n, v, lo, hi in args]
        for reg, v in zip((R.R_COMM_RING, R.R_COMM_X, R.R_COMM_Y, R.R_COMM_OFFSET,
                           R.R_COMM_VEL_TIMER, R.R_COMM_ADVANCE), vals, strict=True):
            self._write(base, reg, v & 0xFF)

    # ------------------------------------------------------------------ modes
    def MOTION_controller_reset(self, handle: int) -> None:
        self._write(self._base(handle), R.R_PROGRAM, R.PC_RESET)

    def MOTION_enter_idle_mode(self, handle: int) -> None:
        self._write(self._base(handle), R.R_PROGRAM, R.PC_INIT_IDLE)

    def MOTION_enter_align_mode(self, handle: int) -> None:
        self._write(self._base(handle), R.R_PROGRAM, R.PC_ALIGN)

    def MOTION_enter_position_mode(self, handle: int) -> None:
        """Clear the control flags (F0, F3, F5) and enter control: position control."""
        base = self._base(handle)
        for f in (R.F0, R.F3, R.F5):
            self._write(base, R.R_FLAG, f)
        self._write(base, R.R_PROGRAM, R.PC_CONTROL)

    def MOTION_execute_trapezoidal_move(self, handle: int) -> None:
        self._write(self._base(handle), R.R_FLAG, R.FLAG_SET | R.F0)

    def MOTION_execute_proportional_velocity(self, handle: int) -> None:
        self._write(self._base(handle), R.R_FLAG, R.FLAG_SET | R.F3)

    def MOTION_end_proportional_velocity(self, handle: int) -> None:
        self._write(self._base(handle), R.R_FLAG, R.F3)

    def MOTION_execute_integral_velocity(self, handle: int) -> None:
        self._write(self._base(handle), R.R_FLAG, R.FLAG_SET | R.F5)

    def MOTION_end_integral_velocity(self, handle: int) -> None:
        self._write(self._base(handle), R.R_FLAG, R.F5)

    def MOTION_wait_until_move_complete(self, handle: int, timeout: float = 60.0) -> int:
        """Advance virtual time until F0 clears: 0 done, 1 halted by LIMIT, 2 timeout."""
        base = self._base(handle)
        timeout = check_positive("timeout", timeout)
        chip = self.bus.board_at(base).chip
        t_end = self.bus.time + timeout
        while True:
            if not self._read(base, R.R_FLAG) & (1 << R.F0):
                return 1 if not self._read(base, R.R_STATUS) & R.ST_LIMIT_CLEAR else 0
            if self.bus.time >= t_end:
                return 2
            self.bus.advance(chip.sample_period)

    # ------------------------------------------------------------------ command data
    def _write24(self, base: int, regs: tuple[int, int, int], name: str, value: int) -> None:
        _int_in(name, value, -(1 << 23), (1 << 24) - 1)
        for reg, byte in zip(regs, R.split24(value), strict=True):
            self._write(base, reg, byte)

    def MOTION_set_command_position(self, handle: int, command_position: int) -> None:
        """MSB, middle, then LSB: writing R0EH latches all 24 bits."""
        self._write24(self._base(handle), (R.R_CMD_POS_MSB, R.R_CMD_POS_MID, R.R_CMD_POS_LSB),
                      "command_position", command_position)

    def MOTION_set_final_position(self, handle: int, final_position: int) -> None:
        self._write24(self._base(handle), (R.R_FINAL_MSB, R.R_FINAL_MID, R.R_FINAL_LSB),
                      "final_position", final_position)

    def MOTION_preset_actual_position(self, handle: int, actual_position: int) -> None:
        """Preset (Init/Idle only): R15H, R16H, then R17H which loads all 24 bits."""
        self._write24(self._base(handle), (R.R_PRESET_MSB, R.R_PRESET_MID, R.R_PRESET_LSB),
                      "actual_position", actual_position)

    def MOTION_set_acceleration(self, handle: int, accel: int) -> None:
        """Acceleration in 1/256 counts/sample^2 (R27H integer, R26H fraction)."""
        base = self._base(handle)
        _int_in("accel", accel, 0, 0x7FFF)
        self._write(base, R.R_ACCEL_LSB, accel & 0xFF)
        self._write(base, R.R_ACCEL_MSB, accel >> 8)

    def MOTION_set_max_velocity(self, handle: int, velocity: int) -> None:
        self._write(self._base(handle), R.R_MAX_VEL, _int_in("velocity", velocity, 0, 127))

    def MOTION_set_proportional_velocity(self, handle: int, velocity: int) -> None:
        """Velocity in 1/16 counts/sample (12.4 fixed point)."""
        base = self._base(handle)
        v = _int_in("velocity", velocity, -32768, 32767) & 0xFFFF
        self._write(base, R.R_PROP_VEL_LSB, v & 0xFF)
        self._write(base, R.R_PROP_VEL_MSB, v >> 8)

    def MOTION_set_integral_velocity(self, handle: int, velocity: int) -> None:
        self._write(self._base(handle), R.R_INT_VEL,
                    _int_in("velocity", velocity, -128, 127) & 0xFF)

    # ------------------------------------------------------------------ read-back
    def _read24(self, base: int, msb: int, mid: int, lsb: int) -> int:
        lo = self._read(base, lsb)  # LSB first: latches the others for the actual position
        return R.join24(self._read(base, msb), self._read(base, mid), lo)

    def MOTION_read_command_position(self, handle: int) -> int:
        return self._read24(self._base(handle), R.R_CMD_POS_MSB, R.R_CMD_POS_MID,
                            R.R_CMD_POS_LSB)

    def MOTION_read_final_position(self, handle: int) -> int:
        return self._read24(self._base(handle), R.R_FINAL_MSB, R.R_FINAL_MID, R.R_FINAL_LSB)

    def MOTION_read_actual_position(self, handle: int) -> int:
        return self._read24(self._base(handle), R.R_ACT_POS_MSB, R.R_ACT_POS_MID,
                            R.R_ACT_POS_LSB)

    def MOTION_read_actual_velocity(self, handle: int) -> int:
        base = self._base(handle)
        lo = self._read(base, R.R_ACT_VEL_LSB)
        return R.signed16(lo | (self._read(base, R.R_ACT_VEL_MSB) << 8))

    # ------------------------------------------------------------------ open loop
    def MOTION_open_loop_stepper(self, handle: int, steps: int, step_time: float,
                                 drive: int = 100) -> None:
        """[reconstructed name] Step open loop: hold the commutator (F4) in Init/Idle, drive
        R09H, and move the phase offset one commutator step (X counts, or X/2... as set by
        X and Y: one X+Y sector per full step, X per half step) every `step_time` seconds.
        Ties up the caller, as the manual warns."""
        base = self._base(handle)
        _int_in("steps", steps, -100000, 100000)
        step_time = check_positive("step_time", step_time)
        _int_in("drive", drive, 1, 100)
        x = self._read(base, R.R_COMM_X)
        y = self._read(base, R.R_COMM_Y)
        ring = self._read(base, R.R_COMM_RING)
        inc = x if y == 0 else math.gcd(x, y)  # a full step, or a half step when Y = X
        if inc == 0 or ring == 0:
            raise MotionError("program the commutator (ring, X, Y) before stepping open loop")
        direction = 1 if steps > 0 else -1
        self._write(base, R.R_PROGRAM, R.PC_INIT_IDLE)
        self._write(base, R.R_FLAG, R.FLAG_SET | R.F4)
        # the commutator leads the held position by about a step in the drive direction;
        # start one step (X + Y) back so the first state is the detent the rotor is on
        start = R.signed8(self._read(base, R.R_COMM_OFFSET))
        offset = (start - direction * (x + y)) % ring
        self._write(base, R.R_COMM_OFFSET, offset)
        self._write(base, R.R_PWM, (direction * drive) & 0xFF)
        for _ in range(abs(steps)):
            offset = (offset + direction * inc) % ring  # stays within the 8-bit range
            self._write(base, R.R_COMM_OFFSET, offset)
            self.delay(step_time)
        self._write(base, R.R_PWM, 0)
        self._write(base, R.R_FLAG, R.F4)
        self._write(base, R.R_COMM_OFFSET, start & 0xFF)  # the ring counter follows again
