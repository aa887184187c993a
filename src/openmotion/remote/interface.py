"""Interface I/O settings of an axis (Motion Creator "I/O configuration"), as the API sees
them: machine-file fields (signal logic, pulse and encoder modes, inversions, move ratio)
plus the responses (EL / ALM stop modes, ERC, SD, INP, RDY) that live in control.guard.safety.

`split_changes` checks a partial change against the rules and splits it into a new
AxisConfig (validated by the config dataclass itself) and new responses; `apply_responses`
(control.guard.responses, re-exported) puts responses on a controller. The responses and
the homing settings are saved in the machine file itself ([axes.<name>.responses],
[axes.<name>.home]: config_toml); the UI sidecar `<machine>.ui.toml` of earlier versions
is still read (`load_sidecar`) and folded into the machine file at its next save.
"""

from __future__ import annotations

import dataclasses
import os
import tempfile
import tomllib
from pathlib import Path
from typing import Any

from ..config import ENCODER_MODES, LOGIC_SIGNALS, PULSE_MODES, SIGNAL_LOGIC, AxisConfig
from ..config_toml import (
    MAX_ERC_S,
    RESPONSE_KEYS,
    SD_KEYS,
    STOP_MODES,
    check_responses,
    default_responses,
)
from ..control.guard.responses import apply_responses
from ..errors import MotionError

CONFIG_FIELDS = ("pulse_mode", "pulse_width_us", "encoder_mode", "invert_a", "invert_b",
                 "invert_z", "swap_ab", "reverse", "move_ratio")


def choices() -> dict[str, Any]:
    return {"logic": {s: list(SIGNAL_LOGIC) for s in LOGIC_SIGNALS},
            "pulse_mode": list(PULSE_MODES), "encoder_mode": list(ENCODER_MODES),
            "el": list(STOP_MODES), "alm": list(STOP_MODES),
            "pulse_width_us": [0.0, 1000.0], "erc_width_s": [0.0, MAX_ERC_S],
            "move_ratio": "> 0"}


def interface_of(cfg: AxisConfig, responses: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {"logic": {s: cfg.signal_logic(s) for s in LOGIC_SIGNALS}}
    for f in CONFIG_FIELDS:
        out[f] = getattr(cfg, f)
    out["responses"] = {k: (dict(v) if isinstance(v, dict) else v)
                        for k, v in responses.items()}
    return out


def _keys(path: str, table: Any, allowed: tuple[str, ...]) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise MotionError(f"{path} must be an object, got {table!r}")
    for k in table:
        if k not in allowed:
            raise MotionError(f"{path}.{k}: unknown key; valid keys: {', '.join(allowed)}")
    return table


def split_changes(cfg: AxisConfig, responses: dict[str, Any], changes: Any
                  ) -> tuple[AxisConfig, dict[str, Any]]:
    """The axis config and responses after `changes` (a partial interface)."""
    path = f"axes.{cfg.name}"
    _keys("changes", changes, ("logic", "responses", *CONFIG_FIELDS))
    kw: dict[str, Any] = {}
    if "logic" in changes:
        logic = _keys(f"{path}.logic", changes["logic"], LOGIC_SIGNALS)
        kw["logic"] = {**cfg.logic, **logic}
    for f in CONFIG_FIELDS:
        if f in changes:
            kw[f] = changes[f]
    new_cfg = dataclasses.replace(cfg, **kw) if kw else cfg   # validates every field
    new_resp = check_responses(f"{path}.responses", changes.get("responses", {}), responses)
    return new_cfg, new_resp


__all__ = ["CONFIG_FIELDS", "MAX_ERC_S", "RESPONSE_KEYS", "SD_KEYS", "STOP_MODES",
           "apply_responses", "atomic_write", "check_responses", "choices",
           "default_responses", "interface_of", "load_sidecar", "sidecar_path",
           "split_changes"]


# -- the UI sidecar file of earlier versions (read only) --------------------------------
def sidecar_path(machine_file: Path) -> Path:
    return machine_file.with_name(machine_file.stem + ".ui.toml")


def load_sidecar(path: Path) -> dict[str, Any]:
    """The old sidecar's tables ({"interface": {axis: responses}, "home": {axis: {...}}});
    empty when there is no file. A malformed file is a MotionError naming it."""
    if not path.is_file():
        return {"interface": {}, "home": {}}
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise MotionError(f"UI settings file {str(path)!r}: {exc}") from None
    _keys(str(path), data, ("interface", "home"))
    return {"interface": dict(data.get("interface", {})), "home": dict(data.get("home", {}))}


def atomic_write(path: Path, text: str) -> None:
    """Write `text` to `path` through a temporary file and a rename (never half a file)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
