"""Expression trees for G-code values: numbers, parameters, operators and functions.

RS-274/NGC as LinuxCNC documents it: `[...]` groups, binary operators in five precedence
levels (lowest first) `AND OR XOR`, `EQ NE GT GE LT LE`, `+ -`, `* / MOD`, `**`, each
evaluated left to right; unary functions `ABS ACOS ASIN COS EXP FIX FUP ROUND LN SIN SQRT
TAN`, `ATAN[y]/[x]` and `EXISTS[#<name>]`. Angles are degrees. Comparisons and logic give
1.0 or 0.0; any non-zero value is true. EQ/NE compare with a tolerance of 1e-6 (LinuxCNC's
TOLERANCE_EQUAL), the other comparisons are exact. MOD has the sign of the divisor's
magnitude (result in [0, |b|)), as LinuxCNC's fmod-then-shift does.

Nodes evaluate against a parameter store (see params.py) through `ev(store)`. A failure
raises `EvalError` carrying the position of the offending node in the compacted line; the
interpreter turns it into a GCodeError with line and column.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

#: |a - b| below this makes EQ true (LinuxCNC TOLERANCE_EQUAL).
EQ_TOLERANCE = 1e-6


class EvalError(Exception):
    """Evaluation failed at compacted position `pos`; `word` is the text shown to the user."""

    def __init__(self, message: str, pos: int, word: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.pos = pos
        self.word = word


class Store(Protocol):
    """What evaluation needs from the parameter store."""

    def get_number(self, index: float, pos: int) -> float: ...
    def get_named(self, name: str, pos: int) -> float: ...
    def has_named(self, name: str) -> bool: ...


class Node:
    """An expression node; `pos` is its position in the compacted line."""

    __slots__ = ("pos",)

    def ev(self, store: Store) -> float:
        raise NotImplementedError

    def constant(self) -> bool:
        """True when the value does not depend on parameters (safe to fold at parse time)."""
        return False


class Num(Node):
    __slots__ = ("value",)

    def __init__(self, value: float, pos: int) -> None:
        self.value = value
        self.pos = pos

    def ev(self, store: Store) -> float:
        return self.value

    def constant(self) -> bool:
        return True


class NumParam(Node):
    """#n, #[expr] or ##n: the numbered parameter whose index is the inner value."""

    __slots__ = ("index",)

    def __init__(self, index: Node, pos: int) -> None:
        self.index = index
        self.pos = pos

    def ev(self, store: Store) -> float:
        return store.get_number(self.index.ev(store), self.pos)


class NamedParam(Node):
    """#<name>: a named parameter (leading '_' = global, else local to the subroutine)."""

    __slots__ = ("name",)

    def __init__(self, name: str, pos: int) -> None:
        self.name = name
        self.pos = pos

    def ev(self, store: Store) -> float:
        return store.get_named(self.name, self.pos)


class Exists(Node):
    """EXISTS[#<name>]: 1.0 if the named parameter is defined in the current scope."""

    __slots__ = ("name",)

    def __init__(self, name: str, pos: int) -> None:
        self.name = name
        self.pos = pos

    def ev(self, store: Store) -> float:
        return 1.0 if store.has_named(self.name) else 0.0


class ExistsNumber(Node):
    """EXISTS[#expr]: 1.0 if the numbered parameter the index names exists (an integer in
    1..5601), without reading it (LinuxCNC)."""

    __slots__ = ("index",)

    def __init__(self, index: Node, pos: int) -> None:
        self.index = index
        self.pos = pos

    def ev(self, store: Store) -> float:
        v = self.index.ev(store)
        n = round(v)
        return 1.0 if abs(v - n) <= 1e-4 and 1 <= n <= 5601 else 0.0


def _need(cond: bool, message: str, node: Node, word: str) -> None:
    if not cond:
        raise EvalError(message, node.pos, word)


def _fix(x: float) -> float:
    return float(math.floor(x))


def _fup(x: float) -> float:
    return float(math.ceil(x))


def _round(x: float) -> float:
    # Half away from zero (C's round), not Python's banker's rounding.
    return float(math.floor(abs(x) + 0.5)) * (1.0 if x >= 0 else -1.0)


def _sqrt(x: float) -> float:
    return math.sqrt(x)


def _acos(x: float) -> float:
    return math.degrees(math.acos(x))


def _asin(x: float) -> float:
    return math.degrees(math.asin(x))


FUNCTIONS: dict[str, Any] = {
    "ABS": abs,
    "ACOS": _acos,
    "ASIN": _asin,
    "COS": lambda x: math.cos(math.radians(x)),
    "EXP": math.exp,
    "FIX": _fix,
    "FUP": _fup,
    "ROUND": _round,
    "LN": math.log,
    "SIN": lambda x: math.sin(math.radians(x)),
    "SQRT": _sqrt,
    "TAN": lambda x: math.tan(math.radians(x)),
}

#: Domain rules checked before calling the function: (predicate, message).
_DOMAINS: dict[str, tuple[Any, str]] = {
    "ACOS": (lambda x: -1.0 <= x <= 1.0, "ACOS argument must be in [-1, 1]"),
    "ASIN": (lambda x: -1.0 <= x <= 1.0, "ASIN argument must be in [-1, 1]"),
    "LN": (lambda x: x > 0.0, "LN argument must be > 0"),
    "SQRT": (lambda x: x >= 0.0, "SQRT argument must be >= 0"),
}


