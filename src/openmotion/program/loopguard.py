"""Refuse endless O-word loops early: an iteration limit and repeated-state detection.

An interpreter that runs a program to completion before anything moves cannot let a
`while [1]` run into the executed-line limit (10 M lines took 35 s and 1 GB). Each active
loop counts its iterations (limit `max_loop_iterations` per entry into the loop), and when
no parameter changed since its last test the loop compares the whole interpreter state
(modal state, positions, repeat counters) with the state at that test: the same state at
the same test means the program repeats forever, which is refused at once.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from .parser import Block

#: Modal attributes that are not part of the state: constant while a program runs, or a
#: record of what ran (the unit log and where the block's commands start, progunits.py).
_CONSTANT = frozenset({"opt", "params", "letters", "unit_log", "out_at"})


class _Unfreezable(Exception):
    """A state value the guard cannot compare by value: detection is off for it."""


def _freeze(v: Any) -> Any:
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    if isinstance(v, (list, tuple)):
        return tuple(_freeze(x) for x in v)
    if isinstance(v, dict):
        return tuple((k, _freeze(x)) for k, x in v.items())
    if isinstance(v, (set, frozenset)):
        return frozenset(v)
    if dataclasses.is_dataclass(v) and not isinstance(v, type):  # CutterComp, CycleState...
        return (type(v).__name__,) + tuple(_freeze(getattr(v, f.name))
                                           for f in dataclasses.fields(v))
    raise _Unfreezable


class LoopGuard:
    """Per-loop iteration counts and state fingerprints; one per interpreter run."""

    def __init__(self, modal: Any, max_iterations: int) -> None:
        self.modal = modal
        self.params = modal.params
        self.max_iterations = max_iterations

    def _state(self, repeats: dict[int, int]) -> tuple[Any, ...] | None:
        try:
            fields = tuple((k, _freeze(v)) for k, v in vars(self.modal).items()
                           if k not in _CONSTANT)
        except _Unfreezable:
            return None
        return fields, tuple(repeats.items())

    def iterate(self, loops: dict[int, list[Any]], repeats: dict[int, int], head: int,
                block: Block) -> None:
        """Loop `head` (its opening block is `block`) starts another iteration."""
        st = loops.get(head)
        version = self.params.version
        if st is None:
            loops[head] = [1, version, None]
            return
        st[0] += 1
        o = block.oword
        assert o is not None
        word = f"O{o.label} {o.keyword.lower()}"
        if st[0] > self.max_iterations:
            raise block.error(f"loop {word} ran more than {self.max_iterations} iterations "
                              "(max_loop_iterations; endless loop?)", o.pos, word)
        if version != st[1]:
            st[1], st[2] = version, None
            return
        snap = self._state(repeats)
        if snap is not None and snap == st[2]:
            raise block.error(f"endless loop {word}: iteration {st[0] - 1} changed no "
                              "parameter and left the machine state as it found it",
                              o.pos, word)
        st[2] = snap

    @staticmethod
    def leave(loops: dict[int, list[Any]], head: int) -> None:
        """Loop `head` ended (condition false, count done or break)."""
        loops.pop(head, None)

