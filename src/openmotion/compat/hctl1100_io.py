"""HCTL-1100 register reads and writes: the latching, masking and ignore rules of each
register (AIM104 manual appendix 2). Mixed into `HCTL1100`, which owns the state."""

from __future__ import annotations

from collections.abc import Callable

from openmotion.errors import MotionError

from . import hctl1100_regs as R
from .hctl1100_profile import IntegralVelocity
from .hctl1100_regs import Mode

_CONTROL_FLAGS = {R.F0: Mode.TRAPEZOID, R.F3: Mode.PROP_VELOCITY, R.F5: Mode.INTEGRAL_VELOCITY}
_SEVEN_BIT = frozenset({R.R_COMM_RING, R.R_COMM_X, R.R_COMM_Y, R.R_COMM_ADVANCE,
                        R.R_ACCEL_MSB, R.R_MAX_VEL})
_PROFILE_DATA = frozenset({R.R_CMD_POS_MSB, R.R_CMD_POS_MID, R.R_CMD_POS_LSB, R.R_ACCEL_LSB,
                           R.R_ACCEL_MSB, R.R_MAX_VEL, R.R_FINAL_LSB, R.R_FINAL_MID,
                           R.R_FINAL_MSB})


def _duty(mc: int) -> float:
    """PWM duty from the motor command: 100 parts, saturating at 100% [seed, R09H]."""
    return max(-100, min(100, mc)) / 100.0


