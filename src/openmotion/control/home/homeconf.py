"""Homing settings in the API's user units <-> control.home.homing_modes.HomeConfig (pulses).

The API shows speeds in user units/s and offsets in user units; HomeConfig holds pps and
pulses. `home_from_user` builds (and so validates) a HomeConfig; `home_to_user` is its
inverse; `sequence` lists the phases of a mode for the front end's drawing;
`home_configs` turns a machine file's [axes.<name>.home] tables into HomeConfigs (the one
check of their mode rules: the UI, `openmotion config` / `run` and `open_machine` use it).
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any

from ...errors import MotionError
from .homing_modes import EL_STOPS, FINALS, HSL_MODES, MCCL_TYPES, HomeConfig

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller

USER_KEYS = ("mode", "direction", "str_vel", "max_vel", "tacc", "tdec", "ez_count",
             "org_offset", "home_offset", "final", "el_stop", "auto_search", "timeout_s")
MODES: list[int | str] = [*HSL_MODES, *(f"mccl_{k}" for k in MCCL_TYPES)]


def default_home(ax: Axis) -> HomeConfig:
    """Home towards -1 on ORG (mode 0) at 2 % / 20 % of the axis's maximum safe speed."""
    vmax = ax.units.max_speed_pps
    return HomeConfig(mode=0, direction=-1, str_vel=vmax * 0.02, max_vel=vmax * 0.2, tacc=0.1)


def home_to_user(ax: Axis, c: HomeConfig) -> dict[str, Any]:
    ppu = ax.units.pulses_per_unit
    return {"mode": c.mode, "direction": c.direction, "str_vel": c.str_vel / ppu,
            "max_vel": c.max_vel / ppu, "tacc": c.tacc,
            "tdec": c.tacc if c.tdec is None else c.tdec, "ez_count": c.ez_count,
            "org_offset": c.org_offset / ppu,
            "home_offset": float(ax.units.to_units(c.home_offset)), "final": c.final,
            "el_stop": c.el_stop, "auto_search": c.auto_search, "timeout_s": c.timeout_s}


def home_from_user(ax: Axis, old: HomeConfig, changes: Any) -> HomeConfig:
    """`old` with `changes` (user units) applied; MotionError naming the key otherwise."""
    if not isinstance(changes, dict):
        raise MotionError(f"changes must be an object, got {changes!r}")
    for k in changes:
        if k not in USER_KEYS:
            raise MotionError(f"changes.{k}: unknown key; valid keys: {', '.join(USER_KEYS)}")
    ppu = ax.units.pulses_per_unit
    kw: dict[str, Any] = {}
    for k, v in changes.items():
        if k in ("str_vel", "max_vel", "org_offset"):
            kw[k] = _num(k, v) * ppu
        elif k == "home_offset":
            kw[k] = float(round(float(ax.units.to_pulses(_num(k, v)))))
        else:
            kw[k] = v
    for name in ("str_vel", "max_vel"):
        if name in kw:   # the axis's maximum safe speed, refused in the user's units
            ax.check_speed(name, _num(name, changes[name]), units=True)
    try:
        return dataclasses.replace(old, **kw)   # HomeConfig checks every field (pulses)
    except MotionError as exc:
        passed = {k: kw.get(k, getattr(old, k)) for k in _PULSE_KEYS}
        raise MotionError(_in_user_units(str(exc), ax, passed)) from None


def home_configs(ctl: Controller, tables: dict[str, Any]) -> dict[str, HomeConfig]:
    """A HomeConfig per axis of `ctl`: `default_home` with the axis's home table (user
    units, `tables[name]`, as config_toml.machine_settings_from_dict gives it) applied. A
    table breaking a mode rule (mode, speed order, ranges) is a MotionError naming
    `axes.<name>.home`; axes without a table get the default."""
    if not isinstance(tables, dict):
        raise MotionError(f"home tables must be a dict of axis name -> table, got {tables!r}")
    out: dict[str, HomeConfig] = {}
    for ax in ctl.axes:
        base = default_home(ax)
        user = tables.get(ax.name)
        try:
            out[ax.name] = home_from_user(ax, base, user) if user else base
        except MotionError as exc:
            raise MotionError(f"axes.{ax.name}.home: {exc}") from None
    return out


#: HomeConfig fields held in pulses (speeds in pps): the API gives them in user units.
_PULSE_KEYS = ("str_vel", "max_vel", "org_offset", "home_offset")


def _in_user_units(message: str, ax: Axis, pulses: dict[str, Any]) -> str:
    """HomeConfig's refusal quotes the pulse values this module passed it: put back the
    user-unit values they came from (each value quoted as repr, as HomeConfig does)."""
    ppu, unit = ax.units.pulses_per_unit, ax.units.unit
    for k, v in pulses.items():
        if not isinstance(v, (int, float)) or isinstance(v, bool) or v == 0:
            continue
        user = float(ax.units.to_units(v)) if k == "home_offset" else v / ppu
        text = f"{user:.6g} {unit}/s" if k in ("str_vel", "max_vel") else f"{user:.6g} {unit}"
        message = message.replace(repr(v), text)
    return message


def _num(name: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise MotionError(f"{name} must be a number, got {v!r}")
    return float(v)


def choices() -> dict[str, Any]:
    return {"mode": MODES, "direction": [1, -1], "final": list(FINALS),
            "el_stop": list(EL_STOPS), "ez_count": [0, 15]}


def sequence(ax: Axis, c: HomeConfig) -> list[dict[str, Any]]:
    """The phases of the selected mode: what the front end draws."""
    ppu = ax.units.pulses_per_unit
    out = []
    for ph in c.phases():
        out.append({"phase": ph.name, "signal": ph.signal, "edge": ph.edge,
                    "direction": ph.direction * c.direction,
                    "speed": c.speed(ph.speed) / ppu, "reaction": ph.then,
                    "mark": ph.mark})
    return out
