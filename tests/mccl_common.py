"""MCCL facade set-ups shared by tests/test_mccl_*.py (pytest puts tests/ on sys.path)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from openmotion.compat.mccl import (
    MCCL,
    SYS_CARD_CONFIG,
    SYS_GROUP_CONFIG,
    SYS_GROUP_INFO,
    SYS_MACH_PARAM,
)


def manual_param(**kw: Any) -> SYS_MACH_PARAM:
    """The manual's example mechanism parameters (2.4), with overrides."""
    p = SYS_MACH_PARAM()
    for k, v in kw.items():
        setattr(p, k, v)
    return p


def open_lib(period_ms: int = 5, groups: dict[int, list[int]] | None = None,
             param: SYS_MACH_PARAM | None = None, cards: int = 1,
             axis_setup: Callable[[int, int], dict] | None = None) -> MCCL:
    """An initialised library: `groups` maps a group to its x, y, z, u channels of card 0
    (default: MCCL's own default, group 0 on channels 0..3)."""
    lib = MCCL(axis_setup=axis_setup)
    for card in range(cards):
        for ch in range(4):
            assert lib.MCC_SetMachParam(param or manual_param(), ch, card) == 0
    if groups is not None:
        cfg = SYS_GROUP_CONFIG()
        for g, chans in groups.items():
            cfg.nGroupUsed[g] = 0
            cfg.stGroupInfo[g] = SYS_GROUP_INFO(0, list(chans) + [-1] * (6 - len(chans)))
        assert lib.MCC_SetGroupConfig(cfg) == 0
    rc = lib.MCC_InitSystem(period_ms, [SYS_CARD_CONFIG() for _ in range(cards)], cards)
    assert rc == 0, lib.last_error
    return lib


def per_period_pulses(lib: MCCL, axis: int, t0: float, t1: float) -> np.ndarray:
    """Pulses the axis sent in each interpolation period between t0 and t1."""
    ctl = lib.controller
    T = ctl.period
    n0, n1 = round(t0 / T), round(t1 / T)
    t = np.arange(n0, n1 + 1) * T
    p = ctl.history.sample(axis, t).p
    return np.diff(p)


def state_of(lib: MCCL) -> tuple:
    """Everything a refused call must leave unchanged."""
    ctl = lib.controller
    out: list[Any] = [ctl.time if ctl else None]
    for g, gs in sorted(lib._groups.items()):
        grp = gs.group
        out.append((g, grp.state, grp.queue_length, grp._feed, grp.acc_time, grp.dec_time,
                    grp.ptp_times, grp.ptp_settings, grp.override, grp.period_pulse_caps,
                    tuple(grp.position), gs.coord, gs.unit, gs.acc_type, gs.ot_check,
                    grp._next_index, grp.error_code, grp.dry_run, grp._blend))
    if ctl is not None:
        out.append(tuple(a.snapshot() for a in ctl.axes))
    out.append((lib._home_acc_step, lib._home_dec_step, dict(lib._pulse_caps),
                len(lib._comp_params), lib._dry))
    return tuple(out)
