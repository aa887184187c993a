"""Pieces of the ZMotion facade: the error type, per-axis parameters and the TABLE view.

ZMotion BASIC names axis parameters per axis (`UNITS(0)`, `UNITS AXIS(0)`) or for the BASE
axes at once (`UNITS=100,100,100`). In Python: `c.UNITS[0]`, `c.UNITS(0)`, `c.UNITS[0] = 100`
and `c.UNITS = 100, 100, 100` (the BASE axes in order). TABLE is indexable and callable:
`c.TABLE(0, 100, 150)` writes from 0, `c.TABLE(3)` reads, `c.TABLE[0:8] = [...]`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from typing import Any

from ..control.trigger.pso import base_axes
from ..errors import MotionError

#: Error codes of refused commands (ours: the article lists none).
ZERR_PARAMETER = 1     # a parameter out of range, of the wrong type, or not finite
ZERR_STATE = 2         # not allowed now (axis moving, in another interpolation, ...)
ZERR_UNSUPPORTED = 3   # a ZMotion value openmotion does not provide
ZERR_TIMEOUT = 4       # WAIT IDLE did not see the axis idle in time


class ZMotionError(MotionError):
    """A refused ZMotion command: `code`, the `command` and the `parameter` at fault."""

    def __init__(self, command: str, parameter: str, message: str,
                 code: int = ZERR_PARAMETER) -> None:
        super().__init__(f"{command}: {message} (error {code})")
        self.command = command
        self.parameter = parameter
        self.code = code
        self.reason = message


def parameter_of(message: str) -> str:
    """The parameter a core message names first ("maxerr must be > 0" -> "maxerr")."""
    head = message.split(" ", 1)[0].rstrip(":,")
    bare = head
    for ch in "_[]()":
        bare = bare.replace(ch, "")
    return head if bare.isalnum() and head[:1].isalpha() else ""


class AxisParam:
    """One per-axis parameter of a ZController (see the module docstring)."""

    def __init__(self, name: str, n_axes: int, base: Callable[[], Sequence[int]],
                 get: Callable[[int], Any], put: Callable[[dict[int, Any]], None]) -> None:
        self.name = name
        self._n = n_axes
        self._base = base
        self._get = get
        self._put = put

    def _axis(self, axis: object) -> int:
        if isinstance(axis, bool) or not isinstance(axis, int) or not 0 <= axis < self._n:
            raise ZMotionError(self.name, "axis", f"axis must be an integer in "
                               f"[0, {self._n - 1}], got {axis!r}")
        return axis

    def __getitem__(self, axis: int) -> Any:
        return self._get(self._axis(axis))

    def __call__(self, axis: int) -> Any:
        return self[axis]

    def __setitem__(self, axis: int, value: Any) -> None:
        self._put({self._axis(axis): value})

    def assign(self, values: Any) -> None:
        """`c.NAME = v0, v1, ...`: the BASE axes in order (one value: the first BASE axis),
        the list extended by the following axes as for a move (pso.base_axes)."""
        vals = list(values) if isinstance(values, tuple | list) else [values]
        try:
            axes = base_axes(self._base(), len(vals), self._n)
        except MotionError as e:
            raise ZMotionError(self.name, "values", str(e)) from None
        self._put(dict(zip(axes, vals, strict=True)))

    def __iter__(self) -> Iterator[Any]:
        return (self._get(a) for a in self._base())

    def __repr__(self) -> str:
        return f"{self.name}{tuple(self._get(a) for a in range(self._n))!r}"


class TableView:
    """TABLE: `c.TABLE(start, v0, ...)` writes, `c.TABLE(i)` reads, indexing and slices."""

    def __init__(self, size: Callable[[], int], read: Callable[[int], float],
                 write: Callable[[int, Sequence[float]], None]) -> None:
        self._size = size
        self._read = read
        self._write = write

    def _index(self, i: object) -> int:
        n = self._size()
        if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < n:
            raise ZMotionError("TABLE", "index", f"index must be an integer in [0, {n - 1}], "
                               f"got {i!r}")
        return i

    def __call__(self, start: int, *values: float) -> float | None:
        if not values:
            return self._read(self._index(start))
        self._write(self._index(start), values)
        return None

    def _slice(self, s: slice) -> range:
        if s.step not in (None, 1):
            raise ZMotionError("TABLE", "index", f"slices must be contiguous, got step {s.step}")
        return range(*s.indices(self._size()))

    def __getitem__(self, key: int | slice) -> float | list[float]:
        if isinstance(key, slice):
            return [self._read(i) for i in self._slice(key)]
        return self._read(self._index(key))

    def __setitem__(self, key: int | slice, value: Any) -> None:
        if isinstance(key, slice):
            r = self._slice(key)
            vals = list(value)
            if len(vals) != len(r):
                raise ZMotionError("TABLE", "values", f"{len(vals)} values for a slice of "
                                   f"{len(r)} entries")
            if r:
                self._write(r.start, vals)
            return
        self._write(self._index(key), [value])

    def __len__(self) -> int:
        return self._size()
