"""plan_speeds accepts any path element and refuses anything else, also after it has seen
elements of the same type (the type cache of lookahead._is_element)."""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.errors import MotionError
from openmotion.path.geometry import Line
from openmotion.path.lookahead import plan_speeds


class _Half:
    """A user's element type whose second instance lacks `start` (a broken wrapper)."""

    def __init__(self, line: Line, broken: bool = False) -> None:
        self._line = line
        if not broken:
            self.start = line.start
        self.end = line.end

    def __getattr__(self, name):
        if name == "start":
            raise AttributeError(name)
        return getattr(self._line, name)


def test_a_user_type_is_checked_at_every_call():
    line = Line(np.zeros(2), np.array([1.0, 0.0]))
    plan_speeds([_Half(line)], 10.0, 100.0)
    with pytest.raises(MotionError, match=r"elements\[0\] must be a path element"):
        plan_speeds([_Half(line, broken=True)], 10.0, 100.0)
    with pytest.raises(MotionError, match=r"elements\[1\] must be a path element"):
        plan_speeds([line, object()], 10.0, 100.0)
