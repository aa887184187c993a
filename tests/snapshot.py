"""One snapshot of everything a refused call must leave unchanged (the fuzz suite's oracle).

`snapshot(ctl, *objects)` returns bytes: controller time and cycle count, every axis's
state, fault, position, velocity, counters and motion (Axis.snapshot), every axis's and
object's settings (their plain attributes: numbers, strings, flags, enums, tuples, arrays),
history record counts, group states and queue lengths, hook counts, the event count, the
safety settings and the hardware outputs. Two equal snapshots mean byte-identical state.
"""

from __future__ import annotations

import enum
import hashlib
from typing import Any

import numpy as np

_PLAIN = (bool, int, float, str, bytes, type(None), enum.Enum)


def _plain(v: Any, depth: int = 0) -> Any:
    """A comparable image of `v`, or a marker for what is not plain data."""
    if isinstance(v, _PLAIN):
        return v
    if isinstance(v, np.ndarray):  # its bytes by digest: the repr of a large array's bytes
        # was most of a fuzz run's time (~40 ms per snapshot)
        return ("ndarray", v.dtype.str, v.shape, hashlib.blake2b(v.tobytes()).digest())
    if isinstance(v, np.generic):
        return v.item()
    if depth < 3 and isinstance(v, (list, tuple, set, frozenset)):
        items = [_plain(x, depth + 1) for x in v]
        return (type(v).__name__, tuple(sorted(items, key=repr)) if isinstance(
            v, (set, frozenset)) else tuple(items))
    if depth < 3 and isinstance(v, dict):
        return ("dict", tuple((repr(k), _plain(x, depth + 1)) for k, x in v.items()))
    if hasattr(v, "__dataclass_fields__") and depth < 3:
        return (type(v).__name__, settings(v, depth + 1))
    return ("obj", type(v).__name__)  # identity-free: objects are compared by their type


def settings(obj: Any, depth: int = 0) -> tuple:
    """The plain attributes of `obj` (its settings and counters), sorted by name."""
    try:
        items = vars(obj).items()
    except TypeError:  # slots
        names = getattr(type(obj), "__slots__", ())
        items = [(n, getattr(obj, n)) for n in names if hasattr(obj, n)]
    return tuple((k, _plain(v, depth)) for k, v in sorted(items, key=lambda kv: kv[0])
                 if not k.startswith("__") and k not in ("_lock",))


def snapshot(ctl: Any, *objects: Any) -> bytes:
    """Bytes that differ whenever any observable state of `ctl` or `objects` differs."""
    parts: list[Any] = [ctl.time, ctl.cycles, ctl.estop_active]
    for a in ctl.axes:
        snap = list(a.snapshot())
        snap[6] = snap[6] is not None and snap[7] is not None  # id(motion): presence only
        parts.append(tuple(snap))
        parts.append(settings(a))
        parts.append(ctl.history.n_records(a.index))
        parts.append(a.counters.snapshot())
    parts.append(len(ctl.events))
    parts.append(tuple(len(getattr(ctl, n)) for n in (
        "_edge_hooks", "_cycle_hooks", "_pre_hooks", "_sample_hooks", "_fault_hooks",
        "_motion_checks")))
    if ctl.safety is not None:
        parts.append(tuple(settings(c) for c in ctl.safety._cfg))
    hw = ctl.hardware
    for name in ("_do", "_outputs", "outputs"):
        if hasattr(hw, name):
            parts.append(_plain(getattr(hw, name)))
    for obj in objects:
        parts.append((type(obj).__name__, settings(obj)))
        for attr in ("state", "queue_length"):
            if hasattr(obj, attr):
                try:
                    parts.append(_plain(getattr(obj, attr)))
                except Exception as e:  # noqa: BLE001 - a property that fails is state too
                    parts.append(("raises", type(e).__name__))
    return repr(parts).encode()
