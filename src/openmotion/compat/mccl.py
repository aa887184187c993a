"""The HIWIN MCCL library (PCI-4P cards) in Python: `openmotion.compat.mccl`.

Every function of the HIWIN PCI-4P motion library user's manual (Mar. 2005) under its
MCCL name, with the header's return codes (mccl_defs): a command returns its index
(>= 0) when accepted, a negative code when refused (nothing changed), and no call raises.
Structures are dataclasses with the manual's field names. The functions run on a
simulated machine (one controller, four channels per card) built by MCC_InitSystem;
`MCCL.controller` is that controller, `MCCL.advance(seconds)` lets virtual time pass.

Python differences: C out-parameters of structures are filled in place
(MCC_GetMachParam, MCC_GetCurCommand); scalar out-parameters come back as a tuple
(return code, values...); group and card indices are the last arguments as in C.
Module-level MCC_* names call one library instance, as the DLL holds one state.
The rules (speed caps, homing phases, working interval, delays, compensation, in-position)
are the core's; this module maps arguments and codes only. docs/porting-mccl.md lists
every function and its status.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from openmotion.control.core.states import AxisState
from openmotion.control.groups import group as G
from openmotion.control.guard.inposition import INPOS_TIMEOUT
from openmotion.control.guard.softlimits import working_interval
from openmotion.control.home.homing_modes import HomeConfig
from openmotion.control.home.homing_sequence import HomeSequence
from openmotion.control.loops.compensation import Compensation, PitchCompTable
from openmotion.control.manual.jog import MAX_JOG_PULSES
from openmotion.errors import MotionError, check_nonnegative

from . import mccl_defs as D
from .mccl_base import GroupSlot, Refused, _api, _int, _num
from .mccl_defs import *  # noqa: F403 - the header's names, as `#include "MCCL.h"`
from .mccl_motion import MCCLMotion

_HOME_MODES = {D.NORMAL_MODE: "mccl_normal", D.HOME_ONLY_MODE: "mccl_home_only",
               D.INDEX_ONLY_MODE: "mccl_index_only"}


class MCCL(MCCLMotion):
    """One MCCL library state (the DLL's): see the module doc."""

    # ------------------------------------------------------------------ virtual time
    def advance(self, seconds: float) -> None:
        """Let `seconds` of virtual time pass (the cards run their queues)."""
        if self.controller is not None:
            self.controller.advance(check_nonnegative("seconds", seconds))

    def wait_motion(self, wGroupIndex: int = 0, timeout: float = 60.0) -> bool:
        """Run until the group stops (GMS_STOP) or `timeout` s pass; True when it did."""
        if self.controller is None or wGroupIndex not in self._groups:
            return False
        return self.controller.run_until(
            lambda: self.MCC_GetMotionStatus(wGroupIndex) == D.GMS_STOP, timeout)

    # ------------------------------------------------------------------ limits
    def _apply_soft_limits(self, gs: GroupSlot) -> None:
        """Over-travel check of the group's axes: soft limits at the working interval."""
        ctl = self._ctl()
        soft = ctl.safety.soft if ctl.safety is not None else None
        if soft is None:
            return
        for s, ax in zip(gs.slots, gs.group.axes, strict=True):
            lo, hi = self._interval_pulses(ax)
            if lo < hi:
                soft.set(ax.index, hi, lo)
            if gs.ot_check[s]:
                soft.enable(ax.index, "immediate")
            else:
                soft.disable(ax.index)

    @_api
    def MCC_SetOverTravelCheck(self, nOTCheck0: int, nOTCheck1: int, nOTCheck2: int,
                               nOTCheck3: int, nOTCheck4: int = 0, nOTCheck5: int = 0,
                               wGroupIndex: int = 0) -> int:
        """Software limit check per axis x..w (1 on, 0 off; 2.6.1 IV): the command
        position stays in the working interval [dfLowLimit + dfLowLimitOffset,
        dfHighLimit - dfHighLimitOffset]; a command that would leave it is refused."""
        gs = self._g(wGroupIndex)
        flags = tuple(_int(f"nOTCheck{k}", v, 0, 1) for k, v in enumerate(
            (nOTCheck0, nOTCheck1, nOTCheck2, nOTCheck3, nOTCheck4, nOTCheck5)))
        old = gs.ot_check
        gs.ot_check = flags
        try:
            self._apply_soft_limits(gs)
        except BaseException:
            gs.ot_check = old
            self._apply_soft_limits(gs)
            raise
        return D.NO_ERR

    @_api
    def MCC_GetOverTravelCheck(self, wGroupIndex: int = 0) -> tuple[int, ...]:
        return (D.NO_ERR, *self._g(wGroupIndex).ot_check)

    @_api
    def MCC_EnableLimitSwitchCheck(self, nMode: int = 0) -> int:
        """Limit switch check (2.4): mode 0 stops a group whose axis moves into the
        switch ahead of it, mode 1 stops it on any engaged switch of a moving axis. The
        core always applies mode 0 (openmotion's safety rule: limits stop motion)."""
        self._ctl()
        m = _int("nMode", nMode, 0, 1)
        for gs in self._groups.values():
            gs.group.set_limit_mode("any" if m == 1 else "direction")
        self._limit_check = True
        return D.NO_ERR

    @_api
    def MCC_DisableLimitSwitchCheck(self) -> int:
        """Back to mode 0: switches ahead still stop motion (the safety rule)."""
        self._ctl()
        for gs in self._groups.values():
            gs.group.set_limit_mode("direction")
        self._limit_check = False
        return D.NO_ERR

    @_api
    def MCC_GetLimitSwitchStatus(self, wUpDown: int, wChannel: int,
                                 wCardIndex: int = 0) -> tuple[int, int]:
        """(NO_ERR, 1 engaged / 0): wUpDown 0 the positive (OT+), 1 the negative (OT-)."""
        ud = _int("wUpDown", wUpDown, 0, 1)
        ax = self._axis(wChannel, wCardIndex)
        return D.NO_ERR, int(self._ctl().input_active(ax.index, "pel" if ud == 0 else "mel"))

    # ------------------------------------------------------------------ jog
    def _jog_group(self, cAxis: object, wGroupIndex: int) -> tuple[GroupSlot, int]:
        gs = self._g(wGroupIndex)
        a = _int("cAxis", cAxis, 0, 5)
        if a not in gs.slots:
            raise Refused(D.GROUP_PARAMETER_ERR, f"axis {a} is not dispatched in group "
                                                 f"{wGroupIndex}")
        return gs, gs.slots.index(a)

    @_api
    def MCC_JogPulse(self, nPulse: int, cAxis: int, wGroupIndex: int = 0) -> int:
        """Jog by pulses (|nPulse| 1..2048), only when the group has no motion (2.6.2
        III A); the command index."""
        gs, k = self._jog_group(cAxis, wGroupIndex)
        n = _int("nPulse", nPulse, -MAX_JOG_PULSES, MAX_JOG_PULSES)
        if n == 0:
            raise Refused(D.PARAMETER_ERR, "nPulse must be non-zero")
        if not self._idle(gs):
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "MCC_JogPulse needs a group at rest")
        g = gs.group
        d = [0.0] * len(gs.slots)
        d[k] = n / float(g._k[k])
        return g.ptp(d, relative=True, ratio=g.ptp_settings[0])

    @_api
    def MCC_JogSpace(self, dfOffset: float, dfRatio: float, cAxis: int,
                     wGroupIndex: int = 0) -> int:
        """Short-stroke jog of dfOffset (unit) at dfRatio % of the maximum safe speed."""
        gs, k = self._jog_group(cAxis, wGroupIndex)
        off = _num("dfOffset", dfOffset) * gs.scale
        if off == 0.0:
            raise Refused(D.PARAMETER_ERR, "dfOffset must be non-zero")
        d = [0.0] * len(gs.slots)
        d[k] = off
        return gs.group.ptp(d, relative=True, ratio=_num("dfRatio", dfRatio))

    @_api
    def MCC_JogConti(self, nDir: int, dfRatio: float, cAxis: int,
                     wGroupIndex: int = 0) -> int:
        """Continuous jog (nDir 0 positive, 1 negative) at dfRatio %: it stops at the
        border of the working interval (2.6.2 III C), or by MCC_AbortMotion."""
        gs, k = self._jog_group(cAxis, wGroupIndex)
        d = _int("nDir", nDir, 0, 1)
        ax = gs.group.axes[k]
        card, ch = divmod(ax.index, D.CHANNELS_PER_CARD)
        p = self._param(ch, card)
        lo, hi = working_interval(p.dfHighLimit, p.dfLowLimit, p.dfHighLimitOffset,
                                  p.dfLowLimitOffset)
        target = gs.group.end_point
        border = hi if d == 0 else lo
        if (border - target[k]) * (1 if d == 0 else -1) <= 0.0:
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "the axis is at the border of its "
                                                     "working interval")
        target[k] = border
        return gs.group.ptp(target, ratio=_num("dfRatio", dfRatio))

    # ------------------------------------------------------------------ errors
    @_api
    def MCC_GetErrorCode(self, wGroupIndex: int = 0) -> int:
        """The run-time error of the group (ERROR_* of mccl_defs; 0: none)."""
        gs = self._g(wGroupIndex)
        if self._inpos is not None and self._inpos.error_code == INPOS_TIMEOUT and \
                self._inpos.error_axis in [a.index for a in gs.group.axes]:
            return D.ERROR_INPOS_TIMEOUT
        code = gs.group.error_code
        if code == 0:
            return D.ERROR_NONE
        msg = gs.group.error_message
        if self._ctl().estop_active:
            return D.ERROR_EMERGENCY
        if code == G.ERR_LIMIT:
            return D.ERROR_SOFT_LIMIT if "SL" in msg or "soft" in msg else \
                D.ERROR_LIMIT_SWITCH
        if code in (G.ERR_SPEED,):
            return D.ERROR_OVER_SPEED
        if code in (G.ERR_ACCEL,):
            return D.ERROR_OVER_ACC
        if code == G.ERR_ARC:
            return D.ERROR_ARC
        return D.ERROR_AXIS_FAULT

    @_api
    def MCC_ClearError(self, wGroupIndex: int = 0) -> int:
        """Clear the group's error and reset its axes to normal (2.6.3 VI); refused while
        the cause persists (an emergency stop, a servo alarm)."""
        gs = self._g(wGroupIndex)
        for ax in gs.group.axes:
            ax.reset()
        gs.group.clear_error()
        if self._inpos is not None and self._inpos.error_axis in [a.index for a in
                                                                  gs.group.axes]:
            self._inpos.clear_error()
        return D.NO_ERR

    # ------------------------------------------------------------------ homing
    @_api
    def MCC_SetHomeConfig(self, psHomeConfig: D.HOME_CONFIG, wChannel: int,
                          wCardIndex: int = 0) -> int:
        """The stHome part of an axis's mechanism parameters (seed-facts 5)."""
        if not isinstance(psHomeConfig, D.HOME_CONFIG):
            raise Refused(D.PARAMETER_ERR, "psHomeConfig must be a HOME_CONFIG")
        ch = _int("wChannel", wChannel, 0, D.CHANNELS_PER_CARD - 1)
        card = _int("wCardIndex", wCardIndex, 0, D.MAX_CARD - 1)
        param = self._copy(self._param(ch, card))
        param.stHome = self._copy(psHomeConfig)
        from .mccl_motion import _check_mach

        _check_mach(param)
        self._mach[(card, ch)] = param
        return D.NO_ERR

    @_api
    def MCC_SetGoHomeAccStep(self, wStep: int) -> int:
        """Homing acceleration time = wStep x interpolation time (default 20)."""
        self._home_acc_step = self._step("wStep", wStep)
        return D.NO_ERR

    @_api
    def MCC_SetGoHomeDecStep(self, wStep: int) -> int:
        """Homing deceleration time = wStep x interpolation time (default 20)."""
        self._home_dec_step = self._step("wStep", wStep)
        return D.NO_ERR

    @_api
    def MCC_GoHome(self, dfXSpeed: float, dfYSpeed: float, dfZSpeed: float, dfUSpeed: float,
                   dfVSpeed: float, dfWSpeed: float, nXOrder: int, nYOrder: int,
                   nZOrder: int, nUOrder: int, nVOrder: int = -1, nWOrder: int = -1,
                   wCardIndex: int = 0) -> int:
        """Home channels 0..3 of a card (2.7): phase-0 speed (mm/s) and order of each;
        axes with the same order home together, lower orders first; order < 0: not
        homed. Phases 1-3 run at 1/10 of the speed (the core's MCCL modes)."""
        ctl = self._ctl()
        card = _int("wCardIndex", wCardIndex, 0, self._n_cards - 1)
        if self._home is not None and self._home.state == "running":
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "homing is running")
        speeds = [_num(n, v) for n, v in zip(("dfXSpeed", "dfYSpeed", "dfZSpeed",
                                               "dfUSpeed"), (dfXSpeed, dfYSpeed, dfZSpeed,
                                                             dfUSpeed), strict=True)]
        orders = [_int(n, v, -1, 5) for n, v in zip(("nXOrder", "nYOrder", "nZOrder",
                                                      "nUOrder"), (nXOrder, nYOrder, nZOrder,
                                                                   nUOrder), strict=True)]
        for n, v in (("dfVSpeed", dfVSpeed), ("dfWSpeed", dfWSpeed)):
            _num(n, v)
        for n, v in (("nVOrder", nVOrder), ("nWOrder", nWOrder)):
            _int(n, v, -1, 5)
        T = self._period
        plan: dict[int | str, tuple[HomeConfig, int]] = {}
        for ch in range(D.CHANNELS_PER_CARD):
            if orders[ch] < 0:
                continue
            ax = ctl.axes[card * D.CHANNELS_PER_CARD + ch]
            h = self._param(ch, card).stHome
            if speeds[ch] <= 0.0:
                raise Refused(D.PARAMETER_ERR, f"homing speed of channel {ch} must be > 0")
            v = speeds[ch] * ax.units.pulses_per_unit
            sign = ax.units.sign
            cfg = HomeConfig(mode=_HOME_MODES[h.wType],
                             direction=sign * (1 if h.wPhase0Dir == 0 else -1),
                             str_vel=v / 10.0, max_vel=v, tacc=self._home_acc_step * T,
                             tdec=self._home_dec_step * T,
                             phase1_same_direction=h.wPhase1Dir == h.wPhase0Dir,
                             home_offset=float(round(ax.units.to_pulses(h.dfOffset))))
            plan[ax.index] = (cfg, orders[ch])
        if not plan:
            raise Refused(D.PARAMETER_ERR, "no axis to home (every order < 0)")
        for i in plan:
            ax = ctl.axes[int(i)]
            if ax.is_moving or ax.state is not AxisState.STANDSTILL:
                raise Refused(D.COMMAND_NOTACCEPTED_ERR, f"axis {ax.name} must be at "
                                                         f"standstill (state {ax.state.value})")
        seq = HomeSequence(ctl, plan)
        try:
            seq.start()
        except BaseException:
            seq.abort()  # an axis refused: none keeps homing
            raise
        self._home = seq
        return D.NO_ERR

    @_api
    def MCC_GetGoHomeStatus(self) -> int:
        """1 homing finished, -1 in process, 0 failed or aborted (2.7)."""
        self._ctl()
        if self._home is None:
            raise Refused(D.HOME_COMMAND_NOTCALLED_ERR, "MCC_GoHome has not been called")
        return self._home.code

    @_api
    def MCC_AbortGoHome(self) -> int:
        self._ctl()
        if self._home is None:
            raise Refused(D.HOME_COMMAND_NOTCALLED_ERR, "MCC_GoHome has not been called")
        if self._home.state == "running":
            self._home.abort()
        return D.NO_ERR

    @_api
    def MCC_GetHomeSensorStatus(self, wChannel: int, wCardIndex: int = 0) -> tuple[int, int]:
        """(NO_ERR, 1 on / 0 off) of the HOM input of a channel (2.8.1)."""
        ax = self._axis(wChannel, wCardIndex)
        return D.NO_ERR, int(self._ctl().input_active(ax.index, "org"))

    # ------------------------------------------------------------------ compensation
    @_api
    def MCC_SetCompParam(self, psCompParam: D.SYS_COMP_PARAM, wChannel: int,
                         wCardIndex: int = 0) -> int:
        """Store an axis's compensation table (2.10.1); MCC_UpdateCompParam applies it."""
        if not isinstance(psCompParam, D.SYS_COMP_PARAM):
            raise Refused(D.PARAMETER_ERR, "psCompParam must be a SYS_COMP_PARAM")
        ch = _int("wChannel", wChannel, 0, D.CHANNELS_PER_CARD - 1)
        card = _int("wCardIndex", wCardIndex, 0, D.MAX_CARD - 1)
        p = psCompParam
        if len(p.nForwardTable) != D.MAX_COMP_POINT or len(p.nBackwardTable) != \
                D.MAX_COMP_POINT:
            raise Refused(D.PARAMETER_ERR, f"the tables must hold {D.MAX_COMP_POINT} points")
        _int("dwInterval", p.dwInterval, -2**31, 2**31 - 1)
        _int("wHome_No", p.wHome_No, 0, D.MAX_COMP_POINT - 1)
        self._comp_params[(card, ch)] = self._copy(p)
        return D.NO_ERR

    @_api
    def MCC_UpdateCompParam(self) -> int:
        """Apply every stored table: the slots the working interval needs (its range
        must cover the whole stroke); dwInterval <= 0 disables. All are checked before
        any changes."""
        ctl = self._ctl()
        tables: dict[int, PitchCompTable | None] = {}
        for (card, ch), p in self._comp_params.items():
            if card >= self._n_cards:
                raise Refused(D.PARAMETER_ERR, f"card {card} is not installed")
            ax = ctl.axes[card * D.CHANNELS_PER_CARD + ch]
            if p.dwInterval <= 0:
                tables[ax.index] = None
                continue
            tables[ax.index] = PitchCompTable.from_slots(
                p.dwInterval, p.wHome_No, p.nForwardTable, p.nBackwardTable,
                self._interval_pulses(ax))
        for i, tab in tables.items():
            comp = self._comp.get(i)
            if tab is None:
                if comp is not None:
                    comp.clear_pitch_table()
                continue
            if comp is None:
                ax = ctl.axes[i]
                comp = Compensation(ax, max_accel=30000.0 / (self._period ** 2))
                self._comp[i] = comp
            comp.set_pitch_table(tab.interval, tab.home_index, tab.forward, tab.backward,
                                 stroke=tab.span)
        return D.NO_ERR

    # ------------------------------------------------------------------ in-position
    @_api
    def MCC_SetInPosTolerance(self, pdfTolerance: Sequence[float], wGroupIndex: int = 0) -> int:
        """In-position tolerance of each axis x..w (unit; 2.10.2)."""
        gs = self._g(wGroupIndex)
        vals = [_num(f"pdfTolerance[{k}]", v) for k, v in enumerate(pdfTolerance)]
        if len(vals) < 4 or any(v < 0.0 for v in vals):
            raise Refused(D.PARAMETER_ERR, "pdfTolerance must hold 4 to 6 values >= 0")
        assert self._inpos is not None
        for s, ax in zip(gs.slots, gs.group.axes, strict=True):
            self._inpos.set_tolerance(ax.index, vals[s] * gs.scale, units=True)
        return D.NO_ERR

    @_api
    def MCC_GetInPosToleranceEx(self, wGroupIndex: int = 0) -> tuple[int, ...]:
        """(NO_ERR, tx, ty, tz, tu, tv, tw) in the group's unit."""
        gs = self._g(wGroupIndex)
        assert self._inpos is not None
        tol = [self._inpos.tolerance(ax.index) / ax.units.pulses_per_unit
               for ax in gs.group.axes]
        return (D.NO_ERR, *self._out6(gs, tol))

    @_api
    def MCC_SetInPosCheckTime(self, dwCheckTime: int, wGroupIndex: int = 0) -> int:
        """How long (ms) a finished command may wait for in-position before the error."""
        gs = self._g(wGroupIndex)
        ms = _int("dwCheckTime", dwCheckTime, 1, 2**31 - 1)
        assert self._inpos is not None
        for ax in gs.group.axes:
            self._inpos.set_check_time(ax.index, ms / 1000.0)
        return D.NO_ERR

    @_api
    def MCC_EnableInPos(self, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        assert self._inpos is not None
        self._inpos.enable([a.index for a in gs.group.axes])
        gs.group.set_wait_in_position(True)
        return D.NO_ERR

    @_api
    def MCC_DisableInPos(self, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        assert self._inpos is not None
        self._inpos.disable([a.index for a in gs.group.axes])
        gs.group.set_wait_in_position(False)
        return D.NO_ERR

    @_api
    def MCC_GetInPosStatus(self, wGroupIndex: int = 0) -> int:
        """1 when every axis of the group is within its tolerance, 0 otherwise."""
        gs = self._g(wGroupIndex)
        assert self._inpos is not None
        return int(all(self._inpos.in_position(a.index) for a in gs.group.axes))

    # ------------------------------------------------------------------ I/O, encoder
    @_api
    def MCC_GetEmgcStopStatus(self, wCardIndex: int = 0) -> tuple[int, int]:
        """(NO_ERR, 1 emergency stop active / 0)."""
        ctl = self._ctl()
        _int("wCardIndex", wCardIndex, 0, self._n_cards - 1)
        return D.NO_ERR, int(ctl.estop_active)

    @_api
    def MCC_SetServoOn(self, wChannel: int, wCardIndex: int = 0) -> int:
        self._axis(wChannel, wCardIndex).enable()
        return D.NO_ERR

    @_api
    def MCC_SetServoOff(self, wChannel: int, wCardIndex: int = 0) -> int:
        ax = self._axis(wChannel, wCardIndex)
        if ax.is_moving:
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "the axis is moving")
        ax.disable()
        return D.NO_ERR

    @_api
    def MCC_EnablePosReady(self, wCardIndex: int = 0) -> int:
        """PRDY of the card: digital output do<card> of the machine."""
        card = _int("wCardIndex", wCardIndex, 0, max(0, self._n_cards - 1))
        self._ctl().hardware.write_output(None, f"do{card}", True)
        return D.NO_ERR

    @_api
    def MCC_DisablePosReady(self, wCardIndex: int = 0) -> int:
        card = _int("wCardIndex", wCardIndex, 0, max(0, self._n_cards - 1))
        self._ctl().hardware.write_output(None, f"do{card}", False)
        return D.NO_ERR

    @_api
    def MCC_SetENCInputRate(self, wRate: int, wChannel: int, wCardIndex: int = 0) -> int:
        """Encoder mode x1, x2 or x4 of an A/B encoder (2.9, default 4), before or after
        MCC_InitSystem. On an initialised machine it applies at once to the channel's
        decoder (core `Controller.set_encoder_mode`): the count keeps its value and counts
        x1/x2/x4 of the same encoder from then on (dwPPR is the count per revolution
        after the mode: set it to match and MCC_UpdateMachParam). Only for an A/B input
        (stEncoder.wType 0: else PARAMETER_ERR); refused while the channel moves
        (COMMAND_NOTACCEPTED_ERR)."""
        r = _int("wRate", wRate, 1, 4)
        if r == 3:
            raise Refused(D.PARAMETER_ERR, "wRate must be 1, 2 or 4")
        ch = _int("wChannel", wChannel, 0, D.CHANNELS_PER_CARD - 1)
        card = _int("wCardIndex", wCardIndex, 0, D.MAX_CARD - 1)
        if self.controller is not None:
            ax = self._axis(ch, card)
            if self._param(ch, card).stEncoder.wType != 0:
                raise Refused(D.PARAMETER_ERR, f"card {card} channel {ch}: the encoder "
                                               "rate is for an A/B input (wType 0)")
            try:
                self.controller.set_encoder_mode(ax.index, f"ab_x{r}")
            except MotionError as err:
                raise Refused(D.COMMAND_NOTACCEPTED_ERR, str(err)) from None
        self._enc_rate[(card, ch)] = r
        return D.NO_ERR

    @_api
    def MCC_GetENCValue(self, wChannel: int, wCardIndex: int = 0) -> tuple[int, int]:
        """(NO_ERR, the encoder count of the channel)."""
        ax = self._axis(wChannel, wCardIndex)
        return D.NO_ERR, int(ax.counters.feedback)


#: The library instance the module-level functions use (one per process, as the DLL).
LIBRARY = MCCL()


def _export() -> dict[str, Any]:
    out = {}
    for name in dir(MCCL):
        if name.startswith("MCC_"):
            out[name] = getattr(LIBRARY, name)
    return out


globals().update(_export())
__all__ = ["LIBRARY", "MCCL", *sorted(n for n in dir(MCCL) if n.startswith("MCC_")),
           *(n for n in dir(D) if n.isupper())]
