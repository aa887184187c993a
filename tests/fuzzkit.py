"""The fuzz suite's engine: adversarial values, entry points, one runner, its figures.

An `Entry` is one public call with a valid keyword set. Each fuzz example takes an entry,
replaces one argument with an adversarial value (NaN, inf, -0.0, 5e-324, 1e300, 10**400,
bool, str, Decimal, numpy scalars and arrays, None, wrong-length lists, negative indices)
and calls it. The oracle:
- a refusal is a MotionError (or subclass) whose message names the replaced argument, and
  the controller and the entry's objects are byte-identical afterwards (tests/snapshot.py);
- an accepted call is followed by a few control cycles, which must not raise;
- anything else (another exception) is a defect.
Examples are derandomized (reproducible in CI). The runner does not stop at the first
finding: it records all of them and the test asserts the lists are empty, printing them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction
from typing import Any

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from openmotion.control import Controller
from openmotion.errors import MotionError
from snapshot import snapshot

#: Values no public call may crash on.
ADVERSARIAL: list[Any] = [
    math.nan, math.inf, -math.inf, -0.0, 0.0, 5e-324, -5e-324, 1e-300, 1e300, -1e300,
    10**400, -(10**400), 2**63, 2**31, -1, 0, 1, -2, True, False, "1", "", "x",
    Decimal("1"), Decimal("nan"), Fraction(1, 3), np.float64(math.nan), np.float32(1.5),
    np.int64(3), np.int8(-1), np.bool_(True), np.array(1.0), np.array([1.0, 2.0]),
    np.array([]), np.array([[1.0]]), np.array(["a"]), None, [], [1.0], [1.0] * 7,
    (1, 2, 3), [math.nan, 0.0], [10**400, 0], ["1", 2], {}, {"a": 1}, object(), 1j,
    b"1",
]


def adversarial() -> st.SearchStrategy[Any]:
    return st.one_of(
        st.sampled_from(ADVERSARIAL),
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(-(10**30), 10**30),
        st.lists(st.floats(allow_nan=True), max_size=5),
        st.text(max_size=4),
    )


class World:
    """A fresh enabled controller and the objects entries built on it (cached by key)."""

    def __init__(self, make: Callable[[], Controller] | None = None) -> None:
        self._make = make or _default_controller
        self.reset()

    def reset(self) -> None:
        self.ctl = self._make()
        self.objs: dict[str, Any] = {}

    def get(self, key: str, factory: Callable[[World], Any]) -> Any:
        if key not in self.objs:
            self.objs[key] = factory(self)
        return self.objs[key]

    def snap(self) -> bytes:
        return snapshot(self.ctl, *self.objs.values())


def _default_controller() -> Controller:
    ctl = Controller()
    ctl.enable_all()
    return ctl


@dataclass
class Entry:
    """One public call: `call(world, **kwargs)`; `valid` is an accepted keyword set."""

    name: str
    call: Callable[..., Any]
    valid: dict[str, Any]
    #: words that may stand for an argument in a message (default: the argument's name)
    aliases: dict[str, tuple[str, ...]] = field(default_factory=dict)
    #: arguments that are not fuzzed (objects the entry needs)
    fixed: tuple[str, ...] = ()
    #: builds the objects the call works on before the snapshot (a lazily built object
    #: would otherwise count as a state change)
    prepare: Callable[[World], Any] | None = None


@dataclass
class Stats:
    inputs: int = 0
    refused: int = 0
    accepted: int = 0
    unexpected: list[str] = field(default_factory=list)
    unnamed: list[str] = field(default_factory=list)
    changed: list[str] = field(default_factory=list)
    cycle: list[str] = field(default_factory=list)

    def report(self) -> str:
        lines = [f"inputs {self.inputs}, refused {self.refused}, accepted {self.accepted}, "
                 f"unexpected exceptions {len(self.unexpected)}, unnamed parameter "
                 f"{len(self.unnamed)}, state changed on refusal {len(self.changed)}, "
                 f"cycle failures {len(self.cycle)}"]
        for title, items in (("unexpected", self.unexpected), ("unnamed", self.unnamed),
                             ("changed", self.changed), ("cycle", self.cycle)):
            for s in sorted(set(items))[:40]:
                lines.append(f"  {title}: {s}")
        return "\n".join(lines)

    @property
    def clean(self) -> bool:
        return not (self.unexpected or self.unnamed or self.changed or self.cycle)


TOTALS = Stats()


def _short(v: Any) -> str:
    try:
        text = repr(v)
    except Exception:  # noqa: BLE001
        text = type(v).__name__
    return text if len(text) <= 50 else text[:47] + "..."


def _copy(v: Any) -> Any:
    if isinstance(v, list):
        return [_copy(x) for x in v]
    if isinstance(v, dict):
        return {k: _copy(x) for k, x in v.items()}
    return v


def run_entries(entries: list[Entry], n: int, *, world: World | None = None,
                cycles: float = 0.003) -> Stats:
    """Fuzz `entries` with `n` examples; the figures and every finding."""
    stats = Stats()
    w = world or World()
    fuzzable = [(e, p) for e in entries for p in e.valid if p not in e.fixed]

    @settings(max_examples=n, derandomize=True, database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(st.sampled_from(fuzzable), adversarial())
    def one(pick: tuple[Entry, str], value: Any) -> None:
        entry, param = pick
        kw = {k: _copy(v) for k, v in entry.valid.items()}
        kw[param] = value
        where = f"{entry.name}({param}={_short(value)})"
        stats.inputs += 1
        try:
            if entry.prepare is not None:
                entry.prepare(w)
            before = w.snap()
        except Exception as e:  # noqa: BLE001
            stats.unexpected.append(f"snapshot before {where}: {type(e).__name__}: {e}")
            w.reset()
            return
        try:
            entry.call(w, **kw)
        except MotionError as e:
            stats.refused += 1
            names = entry.aliases.get(param, (param,))
            if not any(nm in str(e) for nm in names):
                stats.unnamed.append(f"{where} -> {_short(str(e))}")
            if w.snap() != before:
                stats.changed.append(where)
                w.reset()
            return
        except Exception as e:  # noqa: BLE001 - the finding this suite exists for
            stats.unexpected.append(f"{where} -> {type(e).__name__}: {_short(str(e))}")
            w.reset()
            return
        stats.accepted += 1
        try:
            w.ctl.advance(cycles)
        except Exception as e:  # noqa: BLE001
            stats.cycle.append(f"{where} then a cycle -> {type(e).__name__}: {_short(str(e))}")
        w.reset()

    one()
    for name in ("inputs", "refused", "accepted"):
        setattr(TOTALS, name, getattr(TOTALS, name) + getattr(stats, name))
    for name in ("unexpected", "unnamed", "changed", "cycle"):
        getattr(TOTALS, name).extend(getattr(stats, name))
    return stats


def examples(fuzz_long: bool, normal: int, long: int = 100_000) -> int:
    return long if fuzz_long else normal
