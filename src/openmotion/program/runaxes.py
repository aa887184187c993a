"""Binding a program to a controller: G-code letters -> axes, travel, `gcode=` fields."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

from ..errors import MotionError, show
from ..units import AxisUnits
from .options import AXIS_LETTERS, GCodeOptions

if TYPE_CHECKING:
    from ..control.core.controller import Controller


def machine_axes(ctl: Controller, axes: Mapping[str, int | str] | None = None) -> dict[str, int]:
    """G-code letter -> controller axis index; default: axes named after letters (x, y, ...),
    except that a degree axis named after a linear letter (the XYZU table's u) becomes the
    first free rotary letter A, B or C (G-code U/V/W are linear and scaled by G20)."""
    if axes is None:
        out = {a.name.upper(): a.index for a in ctl.axes if a.name.upper() in AXIS_LETTERS
               and len(a.name) == 1}
        for letter, index in list(out.items()):
            # a degree axis named u/v/w (G-code linear letters) becomes the next free A/B/C
            if ctl.config.axes[index].unit == "degree" and letter not in "ABC":
                free = [r for r in "ABC" if r not in out]
                if free:
                    del out[letter]
                    out[free[0]] = index
        if not out:
            raise MotionError("axes: no controller axis is named after a G-code letter "
                              f"({AXIS_LETTERS}); pass axes={{'X': 0, ...}}")
        return out
    if not isinstance(axes, Mapping) or not axes:
        raise MotionError(f"axes must be a non-empty mapping letter -> axis, got {axes!r}")
    out = {}
    for letter, key in axes.items():
        if not isinstance(letter, str) or letter.upper() not in AXIS_LETTERS:
            raise MotionError(f"axes keys must be letters of {AXIS_LETTERS}, got {letter!r}")
        out[letter.upper()] = ctl.axis(key).index
    if len(set(out.values())) != len(out):
        raise MotionError("axes must map letters to different controller axes")
    return out


def travel_limits(ctl: Controller, index: int) -> tuple[float, float] | None:
    """Travel of a controller axis in its user units between its MEL and PEL switch edges
    (None when it has neither); an open side is infinite."""
    cfg = ctl.config.axes[index]
    if cfg.mel is None and cfg.pel is None:
        return None
    u = AxisUnits.from_axis(cfg)
    ends = [u.to_units(float(sw.position)) for sw in (cfg.mel, cfg.pel) if sw is not None]
    lo = min(ends) if cfg.mel is not None else -math.inf
    hi = max(ends) if cfg.pel is not None else math.inf
    if cfg.mel is not None and cfg.pel is not None:
        lo, hi = min(ends), max(ends)
    return (lo, hi)


def gcode_fields(gcode: object) -> dict[str, object]:
    """The runner's `gcode` argument: GCodeOptions fields by name, minus those the
    runner sets itself (their values are checked when the options are built)."""
    if gcode is None:
        return {}
    if not isinstance(gcode, Mapping):
        raise MotionError(f"gcode must be a mapping of GCodeOptions fields, got {show(gcode)}")
    names = {f.name for f in dataclasses.fields(GCodeOptions)}
    for key in gcode:
        if key in ("axes", "n_axes", "start", "machine_units"):
            raise MotionError(f"gcode must not set {key!r} (the runner sets it)")
        if key not in names:
            raise MotionError(f"gcode: {key!r} is not a GCodeOptions field "
                              f"({', '.join(sorted(names))})")
    return dict(gcode)