class Func(Node):
    """A unary function call NAME[arg]."""

    __slots__ = ("name", "arg")

    def __init__(self, name: str, arg: Node, pos: int) -> None:
        self.name = name
        self.arg = arg
        self.pos = pos

    def ev(self, store: Store) -> float:
        x = self.arg.ev(store)
        dom = _DOMAINS.get(self.name)
        if dom is not None:
            _need(dom[0](x), f"{dom[1]}, got {x:.6g}", self, self.name)
        try:
            y = float(FUNCTIONS[self.name](x))
        except (OverflowError, ValueError):
            raise EvalError(f"{self.name}[{x:.6g}] has no finite value", self.pos,
                            self.name) from None
        _need(math.isfinite(y), f"{self.name}[{x:.6g}] has no finite value", self, self.name)
        return y

    def constant(self) -> bool:
        return self.arg.constant()


class Atan(Node):
    """ATAN[y]/[x]: the angle of (x, y) in degrees, in (-180, 180]."""

    __slots__ = ("y", "x")

    def __init__(self, y: Node, x: Node, pos: int) -> None:
        self.y = y
        self.x = x
        self.pos = pos

    def ev(self, store: Store) -> float:
        return math.degrees(math.atan2(self.y.ev(store), self.x.ev(store)))

    def constant(self) -> bool:
        return self.y.constant() and self.x.constant()


class Neg(Node):
    __slots__ = ("arg",)

    def __init__(self, arg: Node, pos: int) -> None:
        self.arg = arg
        self.pos = pos

    def ev(self, store: Store) -> float:
        return -self.arg.ev(store)

    def constant(self) -> bool:
        return self.arg.constant()


def _div(a: float, b: float, node: Node) -> float:
    _need(b != 0.0, "division by zero", node, "/")
    return a / b


def _mod(a: float, b: float, node: Node) -> float:
    _need(b != 0.0, "MOD by zero", node, "MOD")
    r = math.fmod(a, b)
    return r + abs(b) if r < 0.0 else r


def _pow(a: float, b: float, node: Node) -> float:
    try:
        return math.pow(a, b)
    except (ValueError, OverflowError):
        raise EvalError(f"{a:.6g} ** {b:.6g} has no finite real value", node.pos,
                        "**") from None


_BINARY: dict[str, Any] = {
    "**": _pow,
    "*": lambda a, b, n: a * b,
    "/": _div,
    "MOD": _mod,
    "+": lambda a, b, n: a + b,
    "-": lambda a, b, n: a - b,
    "EQ": lambda a, b, n: 1.0 if abs(a - b) < EQ_TOLERANCE else 0.0,
    "NE": lambda a, b, n: 0.0 if abs(a - b) < EQ_TOLERANCE else 1.0,
    "GT": lambda a, b, n: 1.0 if a > b else 0.0,
    "GE": lambda a, b, n: 1.0 if a >= b else 0.0,
    "LT": lambda a, b, n: 1.0 if a < b else 0.0,
    "LE": lambda a, b, n: 1.0 if a <= b else 0.0,
    "AND": lambda a, b, n: 1.0 if (a != 0.0 and b != 0.0) else 0.0,
    "OR": lambda a, b, n: 1.0 if (a != 0.0 or b != 0.0) else 0.0,
    "XOR": lambda a, b, n: 1.0 if ((a != 0.0) != (b != 0.0)) else 0.0,
}

#: Precedence of each binary operator (higher binds tighter).
PRECEDENCE: dict[str, int] = {
    "AND": 1, "OR": 1, "XOR": 1,
    "EQ": 2, "NE": 2, "GT": 2, "GE": 2, "LT": 2, "LE": 2,
    "+": 3, "-": 3,
    "*": 4, "/": 4, "MOD": 4,
    "**": 5,
}


class Binary(Node):
    __slots__ = ("op", "a", "b", "fn")

    def __init__(self, op: str, a: Node, b: Node, pos: int) -> None:
        self.op = op
        self.a = a
        self.b = b
        self.fn = _BINARY[op]
        self.pos = pos

    def ev(self, store: Store) -> float:
        return self.fn(self.a.ev(store), self.b.ev(store), self)

    def constant(self) -> bool:
        return self.a.constant() and self.b.constant()


def fold(node: Node) -> Node | float:
    """The value of a constant node as a float (parse-time folding), else the node itself.

    A constant expression that fails (e.g. 1/0) is kept as a node so the error is raised,
    with its position, when the line is executed.
    """
    if isinstance(node, Num):
        return node.value
    if node.constant():
        try:
            v = node.ev(_NO_STORE)
        except EvalError:
            return node
        if math.isfinite(v):
            return v
    return node


class _NoStore:
    def get_number(self, index: float, pos: int) -> float:  # pragma: no cover - unreachable
        raise EvalError("parameter in a constant expression", pos)

    def get_named(self, name: str, pos: int) -> float:  # pragma: no cover - unreachable
        raise EvalError("parameter in a constant expression", pos)

    def has_named(self, name: str) -> bool:  # pragma: no cover - unreachable
        return False


_NO_STORE = _NoStore()
