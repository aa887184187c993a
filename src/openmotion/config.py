"""Machine description: axes, mechanism parameters, pulse/encoder modes, I/O logic, and the
simulated plant behind each axis. Built in code or loaded from / saved to TOML (the file
format lives in openmotion.config_toml; its functions are re-exported here).

Units: mechanism-related lengths are in the axis's user unit; speeds in user units per
second; the simulator section (DriveConfig) is in command pulses unless a name says
otherwise. Switches (SwitchConfig) are in command pulses in code but in the axis's USER
units in a TOML file (people measure switches in mm or degrees): load converts them with
`pulses = user * pulses_per_unit * (-1 if reverse else 1)` and save converts back.

Every dataclass validates itself on construction (also through `dataclasses.replace`), so a
MachineConfig that exists is valid. Errors are MotionError naming the path of the bad field,
e.g. "axes.x.lead must be > 0, got -2".

Sources: mechanism parameters follow MCCL SYS_MACH_PARAM (dwPPR, dfPitch, dfGearRatio,
wPosToEncoderDir, wRPM, wPulseMode, wPulseWidth, over-travel sensor NO/NC); pulse output
modes HSL-4XMO 4.6 "Pulse Command Output"; encoder modes and move ratio HSL-4XMO 4.9 /
4.6 (HSL_M_set_pls_iptmode, HSL_M_set_move_ratio); signal logic HSL-4XMO 4.7 / 4.8.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial
from typing import Any

from openmotion.errors import (
    MotionError,
    check_distance,
    check_finite,
    check_int,
    check_nonnegative,
    check_positive,
)
from openmotion.units import MAX_PULSE_RATE, pulses_per_unit

__all__ = [
    "COMPENSATORS", "CYCLE_RANGE_S", "DRIVE_TYPES", "ENCODER_MODES", "ENCODER_MULTIPLIER",
    "LOGIC_SIGNALS", "MAX_GENERAL_IO", "MAX_PULSE_WIDTH_US", "PULSE_MODES", "SIGNAL_LOGIC",
    "SWITCHES", "SWITCH_DECIMALS", "USER_UNITS",
    "AxisConfig", "DCMotorConfig", "DriveConfig", "LoopConfig", "MachineConfig",
    "SwitchConfig", "default_machine",
    # TOML files (openmotion.config_toml)
    "dumps_machine", "load_machine", "loads_machine", "machine_from_dict", "machine_to_dict",
    "save_machine",
]

USER_UNITS = ("pulse", "mm", "inch", "degree")
PULSE_MODES = (
    "out_dir",      # OUT pulse, DIR level, DIR high = positive, pulse active-high
    "out_dir_inv",  # OUT/DIR with inverted DIR
    "out_dir_lo",   # OUT/DIR with active-low pulse
    "out_dir_lo_inv",
    "cw_ccw",       # dual pulse: CW on OUT, CCW on DIR
    "ab_phase",     # A/B quadrature output
)
ENCODER_MODES = ("ab_x1", "ab_x2", "ab_x4", "cw_ccw", "pulse_dir")
SIGNAL_LOGIC = ("no", "nc")  # normally open / normally closed contacts
LOGIC_SIGNALS = ("pel", "mel", "org", "sd", "ltc", "ez", "alm", "inp", "rdy", "emg")
DRIVE_TYPES = ("ideal_stepper", "stepper", "servo", "dc_servo")
#: Compensators of a control-layer servo loop (LoopConfig.compensator).
COMPENSATORS = ("lead", "pid")
SWITCHES = ("pel", "mel", "org", "sd")

#: Counts per encoder line for each input mode (CW/CCW and pulse/dir count every pulse).
ENCODER_MULTIPLIER = {"ab_x1": 1, "ab_x2": 2, "ab_x4": 4, "cw_ccw": 1, "pulse_dir": 1}
#: MCCL interpolation period range, 1..1000 ms (MCCL manual, MCC_InitSystem).
CYCLE_RANGE_S = (0.001, 1.0)
MAX_PULSE_WIDTH_US = 1000.0
MAX_GENERAL_IO = 4096
#: Switch position/width/hysteresis are kept on a 1e-6 pulse grid (see SwitchConfig).
SWITCH_DECIMALS = 6


# -- field checks: each names the field path and the rule ------------------------------
# strict: a file's "1.5" or true is a typing slip, not a number
_real = partial(check_finite, strict=True)
_positive = partial(check_positive, strict=True)
_nonneg = partial(check_nonnegative, strict=True)
_int = check_int


def _bool(path: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise MotionError(f"{path} must be true or false, got {value!r}")
    return value


def _choice(path: str, value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise MotionError(f"{path} must be one of {', '.join(choices)}; got {value!r}")
    return value


def _set(obj: object, name: str, value: Any) -> None:
    """Store a normalised value on a frozen dataclass during __post_init__."""
    object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class SwitchConfig:
    """A switch fixed on the machine at a mechanical position (command pulses).

    It is active while the carriage is within [position, position + width) (width < 0
    spans downwards); `hysteresis` (pulses) is the extra travel needed to release it.
    End limits normally use a large width so they stay active beyond the switch.
    In a TOML file all three are written in the axis's user units instead.
    """

    position: float
    width: float = 100.0
    hysteresis: float = 0.0

    def __post_init__(self) -> None:
        self.validate("switch")

    def validate(self, path: str) -> None:
        """Check the fields; `path` prefixes error messages (e.g. "axes.x.pel").

        Values are rounded to SWITCH_DECIMALS decimals of a pulse: a file holds them in user
        units, and x -> x / scale -> x * scale is not exact in floating point for every
        scale; on this grid the save/load round trip is exact (|x| < 2**28).
        """
        pos = check_distance(f"{path}.position", _real(f"{path}.position", self.position))
        _set(self, "position", round(pos, SWITCH_DECIMALS) + 0.0)
        w = round(_real(f"{path}.width", self.width), SWITCH_DECIMALS)
        if w == 0.0:
            raise MotionError(f"{path}.width must be non-zero (at 1e-{SWITCH_DECIMALS} pulse), "
                              f"got {self.width!r}")
        _set(self, "width", w)
        h = _nonneg(f"{path}.hysteresis", self.hysteresis)
        _set(self, "hysteresis", round(h, SWITCH_DECIMALS) + 0.0)


@dataclass(frozen=True)
class DCMotorConfig:
    """DC motor + PWM amplifier of a "dc_servo" drive, SI units (see hw/sim/dcmotor.py).

    `ke` = 0 means "equal to kt" (an SI motor). The defaults are DCMotorParams' defaults:
    a small unloaded 24 V motor on a 1 A driver.
    """

    supply_v: float = 24.0
    resistance: float = 4.0
    kt: float = 0.03           # N*m/A
    ke: float = 0.0            # V*s/rad; 0 = kt
    inertia: float = 2.0e-6    # kg*m^2
    viscous: float = 1.0e-5    # N*m*s/rad
    current_limit: float = 1.0  # A
    load_torque: float = 0.0   # N*m, constant external torque

    def __post_init__(self) -> None:
        self.validate("motor")

    def validate(self, path: str) -> None:
        """Check the fields; `path` prefixes error messages (e.g. "axes.x.drive.motor")."""
        for name in ("supply_v", "resistance", "kt", "inertia", "current_limit"):
            _set(self, name, _positive(f"{path}.{name}", getattr(self, name)))
        for name in ("ke", "viscous"):
            _set(self, name, _nonneg(f"{path}.{name}", getattr(self, name)))
        _set(self, "load_torque", _real(f"{path}.load_torque", self.load_torque))


@dataclass(frozen=True)
class LoopConfig:
    """A position loop closed in the control layer (control/loops/servoloop.py).

    compensator "lead": the HCTL-1100 filter with zero `a`, pole `b`, gain `k` (0..255), its
    8-bit output MC giving the duty min(|MC|, 100)/100 as on the chip. "pid": PIDFF with
    `kp` (> 0), `ki`, `kd` (>= 0), `kvff`, `kaff`, output in duty units (per count, count/s,
    count/s^2). `samples_per_cycle` (>= 1): loop samples per controller cycle.
    `following_error` (encoder counts, > 0, inf = off): the limit that trips ErrorStop.
    """

    compensator: str = "lead"
    a: int = 0xE5
    b: int = 0x40
    k: int = 0x40
    kp: float = 0.0
    ki: float = 0.0
    kd: float = 0.0
    kvff: float = 0.0
    kaff: float = 0.0
    samples_per_cycle: int = 1
    following_error: float = 1000.0

    def __post_init__(self) -> None:
        self.validate("loop")

    def validate(self, path: str) -> None:
        """Check the fields; `path` prefixes error messages (e.g. "axes.x.loop")."""
        _choice(f"{path}.compensator", self.compensator, COMPENSATORS)
        for name in ("a", "b", "k"):
            _int(f"{path}.{name}", getattr(self, name), 0, 255)
        for name in ("kp", "ki", "kd"):
            _set(self, name, _nonneg(f"{path}.{name}", getattr(self, name)))
        for name in ("kvff", "kaff"):
            _set(self, name, _real(f"{path}.{name}", getattr(self, name)))
        if self.compensator == "pid" and self.kp <= 0.0:
            raise MotionError(f"{path}.kp must be > 0 for the pid compensator, got {self.kp!r}")
        _int(f"{path}.samples_per_cycle", self.samples_per_cycle, 1, 1000)
        fe = self.following_error
        if isinstance(fe, bool) or not isinstance(fe, (int, float)) or math.isnan(fe) \
                or fe <= 0.0:
            raise MotionError(f"{path}.following_error must be > 0 counts (inf = off), "
                              f"got {fe!r}")
        _set(self, "following_error", float(fe))


@dataclass(frozen=True)
class DriveConfig:
    """The simulated drive/motor behind one axis.

    ideal_stepper: follows every pulse. stepper: loses steps when the commanded speed
    exceeds `pullout_speed` (pps) or the acceleration exceeds `pullout_accel` (pps/s).
    servo: tracks the command with a second-order lag (`bandwidth_hz`, `damping`), reports
    INP within `inp_band` pulses, READY after servo-on, ALM on `alarm` scenarios.
    dc_servo: a DC motor (`motor`) on a PWM amplifier, driven by the control layer's servo
    loop (AxisConfig.loop); the amplifier is on while SVON is on and no alarm.
    """

    type: str = "ideal_stepper"
    pullout_speed: float = 0.0
    pullout_accel: float = 0.0
    bandwidth_hz: float = 30.0
    damping: float = 0.9
    inp_band: float = 5.0
    backlash: float = 0.0          # mechanical backlash (command pulses), feedback side
    pitch_error: tuple[float, ...] = ()  # lead-screw error table (pulses), see docs
    motor: DCMotorConfig = field(default_factory=DCMotorConfig)  # dc_servo only

    def __post_init__(self) -> None:
        self.validate("drive")

    def validate(self, path: str) -> None:
        """Check the fields; `path` prefixes error messages (e.g. "axes.x.drive")."""
        _choice(f"{path}.type", self.type, DRIVE_TYPES)
        if self.type == "stepper":
            _set(self, "pullout_speed", _positive(f"{path}.pullout_speed", self.pullout_speed))
            _set(self, "pullout_accel", _positive(f"{path}.pullout_accel", self.pullout_accel))
        else:
            _set(self, "pullout_speed", _nonneg(f"{path}.pullout_speed", self.pullout_speed))
            _set(self, "pullout_accel", _nonneg(f"{path}.pullout_accel", self.pullout_accel))
        _set(self, "bandwidth_hz", _positive(f"{path}.bandwidth_hz", self.bandwidth_hz))
        _set(self, "damping", _positive(f"{path}.damping", self.damping))
        _set(self, "inp_band", _nonneg(f"{path}.inp_band", self.inp_band))
        _set(self, "backlash", _nonneg(f"{path}.backlash", self.backlash))
        if isinstance(self.pitch_error, (str, bytes)) or not hasattr(self.pitch_error, "__iter__"):
            raise MotionError(f"{path}.pitch_error must be a list of numbers, "
                              f"got {self.pitch_error!r}")
        _set(self, "pitch_error", tuple(
            _real(f"{path}.pitch_error[{i}]", e) for i, e in enumerate(self.pitch_error)))
        if not isinstance(self.motor, DCMotorConfig):
            raise MotionError(f"{path}.motor must be a DCMotorConfig, got {self.motor!r}")
        self.motor.validate(f"{path}.motor")


@dataclass(frozen=True)
class AxisConfig:
    """One axis: mechanism, pulse output, encoder input, signal logic, simulated plant."""

    name: str
    pulses_per_rev: int = 10000
    lead: float = 10.0              # ball-screw pitch: user units per screw revolution
    gear_ratio: float = 1.0         # motor revolutions per screw revolution
    reverse: bool = False           # direction reversal
    unit: str = "mm"
    max_speed: float = 500.0        # maximum safe speed, user units/s
    max_accel: float = 0.0          # acceleration limit, user units/s^2 (0: none)
    max_jerk: float = 0.0           # jerk limit, user units/s^3 (0: none)
    pulse_mode: str = "out_dir"
    pulse_width_us: float = 2.0
    encoder_mode: str = "ab_x4"
    encoder_lines_per_rev: int = 2500  # A/B lines per motor revolution (x4 -> 10000 counts)
    invert_a: bool = False
    invert_b: bool = False
    invert_z: bool = False
    swap_ab: bool = False
    move_ratio: float = 1.0         # feedback counts per command pulse
    logic: dict[str, str] = field(default_factory=dict)  # signal -> "no" | "nc"
    drive: DriveConfig = field(default_factory=DriveConfig)
    pel: SwitchConfig | None = None
    mel: SwitchConfig | None = None
    org: SwitchConfig | None = None
    sd: SwitchConfig | None = None
    loop: LoopConfig | None = None  # control-layer servo loop; dc_servo drives get a default

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        """Check every field; messages name "axes.<name>.<field>"."""
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise MotionError(f"axes name must be an identifier (letters, digits, _), "
                              f"got {self.name!r}")
        p = f"axes.{self.name}"
        _int(f"{p}.pulses_per_rev", self.pulses_per_rev, 1)
        _set(self, "lead", _positive(f"{p}.lead", self.lead))
        _set(self, "gear_ratio", _positive(f"{p}.gear_ratio", self.gear_ratio))
        _choice(f"{p}.unit", self.unit, USER_UNITS)
        _set(self, "max_speed", _positive(f"{p}.max_speed", self.max_speed))
        max_pps = self.max_speed * self.pulses_per_unit
        if max_pps > MAX_PULSE_RATE:
            raise MotionError(
                f"{p}.max_speed must be <= {MAX_PULSE_RATE / self.pulses_per_unit:g} "
                f"{self.unit}/s (pulse output limit {MAX_PULSE_RATE:g} pps at "
                f"{self.pulses_per_unit:g} pulses/{self.unit} from pulses_per_rev="
                f"{self.pulses_per_rev!r}, lead={self.lead!r}, gear_ratio={self.gear_ratio!r}), "
                f"got {self.max_speed!r}")
        for lim in ("max_accel", "max_jerk"):
            _set(self, lim, _nonneg(f"{p}.{lim}", getattr(self, lim)))
        _choice(f"{p}.pulse_mode", self.pulse_mode, PULSE_MODES)
        w = _positive(f"{p}.pulse_width_us", self.pulse_width_us)
        if w > MAX_PULSE_WIDTH_US:
            raise MotionError(f"{p}.pulse_width_us must be <= {MAX_PULSE_WIDTH_US:g}, "
                              f"got {self.pulse_width_us!r}")
        _set(self, "pulse_width_us", w)
        _choice(f"{p}.encoder_mode", self.encoder_mode, ENCODER_MODES)
        _int(f"{p}.encoder_lines_per_rev", self.encoder_lines_per_rev, 1)
        for flag in ("reverse", "invert_a", "invert_b", "invert_z", "swap_ab"):
            _bool(f"{p}.{flag}", getattr(self, flag))
        _set(self, "move_ratio", _positive(f"{p}.move_ratio", self.move_ratio))
        if not isinstance(self.logic, dict):
            raise MotionError(f"{p}.logic must be a table of signal = \"no\" | \"nc\", "
                              f"got {self.logic!r}")
        for sig, val in self.logic.items():
            if sig not in LOGIC_SIGNALS:
                raise MotionError(f"{p}.logic.{sig}: unknown signal; "
                                  f"valid signals: {', '.join(LOGIC_SIGNALS)}")
            _choice(f"{p}.logic.{sig}", val, SIGNAL_LOGIC)
        _set(self, "logic", dict(self.logic))  # own copy: the caller's dict stays theirs
        if not isinstance(self.drive, DriveConfig):
            raise MotionError(f"{p}.drive must be a DriveConfig, got {self.drive!r}")
        self.drive.validate(f"{p}.drive")
        if self.loop is None and self.drive.type == "dc_servo":
            _set(self, "loop", LoopConfig())
        if self.loop is not None:
            if not isinstance(self.loop, LoopConfig):
                raise MotionError(f"{p}.loop must be a LoopConfig or None, got {self.loop!r}")
            self.loop.validate(f"{p}.loop")
        for sw in SWITCHES:
            s = getattr(self, sw)
            if s is not None:
                if not isinstance(s, SwitchConfig):
                    raise MotionError(f"{p}.{sw} must be a SwitchConfig or None, got {s!r}")
                s.validate(f"{p}.{sw}")
        if self.pel is not None and self.mel is not None and \
                not self.pel.position > self.mel.position:
            raise MotionError(
                f"{p}.pel.position must be > {p}.mel.position in command pulses "
                f"(PEL is the limit in the positive pulse direction), got "
                f"pel {self.pel.position!r} <= mel {self.mel.position!r}")

    # -- derived figures ---------------------------------------------------------------
    @property
    def pulses_per_unit(self) -> float:
        """Command pulses per user unit (see openmotion.units)."""
        return pulses_per_unit(self.pulses_per_rev, self.gear_ratio, self.lead, self.unit)

    @property
    def max_speed_pps(self) -> float:
        """Maximum safe speed in command pulses per second."""
        return self.max_speed * self.pulses_per_unit

    @property
    def encoder_counts_per_rev(self) -> int:
        """Feedback counts per motor revolution (lines x the input-mode multiplier)."""
        return self.encoder_lines_per_rev * ENCODER_MULTIPLIER[self.encoder_mode]

    def signal_logic(self, signal: str) -> str:
        """"no" or "nc" for a signal; signals not listed in `logic` are normally open."""
        _choice("signal", signal, LOGIC_SIGNALS)
        return self.logic.get(signal, "no")


@dataclass(frozen=True)
class MachineConfig:
    """The whole machine: axes in controller order, general I/O counts, cycle period."""

    name: str = "machine"
    axes: tuple[AxisConfig, ...] = ()
    digital_inputs: int = 16
    digital_outputs: int = 16
    cycle_s: float = 0.001

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        """Check every field and every axis; axis names must be unique."""
        if not isinstance(self.name, str) or not self.name.strip():
            raise MotionError(f"name must be a non-empty string, got {self.name!r}")
        if isinstance(self.axes, (str, bytes, dict)) or not hasattr(self.axes, "__iter__"):
            raise MotionError(f"axes must be a sequence of AxisConfig, got {self.axes!r}")
        axes = tuple(self.axes)
        seen: set[str] = set()
        for i, ax in enumerate(axes):
            if not isinstance(ax, AxisConfig):
                raise MotionError(f"axes[{i}] must be an AxisConfig, got {ax!r}")
            ax.validate()
            if ax.name in seen:
                raise MotionError(f"axes.{ax.name}: axis names must be unique, "
                                  f"{ax.name!r} appears twice")
            seen.add(ax.name)
        _set(self, "axes", axes)
        _int("digital_inputs", self.digital_inputs, 0, MAX_GENERAL_IO)
        _int("digital_outputs", self.digital_outputs, 0, MAX_GENERAL_IO)
        c = _real("cycle_s", self.cycle_s)
        lo, hi = CYCLE_RANGE_S
        if not lo <= c <= hi:
            raise MotionError(f"cycle_s must be in [{lo:g}, {hi:g}] (MCCL 1..1000 ms), "
                              f"got {self.cycle_s!r}")
        _set(self, "cycle_s", c)

    @property
    def axis_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    def axis(self, key: str | int) -> AxisConfig:
        """An axis by name or by controller index; MotionError if there is none."""
        if isinstance(key, bool):
            raise MotionError(f"axis must be a name or an index, got {key!r}")
        if isinstance(key, int):
            if not 0 <= key < len(self.axes):
                raise MotionError(f"axis index must be in [0, {len(self.axes) - 1}], "
                                  f"got {key!r}")
            return self.axes[key]
        for a in self.axes:
            if a.name == key:
                return a
        raise MotionError(f"axis {key!r} is not on machine {self.name!r}; "
                          f"axes: {', '.join(self.axis_names) or '(none)'}")

    def index(self, name: str) -> int:
        """Controller index of the axis called `name`."""
        return self.axes.index(self.axis(name))

    def with_axis(self, axis: AxisConfig) -> MachineConfig:
        """A copy with `axis` replacing the axis of the same name, or appended if new."""
        if not isinstance(axis, AxisConfig):
            raise MotionError(f"axis must be an AxisConfig, got {axis!r}")
        names = self.axis_names
        if axis.name in names:
            axes = tuple(axis if a.name == axis.name else a for a in self.axes)
        else:
            axes = self.axes + (axis,)
        return MachineConfig(self.name, axes, self.digital_inputs, self.digital_outputs,
                             self.cycle_s)


# -- the default machine -------------------------------------------------------------------
def _linear(name: str, lead: float, gear: float, max_speed: float, travel: float) -> AxisConfig:
    """A ball-screw axis, 10000 pulses/rev, with MEL below 0, ORG at 0..3 and PEL past
    `travel` (all given here in mm and converted to command pulses)."""
    ppu = 10000 * gear / lead
    return AxisConfig(
        name=name, pulses_per_rev=10000, lead=lead, gear_ratio=gear, unit="mm",
        max_speed=max_speed, logic={"pel": "nc", "mel": "nc", "org": "no"},
        mel=SwitchConfig(position=-5.0 * ppu, width=-50.0 * ppu, hysteresis=0.05 * ppu),
        org=SwitchConfig(position=0.0, width=3.0 * ppu, hysteresis=0.05 * ppu),
        pel=SwitchConfig(position=(travel + 5.0) * ppu, width=50.0 * ppu,
                         hysteresis=0.05 * ppu),
    )


def default_machine() -> MachineConfig:
    """The 4-axis XYZU table, identical to examples/xyzu.toml.

    x: 10 mm lead, 1000 pulses/mm, 300 mm travel; y: 5 mm lead, 2000 pulses/mm, 200 mm;
    z: 5 mm lead on a 2:1 belt, 4000 pulses/mm, 100 mm; u: rotary, 7200 pulses/rev on a 5:1
    reducer, 100 pulses/degree, ORG at 0..2 degrees, no end limits. Ideal stepper drives.
    """
    u = AxisConfig(
        name="u", pulses_per_rev=7200, lead=360.0, gear_ratio=5.0, unit="degree",
        max_speed=720.0, encoder_lines_per_rev=1800, logic={"org": "no"},
        org=SwitchConfig(position=0.0, width=200.0, hysteresis=5.0),
    )
    return MachineConfig(
        name="xyzu",
        axes=(
            _linear("x", lead=10.0, gear=1.0, max_speed=500.0, travel=300.0),
            _linear("y", lead=5.0, gear=1.0, max_speed=250.0, travel=200.0),
            _linear("z", lead=5.0, gear=2.0, max_speed=100.0, travel=100.0),
            u,
        ),
        digital_inputs=16, digital_outputs=16, cycle_s=0.001,
    )


# -- TOML files: openmotion.config_toml; re-exported so `openmotion.config` stays the one
# import for machine descriptions. Imported last: config_toml builds on the classes above
# (the package __init__ imports this module first, so the cycle always resolves).
from openmotion.config_toml import (  # noqa: E402
    dumps_machine,
    load_machine,
    loads_machine,
    machine_from_dict,
    machine_to_dict,
    save_machine,
)
