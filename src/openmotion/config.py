"""Machine description: axes, mechanism parameters, pulse/encoder modes, I/O logic, and the
simulated plant behind each axis. Built in code or loaded from / saved to TOML.

Units: mechanism-related lengths are in the axis's user unit; speeds in user units per
second; the simulator section is in command pulses unless a name says otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field

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
DRIVE_TYPES = ("ideal_stepper", "stepper", "servo")


@dataclass(frozen=True)
class SwitchConfig:
    """A switch fixed on the machine at a mechanical position (command pulses).

    It is active while the carriage is within [position, position + width) (width < 0
    spans downwards); `hysteresis` (pulses) is the extra travel needed to release it.
    End limits normally use a large width so they stay active beyond the switch.
    """

    position: float
    width: float = 100.0
    hysteresis: float = 0.0


@dataclass(frozen=True)
class DriveConfig:
    """The simulated drive/motor behind one axis.

    ideal_stepper: follows every pulse. stepper: loses steps when the commanded speed
    exceeds `pullout_speed` (pps) or the acceleration exceeds `pullout_accel` (pps/s).
    servo: tracks the command with a second-order lag (`bandwidth_hz`, `damping`), reports
    INP within `inp_band` pulses, READY after servo-on, ALM on `alarm` scenarios.
    """

    type: str = "ideal_stepper"
    pullout_speed: float = 0.0
    pullout_accel: float = 0.0
    bandwidth_hz: float = 30.0
    damping: float = 0.9
    inp_band: float = 5.0
    backlash: float = 0.0          # mechanical backlash (command pulses), feedback side
    pitch_error: tuple[float, ...] = ()  # lead-screw error table (pulses), see docs


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


@dataclass(frozen=True)
class MachineConfig:
    """The whole machine: axes in controller order, general I/O counts, cycle period."""

    name: str = "machine"
    axes: tuple[AxisConfig, ...] = ()
    digital_inputs: int = 16
    digital_outputs: int = 16
    cycle_s: float = 0.001
