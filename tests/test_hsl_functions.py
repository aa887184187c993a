"""The function table: every HSL function name in the manual's text is offered and done,
and the docs' table is the generated one."""

from __future__ import annotations

import re
from pathlib import Path

from openmotion.compat.hsl import HslLibrary, functions

ROOT = Path(__file__).resolve().parent.parent
MANUAL = Path("/work/shared/seeds/hsl-4xmo-users-manual.txt")


def manual_names() -> set[str]:
    text = MANUAL.read_text(encoding="utf-8")
    names = set(re.findall(r"HSL_[A-Za-z0-9_]+", text))
    names |= {n.replace("\\", "") for n in re.findall(r"HSL\\_[A-Za-z0-9_\\]+", text)}
    names |= {"HSL_M_start_" + m.replace(" ", "")           # "HSL_M_start_r_ arc _zu"
              for m in re.findall(r"HSL_M_start_([ar]_ arc _zu)", text)}
    # fragments of the extraction, not names
    return {n for n in names if not n.endswith("_")} - {"HSL_4XMO", "HSL_M_v", "HSL_M_start"}


def test_every_manual_name_is_in_the_table_and_implemented():
    if MANUAL.exists():
        names = manual_names()
        assert len(names) == 93
        assert names == set(functions.MANUAL_NAMES)
    for e in functions.TABLE:
        assert callable(getattr(HslLibrary, e.name)), e.name
        assert e.status == "done"
        assert e.origin in ("manual", "header", "ours")
    assert len({e.name for e in functions.TABLE}) == len(functions.TABLE)


def test_the_docs_carry_the_generated_table():
    doc = (ROOT / "docs" / "porting-hsl.md").read_text(encoding="utf-8")
    assert functions.markdown() in doc


def test_misspellings_are_the_same_functions():
    h = HslLibrary
    assert h.HSL_M_get_currebt_speed is h.HSL_M_get_current_speed
    assert h.HSL_M_diable_softlimit is h.HSL_M_disable_softlimit
    assert h.HSL_M_build_comp_table is h.HSL_M_build_compare_table
    assert h.HSL_M_start_tv_move is h.HSL_M_tv_move


def test_set_sd_mode_1_slows_down_and_stops():
    """HSL_M_set_sd(..., sd_mode=1): SD active makes a decelerating stop (core
    Safety.set_sd(stop=True)); sd_mode 0 keeps the slow run at StrVel."""
    from openmotion.compat.hsl import HslLibrary

    hsl = HslLibrary.simulated(1)
    assert hsl.HSL_initial(0) == 0
    ctl = hsl.controller(0)
    logic = 1 if ctl.axes[0].config.signal_logic("sd") == "nc" else 0
    assert hsl.HSL_M_set_sd(0, 1, logic, 0, 1) == 0
    assert ctl.safety.settings(0).sd_stop
    assert hsl.HSL_M_set_sd(0, 1, logic, 0, 0) == 0
    assert not ctl.safety.settings(0).sd_stop
    assert hsl.HSL_M_set_sd(0, 1, logic, 0, 2) < 0      # a bad mode: refused, unchanged
    assert not ctl.safety.settings(0).sd_stop
