"""A simulated spindle: a servo motor with an encoder and its index pulse, as one axis.

A motion controller drives a spindle the way it drives any servo axis in velocity mode:
pulses (or a speed command) to the drive, the motor's encoder back on the axis's encoder
input, and the encoder's index (EZ) once per revolution. The simulator already models each
part (servo plant with its lag, the decoder, the index window), so a spindle is an axis
configured for it; `spindle_axis` builds that configuration. The control layer and the
G-code runner (program/spindle.py) see an ordinary axis: they command its speed and read
its encoder and index edges, and cannot tell it is simulated.

    config = replace(default_machine(), axes=(*default_machine().axes, spindle_axis()))
"""

from __future__ import annotations

from openmotion.config import AxisConfig, DriveConfig
from openmotion.errors import MotionError, check_positive


def spindle_axis(name: str = "spindle", counts_per_rev: int = 4096, max_rpm: float = 6000.0,
                 bandwidth_hz: float = 60.0, damping: float = 0.9) -> AxisConfig:
    """An axis for a spindle: unit degrees (360 per revolution), `counts_per_rev` pulses and
    encoder counts (x4 decoding) per revolution, index once per revolution, a servo drive
    (second-order lag `bandwidth_hz`, `damping`), `max_rpm` as its speed limit."""
    if isinstance(counts_per_rev, bool) or not isinstance(counts_per_rev, int) \
            or counts_per_rev < 4 or counts_per_rev % 4:
        raise MotionError(f"counts_per_rev must be a multiple of 4 (x4 encoder), >= 4, "
                          f"got {counts_per_rev!r}")
    rpm = check_positive("max_rpm", max_rpm)
    return AxisConfig(name, pulses_per_rev=counts_per_rev, lead=360.0, unit="degree",
                      max_speed=rpm * 6.0, encoder_lines_per_rev=counts_per_rev // 4,
                      drive=DriveConfig("servo", bandwidth_hz=bandwidth_hz, damping=damping,
                                        inp_band=2.0))
