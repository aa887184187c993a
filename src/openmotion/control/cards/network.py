"""An HSL network in virtual time: motion modules on one link, and what each call costs.

Each module is a `Controller` (its own axes, E-stop, comparators); the `Network` steps all
of them in lockstep and charges every host call the command-delivery time of the HSL-4XMO
timing tables, so a polling loop on the host advances time and ends (HSL-4XMO 4.3, 6.1):

* base scan time per slave ID (Table 4-1): 3M 118 / 60.7 us, 6M 59 / 30.4 us, 12M 29.5 /
  15.2 us (half / full duplex); the scan covers N IDs, N = the highest ID a module occupies,
  in full duplex rounded up to an even count (a full-duplex module occupies start, +2, +4,
  +6). One module at ID 1, full duplex: IDs 1, 3, 5, 7, N = 8, 8 x 30.4 = 243.2 us (the
  manual's example); half duplex ID 1: IDs 1..4, 236 us ("240 us for one module").
* command time (Table 6-2, 6M full duplex, ms, measured with 1 / 4 / 8 modules) per command
  type 1..8 (Table 6-1); other module counts: deliveries x the recommended time per
  delivery (0.5 ms below 4 modules; 0.5 + (N + 1 - 4)/2 x 0.24 ms odd, 0.5 + (N - 4)/2 x
  0.24 ms even). Other rates and duplex modes scale the 6M full-duplex times by the ratio
  of base scan times (our assumption; the manual measured 6M full duplex only).

`charge(kind)` advances every module by the command time; virtual time only (a network is
not run in real-time mode). Times are configurable (`NetworkTiming`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING

from ...errors import MotionError, check_int, check_nonnegative
from ..core.controller import Controller

if TYPE_CHECKING:
    from ...config_network import NetworkConfig

#: Table 4-1: base scan time per ID (s), by rate and duplex.
BASE_SCAN_S: Mapping[tuple[str, str], float] = MappingProxyType({
    ("3M", "half"): 118e-6, ("3M", "full"): 60.7e-6,
    ("6M", "half"): 59e-6, ("6M", "full"): 30.4e-6,
    ("12M", "half"): 29.5e-6, ("12M", "full"): 15.2e-6,
})
RATES = ("3M", "6M", "12M")
DUPLEX = ("half", "full")
#: Table 6-1 command types (deliveries per call).
SIMPLE, SET_U16, SET_U32, GET_U16, GET_U32, ONE_AXIS, TWO_AXIS, SHORT = range(1, 9)
DELIVERIES: Mapping[int, int] = MappingProxyType(
    {SIMPLE: 1, SET_U16: 1, SET_U32: 1, GET_U16: 1, GET_U32: 1, ONE_AXIS: 6, TWO_AXIS: 7,
     SHORT: 2})
#: Table 6-2 (ms) with one, four and eight modules, 6M full duplex.
COMMAND_MS: Mapping[int, Mapping[int, float]] = MappingProxyType({
    SIMPLE: {1: 0.413, 4: 0.500, 8: 1.000},
    SET_U16: {1: 0.429, 4: 0.501, 8: 1.000},
    SET_U32: {1: 0.453, 4: 0.501, 8: 1.000},
    GET_U16: {1: 0.497, 4: 0.505, 8: 1.000},
    GET_U32: {1: 0.500, 4: 0.509, 8: 1.000},
    ONE_AXIS: {1: 2.588, 4: 3.023, 8: 6.000},
    TWO_AXIS: {1: 3.026, 4: 3.500, 8: 7.000},
    SHORT: {1: 0.850, 4: 1.012, 8: 2.000},
})


def delivery_ms(n_modules: int) -> float:
    """The manual's recommended time of one delivery (6.1 notes), ms."""
    n = check_int("n_modules", n_modules, 1, 16)
    if n < 4:
        return 0.5
    return 0.5 + ((n + 1 - 4) if n % 2 else (n - 4)) / 2 * 0.24


def occupied(start: int, n_axes: int, duplex: str) -> tuple[int, ...]:
    """The slave IDs of a module at `start` with `n_axes` axes (one ID per axis)."""
    step = 2 if duplex == "full" else 1
    return tuple(start + k * step for k in range(n_axes))


def scan_ids(ids: Sequence[int], duplex: str) -> int:
    """N of Table 4-1: the IDs one scan covers, given every occupied ID."""
    top = max(ids)
    return top + (top % 2) if duplex == "full" else top


