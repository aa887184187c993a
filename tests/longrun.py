"""Sizes for heavy tests: reduced in the normal run, full with `pytest --long`.

conftest.py sets OPENMOTION_LONG=1 in pytest_configure when --long is given (before any
test module is imported, in xdist workers too), so sizes can be chosen at decoration time
(hypothesis `max_examples`, parametrize lists). The reduced runs check the same properties
on fewer or shorter cases.
"""

from __future__ import annotations

import os


def long_run() -> bool:
    return os.environ.get("OPENMOTION_LONG") == "1"


def size(normal: int, full: int) -> int:
    """`full` with --long, else `normal`."""
    return full if long_run() else normal
