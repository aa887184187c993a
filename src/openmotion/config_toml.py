"""Machine files: TOML text <-> MachineConfig, with unknown-key (typo) detection.

Layout: top-level name / cycle_s / digital_inputs / digital_outputs, then one [axes.<name>]
table per axis in controller order, with nested [axes.<name>.logic], [axes.<name>.drive]
(and [axes.<name>.drive.motor]), [axes.<name>.loop] and [axes.<name>.pel|mel|org|sd].
Two more tables per axis hold what a commissioning tool sets up (Motion Creator's I/O and
home dialogs): [axes.<name>.responses] (end-limit / alarm stop modes, ERC, SD, INP, RDY)
and [axes.<name>.home] (homing settings in user units). They are not part of MachineConfig
(the mechanism); `machine_settings_from_dict` / `loads_machine_settings` /
`load_machine_settings` read them and `dumps_machine(cfg, settings)` writes them;
openmotion.machine_file applies them to a controller (open_machine, run, config).
Every key is checked: an unknown key is an error naming it. Switch position / width /
hysteresis are written in the axis's USER units in the file (a person measures switches in
mm or degrees) and converted to command pulses on load, back on save; `reverse` flips the
sign of position and width. Every name here is also importable from openmotion.config.
"""

from __future__ import annotations

import math
import os
from dataclasses import replace
from typing import Any, TypeVar

from openmotion.config import (
    SWITCHES,
    AxisConfig,
    DCMotorConfig,
    DriveConfig,
    LoopConfig,
    MachineConfig,
    SwitchConfig,
    _real,
)
from openmotion.errors import MotionError

__all__ = ["HOME_KEYS", "RESPONSE_KEYS", "check_home_table", "check_responses",
           "default_responses", "dumps_machine", "load_machine", "load_machine_settings",
           "loads_machine", "loads_machine_settings", "machine_from_dict", "read_machine_text",
           "machine_settings_from_dict", "machine_to_dict", "save_machine"]

_TOP_KEYS = ("name", "cycle_s", "digital_inputs", "digital_outputs", "axes")
_AXIS_TABLES = ("logic", "drive", "loop") + SWITCHES
_SETTING_TABLES = ("responses", "home")
_CONFIG_KEYS = tuple(f for f in AxisConfig.__dataclass_fields__ if f != "name")
_AXIS_KEYS = _CONFIG_KEYS + _SETTING_TABLES
_AXIS_SCALARS = tuple(k for k in _CONFIG_KEYS if k not in _AXIS_TABLES)
_DRIVE_KEYS = tuple(DriveConfig.__dataclass_fields__)
_SWITCH_KEYS = tuple(SwitchConfig.__dataclass_fields__)
_MOTOR_KEYS = tuple(DCMotorConfig.__dataclass_fields__)
_LOOP_KEYS = tuple(LoopConfig.__dataclass_fields__)

_T = TypeVar("_T")

_HEADER = """\
# openmotion machine file. Lengths and speeds are in each axis's user unit (`unit`);
# switch position/width/hysteresis too (converted to command pulses on load).
"""


