"""Encoder signals and the board's decoder (HSL-4XMO 4.9, "Feedback Position Counter").

The physical encoder is described by `EncoderWiring`: its signal kind ("ab" quadrature,
"cw_ccw" dual pulse, "pulse_dir"), its resolution in native units per command pulse (one
native unit = one quadrature state for "ab", one pulse otherwise) and how its wires are
connected (swap/invert flags: the board settings that would read it correctly). By default
the machine is wired as configured, so the board reads `move_ratio` counts per command
pulse; a wiring that differs from the AxisConfig models a mis-set board.

Decoding is exact and closed form. The physical index Q (native units) is quantized from
the load position like the pulse count (last integer reached). Each unit step of Q is a
fixed sequence of A/B edges; the decoder turns each edge into -1, 0 or +1:

    ab_x4  every edge, +1 when the Gray sequence 00->10->11->01 advances (A leads B)
    ab_x2  A edges only (+1 rising with B low / falling with B high, else -1)
    ab_x1  A edges with B low only (+1 rising, -1 falling)
    cw_ccw +1 on each rising edge of A, -1 on each rising edge of B
    pulse_dir  rising edge of A: +1 if B (direction) is high, else -1

Per-step increments repeat with the signal's period, so a run of n steps costs O(1) with
prefix sums. A config flag that differs from the wiring flips the decoded signal: a single
inverted channel or swapped A/B counts backwards; x1 on an x4-resolution wiring counts a
quarter. (Swap and inversion are applied as independent flips of the decoded signals.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from openmotion.config import AxisConfig
from openmotion.errors import MotionError, check_positive

from .pieces import EPS_PULSE

WIRING_KINDS = ("ab", "cw_ccw", "pulse_dir")
DECODE_MODES = ("ab_x1", "ab_x2", "ab_x4", "cw_ccw", "pulse_dir")

# quadrature levels (A, B) for state k mod 4: A leads B when k increases
_AB_STATES = ((0, 0), (1, 0), (1, 1), (0, 1))


@dataclass(frozen=True)
class EncoderWiring:
    """The physical encoder of one axis, as wired to the board."""

    kind: str = "ab"
    units_per_pulse: float = 4.0   # native units (quadrature states or pulses) per cmd pulse
    swap_ab: bool = False
    invert_a: bool = False
    invert_b: bool = False
    invert_z: bool = False

    def __post_init__(self) -> None:
        if self.kind not in WIRING_KINDS:
            raise MotionError(f"kind must be one of {WIRING_KINDS}, got {self.kind!r}")
        check_positive("units_per_pulse", self.units_per_pulse)


def default_wiring(ax: AxisConfig) -> EncoderWiring:
    """The wiring under which `ax`'s decoder reads move_ratio counts per command pulse."""
    mode = ax.encoder_mode
    per_count = {"ab_x4": 1.0, "ab_x2": 2.0, "ab_x1": 4.0}.get(mode, 1.0)
    kind = "ab" if mode.startswith("ab") else mode
    return EncoderWiring(kind, ax.move_ratio * per_count, ax.swap_ab, ax.invert_a,
                         ax.invert_b, ax.invert_z)


def _decode_edge(mode: str, a0: int, b0: int, a1: int, b1: int) -> int:
    """Counter increment for one signal change (exactly one of A, B changes)."""
    if mode == "ab_x4":
        i0, i1 = _AB_STATES.index((a0, b0)), _AB_STATES.index((a1, b1))
        return 1 if (i1 - i0) % 4 == 1 else -1
    if a0 != a1:
        rising = a1 == 1
        if mode == "ab_x2":
            return 1 if rising == (b0 == 0) else -1
        if mode == "ab_x1":
            return 0 if b0 else (1 if rising else -1)
        if mode == "cw_ccw":
            return 1 if rising else 0
        return (1 if b0 else -1) if rising else 0  # pulse_dir
    if mode == "cw_ccw":
        return -1 if b1 == 1 and b0 == 0 else 0
    return 0


def _levels(kind: str, k: int, last_dir: int) -> tuple[int, int]:
    """Physical (A, B) at rest at native index k (pulse kinds: both pulse lines low)."""
    if kind == "ab":
        return _AB_STATES[k % 4]
    if kind == "pulse_dir":
        return (0, 1 if last_dir > 0 else 0)
    return (0, 0)


def _step_levels(kind: str, k: int, d: int) -> list[tuple[int, int]]:
    """Level sequence of one step from index k in direction d (start excluded)."""
    if kind == "ab":
        return [_AB_STATES[(k + d) % 4]]
    if kind == "cw_ccw":
        return [(1, 0), (0, 0)] if d > 0 else [(0, 1), (0, 0)]
    b = 1 if d > 0 else 0
    return [(1, b), (0, b)]


