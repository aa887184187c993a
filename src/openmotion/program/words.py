"""Evaluated G-code words and the small helpers the line executors share (modal.py,
arcmove.py, coords.py): a word's text for messages, the feed length of a move."""

from __future__ import annotations

import math

from .options import ROTARY_LETTERS


class Word:
    """A word's evaluated value and where it was (for error messages)."""

    __slots__ = ("value", "pos")

    def __init__(self, value: float, pos: int) -> None:
        self.value = value
        self.pos = pos


def fmt(letter: str, v: float) -> str:
    """The word as a program shows it, e.g. fmt("X", 1.5) -> "X1.5"."""
    return f"{letter}{v:g}"


def feed_length(start: list[float], end: list[float], letters: dict[str, tuple[int, int]],
                 skip: tuple[int, ...] = ()) -> float:
    """Move length as LinuxCNC measures feed: linear axes if any moves, else rotary."""
    lin = rot = 0.0
    for L, (ax, _k) in letters.items():
        if ax in skip:
            continue
        d = (end[ax] - start[ax]) ** 2
        if L in ROTARY_LETTERS:
            rot += d
        else:
            lin += d
    return math.sqrt(lin) if lin > 0.0 else math.sqrt(rot)
