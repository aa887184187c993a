"""A machine file to a controller that obeys all of it: the mechanism (MachineConfig) and
the per-axis tables [axes.<name>.responses] (stop responses, put on the safety layer) and
[axes.<name>.home] (homing settings, checked against the mode rules and returned as
HomeConfigs). `openmotion run`, `openmotion config` and scripts (`open_machine`) use this
module; the UI uses the same control-layer functions (control.guard.responses,
control.home.homeconf).
"""

from __future__ import annotations

import os
from typing import Any

from .config import MachineConfig
from .config_toml import loads_machine, loads_machine_settings, read_machine_text
from .control import Controller, HomeConfig
from .control.guard.responses import apply_machine_responses
from .control.home.homeconf import home_configs
from .errors import MotionError

Settings = dict[str, dict[str, Any]]


def read_machine_file(path: str | os.PathLike[str], what: str = "machine file"
                      ) -> tuple[MachineConfig, Settings]:
    """The machine and its per-axis settings ({axis: {"responses", "home"}}) from one read
    of `path`; every failure is a MotionError naming `what` and the file (a bad table names
    its key, e.g. `axes.x.responses.el`)."""
    text = read_machine_text(path, what)
    try:
        return loads_machine(text), loads_machine_settings(text)
    except MotionError as e:
        raise MotionError(f"{os.fspath(path)}: {e}") from None


def apply_machine_settings(ctl: Controller, settings: Settings) -> dict[str, HomeConfig]:
    """Put the settings' stop responses on `ctl` and return a HomeConfig per axis (the home
    table applied to the default). Everything is checked before anything changes: a bad
    table is a MotionError naming `axes.<name>.responses…` / `axes.<name>.home` and leaves
    `ctl` as it was. Axes of `ctl` the settings do not name keep the defaults."""
    if not isinstance(settings, dict):
        raise MotionError(f"settings must be a dict of axis name -> tables, got {settings!r}")
    for name, s in settings.items():
        if not isinstance(s, dict) or not set(s) <= {"responses", "home"}:
            raise MotionError(f"settings[{name!r}] must be a dict with 'responses' and/or "
                              f"'home', got {s!r}")
    homes = home_configs(ctl, {n: s.get("home") or {} for n, s in settings.items()})
    apply_machine_responses(ctl, {n: s.get("responses") or {} for n, s in settings.items()})
    return homes


def check_machine_settings(cfg: MachineConfig, settings: Settings) -> dict[str, HomeConfig]:
    """The checks `apply_machine_settings` makes, on a throw-away simulated controller of
    `cfg` (what `openmotion config` reports)."""
    return apply_machine_settings(Controller(cfg), settings)


def open_machine(path: str | os.PathLike[str], **controller_options: Any) -> Controller:
    """A Controller of the machine file `path` (simulated unless `hardware=` is given;
    other keywords as Controller) with the file's stop responses applied and its home
    tables checked; `ctl.home_settings` holds the HomeConfig per axis name (for
    `control.Homing(ctl, axis, ctl.home_settings[name])`)."""
    cfg, settings = read_machine_file(path)
    ctl = Controller(cfg, **controller_options)
    try:
        homes = apply_machine_settings(ctl, settings)
    except MotionError as e:
        raise MotionError(f"{os.fspath(path)}: {e}") from None
    ctl.home_settings = homes
    return ctl


__all__ = ["apply_machine_settings", "check_machine_settings", "open_machine",
           "read_machine_file"]
