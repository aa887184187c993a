"""Vendor compatibility facades. `hctl1100`: the HCTL-1100 chip emulation; `aim104`: the
Arcom AIM104-MOTION-1 board (I/O map, interrupts, SYNC); `aim104_lib`: its MOTION_* library;
`mccl`: the HIWIN PCI-4P MCCL library (MCC_* functions; docs/porting-mccl.md)."""

from .aim104 import AIM104Board, BoardEvent, PC104Bus
from .aim104_lib import MotionLibrary
from .hctl1100 import HCTL1100, ChipEvent, Trace
from .hctl1100_commutator import IdealStepper
from .hctl1100_regs import Mode
from .mccl import MCCL

__all__ = ["AIM104Board", "BoardEvent", "ChipEvent", "HCTL1100", "IdealStepper", "Mode",
           "MCCL", "MotionLibrary", "PC104Bus", "Trace"]