class RegisterAccess:
    """Register semantics; expects the state attributes `HCTL1100` creates."""

    # ------------------------------------------------------------------ register access
    def write(self, reg: int, value: int) -> None:
        """Write one 8-bit register (refused with MotionError before any change if invalid)."""
        R.check_register("reg", reg, R.WRITABLE)
        R.check_byte("value", value)
        if reg in _SEVEN_BIT and value > 0x7F:
            raise MotionError(f"value for register {reg:#04x} must be in 0x00..0x7f, "
                              f"got {value:#04x}")
        if reg in _PROFILE_DATA and self._flags & (1 << R.F0) and self.mode is Mode.TRAPEZOID:
            self.ignored_writes += 1  # "no new command data while in Profile"
            return
        handler = _WRITERS.get(reg)
        if handler is not None:
            handler(self, reg, value)
        else:  # commutator registers
            self._comm[reg] = value

    def _w_flag(self, reg: int, value: int) -> None:
        flag = value & 0x07
        on = bool(value & R.FLAG_SET)
        if flag in (R.F1, 6, 7):
            self.ignored_writes += 1  # F1 belongs to the chip; 6/7 are not flags
            return
        new = (self._flags | (1 << flag)) if on else (self._flags & ~(1 << flag))
        ctrl = [f for f in _CONTROL_FLAGS if new & (1 << f)]
        if len(ctrl) > 1:
            raise MotionError("only one control flag (F0, F3, F5) may be set at a time")
        if new & (1 << R.F4) and not self._flags & (1 << R.F4):
            self._ring_hold = self.plant.counts - self._ring_origin  # freeze the ring counter
        mode = self.mode
        if mode is Mode.INIT_IDLE or mode is Mode.ALIGN or new == self._flags:
            self._flags = new
            return
        # in a control mode the flags switch modes at once (datasheet mode flowchart)
        target = _CONTROL_FLAGS[ctrl[0]] if ctrl else Mode.POSITION
        if target is not Mode.POSITION:
            if mode is not Mode.POSITION:
                raise MotionError(f"{target.value} can only be entered from position control"
                                  f" (now in {mode.value})")
            self._require_timer(target, self._t_buffer)
        old_flags = self._flags
        self._flags = new
        try:
            if target is Mode.TRAPEZOID:
                self._start_profile()
            elif target is Mode.INTEGRAL_VELOCITY:
                self._iv = IntegralVelocity(self._cmd)
                self.mode = target
            elif target is Mode.PROP_VELOCITY:
                self._prev_actual = self.actual_position
                self.mode = target
            else:  # back to position control, holding where the generator is
                if mode is Mode.PROP_VELOCITY:
                    self._cmd = self.actual_position
                    self._filter.reset()  # its history predates the velocity mode
                self._traj = None
                self._iv = None
                self.mode = Mode.POSITION
        except MotionError:
            self._flags = old_flags
            raise

    def _w_program(self, reg: int, value: int) -> None:
        if value == R.PC_RESET:
            self._soft_reset()
        elif value == R.PC_INIT_IDLE:
            self._enter_idle()
        elif value in (R.PC_ALIGN, R.PC_CONTROL):
            if self.mode is not Mode.INIT_IDLE or self.limit_pin:
                self.ignored_writes += 1  # only from Init/Idle, not while LIMIT holds
                return
            if value == R.PC_ALIGN:
                self._require_timer(Mode.ALIGN, self._t_buffer)
                self._ring_hold = self.plant.counts - self._ring_origin
                self._flags |= 1 << R.F4
                self._align_k = 0
                self.mode = Mode.ALIGN
            else:
                self._enter_control()
        else:
            raise MotionError(f"program counter command must be 00h..03h, got {value:#04x}")

    def _w_status(self, reg: int, value: int) -> None:
        if value & R.ST_RESERVED:
            raise MotionError("status register bit 3 must be written as 0")
        self._status_low = value & 0x07
        # [low] a status write clears the LIMIT/STOP latches once the pins are inactive
        if not self.limit_pin:
            self._limit_latched = False
        if not self.stop_pin:
            self._stop_latched = False

    def _w_pwm(self, reg: int, value: int) -> None:
        if self.mode is not Mode.INIT_IDLE:
            self.ignored_writes += 1  # the control modes overwrite R09H every sample
            return
        self._mc = R.signed8(value)
        self._duty = _duty(self._mc)

    def _w_cmd(self, reg: int, value: int) -> None:
        if reg == R.R_CMD_POS_LSB:
            if self.mode is Mode.INTEGRAL_VELOCITY:
                self.ignored_writes += 1  # the profiler owns the command position
                return
            self._cmd = R.join24(self._cmd_buf[0], self._cmd_buf[1], value)
        else:
            self._cmd_buf[reg - R.R_CMD_POS_MSB] = value

    def _w_timer(self, reg: int, value: int) -> None:
        self._require_timer(self.mode, value)
        self._t_buffer = value  # used from the next sample on

    def _w_act_clear(self, reg: int, value: int) -> None:
        self._pos_offset = -self.plant.counts

    def _w_preset(self, reg: int, value: int) -> None:
        if self.mode is not Mode.INIT_IDLE:
            self.ignored_writes += 1  # preset only in Init/Idle
            return
        if reg == R.R_PRESET_LSB:
            target = R.join24(self._preset_buf[0], self._preset_buf[1], value)
            self._pos_offset = target - self.plant.counts
        else:
            self._preset_buf[reg - R.R_PRESET_MSB] = value

    def _w_filter(self, reg: int, value: int) -> None:
        f = self._filter
        a, b, k = f.a, f.b, f.k
        if reg == R.R_FILTER_A:
            a = value
        elif reg == R.R_FILTER_B:
            b = value
        else:
            k = value
        f.set_parameters(a, b, k)

    def _w_prop_vel(self, reg: int, value: int) -> None:
        v = self._prop_vel & 0xFFFF
        v = (v & 0xFF00) | value if reg == R.R_PROP_VEL_LSB else (v & 0x00FF) | (value << 8)
        self._prop_vel = R.signed16(v)

    def _w_accel(self, reg: int, value: int) -> None:
        a = self._accel
        self._accel = (a & 0xFF00) | value if reg == R.R_ACCEL_LSB else (a & 0xFF) | (value << 8)

    def _w_max_vel(self, reg: int, value: int) -> None:
        self._vmax = value

    def _w_final(self, reg: int, value: int) -> None:
        shift = 8 * (reg - R.R_FINAL_LSB)
        f = self._final & 0xFFFFFF
        f = (f & ~(0xFF << shift)) | (value << shift)
        self._final = R.wrap24(f)

    def _w_int_vel(self, reg: int, value: int) -> None:
        v = R.signed8(value)
        if abs(v - self._int_vel) > 127:
            raise MotionError(f"integral velocity may change by at most 127 per command, "
                              f"{self._int_vel} -> {v}")
        self._int_vel = v

    def read(self, reg: int) -> int:
        """Read one 8-bit register (reading R14H latches R12H/R13H)."""
        R.check_register("reg", reg, R.READABLE)
        if reg == R.R_FLAG:
            return self.flags
        if reg == R.R_STATUS:
            return self.status
        if reg == R.R_PWM:
            return self._mc & 0xFF
        if reg in (R.R_CMD_POS_MSB, R.R_CMD_POS_MID, R.R_CMD_POS_LSB):
            return R.split24(self._cmd)[reg - R.R_CMD_POS_MSB]
        if reg == R.R_SAMPLE_TIMER:
            frac = self._into / self._period
            return max(0, self._t_reg - int(frac * (self._t_reg + 1)))
        if reg == R.R_ACT_POS_LSB:
            msb, mid, lsb = R.split24(self.actual_position)
            self._act_latch = (msb, mid)
            return lsb
        if reg in (R.R_ACT_POS_MSB, R.R_ACT_POS_MID):
            return self._act_latch[reg - R.R_ACT_POS_MSB]
        if reg in self._comm:
            return self._comm[reg]
        if reg in (R.R_FILTER_A, R.R_FILTER_B, R.R_FILTER_K):
            return (self._filter.a, self._filter.b, self._filter.k)[reg - R.R_FILTER_A]
        if reg in (R.R_PROP_VEL_LSB, R.R_PROP_VEL_MSB):
            return (self._prop_vel >> (8 * (reg - R.R_PROP_VEL_LSB))) & 0xFF
        if reg in (R.R_ACCEL_LSB, R.R_ACCEL_MSB):
            return (self._accel >> (8 * (reg - R.R_ACCEL_LSB))) & 0xFF
        if reg == R.R_MAX_VEL:
            return self._vmax
        if reg in (R.R_FINAL_LSB, R.R_FINAL_MID, R.R_FINAL_MSB):
            return (self._final >> (8 * (reg - R.R_FINAL_LSB))) & 0xFF
        if reg in (R.R_ACT_VEL_LSB, R.R_ACT_VEL_MSB):
            return (self._act_vel >> (8 * (reg - R.R_ACT_VEL_LSB))) & 0xFF
        return self._int_vel & 0xFF  # R3CH

    @property
    def status(self) -> int:
        """R07H: low 4 bits as written, F0, F1, STOP and LIMIT (0 = triggered)."""
        s = self._status_low
        if self._flags & (1 << R.F0):
            s |= R.ST_PROFILE
        if self.mode is Mode.INIT_IDLE:
            s |= R.ST_INIT
        if not self._stop_latched:
            s |= R.ST_STOP_CLEAR
        if not self._limit_latched:
            s |= R.ST_LIMIT_CLEAR
        return s

    @property
    def ring_config(self) -> dict[int, int]:
        """Commutator registers and whether they count in full counts (status bit 2)."""
        return dict(self._comm)


