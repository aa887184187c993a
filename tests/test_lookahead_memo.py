"""The look-ahead's per-element memo (path/lookahead.py `_Memo`): by identity, no element
kept alive, an entry gone with its element, elements without weak references planned
unmemoized."""

from __future__ import annotations

import gc

import numpy as np

from openmotion.path import Line, plan_speeds
from openmotion.path.lookahead import _Memo


def test_memo_is_by_identity_and_weak() -> None:
    memo = _Memo()
    a = Line(np.array([0.0, 0.0]), np.array([1.0, 0.0]))
    b = Line(np.array([0.0, 0.0]), np.array([1.0, 0.0]))  # equal, another object
    memo.put(a, 1)
    assert memo.get(a) == 1 and memo.get(b) is None
    memo.put(b, 2)
    assert memo.get(a) == 1 and memo.get(b) == 2
    del a
    gc.collect()
    assert len(memo._d) == 1 and memo.get(b) == 2
    memo.put(3.5, "x")  # takes no weak reference: not remembered
    assert memo.get(3.5) is None


def test_plans_are_the_same_asked_twice() -> None:
    els = [Line(np.array([0.0, 0.0]), np.array([1.0, 0.0])),
           Line(np.array([1.0, 0.0]), np.array([1.0, 1.0]))]
    kw = {"square_corner_velocity": 2.0, "axis_vmax": np.array([5.0, 5.0]),
          "axis_amax": np.array([50.0, 50.0])}
    first = plan_speeds(els, 4.0, 30.0, **kw)
    assert plan_speeds(els, 4.0, 30.0, **kw) == first
    other = plan_speeds(els, 3.0, 30.0, **kw)  # other limits: not the memo's
    assert other != first and plan_speeds(els, 3.0, 30.0, **kw) == other