def _check_keys(path: str, table: dict[str, Any], allowed: tuple[str, ...]) -> None:
    import difflib

    for key in table:
        if key not in allowed:
            where = f"{path}.{key}" if path else key
            close = difflib.get_close_matches(key, allowed, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            note = " (the axis name is its table key)" if key == "name" and path else ""
            raise MotionError(f"{where}: unknown key{note}; {hint}valid keys: "
                              f"{', '.join(allowed)}")


def _table(path: str, value: Any) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise MotionError(f"{path} must be a table, got {value!r}")
    return value


def _rebased(err: MotionError, local: str, path: str) -> MotionError:
    """Re-prefix a message from a standalone validate("drive"/"switch") with the file path."""
    msg = str(err)
    return MotionError(path + msg[len(local):] if msg.startswith(local + ".") else msg)


def _exact_units(p: float, scale: float) -> float:
    """The user-unit value to write for pulses p: one with u * scale == p exactly when such
    a float exists (tidier files); otherwise p / scale, and the 1e-6 pulse grid of
    SwitchConfig absorbs the last-bit error on load."""
    u = p / scale
    for direction in (math.inf, -math.inf):
        c = u
        for _ in range(4):
            if c * scale == p:
                return c + 0.0  # +0.0 turns -0.0 into 0.0 for a tidy file
            c = math.nextafter(c, direction)
    return u + 0.0


def _section(path: str, value: Any, cls: type[_T], keys: tuple[str, ...], local: str,
             extra: dict[str, Any] | None = None) -> _T:
    """The config object `cls` of the table at `path` (unknown keys refused, `extra`
    replacing entries); `local` is the prefix cls's own messages use, e.g. "drive"."""
    table = _table(path, value)
    _check_keys(path, table, keys)
    try:
        return cls(**{**table, **(extra or {})})
    except MotionError as e:
        raise _rebased(e, local, path) from None


def _axis_from_toml(name: str, data: dict[str, Any]) -> AxisConfig:
    path = f"axes.{name}"
    _table(path, data)
    _check_keys(path, data, _AXIS_KEYS)
    kw = {k: data[k] for k in _AXIS_SCALARS if k in data}
    if "logic" in data:
        kw["logic"] = _table(f"{path}.logic", data["logic"])
    if "drive" in data:
        dp = f"{path}.drive"
        drive = _table(dp, data["drive"])
        _check_keys(dp, drive, _DRIVE_KEYS)  # the drive's own typos before its motor's
        extra = {}
        if "motor" in drive:
            extra["motor"] = _section(f"{dp}.motor", drive["motor"], DCMotorConfig,
                                      _MOTOR_KEYS, "motor")
        kw["drive"] = _section(dp, drive, DriveConfig, _DRIVE_KEYS, "drive", extra)
    if "loop" in data:
        kw["loop"] = _section(f"{path}.loop", data["loop"], LoopConfig, _LOOP_KEYS, "loop")
    if not name.isidentifier():
        raise MotionError(f"axes name must be an identifier (letters, digits, _), got {name!r}")
    base = AxisConfig(name=name, **kw)   # validates the mechanism before we use its scale
    scale = base.pulses_per_unit
    sign = -1.0 if base.reverse else 1.0
    switches = {}
    for sw in SWITCHES:
        if sw not in data:
            continue
        sp = f"{path}.{sw}"
        t = _table(sp, data[sw])
        _check_keys(sp, t, _SWITCH_KEYS)
        if "position" not in t:
            raise MotionError(f"{sp}.position is required")
        vals = {k: _real(f"{sp}.{k}", v) for k, v in t.items()}
        conv = {"position": vals["position"] * sign * scale}
        if "width" in vals:
            conv["width"] = vals["width"] * sign * scale
        if "hysteresis" in vals:
            conv["hysteresis"] = vals["hysteresis"] * scale
        try:
            switches[sw] = SwitchConfig(**conv)
        except MotionError as e:
            raise _rebased(e, "switch", sp) from None
    if not switches:
        return base
    return replace(base, **switches)


# -- [axes.<name>.responses] and [axes.<name>.home] -------------------------------------
RESPONSE_KEYS = ("el", "el_enabled", "el_direction_sensitive", "alm", "erc_width_s", "sd",
                 "inp", "rdy")
SD_KEYS = ("enabled", "latched", "stop")
STOP_MODES = ("immediate", "decel")
MAX_ERC_S = 1.0
#: homing settings in the axis's user units (speeds unit/s, offsets unit, times s)
HOME_KEYS = ("mode", "direction", "str_vel", "max_vel", "tacc", "tdec", "ez_count",
             "org_offset", "home_offset", "final", "el_stop", "auto_search", "timeout_s")
_HOME_NUMBERS = ("str_vel", "max_vel", "tacc", "tdec", "org_offset", "home_offset",
                 "timeout_s")


def default_responses() -> dict[str, Any]:
    """The responses of an axis nobody configured (the HSL power-on defaults)."""
    return {"el": "immediate", "el_enabled": True, "el_direction_sensitive": True,
            "alm": "immediate", "erc_width_s": 0.0,
            "sd": {"enabled": False, "latched": False, "stop": False},
            "inp": False, "rdy": False}


def _bool(path: str, v: Any) -> bool:
    if not isinstance(v, bool):
        raise MotionError(f"{path} must be true or false, got {v!r}")
    return v


def _known(path: str, table: Any, allowed: tuple[str, ...]) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise MotionError(f"{path} must be a table, got {table!r}")
    _check_keys(path, table, allowed)
    return table


def check_responses(path: str, changes: Any, old: dict[str, Any]) -> dict[str, Any]:
    """`old` with `changes` applied, every value checked (messages name `path.key`)."""
    _known(path, changes, RESPONSE_KEYS)
    new = {k: (dict(v) if isinstance(v, dict) else v) for k, v in old.items()}
    for k, v in changes.items():
        p = f"{path}.{k}"
        if k in ("el", "alm"):
            if v not in STOP_MODES:
                raise MotionError(f"{p} must be one of {', '.join(STOP_MODES)}; got {v!r}")
            new[k] = v
        elif k == "erc_width_s":
            if isinstance(v, bool) or not isinstance(v, (int, float)) or \
                    not 0.0 <= v <= MAX_ERC_S:
                raise MotionError(f"{p} must be a number in [0, {MAX_ERC_S:g}] s "
                                  f"(0 = no ERC pulse), got {v!r}")
            new[k] = float(v)
        elif k == "sd":
            _known(p, v, SD_KEYS)
            new["sd"] = {**new["sd"], **{s: _bool(f"{p}.{s}", x) for s, x in v.items()}}
        else:
            new[k] = _bool(p, v)
    return new


def check_home_table(path: str, table: Any) -> dict[str, Any]:
    """The keys and value types of a home table (user units). The rules that need the
    homing model and the axis (mode numbers, speed order, ranges) are checked by
    `openmotion.control.home.homeconf.home_configs` (config, run, open_machine, the UI)."""
    _known(path, table, HOME_KEYS)
    out: dict[str, Any] = {}
    for k, v in table.items():
        p = f"{path}.{k}"
        if k in _HOME_NUMBERS:
            out[k] = _real(p, v)
        elif k in ("direction", "ez_count"):
            if isinstance(v, bool) or not isinstance(v, int):
                raise MotionError(f"{p} must be an integer, got {v!r}")
            out[k] = v
        elif k == "auto_search":
            out[k] = _bool(p, v)
        elif k == "mode":
            if isinstance(v, bool) or not isinstance(v, (int, str)):
                raise MotionError(f"{p} must be a mode number 0..12 or an mccl_* name, "
                                  f"got {v!r}")
            out[k] = v
        else:   # final, el_stop
            if not isinstance(v, str):
                raise MotionError(f"{p} must be a string, got {v!r}")
            out[k] = v
    return out


def machine_settings_from_dict(data: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Per axis {"responses": full responses, "home": the home table as written (may be
    empty)} from the parsed layout; axes without the tables get the defaults."""
    _table("machine file", data)
    out: dict[str, dict[str, Any]] = {}
    for name, a in _table("axes", data.get("axes", {})).items():
        a = _table(f"axes.{name}", a)
        resp = check_responses(f"axes.{name}.responses", a.get("responses", {}),
                               default_responses())
        home = check_home_table(f"axes.{name}.home", a.get("home", {}))
        out[str(name)] = {"responses": resp, "home": home}
    return out


def loads_machine_settings(text: str) -> dict[str, dict[str, Any]]:
    """The responses and home tables of machine-file text (see machine_settings_from_dict);
    the machine part is validated too (loads_machine)."""
    import tomllib

    cfg = loads_machine(text)
    data = tomllib.loads(text)
    settings = machine_settings_from_dict(data)
    return {a.name: settings[a.name] for a in cfg.axes}


def read_machine_text(path: str | os.PathLike[str], what: str = "machine file") -> str:
    """The text of a machine file; a file that cannot be read is a MotionError naming
    `what`, the file and the cause (no such file, a folder, not UTF-8, permission)."""
    if not isinstance(path, (str, os.PathLike)):
        raise MotionError(f"{what} must be a str or path, got {path!r}")
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except FileNotFoundError:
        raise MotionError(f"{what} {os.fspath(path)!r}: no such file") from None
    except IsADirectoryError:
        raise MotionError(f"{what} {os.fspath(path)!r} is a folder, not a TOML machine "
                          "file") from None
    except OSError as exc:
        raise MotionError(f"{what} {os.fspath(path)!r}: cannot read "
                          f"({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise MotionError(f"{what} {os.fspath(path)!r} is not a UTF-8 TOML text file") from None


def load_machine_settings(path: str | os.PathLike[str]) -> dict[str, dict[str, Any]]:
    """Read a machine file's responses and home tables (MotionError if it cannot be read
    or a table is bad)."""
    text = read_machine_text(path)
    try:
        return loads_machine_settings(text)
    except MotionError as e:
        raise MotionError(f"{os.fspath(path)}: {e}") from None


def _settings_tables(name: str, settings: dict[str, dict[str, Any]] | None
                     ) -> dict[str, Any]:
    """The responses / home tables to write for axis `name` (defaults left out)."""
    if not settings or name not in settings:
        return {}
    s = _known(f"settings.{name}", settings[name], _SETTING_TABLES)
    out: dict[str, Any] = {}
    resp = check_responses(f"axes.{name}.responses", s.get("responses", {}),
                           default_responses())
    if resp != default_responses():
        out["responses"] = resp
    home = check_home_table(f"axes.{name}.home", s.get("home", {}))
    if home:
        out["home"] = home
    return out


def machine_from_dict(data: dict[str, Any]) -> MachineConfig:
    """Build a MachineConfig from the parsed TOML layout (see the module docstring)."""
    _table("machine file", data)
    _check_keys("", data, _TOP_KEYS)
    axes_t = _table("axes", data.get("axes", {}))
    axes = tuple(_axis_from_toml(str(n), a) for n, a in axes_t.items())
    kw = {k: data[k] for k in _TOP_KEYS[:-1] if k in data}
    cfg = MachineConfig(axes=axes, **kw)
    machine_settings_from_dict(data)   # the responses / home tables are checked on load too
    return cfg


def machine_to_dict(cfg: MachineConfig, settings: dict[str, dict[str, Any]] | None = None
                    ) -> dict[str, Any]:
    """The TOML layout of `cfg` (switches in user units) and, per axis named in `settings`,
    its responses / home tables; inverse of machine_from_dict + machine_settings_from_dict."""
    if not isinstance(cfg, MachineConfig):
        raise MotionError(f"cfg must be a MachineConfig, got {cfg!r}")
    axes: dict[str, Any] = {}
    for ax in cfg.axes:
        t: dict[str, Any] = {k: getattr(ax, k) for k in _AXIS_SCALARS}
        if ax.logic:
            t["logic"] = dict(ax.logic)
        d = {k: getattr(ax.drive, k) for k in _DRIVE_KEYS}
        d["pitch_error"] = list(ax.drive.pitch_error)
        if ax.drive.type == "dc_servo" or ax.drive.motor != DCMotorConfig():
            d["motor"] = {k: getattr(ax.drive.motor, k) for k in _MOTOR_KEYS}
        else:
            del d["motor"]
        t["drive"] = d
        if ax.loop is not None:
            t["loop"] = {k: getattr(ax.loop, k) for k in _LOOP_KEYS}
        signed = ax.pulses_per_unit * (-1.0 if ax.reverse else 1.0)
        for sw in SWITCHES:
            s = getattr(ax, sw)
            if s is not None:
                t[sw] = {"position": _exact_units(s.position, signed),
                         "width": _exact_units(s.width, signed),
                         "hysteresis": _exact_units(s.hysteresis, ax.pulses_per_unit)}
        t.update(_settings_tables(ax.name, settings))
        axes[ax.name] = t
    return {"name": cfg.name, "cycle_s": cfg.cycle_s, "digital_inputs": cfg.digital_inputs,
            "digital_outputs": cfg.digital_outputs, "axes": axes}


def loads_machine(text: str) -> MachineConfig:
    """Parse and validate a machine description from TOML text."""
    import tomllib

    if not isinstance(text, str):
        raise MotionError(f"text must be a str, got {type(text).__name__}")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise MotionError(f"machine file is not valid TOML: {e}") from None
    return machine_from_dict(data)


def load_machine(path: str | os.PathLike[str]) -> MachineConfig:
    """Read, parse and validate a machine file: the mechanism (MachineConfig; MotionError
    if it cannot be read or is invalid). `Controller(load_machine(path))` keeps the
    power-on stop responses and has no homing settings: the file's [axes.<name>.responses]
    and [axes.<name>.home] tables are applied by `openmotion.open_machine(path)`."""
    text = read_machine_text(path)
    try:
        return loads_machine(text)
    except MotionError as e:
        raise MotionError(f"{os.fspath(path)}: {e}") from None


def dumps_machine(cfg: MachineConfig, settings: dict[str, dict[str, Any]] | None = None
                  ) -> str:
    """TOML text for `cfg` (and the axes' responses / home tables from `settings`);
    loads_machine(dumps_machine(cfg)) == cfg."""
    import tomli_w

    return _HEADER + tomli_w.dumps(machine_to_dict(cfg, settings))


def save_machine(cfg: MachineConfig, path: str | os.PathLike[str],
                 settings: dict[str, dict[str, Any]] | None = None) -> None:
    """Write `cfg` to a TOML file (the text is built first: a bad cfg writes nothing)."""
    if not isinstance(path, (str, os.PathLike)):
        raise MotionError(f"path must be a str or path, got {path!r}")
    text = dumps_machine(cfg, settings)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
