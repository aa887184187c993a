"""openmotion.hw.sim: a simulated machine (drives, motors, encoders, switches, I/O) behind
the hardware boundary, with a scenario API for faults and events at chosen times."""

from .dcmotor import DCMotor, DCMotorParams
from .encoder import EncoderWiring
from .machine import SimMachine
from .pulserecord import PulseRecord
from .scenario import Scenario

__all__ = ["DCMotor", "DCMotorParams", "EncoderWiring", "PulseRecord", "Scenario", "SimMachine"]
