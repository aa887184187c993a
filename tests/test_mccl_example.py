"""The ported MCCL program in examples/mccl runs and ends where it should."""

from __future__ import annotations

import runpy
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "mccl" / "xy_table.py"


def test_xy_table_program():
    r = runpy.run_path(str(EXAMPLE))["main"]()
    assert r["end"] == (0.0, 0.0) and r["pulses"] == (0, 0)
    assert r["in_position"] == 1.0 and r["error"] == 0.0
    x, y = r["held_at"]
    assert 10.0 < x < 60.0 and y == 10.0       # held on the first line of the contour
    # changed on the running machine: 2 ms, and the narrower X interval (2.4)
    assert r["period_ms"] == 2 and r["refused_at_145"] == -3
