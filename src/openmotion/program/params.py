"""Parameter store: numbered #1..#5601, global #<_name> and subroutine-local #<name>.

LinuxCNC rules: numbered parameters read as 0 until set; #1-#30 are local to a
subroutine call (the caller's values are saved on CALL and restored on return); named
parameters without a leading '_' are local to the call that set them, those with '_' are
global; reading an unset named parameter is an error. Names are case-insensitive and may
contain spaces (the parser removes them). Indices 5161.. etc. hold the persistent
positions and offsets the interpreter uses (see modal.py).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from ..errors import MotionError, check_finite
from .expr import EvalError
from .parser import MAX_PARAMETER

#: Numbered parameters local to a subroutine call.
N_LOCAL = 30


class Parameters:
    """The interpreter's parameter store, with a stack of local scopes for calls."""

    def __init__(self, initial: Mapping[int, float] | None = None) -> None:
        self.numbers = [0.0] * (MAX_PARAMETER + 1)
        for key, value in (initial or {}).items():
            if isinstance(key, bool) or not isinstance(key, int) \
                    or not 1 <= key <= MAX_PARAMETER:
                raise MotionError(f"parameters keys must be integers in [1, {MAX_PARAMETER}],"
                                  f" got {key!r}")
            self.numbers[key] = check_finite(f"parameters[{key}]", value)
        self.globals: dict[str, float] = {}
        self.locals: list[dict[str, float]] = [{}]
        self._saved: list[list[float]] = []
        #: Reads #5420-#5428 (current position X..W in program coordinates) when set.
        self.position_hook: Callable[[int], float] | None = None
        #: Predefined read-only globals (#<_x>, #<_metric>, ...): name -> value or None.
        self.predefined_hook: Callable[[str], float | None] | None = None
        #: Counts writes that changed a value (loop detection). A call and its return are
        #: not counted: the return restores #1-#30 and drops the callee's locals.
        self.version = 0

    # -- reads (the expr.Store protocol) -------------------------------------------------
    def get_number(self, index: float, pos: int) -> float:
        n = round(index)
        if abs(index - n) > 1e-4 or not 1 <= n <= MAX_PARAMETER:
            raise EvalError(f"parameter number must be an integer in [1, {MAX_PARAMETER}], "
                            f"got {index:g}", pos, f"#{index:g}")
        if 5420 <= n <= 5428 and self.position_hook is not None:
            return self.position_hook(int(n) - 5420)
        return self.numbers[int(n)]

    def get_named(self, name: str, pos: int) -> float:
        table = self.globals if name.startswith("_") else self.locals[-1]
        try:
            return table[name]
        except KeyError:
            v = self.predefined(name)
            if v is not None:
                return v
            raise EvalError(f"named parameter #<{name.lower()}> is not defined", pos,
                            f"#<{name.lower()}>") from None

    def predefined(self, name: str) -> float | None:
        """Value of a predefined global such as _X or _METRIC, None if `name` is not one."""
        if self.predefined_hook is None or not name.startswith("_"):
            return None
        return self.predefined_hook(name)

    def has_named(self, name: str) -> bool:
        if name in (self.globals if name.startswith("_") else self.locals[-1]):
            return True
        return self.predefined(name) is not None

    # -- writes ----------------------------------------------------------------------
    def set_number(self, index: int, value: float) -> None:
        if self.numbers[index] != value:
            self.version += 1
        self.numbers[index] = value

    def set_named(self, name: str, value: float) -> None:
        table = self.globals if name.startswith("_") else self.locals[-1]
        if table.get(name) != value:
            self.version += 1
        table[name] = value

    # -- call scopes -----------------------------------------------------------------
    def push_call(self, args: list[float] | None) -> None:
        """Enter a subroutine: save #1-#30, set them from `args` (rest 0), new local scope.
        args=None (an M98 call): #1-#30 are shared with the caller (Fanuc, LinuxCNC)."""
        self._saved.append(self.numbers[1:N_LOCAL + 1])
        if args is not None:
            vals = list(args) + [0.0] * (N_LOCAL - len(args))
            self.numbers[1:N_LOCAL + 1] = vals
        self.locals.append({})

    def pop_call(self, keep_numbered: bool = False) -> None:
        """Leave a subroutine: restore the caller's #1-#30 (unless kept) and local names."""
        saved = self._saved.pop()
        if not keep_numbered:
            self.numbers[1:N_LOCAL + 1] = saved
        self.locals.pop()

    @property
    def depth(self) -> int:
        return len(self._saved)
