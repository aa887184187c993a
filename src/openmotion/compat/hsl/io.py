"""HSL motion I/O, counters, comparators, compensation and homing functions.

Wiring settings (signal logic, pulse output and encoder input modes) describe how the
module is wired to the machine; in openmotion that is the module's machine section. A
setting that agrees with it returns 0; one that contradicts it returns ERR_ConfigMismatch
naming the machine-file key to change, and nothing changes (a simulated contact cannot be
rewired by software). Codes: logic 0 = as wired normally open / not inverted ("no"),
1 = normally closed / inverted ("nc") - our assumption (the seed gives no values).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from ...control.cards.network import GET_U16, GET_U32, SET_U16, SET_U32, SHORT, SIMPLE
from ...control.guard.safety import Safety
from ...control.home.homing import escape_home, home_move, home_search
from ...control.home.homing_modes import HomeConfig
from ...control.home.latch import Latch
from ...control.loops.compensation import Compensation
from ...control.trigger.compare import CompareEngine
from ...control.trigger.hsl_trigger import HslTrigger
from ...errors import check_finite, check_int
from .base import HslBase, Module, hsl_call
from .errors import (
    ERR_ConfigMismatch,
    ERR_InvalidParameter,
    ERR_NotSupported,
    Refusal,
)

LOGIC = ("no", "nc")
#: pls_outmode codes (PCI-8164 order, Motion Creator 5.3 list) -> machine pulse_mode.
PLS_OUTMODES = {0: "out_dir_lo", 1: "out_dir", 2: "out_dir_lo_inv", 3: "out_dir_inv",
                4: "cw_ccw", 5: "cw_ccw"}
#: pls_iptmode codes -> machine encoder_mode (Motion Creator: 1X, 2X, 4X A/B, CW/CCW).
PLS_IPTMODES = {0: "ab_x1", 1: "ab_x2", 2: "ab_x4", 3: "cw_ccw"}
#: erc_on_time codes -> ERC pulse width (s), PCL6045 widths; 7 = level (held 1 s here).
ERC_WIDTHS = {0: 12e-6, 1: 102e-6, 2: 409e-6, 3: 1.6e-3, 4: 13e-3, 5: 52e-3, 6: 104e-3,
              7: 1.0}
#: CmpSrc, CmpMethod, CmpAction codes (seed-facts 2.5, [low]).
CMP_SOURCES = {0: "command", 1: "feedback", 2: "error", 3: "general"}
CMP_METHODS = {1: "=", 2: "=+", 3: "=-", 4: ">", 5: "<"}
CMP_ACTIONS = {0: "event", 1: "stop", 2: "slow_stop", 3: "change_speed"}
#: CntSrc of the general counter, in the manual's order (4.9).
GENERAL_SOURCES = {0: "command", 1: "feedback", 2: "manual", 3: "clock"}
#: get_latch_data LatchNo: the four counters (ours).
LATCH_COUNTERS = {0: "command", 1: "feedback", 2: "error", 3: "general"}
#: Compensation output limits (pps^2): the PCL6045 outputs correction pulses at the FA
#: speed; ours is this acceleration budget.
COMP_ACCEL = 1e9


def _code(name: str, value: Any, table: dict[int, Any]) -> Any:
    if isinstance(value, bool) or not isinstance(value, int) or value not in table:
        raise Refusal(ERR_InvalidParameter, f"{name} must be one of {sorted(table)}, "
                      f"got {value!r}")
    return table[value]


def _flag(name: str, value: Any) -> bool:
    return bool(_code(name, value, {0: 0, 1: 1}))


class IoFunctions(HslBase):
    """Motion I/O, counters, compare, compensation, homing."""

    # ------------------------------------------------------------------ wiring checks
    def _wired(self, ax: Any, signals: tuple[str, ...], logic: Any, fn: str) -> None:
        want = LOGIC[_flag("logic", logic)]
        for s in signals:
            have = ax.config.signal_logic(s)
            if have != want:
                raise Refusal(ERR_ConfigMismatch,
                              f"axis {ax.name}: {fn} asks for {s} {want!r} but the machine "
                              f"file wires it {have!r} (axes.{ax.name}.logic.{s})")

    def _safety(self, mod: Module) -> Safety:
        s = mod.ctl.safety
        if s is None:
            raise Refusal(ERR_NotSupported, f"module {mod.index} has no motion I/O safety")
        return s

    # ------------------------------------------------------------------ motion I/O
    @hsl_call(SET_U16)
    def HSL_M_set_alm(self, axis: int, alm_logic: int, alm_mode: int) -> None:
        """ALM logic (as wired) and reaction: 0 stop at once, 1 decelerate and stop."""
        mod, ax = self._axis(axis)
        mode = _flag("alm_mode", alm_mode)
        self._wired(ax, ("alm",), alm_logic, "set_alm")
        self._safety(mod).set_alm(ax.index, int(mode))

    @hsl_call(SET_U16)
    def HSL_M_set_el(self, axis: int, el_mode: int) -> None:
        """End-limit reaction: 0 stop at once, 1 decelerate to StrVel and stop."""
        mod, ax = self._axis(axis)
        self._safety(mod).set_el(ax.index, int(_flag("el_mode", el_mode)))

    @hsl_call(SET_U16)
    def HSL_M_set_el_logic(self, axis: int, el_logic: int) -> None:
        """End-limit contacts: 0 normally open, 1 normally closed (as wired)."""
        _, ax = self._axis(axis)
        self._wired(ax, ("pel", "mel"), el_logic, "set_el_logic")

    @hsl_call(SET_U16)
    def HSL_M_set_inp(self, axis: int, inp_enable: int, inp_logic: int) -> None:
        """Wait for INP before a move is done (inp_enable 1); INP logic as wired."""
        mod, ax = self._axis(axis)
        on = _flag("inp_enable", inp_enable)
        self._wired(ax, ("inp",), inp_logic, "set_inp")
        self._safety(mod).set_inp(ax.index, on)

    @hsl_call(SET_U16)
    def HSL_M_set_erc(self, axis: int, erc_logic: int, erc_on_time: int) -> None:
        """ERC one-shot width code 0..7 (12 us .. 104 ms, 7 level); erc_logic 0/1 (the
        simulated output is logical)."""
        mod, ax = self._axis(axis)
        _flag("erc_logic", erc_logic)
        width = _code("erc_on_time", erc_on_time, ERC_WIDTHS)
        self._safety(mod).set_erc(ax.index, width)

    @hsl_call(SET_U16)
    def HSL_M_set_sd(self, axis: int, enable: int, sd_logic: int, sd_latch: int,
                     sd_mode: int) -> None:
        """Slow-down input: enable, logic (as wired), 1 = latched, sd_mode 0 (slow to
        StrVel) or 1 (slow down and stop)."""
        mod, ax = self._axis(axis)
        on = _flag("enable", enable)
        latch = _flag("sd_latch", sd_latch)
        stop = _flag("sd_mode", sd_mode)
        self._wired(ax, ("sd",), sd_logic, "set_sd")
        self._safety(mod).set_sd(ax.index, on, latched=latch, stop=stop)

    @hsl_call(SET_U16)
    def HSL_M_set_ltc_logic(self, axis: int, ltc_logic: int) -> None:
        """LTC logic (as wired); the latch is always on (4.8)."""
        mod, ax = self._axis(axis)
        self._wired(ax, ("ltc",), ltc_logic, "set_ltc_logic")
        self._latch(mod)

    @hsl_call(SET_U16)
    def HSL_M_set_pls_outmode(self, axis: int, pls_outmode: int) -> None:
        """Pulse output mode 0..5 (OUT/DIR edges and levels, CW/CCW), as wired."""
        _, ax = self._axis(axis)
        want = _code("pls_outmode", pls_outmode, PLS_OUTMODES)
        have = ax.config.pulse_mode
        if have != want:
            raise Refusal(ERR_ConfigMismatch, f"axis {ax.name}: pls_outmode {pls_outmode} "
                          f"is {want!r} but the machine file says {have!r} "
                          f"(axes.{ax.name}.pulse_mode)")

    @hsl_call(SET_U16)
    def HSL_M_set_pls_iptmode(self, axis: int, pls_iptmode: int, pls_logic: int = 0) -> None:
        """Encoder input mode 0..3 (1X/2X/4X A/B, CW/CCW); pls_logic 1 = reversed (A/B
        swapped), as wired."""
        _, ax = self._axis(axis)
        want = _code("pls_iptmode", pls_iptmode, PLS_IPTMODES)
        rev = _flag("pls_logic", pls_logic)
        have = ax.config.encoder_mode
        if have != want or ax.config.swap_ab != rev:
            raise Refusal(ERR_ConfigMismatch, f"axis {ax.name}: pls_iptmode {pls_iptmode}, "
                          f"pls_logic {pls_logic} is {want!r}, swap_ab {rev} but the machine "
                          f"file says {have!r}, swap_ab {ax.config.swap_ab}")

    @hsl_call(SET_U16)
    def HSL_M_set_feedback_src(self, axis: int, Src: int) -> None:
        """Feedback counter source: 1 the EA/EB input (default), 0 the output pulses."""
        _, ax = self._axis(axis)
        ext = _flag("Src", Src)
        ax.counters.set_feedback_source("external" if ext else "internal")

    @hsl_call(SET_U16)
    def HSL_M_Set_Servo(self, axis: int, on_off: int) -> None:
        """SVON output: 1 servo on (the axis is enabled), 0 off."""
        mod, ax = self._axis(axis)
        self._safety(mod).set_servo(ax.index, _flag("on_off", on_off))

    HSL_M_set_servo = HSL_M_Set_Servo   # 5.3 spells it in lower case

    @hsl_call(GET_U16)
    def HSL_M_get_io_status(self, axis: int) -> int:
        """Motion I/O bits: 0 RDY, 1 ALM, 2 +EL, 3 -EL, 4 ORG, 5 DIR, 6 EMG, 7 PCS, 8 ERC,
        9 EZ, 10 CLR, 11 LTC, 12 SD, 13 INP, 14 SVON (seed-facts 2.4)."""
        mod, ax = self._axis(axis)
        return int(self._safety(mod).io_status(ax.index))

    # ------------------------------------------------------------------ counters
    @hsl_call(GET_U32)
    def HSL_M_get_position(self, axis: int) -> float:
        """Feedback position counter."""
        _, ax = self._axis(axis)
        return float(ax.counters.feedback)

    @hsl_call(SET_U32)
    def HSL_M_set_position(self, axis: int, Pos: float) -> None:
        """Set the feedback counter (then reset_target_pos, 4.9)."""
        _, ax = self._axis(axis)
        ax.counters.set_feedback(Pos)

    @hsl_call(GET_U32)
    def HSL_M_get_command(self, axis: int) -> int:
        """Command position counter."""
        _, ax = self._axis(axis)
        return int(ax.counters.command)

    @hsl_call(SET_U32)
    def HSL_M_set_command(self, axis: int, Cmd: int) -> None:
        _, ax = self._axis(axis)
        ax.counters.set_command(Cmd)

    @hsl_call(GET_U32)
    def HSL_M_get_error_counter(self, axis: int) -> int:
        """Position error counter (command - feedback / move ratio)."""
        _, ax = self._axis(axis)
        return int(ax.counters.error)

    @hsl_call(SIMPLE)
    def HSL_M_reset_error_counter(self, axis: int) -> None:
        _, ax = self._axis(axis)
        ax.counters.reset_error()

    @hsl_call(GET_U32)
    def HSL_M_get_general_counter(self, axis: int) -> float:
        _, ax = self._axis(axis)
        return float(ax.counters.general)

    @hsl_call(SET_U32)
    def HSL_M_set_general_counter(self, axis: int, CntSrc: int, Value: float) -> None:
        """General counter source (0 output pulses, 1 feedback, 2 manual pulse, 3 clock) and
        value."""
        _, ax = self._axis(axis)
        src = _code("CntSrc", CntSrc, GENERAL_SOURCES)
        ax.counters.set_general(Value, src)

    @hsl_call(GET_U32)
    def HSL_M_get_target_pos(self, axis: int) -> float:
        """The software target recorder."""
        _, ax = self._axis(axis)
        return float(ax.counters.target)

    @hsl_call(SET_U32)
    def HSL_M_reset_target_pos(self, axis: int, Pos: float = 0.0) -> None:
        """Set the target recorder (after homing or set_position, 4.9)."""
        _, ax = self._axis(axis)
        ax.counters.reset_target(check_finite("Pos", Pos))

    def _latch(self, mod: Module) -> Latch:
        if mod.latch is None:
            mod.latch = Latch(mod.ctl)
        return mod.latch

    @hsl_call(GET_U32)
    def HSL_M_get_latch_data(self, axis: int, LatchNo: int) -> float:
        """A counter captured at the last LTC edge: LatchNo 0 command, 1 feedback, 2 error,
        3 general (ours). NaN before any capture."""
        mod, ax = self._axis(axis)
        name = _code("LatchNo", LatchNo, LATCH_COUNTERS)
        data = self._latch(mod).data(ax.index)
        return math.nan if data is None else float(getattr(data, name))

    # ------------------------------------------------------------------ comparators
    @hsl_call(SET_U32)
    def HSL_M_set_softlimit(self, axis: int, PLimit: float, NLimit: float) -> None:
        """Soft limits on the command counter (comparators 1 and 2)."""
        mod, ax = self._axis(axis)
        self._safety(mod).soft.set(ax.index, PLimit, NLimit)

    @hsl_call(SET_U16)
    def HSL_M_enable_softlimit(self, axis: int, Action: int = 0) -> None:
        """Turn the soft limits on: Action 0 stop at once, 1 decelerate."""
        mod, ax = self._axis(axis)
        self._safety(mod).soft.enable(ax.index, int(_flag("Action", Action)))

    @hsl_call(SET_U16)
    def HSL_M_disable_softlimit(self, axis: int) -> None:
        mod, ax = self._axis(axis)
        self._safety(mod).soft.disable(ax.index)

    HSL_M_diable_softlimit = HSL_M_disable_softlimit     # the manual's spelling (4.12, 4.14)
    HSL_M_set_soft_limit = HSL_M_set_softlimit           # the header's spellings
    HSL_M_enable_soft_limit = HSL_M_enable_softlimit
    HSL_M_disable_soft_limit = HSL_M_disable_softlimit

    @hsl_call(SET_U16)
    def HSL_M_error_counter_check(self, axis: int, Tolerance: int, On_Off: int) -> None:
        """Comparator 3: step-loss detection when |error counter| > Tolerance."""
        mod, ax = self._axis(axis)
        on = _flag("On_Off", On_Off)
        self._safety(mod).cmp.set_error_counter_check(ax.index, Tolerance, on)

    HSL_M_set_error_counter_check = HSL_M_error_counter_check  # 4.12 / header spelling

    @hsl_call(SET_U32)
    def HSL_M_set_general_comparator(self, axis: int, CmpSrc: int, CmpMethod: int,
                                     CmpAction: int, Data: float) -> None:
        """Comparator 4: source 0..3, method 0 off, 1 =, 2 = counting up, 3 = counting
        down, 4 >, 5 <; action 0 event,
        1 stop, 2 decelerate and stop, 3 change speed (cmp_v_change)."""
        mod, ax = self._axis(axis)
        cmp = self._safety(mod).cmp
        if CmpMethod == 0 and not isinstance(CmpMethod, bool):
            cmp.clear_general_comparator(ax.index)
            return
        src = _code("CmpSrc", CmpSrc, CMP_SOURCES)
        method = _code("CmpMethod", CmpMethod, CMP_METHODS)
        action = _code("CmpAction", CmpAction, CMP_ACTIONS)
        cmp.set_general_comparator(ax.index, src, method, action, Data)

    @hsl_call(SET_U32)
    def HSL_M_cmp_v_change(self, axis: int, NewVel: float, Tacc: float) -> None:
        """The speed change comparator 4's action 3 applies."""
        mod, ax = self._axis(axis)
        self._safety(mod).cmp.cmp_v_change(ax.index, NewVel, Tacc)

    def _trigger(self, mod: Module, local: int) -> HslTrigger:
        if local not in (0, 1):
            raise Refusal(ERR_NotSupported, "the trigger comparator (comparator 5) exists on "
                          "the first two axes of a module only (4.12)")
        if mod.trigger is None:
            mod.trigger = HslTrigger(CompareEngine(mod.ctl))
        return mod.trigger

    @hsl_call(SET_U32)
    def HSL_M_set_trigger_comparator(self, axis: int, CmpSrc: int, Method: int,
                                     Data: float) -> None:
        """Comparator 5 (axes 0, 1 of a module): source 0 command / 1 feedback, method
        0 off, 1 =, 2 = up, 3 = down, 4 >, 5 <; a hit pulses CMP."""
        mod, ax = self._axis(axis)
        self._trigger(mod, ax.index).set_trigger_comparator(ax.index, CmpSrc, Method, Data)

    @hsl_call(SET_U16)
    def HSL_M_set_trigger_type(self, axis: int, Type: int) -> None:
        """CMP output: 0 normal high (falling-edge pulse, default), 1 normal low."""
        mod, ax = self._axis(axis)
        self._trigger(mod, ax.index).set_trigger_type(ax.index, Type)

    @hsl_call(SHORT)
    def HSL_M_build_compare_function(self, axis: int, Start: float, End: float,
                                     Interval: float) -> None:
        """Load Start, Start + Interval, ... End (+ the after-final dummy) for auto compare."""
        mod, ax = self._axis(axis)
        self._trigger(mod, ax.index).build_compare_function(ax.index, Start, End, Interval)

    @hsl_call(SHORT)
    def HSL_M_build_compare_table(self, axis: int, tableArray: Any, Size: int) -> None:
        """Load `Size` values of `tableArray` (the last is the after-final dummy)."""
        mod, ax = self._axis(axis)
        self._trigger(mod, ax.index).build_compare_table(ax.index, tableArray, Size)

    HSL_M_build_comp_function = HSL_M_build_compare_function   # the manual's 4.12 spelling
    HSL_M_build_comp_table = HSL_M_build_compare_table

    @hsl_call(SET_U16)
    def HSL_M_set_auto_compare(self, axis: int, SelectSource: int) -> None:
        """1: start comparing the loaded list, 0: stop."""
        mod, ax = self._axis(axis)
        self._trigger(mod, ax.index).set_auto_compare(ax.index, SelectSource)

    @hsl_call(GET_U32)
    def HSL_M_check_compare_data(self, axis: int, CompType: int) -> float:
        """The value a comparator holds now: 1 +soft limit, 2 -soft limit, 3 error-counter
        tolerance, 4 general comparator, 5 trigger comparator (NaN when none)."""
        mod, ax = self._axis(axis)
        check_int("CompType", CompType, 1, 5)
        saf = self._safety(mod)
        if CompType == 5:
            v = self._trigger(mod, ax.index).check_compare_data(ax.index)
        elif CompType == 4:
            g = saf.cmp.general_comparator(ax.index)
            v = None if g is None else g[3]
        elif CompType == 3:
            v = saf.cmp.error_counter_check(ax.index)
        else:
            lim = saf.soft.get(ax.index)
            v = lim.plimit if CompType == 1 else lim.nlimit
        return math.nan if v is None or math.isinf(v) else float(v)

    @hsl_call(GET_U16)
    def HSL_M_check_compare_status(self, axis: int) -> int:
        """1 while the auto-trigger runs on `axis`."""
        mod, ax = self._axis(axis)
        return int(self._trigger(mod, ax.index).check_compare_status(ax.index))

    # ------------------------------------------------------------------ compensation
    def _comp(self, mod: Module, ax: Any) -> Compensation:
        c = mod.comp.get(ax.index)
        if c is None:
            c = Compensation(ax, max_accel=COMP_ACCEL)
            mod.comp[ax.index] = c
        return c

    @hsl_call(SET_U16)
    def HSL_M_backlash_comp(self, axis: int, BCompPulse: int, Mode: int) -> None:
        """Backlash pulses (0..32767) output on every direction change; Mode 1 on, 0 off."""
        mod, ax = self._axis(axis)
        check_int("BCompPulse", BCompPulse, 0, 32767)
        _flag("Mode", Mode)
        self._comp(mod, ax).backlash_comp(BCompPulse, Mode)

    @hsl_call(SET_U16)
    def HSL_M_suppress_vibration(self, axis: int, T1: int, T2: int) -> None:
        """After each move one reverse pulse T1 later, one forward pulse T2 after it;
        T1, T2 in microseconds 0..65535 (ours: the unit is not in the seed)."""
        mod, ax = self._axis(axis)
        t1 = check_int("T1", T1, 0, 65535)
        t2 = check_int("T2", T2, 0, 65535)
        self._comp(mod, ax).suppress_vibration(t1 * 1e-6, t2 * 1e-6)

    # ------------------------------------------------------------------ homing
    @hsl_call(SET_U16)
    def HSL_M_set_home_config(self, axis: int, home_mode: int, org_logic: int,
                              ez_logic: int, ez_count: int, erc_out: int) -> None:
        """Home mode 0..12, ORG and EZ logic (as wired), EZ count 0..15, ERC at the end."""
        mod, ax = self._axis(axis)
        check_int("home_mode", home_mode, 0, 12)
        check_int("ez_count", ez_count, 0, 15)
        erc = _flag("erc_out", erc_out)
        self._wired(ax, ("org",), org_logic, "set_home_config")
        self._wired(ax, ("ez",), ez_logic, "set_home_config")
        cfg = mod.home.setdefault(ax.index, {})
        cfg.update(mode=home_mode, ez_count=ez_count, erc=erc)

    @hsl_call(SET_U32)
    def HSL_M_set_org_offset(self, axis: int, ORG_ESC_Offset: float) -> None:
        """The escape distance after leaving ORG (home_search, escape_home)."""
        mod, ax = self._axis(axis)
        off = check_finite("ORG_ESC_Offset", ORG_ESC_Offset)
        HomeConfig(org_offset=abs(off))  # validates
        mod.home.setdefault(ax.index, {})["org_offset"] = abs(off)

    def _home_config(self, mod: Module, ax: Any, StrVel: float, MaxVel: float, Tacc: float,
                     **extra: Any) -> HomeConfig:
        v = check_finite("MaxVel", MaxVel)
        s = self._home_settings(mod, ax)
        if s.get("erc"):
            saf = self._safety(mod)
            if saf.settings(ax.index).erc_width <= 0.0:
                saf.set_erc(ax.index, ERC_WIDTHS[0])
        return HomeConfig(mode=s["mode"], direction=-1 if v < 0 else 1,
                          str_vel=abs(check_finite("StrVel", StrVel)), max_vel=abs(v),
                          tacc=Tacc, ez_count=s["ez_count"],
                          org_offset=s.get("org_offset", 0.0), final="stay", **extra)

    def _home_settings(self, mod: Module, ax: Any) -> dict[str, Any]:
        return {"mode": 0, "ez_count": 0, "erc": False, **mod.home.get(ax.index, {})}

    @hsl_call(SHORT)
    def HSL_M_home_move(self, axis: int, StrVel: float, MaxVel: float, Tacc: float) -> None:
        """Home return in the configured mode; the sign of MaxVel is the direction. The
        command, feedback, error and general counters read 0 at the end; the target
        recorder does not (reset_target_pos)."""
        mod, ax = self._axis(axis)
        cfg = self._home_config(mod, ax, StrVel, MaxVel, Tacc)
        mod.homing[ax.index] = home_move(mod.ctl, ax.index, cfg)

    @hsl_call(SHORT)
    def HSL_M_home_search(self, axis: int, StrVel: float, MaxVel: float, Tacc: float,
                          ORGOffset: float) -> None:
        """Auto home search (figure 4-29): an end limit met on the way reverses the axis,
        past ORG by ORGOffset, then ORG is searched again slowly."""
        mod, ax = self._axis(axis)
        cfg = self._home_config(mod, ax, StrVel, MaxVel, Tacc)
        off = abs(check_finite("ORGOffset", ORGOffset))
        mod.homing[ax.index] = home_search(mod.ctl, ax.index, replace(cfg, org_offset=off))

    @hsl_call(SHORT)
    def HSL_M_escape_home(self, axis: int, StrVel: float, MaxVel: float, Tacc: float) -> None:
        """Leave ORG against the home direction, then by the ORG offset."""
        mod, ax = self._axis(axis)
        cfg = self._home_config(mod, ax, StrVel, MaxVel, Tacc)
        mod.homing[ax.index] = escape_home(mod.ctl, ax.index, cfg)
