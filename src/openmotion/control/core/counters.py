"""The four per-axis counters of the HSL-4XMO (manual section 4.9) and the target recorder.

The hardware reports raw, unwrapped totals (pulses emitted, encoder counts). Each counter is
a view of one raw total plus its own offset, wrapped to the PCL6045's 28-bit signed range
(-2**27 .. 2**27-1). Setting a counter only changes its offset, so it never disturbs the
other counters or the motion.

- command:  pulses output (raw pulses_out + offset).
- feedback: encoder counts (raw encoder + offset).
- error:    command - feedback through the move ratio, i.e. pulses_out - encoder/ratio,
            rounded to a whole pulse (the seed: "+1 per pulse out, -1 per pulse in"; with a
            ratio other than 1 the feedback is scaled first, as the brief specifies).
- general:  a selectable source: "command", "feedback", "manual" (manual-pulse input; the
            hardware boundary has no MPG yet, so it stays put) or "clock" (CLK/2 = 9.8304 MHz
            counts of controller time). The default is "manual", as on the HSL-4XMO.
- target:   the software target-position recorder (not a hardware counter, not wrapped):
            every new motion command adds its displacement; `reset_target_pos` sets it.

`out_offset` (whole pulses) is what command transforms (control.loops.compensation) add to the
pulse output on top of the planned motion; it is taken off the raw pulses_out, so command,
error and the general counter's "command" source show the *planned* position.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ...errors import MotionError, check_finite
from ...limits import check_quantity

COUNTER_BITS = 28
_HALF = 1 << (COUNTER_BITS - 1)
_FULL = 1 << COUNTER_BITS
COUNTER_MIN = -_HALF
COUNTER_MAX = _HALF - 1
#: General counter clock source: CLK/2 of the 19.6608 MHz reference (HSL 4.9 "9.8 MHz").
CLOCK_HZ = 9_830_400
GENERAL_SOURCES = ("command", "feedback", "manual", "clock")


def _nothing() -> None:
    pass


def wrap28(x: int) -> int:
    """Wrap an integer into the 28-bit signed range, as the PCL6045 counters do."""
    return ((x + _HALF) % _FULL) - _HALF


def _check_count(name: str, value: float) -> int:
    x = check_finite(name, value)
    if x != int(x):
        raise MotionError(f"{name} must be a whole number of pulses, got {value!r}")
    if not COUNTER_MIN <= x <= COUNTER_MAX:
        raise MotionError(
            f"{name} must be in [{COUNTER_MIN}, {COUNTER_MAX}] (28-bit counter), got {value!r}"
        )
    return int(x)


class Counters:
    """Command, feedback, error and general counters plus the target recorder of one axis."""

    __slots__ = ("_pulses", "_encoder", "_time", "_ratio", "_cmd_off", "_fb_off", "_err_off",
                 "_gen_off", "_gen_src", "_target", "_fresh", "out_offset", "_fb_internal",
                 "_raw_out", "_raw_enc")

    def __init__(self, move_ratio: float = 1.0,
                 refresh: Callable[[], None] | None = None) -> None:
        # `refresh` brings the raw totals up to date before any read (the controller reads
        # the hardware lazily, at most once per cycle, only when someone looks).
        self._fresh = refresh or _nothing
        self._pulses = 0
        self._encoder = 0
        self._time = 0.0
        self._ratio = float(move_ratio)
        self._cmd_off = 0
        self._fb_off = 0
        self._err_off = 0
        self._gen_off = 0
        self._gen_src = "manual"
        self._target = 0.0
        self.out_offset = 0
        self._fb_internal = False   # HSL set_feedback_src: count the output pulses
        self._raw_out = 0
        self._raw_enc = 0

    # -- fed by the controller (through `refresh`) ---------------------------------------
    def update(self, pulses_out: int, encoder: int, time: float) -> None:
        """Latest raw hardware totals (unwrapped) and controller time."""
        self._pulses = pulses_out - self.out_offset
        self._raw_out, self._raw_enc = pulses_out, encoder
        self._encoder = pulses_out if self._fb_internal else encoder
        self._time = time

    @property
    def feedback_source(self) -> str:
        """"external" (EA/EB encoder input, default) or "internal" (the output pulses)."""
        return "internal" if self._fb_internal else "external"

    def set_feedback_source(self, source: str) -> None:
        """HSL_M_set_feedback_src: what the feedback counter counts; its value carries on
        from where it was (no jump)."""
        if not isinstance(source, str) or source not in ("external", "internal"):
            raise MotionError(f"source must be 'external' or 'internal', got {source!r}")
        self._fresh()
        before = self._encoder + self._fb_off
        self._fb_internal = source == "internal"
        self._encoder = self._raw_out if self._fb_internal else self._raw_enc
        self._fb_off = before - self._encoder

    # -- raw (unwrapped) views used for motion planning -----------------------------------
    @property
    def move_ratio(self) -> float:
        """Feedback counts per command pulse."""
        return self._ratio

    def set_move_ratio(self, ratio: float) -> None:
        """Set the feedback-to-command ratio, keeping the error counter's reading."""
        self._fresh()
        r = check_quantity("move_ratio", ratio, "ratio")
        before = self.error
        self._ratio = r
        self._err_off += before - self.error

    def command_unwrapped(self) -> int:
        self._fresh()
        return self._pulses + self._cmd_off

    def feedback_unwrapped(self) -> int:
        self._fresh()
        return self._encoder + self._fb_off

    def feedback_in_pulses(self) -> float:
        """Feedback position converted to command pulses through the move ratio."""
        return self.feedback_unwrapped() / self._ratio

    def pulses_from_command(self, command_value: float) -> float:
        """Raw hardware pulse frame position of a command-counter value."""
        return command_value - self._cmd_off

    # -- the four counters ------------------------------------------------------------------
    @property
    def command(self) -> int:
        self._fresh()
        return wrap28(self._pulses + self._cmd_off)

    def set_command(self, value: int) -> None:
        self._fresh()
        self._cmd_off = _check_count("command", value) - self._pulses

    @property
    def feedback(self) -> int:
        self._fresh()
        return self.feedback_from(self._raw_out, self._raw_enc)

    def feedback_from(self, pulses_out, encoder):
        """The feedback counter for raw hardware totals (ints or int arrays): what
        `update(pulses_out, encoder, t)` then `feedback` gives (jumps record with it)."""
        return wrap28((pulses_out if self._fb_internal else encoder) + self._fb_off)

    @staticmethod
    def feedback_of(counters: Sequence[Counters], pulses_out: np.ndarray,
                    encoder: np.ndarray) -> np.ndarray:
        """`feedback_from` of many axes at once: column i of the (m, n) int arrays
        `pulses_out` and `encoder` belongs to counters[i] (the recorder in jumps)."""
        internal = np.array([c._fb_internal for c in counters], dtype=bool)
        off = np.array([c._fb_off for c in counters], dtype=np.int64)
        return wrap28(np.where(internal, pulses_out, encoder) + off)

    def actual(self) -> float:
        """The feedback position in the command-counter frame: the encoder (or the output
        pulses) through the move ratio, plus the command offset, so `Axis.position -
        actual()` is the following error in pulses whatever the counters were set to."""
        self._fresh()
        return self._cmd_off + self._encoder / self._ratio

    def actual_from(self, pulses_out, encoder):
        """`actual()` for raw hardware totals (ints or int arrays: a jump's readback)."""
        return self._cmd_off + (pulses_out if self._fb_internal else encoder) / self._ratio

    def set_feedback(self, value: int) -> None:
        self._fresh()
        self._fb_off = _check_count("position", value) - self._encoder

    def _raw_error(self) -> int:
        self._fresh()
        return round(self._pulses - self._encoder / self._ratio)

    @property
    def error(self) -> int:
        return wrap28(self._raw_error() + self._err_off)

    def reset_error(self) -> None:
        self._err_off = -self._raw_error()

    def _raw_general(self) -> int:
        self._fresh()
        return self._general_source_value(self._pulses, self._encoder, self._time)

    def _general_source_value(self, pulses: int, encoder: int, time: float) -> int:
        src = self._gen_src
        if src == "command":
            return pulses
        if src == "feedback":
            return encoder
        if src == "clock":
            return round(time * CLOCK_HZ)
        return 0  # manual pulse input: no MPG on the hardware boundary yet

    @property
    def general(self) -> int:
        return wrap28(self._raw_general() + self._gen_off)

    @property
    def general_source(self) -> str:
        return self._gen_src

    def set_general(self, value: int, source: str | None = None) -> None:
        """Set the general counter's value, and optionally its source."""
        v = _check_count("general", value)
        if source is not None and source not in GENERAL_SOURCES:
            raise MotionError(f"source must be one of {GENERAL_SOURCES}, got {source!r}")
        if source is not None:
            self._gen_src = source
        self._gen_off = v - self._raw_general()

    # -- readings at other raw totals (latches, homing marks) ----------------------------
    @property
    def command_offset(self) -> int:
        """Command counter minus the raw planned pulses: adding it maps a position in the raw
        pulse frame (motion history, profiles) into the command-counter frame."""
        return self._cmd_off

    def encoder_raw(self) -> int:
        """The raw encoder total (unwrapped, without the feedback counter's offset)."""
        self._fresh()
        return self._encoder

    def readings_at(self, pulses: int, encoder: int,
                    time: float) -> tuple[int, int, int, int]:
        """(command, feedback, error, general) as the counters read when the raw totals are
        `pulses` (planned pulses out) and `encoder` at controller time `time`, with today's
        offsets: a latch uses it for the totals at an input edge's exact time."""
        command = wrap28(pulses + self._cmd_off)
        feedback = wrap28(encoder + self._fb_off)
        error = wrap28(round(pulses - encoder / self._ratio) + self._err_off)
        general = wrap28(self._general_source_value(pulses, encoder, time) + self._gen_off)
        return command, feedback, error, general

    # -- target recorder ------------------------------------------------------------------
    @property
    def target(self) -> float:
        return self._target

    def reset_target(self, value: float = 0.0) -> None:
        self._target = float(_check_count("target", value))

    def add_target(self, displacement: float) -> None:
        self._target += displacement

    def reset_all(self) -> None:
        """Clear command, feedback, error and general counters (home completion)."""
        self._fresh()
        self.set_command(0)
        self.set_feedback(0)
        self.reset_error()
        self._gen_off = -self._raw_general()

    def snapshot(self) -> tuple:
        """Every counter value and offset (tests compare snapshots before and after)."""
        self._fresh()
        return (self.command, self.feedback, self.error, self.general, self._gen_src,
                self._target, self._ratio)
