"""`HslLibrary`: the HSL-4XMO library (HSL_M_* functions) on a simulated HSL network.

    from openmotion.compat.hsl import HslLibrary
    hsl = HslLibrary.from_file("line.toml")     # or HslLibrary.simulated(modules=2)
    hsl.HSL_initial(0)
    hsl.HSL_M_start_tr_move(0, 10000, 0, 1000, 0.1, 0.1)
    while hsl.HSL_M_motion_done(0):               # each call costs its wire time
        pass

Conventions, once for all functions: a command returns 0 or a negative code (errors.py);
a getter returns its value (the C out-pointer becomes the return value; several out values
a tuple) or an `HslError`; `last_error` holds the latest result and
`HSL_M_get_error_message(code)` its text. Nothing raises for bad input.
"""

from __future__ import annotations

import os
from typing import Any

from ...config_network import ModuleConfig, NetworkConfig, default_module, load_network
from ...control.cards.network import GET_U16, Network, NetworkTiming, network_from_config
from ...errors import MotionError
from .base import AXES_PER_MODULE, hsl_call
from .errors import ERR_AxisBusy, ERR_InvalidCard, ERR_InvalidParameter, Refusal, error_message
from .io import IoFunctions
from .motion import MotionFunctions

#: What HSL_M_version_info reports: hardware 1003 (4th digit > 0: arcs with acc/dec time,
#: 4.6), firmware, library (the Motion Creator screen's 409170100).
VERSION = (1003, 9, 409170100)


class HslLibrary(MotionFunctions, IoFunctions):
    """The HSL-4XMO library of one HSL master card (`card`) on `network`."""

    def __init__(self, network: Network, card: int = 0) -> None:
        super().__init__(network, card)

    # ------------------------------------------------------------------ construction
    @classmethod
    def simulated(cls, modules: int = 1, *, timing: NetworkTiming | None = None,
                  card: int = 0) -> HslLibrary:
        """`modules` default four-axis modules (pulses, free travel) at connect indices
        0.., slave IDs 1, 2, 9, 10, ... (full duplex: two interleaved modules per 8 IDs)."""
        if isinstance(modules, bool) or not isinstance(modules, int) or not 1 <= modules <= 16:
            raise MotionError(f"modules must be an integer 1..16, got {modules!r}")
        n_axes = [AXES_PER_MODULE] * modules
        if modules == 16:
            n_axes[-1] = 3  # 63 axes at most on one network (4.10)
        mods = tuple(ModuleConfig(k, 1 + (k // 2) * 8 + k % 2, default_module(f"m{k}", n))
                     for k, n in enumerate(n_axes))
        t = timing or NetworkTiming()
        cfg = NetworkConfig(mods, t.rate, t.duplex, t.scale)
        net = network_from_config(cfg)
        net.timing = t
        return cls(net, card)

    @classmethod
    def from_config(cls, cfg: NetworkConfig, card: int = 0) -> HslLibrary:
        return cls(network_from_config(cfg), card)

    @classmethod
    def from_file(cls, path: str | os.PathLike[str], card: int = 0) -> HslLibrary:
        """A library on the network a network file describes (config_network)."""
        return cls(network_from_config(load_network(path)), card)

    @property
    def network(self) -> Network:
        return self._network

    def controller(self, M_No: int) -> Any:
        """The Controller of module M_No (for scenarios, plots and tests)."""
        return self._module(M_No).ctl

    # ------------------------------------------------------------------ system
    def HSL_initial(self, card_ID: int = 0) -> int:
        """Open the master card: the network's modules become reachable."""
        if card_ID != self._card or isinstance(card_ID, bool):
            return self._fail(ERR_InvalidCard, f"HSL_initial: card_ID must be {self._card}, "
                                               f"got {card_ID!r}", 0)
        self._net = self._network
        return 0

    @hsl_call(0)
    def HSL_close(self, card_ID: int = 0) -> None:
        """Close the card: every axis stops at once, the interpolation groups close; calls
        then return ERR_NotInitial."""
        self._check_card(card_ID)
        for mod in self._modules.values():
            mod.ctl.stop_all(immediately=True)
            for g in mod.groups.values():
                g.close()
            mod.groups.clear()
        self._net = None

    @hsl_call(0)
    def HSL_get_module_count(self, card_ID: int = 0) -> int:
        """Number of HSL-4XMO modules on the card's network (ours)."""
        self._check_card(card_ID)
        return len(self._modules)

    @hsl_call(0)
    def HSL_get_connect_index(self, card_ID: int = 0) -> tuple[int, ...]:
        """The connect indices (module numbers) present, in order (ours)."""
        self._check_card(card_ID)
        return tuple(self._modules)

    @hsl_call(GET_U16)
    def HSL_connect_status(self, card_ID: int, slave_ID: int) -> int:
        """1 if a module answers on slave ID `slave_ID` (any ID it occupies), else 0."""
        self._check_card(card_ID)
        return int(any(slave_ID in ids for ids in self._network.occupied_ids().values()))

    @hsl_call(0)
    def HSL_get_scan_time(self, card_ID: int = 0) -> float:
        """One HSL scan (s) for the modules on the network (Table 4-1; ours)."""
        self._check_card(card_ID)
        return self._network.scan_time

    @hsl_call(0)
    def HSL_get_time(self, card_ID: int = 0) -> float:
        """Host (network) time in seconds (ours: virtual time since start)."""
        self._check_card(card_ID)
        return self._network.time

    @hsl_call(0)
    def HSL_M_get_axis_no(self, connect_index: int, cm: int) -> int:
        """Global axis number of connector CM1..CM4 (`cm` 0..3) of a module (Table 4-5;
        ours)."""
        mod = self._module(connect_index)
        if isinstance(cm, bool) or cm not in range(len(mod.ctl.axes)):
            raise Refusal(ERR_InvalidParameter, f"cm must be 0..{len(mod.ctl.axes) - 1} "
                          f"(CM1..CM{len(mod.ctl.axes)}), got {cm!r}")
        return connect_index * AXES_PER_MODULE + cm

    @hsl_call(0)
    def HSL_M_get_axis_location(self, axis: int) -> tuple[int, int]:
        """(connect index, cm 0..3) of a global axis number (ours)."""
        mod, ax = self._axis(axis)
        return mod.index, ax.index

    @hsl_call(GET_U16)
    def HSL_M_version_info(self, M_No: int) -> tuple[int, int, int]:
        """(hardware, firmware, library) version of a module."""
        self._module(M_No)
        return VERSION

    def HSL_M_get_error_message(self, code: int) -> str:
        """The text of a return code (the last failure's own text for an HslError)."""
        return error_message(code)

    @hsl_call(0)
    def HSL_M_config_from_file(self, filename: str | os.PathLike[str]) -> None:
        """Reload the network from a network file (openmotion's TOML, not Motion Creator's
        INI - ours); refused while any axis moves. The card stays initialised."""
        for mod in self._modules.values():
            if any(a.is_moving for a in mod.ctl.axes):
                raise Refusal(ERR_AxisBusy, "axes are moving; stop them first")
        try:
            net = network_from_config(load_network(filename))
        except OSError as e:
            raise Refusal(ERR_InvalidParameter, f"cannot read {filename!r}: {e}") from None
        for mod in self._modules.values():
            for g in mod.groups.values():
                g.close()
        self.__init__(net, self._card)  # type: ignore[misc]
        self._net = net