@dataclass(frozen=True)
class NetworkTiming:
    """Rate, duplex and the command-time table (ms by type, then by module count).

    `scale` multiplies every command time (0 turns network time off)."""

    rate: str = "6M"
    duplex: str = "full"
    command_ms: Mapping[int, Mapping[int, float]] = field(default_factory=lambda: COMMAND_MS)
    scale: float = 1.0

    def __post_init__(self) -> None:
        if self.rate not in RATES:
            raise MotionError(f"rate must be one of {', '.join(RATES)}, got {self.rate!r}")
        if self.duplex not in DUPLEX:
            raise MotionError(f"duplex must be 'half' or 'full', got {self.duplex!r}")
        check_nonnegative("scale", self.scale)
        for kind in DELIVERIES:
            if kind not in self.command_ms:
                raise MotionError(f"command_ms must give command type {kind}")
            for n, ms in self.command_ms[kind].items():
                check_int(f"command_ms[{kind}] module count", n, 1, 16)
                check_nonnegative(f"command_ms[{kind}][{n}]", ms)

    @property
    def base_scan_s(self) -> float:
        return BASE_SCAN_S[(self.rate, self.duplex)]

    def scan_time(self, ids: Sequence[int]) -> float:
        """One HSL scan (s) covering the occupied slave IDs `ids` (Table 4-1)."""
        return self.base_scan_s * scan_ids(ids, self.duplex)

    def command_time(self, kind: int, n_modules: int) -> float:
        """Seconds one call of command type `kind` takes with `n_modules` on the link."""
        check_int("kind", kind, 1, 8)
        table = self.command_ms[kind]
        ms = table.get(n_modules)
        if ms is None:
            ms = DELIVERIES[kind] * delivery_ms(n_modules)
        ratio = self.base_scan_s / BASE_SCAN_S[("6M", "full")]
        return ms * 1e-3 * ratio * self.scale


class Network:
    """Modules (Controllers, one per HSL-4XMO) on one link, stepped together.

    modules: connect index -> Controller, all with the same cycle period and start time;
    slave_ids: connect index -> the module's start ID (S1 switch); timing: NetworkTiming.
    """

    def __init__(self, modules: Mapping[int, Controller], slave_ids: Mapping[int, int],
                 timing: NetworkTiming | None = None) -> None:
        if not modules:
            raise MotionError("a network needs at least one module")
        ctls = list(modules.values())
        for c in ctls:
            if not isinstance(c, Controller):
                raise MotionError(f"modules must be Controllers, got {type(c).__name__}")
        if len({c.period for c in ctls}) != 1 or len({c.time for c in ctls}) != 1:
            raise MotionError("every module must have the same cycle period and time")
        if set(slave_ids) != set(modules):
            raise MotionError("slave_ids must give one start ID per module")
        self.modules: dict[int, Controller] = dict(sorted(modules.items()))
        self.slave_ids = dict(slave_ids)
        self.timing = timing if timing is not None else NetworkTiming()
        self.period = ctls[0].period
        self._time = ctls[0].time
        #: calls charged, by command type (for reports and tests)
        self.calls: dict[int, int] = dict.fromkeys(DELIVERIES, 0)

    @property
    def time(self) -> float:
        """Network (host) time, s: the modules have run every cycle that ends by then."""
        return self._time

    def occupied_ids(self) -> dict[int, tuple[int, ...]]:
        """connect index -> the slave IDs its axes occupy."""
        return {k: occupied(self.slave_ids[k], len(c.axes), self.timing.duplex)
                for k, c in self.modules.items()}

    @property
    def scan_time(self) -> float:
        """One HSL scan (s) for the modules on the link (Table 4-1)."""
        return self.timing.scan_time([i for ids in self.occupied_ids().values() for i in ids])

    def command_time(self, kind: int) -> float:
        return self.timing.command_time(kind, len(self.modules))

    def charge(self, kind: int) -> float:
        """A call of command type `kind` went over the link: advance by its time."""
        dt = self.command_time(kind)
        self.calls[kind] += 1
        self.advance(dt)
        return dt

    def advance(self, dt: float) -> None:
        """Advance host time by `dt` s; every module runs the cycles that end by then."""
        self._time += check_nonnegative("dt", dt)
        ctls = tuple(self.modules.values())
        t = self._time + 1e-12
        while ctls[0].time + self.period <= t:
            for c in ctls:
                c.step()

    def run_until(self, condition: Callable[[], bool], timeout: float) -> bool:
        """Advance cycle by cycle until `condition()` holds; False after `timeout` s."""
        n = math.ceil(check_nonnegative("timeout", timeout) / self.period - 1e-9)
        for _ in range(n):
            if condition():
                return True
            self.advance(self.period)
        return bool(condition())


def network_from_config(cfg: NetworkConfig, *, speed_model: bool = True) -> Network:
    """Build a Network from a network file's config: one enabled Controller per module,
    each axis on the PCL6045 speed-register grid (`speed_model`, control.cards.speed_range) and
    counting with move ratio 1 (the machine file's move_ratio is the encoder's physical
    counts per pulse; the program sets the card's ratio with set_move_ratio)."""
    from ...config_network import NetworkConfig as _NC
    from .speed_range import attach_speed_model

    if not isinstance(cfg, _NC):
        raise MotionError(f"cfg must be a NetworkConfig, got {type(cfg).__name__}")
    modules: dict[int, Controller] = {}
    for m in cfg.modules:
        ctl = Controller(m.machine)
        ctl.enable_all()
        for ax in ctl.axes:
            # the machine's move_ratio is its physical encoder resolution; the PCL6045
            # counts with ratio 1 until told (HSL_M_set_move_ratio, 4.6)
            ax.set_move_ratio(1.0)
            if speed_model:
                attach_speed_model(ax)
        modules[m.index] = ctl
    timing = NetworkTiming(cfg.rate, cfg.duplex, scale=cfg.time_scale)
    return Network(modules, {m.index: m.slave_id for m in cfg.modules}, timing)
