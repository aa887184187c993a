"""The method table of the remote API: name -> handler, and whether it is a command.

A handler takes the call context and the request's `Params`, reads and type-checks every
parameter, calls `p.done()` (unknown parameters are refused before anything runs) and
then acts. Commands run one at a time (the server's command lock) and honour
`config_version`; queries only read. The handlers live in methods_*.py by page.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..errors import MotionError
from .protocol import Params

if TYPE_CHECKING:
    from .service import MachineService


@dataclass
class Context:
    """What a handler may use: the machine, and the connection the call came on."""

    svc: MachineService
    conn: Any = None


Handler = Callable[[Context, Params], Any]


@dataclass(frozen=True)
class Method:
    fn: Handler
    command: bool


METHODS: dict[str, Method] = {}


def method(name: str, *, command: bool = True) -> Callable[[Handler], Handler]:
    def register(fn: Handler) -> Handler:
        if name in METHODS:
            raise RuntimeError(f"method {name} registered twice")
        METHODS[name] = Method(fn, command)
        return fn
    return register


def renamed(exc: MotionError, names: dict[str, str]) -> MotionError:
    """`exc` with library parameter names replaced by the API's (new_vel -> velocity)."""
    text = str(exc)
    for old, new in names.items():
        text = re.sub(rf"\b{re.escape(old)}\b", new, text)
    return type(exc)(text) if text != str(exc) else exc


def load_all() -> dict[str, Method]:
    """Import the handler modules (they register themselves) and return the table."""
    from . import methods_machine, methods_motion, methods_program, methods_tuning  # noqa: F401

    return METHODS
