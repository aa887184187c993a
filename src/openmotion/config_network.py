"""Network files: several motion modules on one HSL link, each with its own machine section.

Layout (TOML):

    [network]                 # optional; the defaults shown
    rate = "6M"               # 3M, 6M, 12M (JP1)
    duplex = "full"           # full or half (JP2-3)
    time_scale = 1.0          # multiplies every command time (0: network time off)

    [modules.0]               # connect index 0 (global axes 0..3)
    slave_id = 1              # start ID (S1 switch)
    name = "xy-table"         # ...then everything a machine file has: cycle_s, axes...
    [modules.0.axes.x]
    unit = "pulse"

Each module's table is a machine file (openmotion.config_toml) plus `slave_id`. Rules
(HSL-4XMO 2.11, 4.3, 4.10): connect indices 0..15, at most 4 axes a module, at most 63 axes
on the link, slave IDs 1..63 that do not overlap: axis k of a module occupies start + 2k in
full duplex, start + k in half duplex (a module of 4 axes: start, +2, +4, +6 or
start..start+3). 63 IDs hold 63 axes: a 16th module has 3 (its 4th ID would be 64).
`default_module(name)` is a four-axis module in pulses with free travel.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.config_toml import _check_keys, _table, machine_from_dict
from openmotion.errors import MotionError, check_int

__all__ = ["MAX_AXES", "MAX_MODULES", "ModuleConfig", "NetworkConfig", "default_module",
           "load_network", "loads_network", "network_from_dict"]

MAX_MODULES = 16
MAX_AXES = 63
AXES_PER_MODULE = 4
_NET_KEYS = ("rate", "duplex", "time_scale")


@dataclass(frozen=True)
class ModuleConfig:
    """One HSL-4XMO: its connect index (0..15), start slave ID and machine section."""

    index: int
    slave_id: int
    machine: MachineConfig

    def __post_init__(self) -> None:
        check_int("modules connect index", self.index, 0, MAX_MODULES - 1)
        check_int(f"modules.{self.index}.slave_id", self.slave_id, 1, 63)
        if not isinstance(self.machine, MachineConfig):
            raise MotionError(f"modules.{self.index}.machine must be a MachineConfig")
        n = len(self.machine.axes)
        if not 1 <= n <= AXES_PER_MODULE:
            raise MotionError(f"modules.{self.index} must have 1..{AXES_PER_MODULE} axes, "
                              f"has {n}")

    def ids(self, duplex: str) -> tuple[int, ...]:
        """The slave IDs the module's axes occupy (one per axis)."""
        step = 2 if duplex == "full" else 1
        return tuple(self.slave_id + k * step for k in range(len(self.machine.axes)))


@dataclass(frozen=True)
class NetworkConfig:
    """The modules of one link and its rate/duplex/time scale."""

    modules: tuple[ModuleConfig, ...]
    rate: str = "6M"
    duplex: str = "full"
    time_scale: float = 1.0

    def __post_init__(self) -> None:
        from openmotion.control.cards.network import NetworkTiming

        NetworkTiming(self.rate, self.duplex, scale=self.time_scale)  # validates the three
        mods = tuple(self.modules)
        if not 1 <= len(mods) <= MAX_MODULES:
            raise MotionError(f"modules must list 1..{MAX_MODULES} modules, got {len(mods)}")
        seen: dict[int, int] = {}
        idx: set[int] = set()
        for m in mods:
            if not isinstance(m, ModuleConfig):
                raise MotionError(f"modules must be ModuleConfig, got {m!r}")
            if m.index in idx:
                raise MotionError(f"modules.{m.index}: connect index used twice")
            idx.add(m.index)
            for i in m.ids(self.duplex):
                if i > 63:
                    raise MotionError(f"modules.{m.index}.slave_id {m.slave_id} occupies ID "
                                      f"{i} > 63 in {self.duplex} duplex")
                if i in seen:
                    raise MotionError(f"modules.{m.index}.slave_id {m.slave_id} occupies ID "
                                      f"{i}, already used by module {seen[i]}")
                seen[i] = m.index
        total = sum(len(m.machine.axes) for m in mods)
        if total > MAX_AXES:
            raise MotionError(f"a network holds at most {MAX_AXES} axes, these modules have "
                              f"{total}")
        object.__setattr__(self, "modules", tuple(sorted(mods, key=lambda m: m.index)))


def default_module(name: str = "hsl4xmo", n_axes: int = AXES_PER_MODULE) -> MachineConfig:
    """A module of `n_axes` axes in pulses (10000 pulses/rev steppers), no switches, up to
    the 6.55 Mpps pulse output."""
    check_int("n_axes", n_axes, 1, AXES_PER_MODULE)
    axes = tuple(AxisConfig(name=f"cm{k + 1}", unit="pulse", max_speed=6.55e6,
                            drive=DriveConfig(type="ideal_stepper"))
                 for k in range(n_axes))
    return MachineConfig(name=name, axes=axes)


def network_from_dict(data: dict[str, Any]) -> NetworkConfig:
    """A NetworkConfig from the parsed layout (module docstring)."""
    _table("network file", data)
    _check_keys("", data, ("network", "modules"))
    net = _table("network", data.get("network", {}))
    _check_keys("network", net, _NET_KEYS)
    mods_t = _table("modules", data.get("modules", {}))
    mods = []
    for key, sec in mods_t.items():
        path = f"modules.{key}"
        if not str(key).isdigit():
            raise MotionError(f"{path}: the key must be the connect index 0..15")
        sec = dict(_table(path, sec))
        if "slave_id" not in sec:
            raise MotionError(f"{path}.slave_id is required")
        sid = sec.pop("slave_id")
        try:
            machine = machine_from_dict(sec)
        except MotionError as e:
            raise MotionError(f"{path}: {e}") from None
        mods.append(ModuleConfig(int(key), sid, machine))
    return NetworkConfig(tuple(mods), **net)


def loads_network(text: str) -> NetworkConfig:
    """Parse and validate a network file from TOML text."""
    import tomllib

    if not isinstance(text, str):
        raise MotionError(f"text must be a str, got {type(text).__name__}")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise MotionError(f"network file is not valid TOML: {e}") from None
    return network_from_dict(data)


def load_network(path: str | os.PathLike[str]) -> NetworkConfig:
    """Read, parse and validate a network file."""
    if not isinstance(path, (str, os.PathLike)):
        raise MotionError(f"path must be a str or path, got {path!r}")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    try:
        return loads_network(text)
    except MotionError as e:
        raise MotionError(f"{os.fspath(path)}: {e}") from None
