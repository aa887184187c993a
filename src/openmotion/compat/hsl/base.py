"""The HSL library's plumbing: cards, modules, axis numbers, the call wrapper.

Addressing (HSL-4XMO 4.10, Table 4-5): a card (the HSL master, `card_ID`) drives one
network; module k (connect index k, 0..15) holds the global axis numbers 4k .. 4k+3
(CM1..CM4); at most 63 axes, so axis 63 never exists. Functions of one axis take the global
axis number, functions of a module (`_move_xy`, `_arc_xy`, `_line4`) take the module
number `M_No` (the connect index), `_line2/3` and `_arc2` an array of axis numbers of one
module.

Every public call goes through `hsl_call(kind)`: the core does the work (a refusal raises
MotionError and changes nothing), the network then charges the call's command time of
type `kind` (Table 6-1/6-2; 0 = the host library alone, no packet), and the result is 0,
the getter's value, or an `HslError` (negative code + message; argument errors the host
library finds are not charged, the packet is never sent).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import wraps
from typing import TYPE_CHECKING, Any, TypeVar

from ...errors import MotionError
from .errors import (
    HOST_SIDE,
    ERR_InvalidAxis,
    ERR_InvalidCard,
    ERR_InvalidModule,
    ERR_InvalidParameter,
    ERR_NoError,
    ERR_NotInitial,
    HslError,
    Refusal,
    classify,
)

if TYPE_CHECKING:
    from ...control.cards.network import Network
    from ...control.core.axis import Axis
    from ...control.core.controller import Controller
    from ...control.groups.group import Group
    from ...control.home.homing import Homing
    from ...control.home.latch import Latch
    from ...control.loops.compensation import Compensation
    from ...control.trigger.hsl_trigger import HslTrigger

F = TypeVar("F", bound=Callable[..., Any])
AXES_PER_MODULE = 4
MAX_AXIS_NO = 62


@dataclass
class Module:
    """What the library keeps for one module: its controller and the core objects it
    created on demand (trigger comparator, latch, compensation, groups, homing)."""

    index: int
    ctl: Controller
    trigger: HslTrigger | None = None
    latch: Latch | None = None
    comp: dict[int, Compensation] = field(default_factory=dict)
    groups: dict[tuple[int, ...], Group] = field(default_factory=dict)
    home: dict[int, dict[str, Any]] = field(default_factory=dict)
    homing: dict[int, Homing] = field(default_factory=dict)
    simple: dict[int, dict[str, float]] = field(default_factory=dict)


def hsl_call(kind: int) -> Callable[[F], F]:
    """Wrap a library function: not-initialised check, core refusals to codes, network
    time charged for command type `kind` (0: none)."""

    def deco(fn: F) -> F:
        @wraps(fn)
        def wrapper(self: HslBase, *args: Any, **kwargs: Any) -> Any:
            if self._net is None:
                return self._fail(ERR_NotInitial, f"{fn.__name__}: call HSL_initial first",
                                  0)
            try:
                result = fn(self, *args, **kwargs)
            except Refusal as e:
                return self._fail(e.code, f"{fn.__name__}: {e.message}", kind)
            except MotionError as e:
                return self._fail(classify(e), f"{fn.__name__}: {e}", kind)
            except (TypeError, ValueError, ArithmeticError) as e:
                # an argument of a type no C caller could pass (a list for a number...):
                # the library's contract is a code, never an exception
                return self._fail(ERR_InvalidParameter, f"{fn.__name__}: invalid argument "
                                  f"({type(e).__name__}: {e})", 0)
            if kind:
                self._net.charge(kind)
            self.last_error = HslError(ERR_NoError)
            return 0 if result is None else result

        wrapper.hsl_kind = kind  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return deco


class HslBase:
    """State and addressing shared by the function groups (see HslLibrary)."""

    def __init__(self, network: Network, card: int = 0) -> None:
        from ...control.cards.network import Network

        if not isinstance(network, Network):
            raise MotionError(f"network must be a Network, got {type(network).__name__}")
        self._network = network
        self._card = card
        self._net: Network | None = None
        self._modules = {k: Module(k, c) for k, c in network.modules.items()}
        self.last_error = HslError(ERR_NoError)

    # ------------------------------------------------------------------ results
    def _fail(self, code: int, message: str, kind: int) -> HslError:
        if kind and code not in HOST_SIDE and self._net is not None:
            self._net.charge(kind)  # the module answered the refusal
        err = HslError(code, message)
        self.last_error = err
        return err

    # ------------------------------------------------------------------ addressing
    def _check_card(self, card_ID: int) -> None:
        if card_ID != self._card or isinstance(card_ID, bool):
            raise Refusal(ERR_InvalidCard, f"card_ID must be {self._card}, got {card_ID!r}")

    def _module(self, m_no: int) -> Module:
        if isinstance(m_no, bool) or not isinstance(m_no, int) or m_no not in self._modules:
            raise Refusal(ERR_InvalidModule, f"M_No must be one of "
                          f"{sorted(self._modules)} (connect index), got {m_no!r}")
        return self._modules[m_no]

    def _axis(self, axis_no: int) -> tuple[Module, Axis]:
        if isinstance(axis_no, bool) or not isinstance(axis_no, int) \
                or not 0 <= axis_no <= MAX_AXIS_NO:
            raise Refusal(ERR_InvalidAxis, f"axis must be an integer 0..{MAX_AXIS_NO}, got "
                          f"{axis_no!r}")
        k, cm = divmod(axis_no, AXES_PER_MODULE)
        mod = self._modules.get(k)
        if mod is None or cm >= len(mod.ctl.axes):
            raise Refusal(ERR_InvalidAxis, f"axis {axis_no} (module {k}, CM{cm + 1}) is not "
                          "on the network")
        return mod, mod.ctl.axes[cm]

    def _axes(self, axis_array: Any, n: int) -> tuple[Module, tuple[int, ...]]:
        """An array of `n` axis numbers of one module -> (module, local indices)."""
        try:
            items = list(axis_array)
        except TypeError:
            raise Refusal(ERR_InvalidParameter, f"AxisArray must be a sequence of {n} axis "
                          f"numbers, got {axis_array!r}") from None
        if len(items) != n:
            raise Refusal(ERR_InvalidParameter, f"AxisArray must hold {n} axis numbers, got "
                          f"{len(items)}")
        found = [self._axis(a) for a in items]
        mods = {m.index for m, _ in found}
        if len(mods) != 1:
            raise Refusal(ERR_InvalidAxis, f"AxisArray {items} must name axes of one module")
        local = tuple(a.index for _, a in found)
        if len(set(local)) != n:
            raise Refusal(ERR_InvalidParameter, f"AxisArray {items} names an axis twice")
        return found[0][0], local
