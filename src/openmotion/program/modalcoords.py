"""Modal's coordinates: program words -> machine positions, and the soft-limit check.

A mixin of `modal.Modal` (the state lives there): the program <-> machine mapping of one
axis word (G20/G21 scale, G90/G91, G7 diameters, the rotated XY frame of frame.py) and the
refusal of a move beyond the machine's soft limits, with the active offsets named in the
message. Kept apart from the line's order of execution (modal.py), which only calls it.
"""

from __future__ import annotations

from typing import Any

from . import frame
from .options import AXIS_LETTERS, ROTARY_LETTERS, GCodeOptions
from .params import Parameters
from .parser import Block
from .words import Word, fmt

COORD_SYSTEMS = {540: 1, 550: 2, 560: 3, 570: 4, 580: 5, 590: 6, 591: 7, 592: 8, 593: 9}


class ModalCoordinates:
    """Mixin of `Modal`: axis words to machine targets, positions, soft limits."""

    opt: GCodeOptions
    params: Parameters
    pos: list[float]
    letters: dict[str, tuple[int, int]]
    lscale: float
    ldiv: float
    incremental: bool
    diameter_mode: bool
    rotated: bool
    off: list[float]
    g92: list[float]
    coord: int
    comp: Any

    def update_offsets(self) -> None:
        frame.update(self)

    def lin(self, v: float) -> float:
        """A program length in machine units (exact when the units agree or 1 in = 25.4 mm)."""
        return v * self.lscale / self.ldiv

    def conv(self, v: float, letter: str) -> float:
        """Program value of axis `letter` in machine units (rotary axes are degrees)."""
        return v if letter in ROTARY_LETTERS else v * self.lscale / self.ldiv

    def program_position(self, k: int) -> float:
        """Current position of axis letter number k (X=0..W=8) in program coordinates."""
        letter = AXIS_LETTERS[k]
        info = self.letters.get(letter)
        if info is None:
            return 0.0
        if self.rotated and k in (0, 1):
            xy = frame.machine_to_xy(self, self.pos[self.letters["X"][0]],
                                     self.pos[self.letters["Y"][0]])
            return xy[k] * self.ldiv / self.lscale
        d = self.pos[info[0]] - self.off[k]
        return d if letter in ROTARY_LETTERS else d * self.ldiv / self.lscale

    def axis_index(self, b: Block, letter: str, w: Word) -> int:
        info = self.letters.get(letter)
        if info is None:
            raise b.error(f"axis letter {letter} has no machine axis (axes: "
                          f"{', '.join(sorted(self.letters))})", w.pos, fmt(letter, w.value))
        return info[0]

    def target_position(self, b: Block, axes: dict[str, Word], machine: bool = False,
                        incremental: bool | None = None, diameter: bool = True
                        ) -> list[float]:
        """Machine end point of axis words (program units; G90/G91, G7 on X, rotation)."""
        inc = self.incremental if incremental is None else incremental
        target = self.pos[:]
        xy: list[float] | None = None
        for letter, w in axes.items():
            ax = self.axis_index(b, letter, w)
            v = self.conv(w.value, letter)
            if letter == "X" and self.diameter_mode and diameter and not machine:
                v *= 0.5  # G7: X words are diameters
            k = self.letters[letter][1]
            if machine:
                target[ax] = v
            elif self.rotated and k < 2:
                if xy is None:
                    xy = list(frame.machine_to_xy(self, self.pos[self.letters["X"][0]],
                                                  self.pos[self.letters["Y"][0]]))
                xy[k] = xy[k] + v if inc else v
            elif inc:
                target[ax] = self.pos[ax] + v
            else:
                target[ax] = v + self.off[k]
        if xy is not None:
            mx, my = frame.xy_to_machine(self, xy[0], xy[1])
            target[self.letters["X"][0]], target[self.letters["Y"][0]] = mx, my
        return target

    def check_limits(self, b: Block, lo: list[float], hi: list[float], word: str,
                      pos: int) -> None:
        limits = self.opt.soft_limits
        if limits is None:
            return
        for ax, lim in enumerate(limits):
            if lim is None:
                continue
            if lo[ax] < lim[0] - 1e-9 * max(1.0, abs(lim[0])):
                raise b.error(f"move beyond soft limit: {self._limit_axis(ax)} would reach "
                              f"machine {lo[ax]:.6g} < min {lim[0]:g} {self._unit(ax)}"
                              f"{self._offset_note(ax)}", pos, word)
            if hi[ax] > lim[1] + 1e-9 * max(1.0, abs(lim[1])):
                raise b.error(f"move beyond soft limit: {self._limit_axis(ax)} would reach "
                              f"machine {hi[ax]:.6g} > max {lim[1]:g} {self._unit(ax)}"
                              f"{self._offset_note(ax)}", pos, word)

    def _unit(self, ax: int) -> str:
        """The unit of machine axis `ax`'s positions: degrees on A/B/C, else the machine's."""
        names = [L for L, (a, _) in self.letters.items() if a == ax]
        return "deg" if names and names[0] in "ABC" else self.opt.machine_units

    def _limit_axis(self, ax: int) -> str:
        """The program's letter for machine axis `ax` (soft-limit messages)."""
        names = [L for L, (a, _) in self.letters.items() if a == ax]
        return names[0] if names else f"machine axis {ax}"

    def _offset_note(self, ax: int) -> str:
        """' (active offset G55 X-60, G92 X5)': where the program origin of axis `ax` is."""
        names = [(L, k) for L, (a, k) in self.letters.items() if a == ax]
        if not names:
            return ""
        letter, k = names[0]
        system = {v: f"G{c // 10}" + (f".{c % 10}" if c % 10 else "")
                  for c, v in COORD_SYSTEMS.items()}[self.coord]
        work = self.params.numbers[5221 + 20 * (self.coord - 1) + k]
        note = f" (active offset {system} {letter}{work:g}"
        if self.g92[k]:
            note += f", G92 {letter}{self.g92[k]:g}"
        return note + ")"