class Decoder:
    """Exact decoded count of one axis's encoder input, as the board sees it."""

    __slots__ = ("kind", "upp", "mode", "flip_a", "flip_b", "swap", "period",
                 "fwd", "bwd", "fwd_pre", "bwd_pre", "turn", "q", "last_dir", "count")

    def __init__(self, wiring: EncoderWiring, ax: AxisConfig, y: float = 0.0) -> None:
        if ax.encoder_mode not in DECODE_MODES:
            raise MotionError(f"encoder_mode must be one of {DECODE_MODES}, "
                              f"got {ax.encoder_mode!r}")
        self.kind = wiring.kind
        self.upp = wiring.units_per_pulse
        self.mode = ax.encoder_mode
        self.flip_a = wiring.invert_a != ax.invert_a
        self.flip_b = wiring.invert_b != ax.invert_b
        self.swap = wiring.swap_ab != ax.swap_ab
        self.period = 4 if self.kind == "ab" else 1
        self.fwd = [self._step_inc(k, 1) for k in range(self.period)]
        self.bwd = [self._step_inc(k, -1) for k in range(self.period)]
        self.fwd_pre = _prefix(self.fwd)
        self.bwd_pre = _prefix(self.bwd)
        # direction change of a pulse_dir signal toggles B by itself: one edge
        self.turn = {d: self._turn_inc(d) for d in (1, -1)}
        self.q = self.index_after(y, 0, 1 if y >= 0 else -1)
        self.last_dir = 1
        self.count = 0

    # -- signal model -------------------------------------------------------------------
    def _seen(self, lv: tuple[int, int]) -> tuple[int, int]:
        a, b = lv[0] ^ self.flip_a, lv[1] ^ self.flip_b
        return (b, a) if self.swap else (a, b)

    def _step_inc(self, k: int, d: int) -> int:
        prev = self._seen(_levels(self.kind, k, d))
        inc = 0
        for lv in _step_levels(self.kind, k, d):
            cur = self._seen(lv)
            inc += _decode_edges(self.mode, prev, cur)
            prev = cur
        return inc

    def _turn_inc(self, d: int) -> int:
        if self.kind != "pulse_dir":
            return 0
        return _decode_edges(self.mode, self._seen(_levels(self.kind, 0, -d)),
                             self._seen(_levels(self.kind, 0, d)))

    # -- counting -----------------------------------------------------------------------
    def index_after(self, y: float, q: int, d: int) -> int:
        """Native index after the load moves monotonically to y (last integer reached)."""
        x = y * self.upp
        if d > 0:
            k = math.floor(x + EPS_PULSE)
            return k if k > q else q
        if d < 0:
            k = math.ceil(x - EPS_PULSE)
            return k if k < q else q
        return q

    def increment(self, q0: int, q1: int, last_dir: int) -> int:
        """Decoded count change when the index moves monotonically from q0 to q1."""
        if q1 == q0:
            return 0
        d = 1 if q1 > q0 else -1
        inc = self.turn[d] if d != last_dir else 0
        n = abs(q1 - q0)
        if d > 0:
            return inc + _run_sum(self.fwd_pre, q0, n)
        # backward steps start at q0, q0-1, ..., q0-n+1
        return inc + _run_sum(self.bwd_pre, q0 - n + 1, n)

    def advance(self, y: float, d: int) -> None:
        """Commit a monotone move of the load to y."""
        q1 = self.index_after(y, self.q, d)
        if q1 != self.q:
            self.count += self.increment(self.q, q1, self.last_dir)
            self.last_dir = 1 if q1 > self.q else -1
            self.q = q1

    def peek(self, y: float, d: int) -> int:
        """Count if the load moved monotonically to y now (no state change)."""
        q1 = self.index_after(y, self.q, d)
        return self.count + self.increment(self.q, q1, self.last_dir)


def _decode_edges(mode: str, prev: tuple[int, int], cur: tuple[int, int]) -> int:
    inc = 0
    a0, b0 = prev
    a1, b1 = cur
    if a0 != a1 and b0 != b1:  # swap/invert never makes both change; split to be safe
        inc += _decode_edge(mode, a0, b0, a1, b0)
        a0 = a1
    if (a0, b0) != (a1, b1):
        inc += _decode_edge(mode, a0, b0, a1, b1)
    return inc


def _prefix(table: list[int]) -> list[int]:
    out = [0]
    for v in table:
        out.append(out[-1] + v)
    return out


def _run_sum(pre: list[int], k0: int, n: int) -> int:
    """Sum of table[(k0 + i) mod P] for i in range(n), with pre its prefix sums."""
    p = len(pre) - 1
    full, rest = divmod(n, p)
    total = full * pre[p]
    start = k0 % p
    end = start + rest
    if end <= p:
        total += pre[end] - pre[start]
    else:
        total += pre[p] - pre[start] + pre[end - p]
    return total