_WRITERS: dict[int, Callable[[RegisterAccess, int, int], None]] = {
    R.R_FLAG: RegisterAccess._w_flag,
    R.R_PROGRAM: RegisterAccess._w_program,
    R.R_STATUS: RegisterAccess._w_status,
    R.R_PWM: RegisterAccess._w_pwm,
    R.R_CMD_POS_MSB: RegisterAccess._w_cmd,
    R.R_CMD_POS_MID: RegisterAccess._w_cmd,
    R.R_CMD_POS_LSB: RegisterAccess._w_cmd,
    R.R_SAMPLE_TIMER: RegisterAccess._w_timer,
    R.R_ACT_POS_MID: RegisterAccess._w_act_clear,
    R.R_PRESET_MSB: RegisterAccess._w_preset,
    R.R_PRESET_MID: RegisterAccess._w_preset,
    R.R_PRESET_LSB: RegisterAccess._w_preset,
    R.R_FILTER_A: RegisterAccess._w_filter,
    R.R_FILTER_B: RegisterAccess._w_filter,
    R.R_FILTER_K: RegisterAccess._w_filter,
    R.R_PROP_VEL_LSB: RegisterAccess._w_prop_vel,
    R.R_PROP_VEL_MSB: RegisterAccess._w_prop_vel,
    R.R_ACCEL_LSB: RegisterAccess._w_accel,
    R.R_ACCEL_MSB: RegisterAccess._w_accel,
    R.R_MAX_VEL: RegisterAccess._w_max_vel,
    R.R_FINAL_LSB: RegisterAccess._w_final,
    R.R_FINAL_MID: RegisterAccess._w_final,
    R.R_FINAL_MSB: RegisterAccess._w_final,
    R.R_INT_VEL: RegisterAccess._w_int_vel,
}
