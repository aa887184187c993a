"""openmotion: a multi-axis motion controller in Python.

Layers (lower never imports higher): config/units -> profile -> path -> hw -> control ->
program -> cli. See docs/architecture.md. The most used names are re-exported here;
`Controller` is loaded on first use so `import openmotion.profile` stays light.
"""

from typing import Any

__version__ = "0.1.0"

__all__ = ["Controller", "MotionError", "__version__", "default_machine", "load_machine"]

from .config import default_machine, load_machine
from .errors import MotionError


def __getattr__(name: str) -> Any:
    if name == "Controller":
        from .control import Controller

        return Controller
    raise AttributeError(f"module 'openmotion' has no attribute {name!r}")
