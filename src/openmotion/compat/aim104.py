"""Arcom AIM104-MOTION-1 board emulation (I/O map, interrupts, SYNC) and its MOTION_* library.

`PC104Bus` holds boards at their base addresses and the one virtual clock; `AIM104Board`
decodes the four I/O bytes of the manual's register map:

    base+0  write: HCTL-1100 register address     read: the mandatory dummy read
    base+1  write: data to that register          read: data from it
    base+2  write: clear interrupt / status flags read: board status register
    base+3  configuration register (bits 0-1 motor drive, bit 2 toggles SYNC, reads 0)

Access protocol (manual, "Reading and Writing..."): after each address write, dummy read or
data write the controller is busy; the ready flag (status bit 0) reads 1 once and then 0,
so a program that polls it (or calls `delay_us(>= 1.7)`) proceeds. With `strict=True` (the
default) touching the data port while busy, reading data without the dummy read, or using
the data port before any address raises MotionError naming the rule - a ported program
learns its bug instead of reading stale data.

Status bits 1-4 (LIMIT1, LIMIT2, STOP, HOME; 0 = triggered) and bit 5 (profile, 1 = a
profile ran) latch until `base+2` is written; an input still active re-latches at once.
Interrupts: a LIMIT or STOP going active, a trapezoidal profile completing, HOME going
active with link 6 made; each is a `BoardEvent` passed to `on_interrupt` callbacks and kept
in a bounded `events` deque, and the IRQ line stays asserted until cleared.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from openmotion.errors import MotionError, check_nonnegative
from openmotion.hw.sim.dcmotor import DCMotor

from . import hctl1100_regs as R
from .hctl1100 import HCTL1100, ChipEvent
from .hctl1100_commutator import DRIVE_DC, IdealStepper, winding_angle

ST_BUSY, ST_LIMIT1, ST_LIMIT2, ST_STOP, ST_HOME, ST_PROFILE = 0x01, 0x02, 0x04, 0x08, 0x10, 0x20
CFG_DRIVE_MASK, CFG_SYNC = 0x03, 0x04
IRQ_LINES = (3, 4, 5, 7, 9, 10, 11, 12, 15)


@dataclass(frozen=True)
class BoardEvent:
    """An interrupt cause: 'limit', 'stop', 'profile_done' or 'home' at virtual time."""

    time: float
    base: int
    kind: str


class AIM104Board:
    """One AIM104-MOTION-1 with its HCTL-1100 and motor (a DCMotor or an IdealStepper)."""

    def __init__(self, plant: DCMotor | IdealStepper | None = None, *, base: int = 0x180,
                 irq: int = 5, link5_internal_sync: bool = True,
                 link6_home_halts: bool = False, link7_no_shaping: bool = True,
                 strict: bool = True) -> None:
        if isinstance(base, bool) or not isinstance(base, int) or base % 4 or not (
                0 <= base <= 0x3FC):
            raise MotionError(f"base must be a multiple of 4 in 0x000..0x3fc, got {base!r}")
        if irq not in IRQ_LINES:
            raise MotionError(f"irq must be one of {IRQ_LINES}, got {irq!r}")
        self.base = base
        self.irq = irq
        self.link5_internal_sync = bool(link5_internal_sync)
        self.link6_home_halts = bool(link6_home_halts)
        self.link7_no_shaping = bool(link7_no_shaping)
        self.strict = bool(strict)
        self.plant = plant if plant is not None else DCMotor()
        self.chip = HCTL1100(self.plant)
        self.chip.listeners.append(self._on_chip_event)
        if isinstance(self.plant, IdealStepper):
            self.plant.drive = self._stepper_drive
        self.config = 0
        self.events: deque[BoardEvent] = deque(maxlen=1024)
        self.on_interrupt: list[Callable[[BoardEvent], None]] = []
        self.irq_asserted = False
        self.bus: PC104Bus | None = None
        self._inputs = {"limit1": False, "limit2": False, "stop": False, "home": False}
        self._latched = 0  # status bits 1-5 as "triggered" (1) before the active-low mapping
        self._addr: int | None = None
        self._dummy = False
        self._busy = 0

    # ------------------------------------------------------------------ I/O ports
    def outb(self, port: int, value: int) -> None:
        """Write one byte to base+0..3."""
        off = self._offset(port)
        R.check_byte("value", value)
        if off == 0:
            self._check_ready("write the register address")
            self._addr = value
            self._dummy = False
            self._busy = 1
        elif off == 1:
            self._check_ready("write data")
            if self._addr is None:
                raise MotionError("write a register address to base+0 before data to base+1")
            self.chip.write(self._addr, value)
            self._busy = 1
        elif off == 2:
            self._latched = 0
            self.irq_asserted = False
            self._relatch()
        else:
            self.config = value & CFG_DRIVE_MASK
            if value & CFG_SYNC:
                self._pulse_sync()

    def inb(self, port: int) -> int:
        """Read one byte from base+0..3."""
        off = self._offset(port)
        if off == 0:
            self._dummy = True  # starts the controller read cycle
            self._busy = 1
            return 0xFF
        if off == 1:
            self._check_ready("read data")
            if self._addr is None:
                raise MotionError("write a register address to base+0 before reading base+1")
            if self.strict and not self._dummy:
                raise MotionError("a dummy read of base+0 must follow the address write "
                                  "before data is read from base+1")
            self._dummy = False
            return self.chip.read(self._addr)
        if off == 2:
            return self.status
        return self.config

    def delay_us(self, us: float) -> None:
        """Wait `us` microseconds of virtual time (>= 1.7 us also ends the busy state)."""
        us = check_nonnegative("us", us)
        if us >= 1.7:
            self._busy = 0
        if self.bus is not None:
            self.bus.advance(us * 1e-6)
        else:
            self.chip.advance(us * 1e-6)

    @property
    def status(self) -> int:
        """Board status register; reading it is also the ready-flag poll."""
        s = ST_BUSY if self._busy else 0
        if self._busy:
            self._busy -= 1
        low_active = ST_LIMIT1 | ST_LIMIT2 | ST_STOP | ST_HOME
        s |= low_active & ~self._latched
        s |= self._latched & ST_PROFILE
        return s

    def _offset(self, port: int) -> int:
        if isinstance(port, bool) or not isinstance(port, int):
            raise MotionError(f"port must be an int I/O address, got {port!r}")
        off = port - self.base
        if not 0 <= off <= 3:
            raise MotionError(f"port {port:#x} is outside this board's 4 bytes at "
                              f"{self.base:#x}")
        return off

    def _check_ready(self, what: str) -> None:
        if self.strict and self._busy:
            raise MotionError(f"wait until the ready flag (status bit 0) is clear, or 1.7 us, "
                              f"before you {what}")

    # ------------------------------------------------------------------ inputs, events
    def set_input(self, name: str, active: bool) -> None:
        """Drive 'limit1', 'limit2', 'stop' or 'home' (True = active, opto conducting)."""
        if name not in self._inputs:
            raise MotionError(f"name must be one of {sorted(self._inputs)}, got {name!r}")
        active = bool(active)
        was = self._inputs[name]
        self._inputs[name] = active
        if name in ("limit1", "limit2"):
            if active and not was:
                self._latched |= ST_LIMIT1 if name == "limit1" else ST_LIMIT2
            self.chip.set_limit(self._inputs["limit1"] or self._inputs["limit2"])
        elif name == "stop":
            if active and not was:
                self._latched |= ST_STOP
            self.chip.set_stop(active)
        elif active and not was:  # home
            self._latched |= ST_HOME
            if self.link6_home_halts:
                # a short pulse on the chip LIMIT input: halts, then the pin is free again
                self.chip.set_limit(True)
                self.chip.set_limit(self._inputs["limit1"] or self._inputs["limit2"])
                self._interrupt("home")

    def _relatch(self) -> None:
        i = self._inputs
        for name, bit in (("limit1", ST_LIMIT1), ("limit2", ST_LIMIT2), ("stop", ST_STOP),
                          ("home", ST_HOME)):
            if i[name]:
                self._latched |= bit

    def _on_chip_event(self, ev: ChipEvent) -> None:
        if ev.kind == "profile_start":
            self._latched |= ST_PROFILE  # status bit 5: a profile ran (latched)
            return
        if ev.kind == "limit" and self._inputs["home"] and not (
                self._inputs["limit1"] or self._inputs["limit2"]):
            return  # the home pulse reports itself as 'home'
        self._interrupt(ev.kind)

    def _interrupt(self, kind: str) -> None:
        ev = BoardEvent(self.chip.time, self.base, kind)
        self.events.append(ev)
        self.irq_asserted = True
        for cb in self.on_interrupt:
            cb(ev)

    # ------------------------------------------------------------------ drive, time, SYNC
    @property
    def drive_mode(self) -> int:
        return self.config & CFG_DRIVE_MASK

    def _stepper_drive(self, counts: int, sign: int) -> float | None:
        if self.drive_mode == DRIVE_DC or sign == 0:
            return None
        return winding_angle(self.chip.commutator_output(counts, sign), self.drive_mode)

    def _pulse_sync(self) -> None:
        if self.bus is not None:
            self.bus.pulse_sync(self)
        elif self.link5_internal_sync:
            self.chip.sync()

    def advance(self, dt: float) -> None:
        """Move this board alone through `dt` s of virtual time (use the bus for several)."""
        self.chip.advance(dt)


class PC104Bus:
    """Boards at their base addresses sharing one virtual clock and (optionally) SYNC."""

    def __init__(self) -> None:
        self.boards: dict[int, AIM104Board] = {}
        self.sync_group: list[AIM104Board] = []
        self.time = 0.0

    def add(self, board: AIM104Board, *, tie_sync: bool = False) -> AIM104Board:
        """Plug `board` in (its 4 bytes must be free); `tie_sync` wires its SYNC pin 46
        to the common SYNC line of the other tied boards (appendix 3)."""
        if not isinstance(board, AIM104Board):
            raise MotionError(f"board must be an AIM104Board, got {type(board).__name__}")
        if board.base in self.boards:
            raise MotionError(f"base address {board.base:#x} is already in use")
        if board.bus is not None:
            raise MotionError("board is already on a bus")
        if abs(board.chip.time - self.time) > 1e-12:
            raise MotionError("board's clock differs from the bus clock; add boards at start")
        self.boards[board.base] = board
        board.bus = self
        if tie_sync:
            self.sync_group.append(board)
        return board

    def board_at(self, port: int) -> AIM104Board:
        b = self.boards.get(port & ~0x3) if isinstance(port, int) else None
        if b is None:
            raise MotionError(f"no AIM104 board decodes I/O port {port!r}")
        return b

    def outb(self, port: int, value: int) -> None:
        self.board_at(port).outb(port, value)

    def inb(self, port: int) -> int:
        return self.board_at(port).inb(port)

    def advance(self, dt: float) -> None:
        """Advance every board's chip and motor by `dt` seconds."""
        dt = check_nonnegative("dt", dt)
        for b in self.boards.values():
            b.chip.advance(dt)
        self.time += dt

    def pulse_sync(self, source: AIM104Board) -> None:
        """SYNC toggled on `source`: its own chip resets if link 5 selects the internal
        SYNC; every board tied to the common line resets if the source drives it."""
        if source in self.sync_group and source.link5_internal_sync:
            for b in self.sync_group:
                b.chip.sync()
        elif source.link5_internal_sync:
            source.chip.sync()
