"""Endless O-word loops are refused early (issue #12 defect 12).

A `while [1]` used to run into the 10 M executed-line limit (35 s, 1 GB). Now a loop whose
iteration leaves every parameter and the machine state unchanged is refused at its third
test, and any loop stops at `max_loop_iterations` per entry. The tests give max_blocks a
value that the old code would reach quickly, so they fail on it by message, not by time.
"""

from __future__ import annotations

import pytest

from openmotion.errors import MotionError
from openmotion.program import GCodeError, GCodeOptions, compile_text


def opts(**kw: object) -> GCodeOptions:
    kw.setdefault("max_blocks", 200_000)
    return GCodeOptions(axes={"X": 0, "Y": 1}, **kw)  # type: ignore[arg-type]


def refused(text: str, **kw: object) -> str:
    with pytest.raises(GCodeError) as info:
        compile_text(text, opts(**kw), file="loop.ngc")
    return str(info.value)


@pytest.mark.parametrize("text, line, word", [
    ("O100 while [1]\nO100 endwhile\n", 1, "O100 while"),
    ("G0 X0\nO7 while [1]\nG1 X1 F100\nG1 X0\nO7 endwhile\n", 2, "O7 while"),
    # G20/G21 in the loop: the unit log grows (a record, progunits.py), the state does not
    ("G0 X0\nO8 while [1]\nG20\nG1 X1 F10\nG21\nG1 X0\nO8 endwhile\n", 2, "O8 while"),
    ("O3 do\n#1 = 5\nO3 while [1]\n", 1, "O3 do"),
    ("O1 sub\n#<_cnt> = #1\nO1 endsub\nO9 while [1]\nO1 call [3]\nO9 endwhile\n", 4, "O9 while"),
    ("O5 repeat [1]\nO6 while [#5420 LT 1]\nG90\nO6 endwhile\nO5 endrepeat\n", 2, "O6 while"),
])
def test_loop_that_changes_nothing_is_refused_at_once(text: str, line: int, word: str) -> None:
    msg = refused(text)
    assert "endless loop" in msg and "changed no parameter" in msg
    assert "loop.ngc" in msg and f"line {line}" in msg and word in msg


def test_state_changing_endless_loop_stops_at_the_iteration_limit() -> None:
    msg = refused("O100 while [1]\nG91 G1 X1 F100\nO100 endwhile\n", max_loop_iterations=1000)
    assert "max_loop_iterations" in msg and "O100 while" in msg and "line 1" in msg
    msg = refused("#1 = 0\nO2 repeat [10000000]\n#1 = [#1 + 1]\nO2 endrepeat\n",
                  max_loop_iterations=500)
    assert "500 iterations" in msg and "O2 repeat" in msg


def test_default_limit_is_finite_and_small(long_run: bool) -> None:
    limit = opts().max_loop_iterations  # (the default: opts() does not set it)
    assert isinstance(limit, int) and 0 < limit <= 1_000_000
    if long_run:  # the default limit's refusal itself (1 M iterations, ~6 s; the same
        # guard as the small limits above)
        msg = refused("#1 = 0\nO100 while [1]\n#1 = [#1 + 1]\nO100 endwhile\n",
                      max_blocks=10_000_000)
        assert "max_loop_iterations" in msg


def test_finite_loops_run_to_the_end() -> None:
    text = ("#1 = 0\nO1 while [#1 LT 1000]\n#1 = [#1 + 1]\nO1 endwhile\nG0 X#1\n"
            "O2 repeat [3]\nO3 repeat [400]\nG91 G1 X1 F100\nO3 endrepeat\nO2 endrepeat\n"
            "G90\n#2 = 0\nO4 do\n#2 = [#2 + 1]\nO4 while [#2 LT 1000]\nG0 Y#2\n")
    cmds = compile_text(text, opts(max_loop_iterations=1000))
    assert cmds[0].end[0] == 1000
    assert len(cmds) == 1 + 1200 + 1
    assert cmds[-1].end == (2200, 1000)


def test_a_loop_left_by_break_starts_counting_again() -> None:
    text = ("#1 = 0\nO1 repeat [5]\n#2 = 0\nO2 while [1]\n#2 = [#2 + 1]\n"
            "O3 if [#2 GE 800]\nO2 break\nO3 endif\nO2 endwhile\nO1 endrepeat\nG0 X#2\n")
    cmds = compile_text(text, opts(max_loop_iterations=1000))
    assert cmds[-1].end[0] == 800


def test_max_blocks_message_names_the_active_loop() -> None:
    msg = refused("#1 = 0\nO8 while [1]\n#1 = [#1 + 1]\nO8 endwhile\n", max_blocks=300)
    assert "max_blocks" in msg and "loop O8 at line 2" in msg


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "10"])
def test_max_loop_iterations_is_checked(bad: object) -> None:
    with pytest.raises(MotionError, match="max_loop_iterations"):
        GCodeOptions(axes={"X": 0}, max_loop_iterations=bad)  # type: ignore[arg-type]
