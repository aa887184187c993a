"""Point tables (HSL-4XMO 4.15/4.16 style): numbered, named points with their own speed.

A `PointTable` holds positions over fixed axis letters (machine units; degrees for A/B/C),
each point with its speed (units/min, as G-code F) and its move kind: "line" (G1, straight
at the speed) or "rapid" (G0, at the machine's rapid speed; speed ignored). Points are
addressed by index (0-based, the table order) or by name. A sequence of points becomes a
G-code program (`to_gcode`), so moving through points reuses the program runner and its
validation; `move_to` moves to one point now.

Files: TOML (`[[point]]` tables with name, position = [...], speed, kind) or CSV (header
`name,<letters...>,speed,kind`), chosen by the suffix.
"""

from __future__ import annotations

import csv
import math
import os
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import MotionError
from .options import AXIS_LETTERS

if TYPE_CHECKING:
    from ..control.core.controller import Controller
    from .runner import ProgramRunner

KINDS = ("line", "rapid")


@dataclass(frozen=True)
class TablePoint:
    name: str
    position: tuple[float, ...]
    speed: float = 600.0   # units/min
    kind: str = "line"


@dataclass
class PointTable:
    """Points over the axis `letters` (e.g. "XYZ")."""

    letters: str
    points: list[TablePoint] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not isinstance(self.letters, str) or not self.letters \
                or any(c not in AXIS_LETTERS for c in self.letters) \
                or len(set(self.letters)) != len(self.letters):
            raise MotionError(f"letters must be different letters of {AXIS_LETTERS}, "
                              f"got {self.letters!r}")
        pts, self.points = list(self.points), []
        for p in pts:
            self.add(p.name, p.position, speed=p.speed, kind=p.kind)

    def add(self, name: str, position: Sequence[float], *, speed: float = 600.0,
            kind: str = "line") -> int:
        """Append a point; returns its index."""
        if not isinstance(name, str) or not name.strip() or any(c in name for c in ",\n\"()"):
            raise MotionError(f"name must be non-empty text without , \" ( ) or newline, "
                              f"got {name!r}")
        if name in self.names:
            raise MotionError(f"name {name!r} is already in the table")
        try:
            pos = tuple(float(x) for x in position)
        except (TypeError, ValueError):
            raise MotionError(f"position must be {len(self.letters)} numbers, "
                              f"got {position!r}") from None
        if len(pos) != len(self.letters) or not all(math.isfinite(x) for x in pos):
            raise MotionError(f"position must be {len(self.letters)} finite numbers, "
                              f"got {position!r}")
        if isinstance(speed, bool) or not isinstance(speed, (int, float)) \
                or not math.isfinite(speed) or speed <= 0.0:
            raise MotionError(f"speed must be a finite number > 0 (units/min), got {speed!r}")
        if kind not in KINDS:
            raise MotionError(f"kind must be one of {KINDS}, got {kind!r}")
        self.points.append(TablePoint(name, pos, float(speed), kind))
        return len(self.points) - 1

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.points]

    def index(self, key: int | str) -> int:
        """Index of a point given by index or name."""
        if isinstance(key, str):
            if key not in self.names:
                raise MotionError(f"point {key!r} is not in the table")
            return self.names.index(key)
        if isinstance(key, bool) or not isinstance(key, int) \
                or not 0 <= key < len(self.points):
            raise MotionError(f"point index must be in [0, {len(self.points)}), got {key!r}")
        return key

    def __getitem__(self, key: int | str) -> TablePoint:
        return self.points[self.index(key)]

    def __len__(self) -> int:
        return len(self.points)

    # ------------------------------------------------------------------ programs
    def to_gcode(self, sequence: Sequence[int | str], *, dwell: float = 0.0,
                 outputs: Mapping[int | str, Sequence[tuple[int, bool]]] | None = None) -> str:
        """A G-code program visiting the points in `sequence` (absolute, mm/inch as the
        machine); `dwell` s at each point; `outputs[point] = [(n, level), ...]` set there
        (M64/M65) after arriving."""
        if isinstance(dwell, bool) or not isinstance(dwell, (int, float)) \
                or not math.isfinite(dwell) or dwell < 0.0:
            raise MotionError(f"dwell must be a finite number >= 0, got {dwell!r}")
        idx = [self.index(k) for k in sequence]
        if not idx:
            raise MotionError("sequence must name at least one point")
        outs = {self.index(k): v for k, v in (outputs or {}).items()}
        lines = ["G90 G94 G61"]
        for i in idx:
            p = self.points[i]
            words = " ".join(f"{c}{v:.6f}" for c, v in zip(self.letters, p.position,
                                                           strict=True))
            lines.append(f"G0 {words} (P{i} {p.name})" if p.kind == "rapid"
                         else f"G1 {words} F{p.speed:g} (P{i} {p.name})")
            if dwell > 0.0:
                lines.append(f"G4 P{dwell:g}")
            for n, level in outs.get(i, ()):
                lines.append(f"M{64 if level else 65} P{int(n)}")
        lines.append("M2")
        return "\n".join(lines) + "\n"

    def move_to(self, ctl: Controller, key: int | str, **kw: object) -> ProgramRunner:
        """Move to one point now (virtual time: runs to the end); returns the runner."""
        from .runner import run_program

        return run_program(ctl, self.to_gcode([key]), **kw)  # type: ignore[arg-type]

    # ------------------------------------------------------------------ files
    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write TOML (.toml) or CSV (.csv)."""
        p = Path(path)
        if p.suffix == ".csv":
            with p.open("w", newline="", encoding="utf-8") as f:
                w = csv.writer(f)
                w.writerow(["name", *self.letters, "speed", "kind"])
                for q in self.points:
                    w.writerow([q.name, *(repr(x) for x in q.position), repr(q.speed), q.kind])
        elif p.suffix == ".toml":
            out = [f'letters = "{self.letters}"', ""]
            for q in self.points:
                pos = ", ".join(repr(x) for x in q.position)
                out += ["[[point]]", f'name = "{q.name}"', f"position = [{pos}]",
                        f"speed = {q.speed!r}", f'kind = "{q.kind}"', ""]
            p.write_text("\n".join(out), encoding="utf-8")
        else:
            raise MotionError(f"path must end in .toml or .csv, got {str(path)!r}")
        return p

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> PointTable:
        """Read a table written by `save` (or by hand); errors name the point."""
        p = Path(path)
        if p.suffix == ".toml":
            try:
                data = tomllib.loads(p.read_text(encoding="utf-8"))
            except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
                raise MotionError(f"{p}: not a valid TOML point table: {err}") from None
            unknown = set(data) - {"letters", "point"}
            if unknown:
                raise MotionError(f"{p}: unknown keys {sorted(unknown)}")
            if "letters" not in data:
                raise MotionError(f'{p}: a point table needs letters = "XY.." (its axes)')
            try:
                table = cls(str(data["letters"]))
            except MotionError as err:
                raise MotionError(f"{p}: {err}") from None
            for k, q in enumerate(data.get("point", [])):
                bad = set(q) - {"name", "position", "speed", "kind"}
                if bad:
                    raise MotionError(f"{p}: point {k}: unknown keys {sorted(bad)}")
                try:
                    table.add(q.get("name", str(k)), q.get("position", ()),
                              speed=q.get("speed", 600.0), kind=q.get("kind", "line"))
                except MotionError as err:
                    raise MotionError(f"{p}: point {k}: {err}") from None
            return table
        if p.suffix == ".csv":
            with p.open(newline="", encoding="utf-8") as f:
                rows = list(csv.reader(f))
            if not rows or len(rows[0]) < 4 or rows[0][0] != "name" \
                    or rows[0][-2:] != ["speed", "kind"]:
                raise MotionError(f"{p}: header must be name,<letters>,speed,kind")
            try:
                table = cls("".join(rows[0][1:-2]))
            except MotionError as err:
                raise MotionError(f"{p}: header columns: {err}") from None
            for k, row in enumerate(rows[1:], start=2):
                try:
                    if len(row) != len(rows[0]):
                        raise MotionError(f"expected {len(rows[0])} fields, got {len(row)}")
                    table.add(row[0], [float(x) for x in row[1:-2]], speed=float(row[-2]),
                              kind=row[-1])
                except (MotionError, ValueError) as err:
                    raise MotionError(f"{p}: row {k}: {err}") from None
            return table
        raise MotionError(f"path must end in .toml or .csv, got {str(path)!r}")
