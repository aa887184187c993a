"""openmotion: a multi-axis motion controller in Python.

Layers (lower never imports higher): config/units -> profile -> path -> hw -> control ->
program -> cli. See docs/architecture.md. The most used names are re-exported here;
`Controller` is loaded on first use so `import openmotion.profile` stays light.
"""

from importlib.metadata import PackageNotFoundError, version
from typing import Any

try:
    __version__ = version("openmotion")  # one source of truth: pyproject.toml
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

__all__ = ["Controller", "MotionError", "__version__", "default_machine", "load_machine",
           "open_machine"]

from .config import default_machine, load_machine
from .errors import MotionError


def __getattr__(name: str) -> Any:
    if name == "open_machine":   # a machine file -> a Controller obeying all of it
        from .machine_file import open_machine

        return open_machine
    if name == "Controller":
        from .control import Controller

        return Controller
    raise AttributeError(f"module 'openmotion' has no attribute {name!r}")
