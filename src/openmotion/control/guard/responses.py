"""A machine file's stop responses ([axes.<name>.responses]: EL / ALM stop modes, limit
check, ERC, SD, INP, RDY) put on a controller's safety layer.

One implementation for every user of the file: `openmotion run`, `open_machine` (the
script path) and the UI all call `apply_machine_responses` / `apply_responses`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ...config_toml import check_responses, default_responses
from ...errors import MotionError

if TYPE_CHECKING:
    from ..core.controller import Controller


def _safety(ctl: Controller) -> Any:
    if ctl.safety is None:
        raise MotionError("the controller has no safety layer (built with safety=False): "
                          "the machine file's responses cannot be applied")
    return ctl.safety


def apply_responses(ctl: Controller, axis: int, r: dict[str, Any]) -> None:
    """Put the full, checked responses `r` of axis index `axis` on `ctl.safety`."""
    safety = _safety(ctl)
    safety.set_el(axis, r["el"])
    safety.set_limit_check(axis, r["el_enabled"], direction_sensitive=r["el_direction_sensitive"])
    safety.set_alm(axis, r["alm"])
    safety.set_erc(axis, r["erc_width_s"])
    safety.set_sd(axis, r["sd"]["enabled"], latched=r["sd"]["latched"], stop=r["sd"]["stop"])
    safety.set_inp(axis, r["inp"])
    safety.set_rdy_check(axis, r["rdy"])


def apply_machine_responses(ctl: Controller, responses: dict[str, Any]) -> None:
    """Apply per-axis responses {axis name: responses (partial tables allowed: the rest
    are the defaults)}, e.g. from config_toml.load_machine_settings. Everything is checked
    first (names, keys, values: a MotionError naming `axes.<name>.responses.<key>`), so a
    refusal leaves the controller as it was. Axes not named keep their responses. On a
controller without a safety layer (safety=False) only the defaults are accepted."""
    if not isinstance(responses, dict):
        raise MotionError(f"responses must be a dict of axis name -> table, got {responses!r}")
    names = {ax.name: ax.index for ax in ctl.axes}
    checked = {}
    for name, table in responses.items():
        if name not in names:
            raise MotionError(f"axes.{name}.responses: the controller has no axis {name!r}; "
                              f"axes: {', '.join(names)}")
        checked[names[name]] = check_responses(f"axes.{name}.responses", table,
                                               default_responses())
    if ctl.safety is None and all(r == default_responses() for r in checked.values()):
        return   # nothing to put on a controller built with safety=False
    _safety(ctl)
    for index, r in checked.items():
        apply_responses(ctl, index, r)
