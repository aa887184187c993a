"""MCC_* system, configuration, coordinate, motion, speed and status functions (manual
2.4-2.6). Each maps onto the core (`control.groups.group.Group`, `control.guard.softlimits`); the
facade only converts arguments (six x..w values, mm or inch, steps of the interpolation
time) and return codes."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from openmotion.control.groups import group as G
from openmotion.errors import MotionError

from . import mccl_defs as D
from .mccl_base import GroupSlot, Refused, _api, _int, _num
from .mccl_speed import MCCLSpeed


class MCCLMotion(MCCLSpeed):
    """System, configuration, motion, speed and status functions."""

    # ------------------------------------------------------------------ system
    @_api
    def MCC_SetMachParam(self, psMachParam: D.SYS_MACH_PARAM, wChannel: int,
                         wCardIndex: int = 0) -> int:
        """Set one axis's mechanism parameters (2.4); after MCC_InitSystem they take
        effect with MCC_UpdateMachParam."""
        if not isinstance(psMachParam, D.SYS_MACH_PARAM):
            raise Refused(D.PARAMETER_ERR, "psMachParam must be a SYS_MACH_PARAM")
        ch = _int("wChannel", wChannel, 0, D.CHANNELS_PER_CARD - 1)
        card = _int("wCardIndex", wCardIndex, 0, D.MAX_CARD - 1)
        _check_mach(psMachParam)
        self._mach[(card, ch)] = self._copy(psMachParam)
        return D.NO_ERR

    @_api
    def MCC_GetMachParam(self, psMachParam: D.SYS_MACH_PARAM, wChannel: int,
                         wCardIndex: int = 0) -> int:
        """Fill `psMachParam` with the axis's mechanism parameters."""
        if not isinstance(psMachParam, D.SYS_MACH_PARAM):
            raise Refused(D.PARAMETER_ERR, "psMachParam must be a SYS_MACH_PARAM")
        ch = _int("wChannel", wChannel, 0, D.CHANNELS_PER_CARD - 1)
        card = _int("wCardIndex", wCardIndex, 0, D.MAX_CARD - 1)
        src = self._copy(self._param(ch, card))
        for f in src.__dataclass_fields__:
            setattr(psMachParam, f, getattr(src, f))
        return D.NO_ERR

    @_api
    def MCC_UpdateMachParam(self) -> int:
        """Apply the mechanism parameters set (MCC_SetMachParam) after MCC_InitSystem
        (2.4): the mechanism ratio (dwPPR, dfPitch, dfGearRatio), wRPM, wPosToEncoderDir,
        the pulse output format and width, the encoder format and its inversions, the
        sensor logic of home and over-travel inputs (core `Controller.reconfigure_axis`),
        the working interval (soft limits) and the homing settings. The counters keep
        their pulses (positions in mm follow the new ratio). Every channel is checked
        before any changes: a bad value is PARAMETER_ERR; while a group has commands
        queued, running or held, or an axis moves, COMMAND_NOTACCEPTED_ERR."""
        from openmotion.control.core.controller import RECONFIGURABLE

        ctl = self._ctl()
        if not all(self._idle(gs) for gs in self._groups.values()) or \
                any(a.is_moving for a in ctl.axes):
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "the machine must be at rest (groups "
                                                     "idle) to update its parameters")
        plan = []
        for ax in ctl.axes:
            card, ch = divmod(ax.index, D.CHANNELS_PER_CARD)
            _check_mach(self._param(ch, card))
            new = self._axis_config(card, ch)
            # (MCCL has no move ratio: MCC_SetENCInputRate keeps it right)
            changes = {k: getattr(new, k) for k in RECONFIGURABLE
                       if k != "move_ratio" and getattr(new, k) != getattr(ax.config, k)}
            plan.append((ax.index, changes))
        for index, changes in plan:
            if changes:
                try:
                    ctl.reconfigure_axis(index, **changes)
                except MotionError as err:
                    raise Refused(D.PARAMETER_ERR, str(err)) from None
        for gs in self._groups.values():
            self._apply_soft_limits(gs)
        return D.NO_ERR

    @_api
    def MCC_SetGroupConfig(self, psGroupConfig: D.SYS_GROUP_CONFIG) -> int:
        """Groups and their channels (2.5.1); before MCC_InitSystem."""
        if not isinstance(psGroupConfig, D.SYS_GROUP_CONFIG):
            raise Refused(D.PARAMETER_ERR, "psGroupConfig must be a SYS_GROUP_CONFIG")
        if self.controller is not None:
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "groups are set before MCC_InitSystem")
        if len(psGroupConfig.nGroupUsed) != D.MAX_GROUP or \
                len(psGroupConfig.stGroupInfo) != D.MAX_GROUP:
            raise Refused(D.GROUP_PARAMETER_ERR, f"the arrays must hold {D.MAX_GROUP} groups")
        self._group_cfg = self._copy(psGroupConfig)
        return D.NO_ERR

    @_api
    def MCC_InitSystem(self, nInterpolateTime: int, psCardConfig: Sequence[D.SYS_CARD_CONFIG],
                       wCardNo: int) -> int:
        """Initialise MCCL (2.5.1): interpolation time 1..1000 ms, `wCardNo` cards
        (wCardType 2). Builds the (simulated) machine and opens the groups."""
        if self.controller is not None:
            raise Refused(D.INITIAL_MOTION_ERR, "already initialised: MCC_CloseSystem first")
        n = _int("nInterpolateTime", nInterpolateTime, 1, 1000)
        cards = _int("wCardNo", wCardNo, 1, D.MAX_CARD)
        if isinstance(psCardConfig, D.SYS_CARD_CONFIG):
            psCardConfig = [psCardConfig]
        if len(psCardConfig) < cards or any(
                not isinstance(c, D.SYS_CARD_CONFIG) or c.wCardType != D.CARD_TYPE_PCI_4P
                for c in psCardConfig[:cards]):
            raise Refused(D.PARAMETER_ERR, f"psCardConfig must hold {cards} SYS_CARD_CONFIG "
                                           "with wCardType 2 (PCI-4P)")
        for card in range(cards):  # every parameter set is checked before anything starts
            for ch in range(D.CHANNELS_PER_CARD):
                _check_mach(self._param(ch, card))
        self._n_cards = cards
        try:
            ctl = self._machine(cards, n / 1000.0)
            groups = self._build_groups(ctl)
        except BaseException:
            self._n_cards = 0
            raise
        self.controller, self._period, self._groups = ctl, n / 1000.0, groups
        from openmotion.control.guard.inposition import InPositionControl

        self._inpos = InPositionControl(ctl)
        for gs in groups.values():
            self._apply_caps(gs)
            self._apply_soft_limits(gs)
        return D.NO_ERR

    @_api
    def MCC_CloseSystem(self) -> int:
        """Close MCCL: stop every group at once, forget everything."""
        if self.controller is not None:
            for gs in self._groups.values():
                gs.group.close()
        setup = self._axis_setup
        self._reset()
        self._axis_setup = setup
        return D.NO_ERR

    @_api
    def MCC_SetInterpolationTime(self, nInterpolateTime: int) -> int:
        """The interpolation time, 1..1000 ms, after MCC_InitSystem (2.6.4 I: "set it
        later any time"): applied at once between two cycles while the machine is at rest
        (core `Controller.set_period`); the steps set before (MCC_SetAccStep ...) keep their
        counts, so their times and the per-period pulse caps scale with it. While a group
        has commands queued, running or held, or an axis moves, refused with
        COMMAND_NOTACCEPTED_ERR (those commands were checked against the old time's
        caps), nothing changed."""
        n = _int("nInterpolateTime", nInterpolateTime, 1, 1000)
        ctl = self._ctl()
        old = self._period
        try:
            ctl.set_period(n / 1000.0)
        except MotionError as err:
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, str(err)) from None
        try:
            self._step_times(n / 1000.0)
        except MotionError:  # a step time out of range at the new time: all back
            ctl.set_period(old)
            self._step_times(old)
            raise
        self._period = n / 1000.0
        return D.NO_ERR

    def _step_times(self, T: float) -> None:
        """Every group's step counts (MCC_SetAccStep ...) as times at interpolation time T."""
        for gs in self._groups.values():
            g = gs.group
            g.set_acc_time(gs.acc_step * T)
            if g._dec_time is not None:
                g.set_dec_time(gs.dec_step * T)
            if g._ptp_acc_time is not None:
                g.set_ptp_acc_time(gs.ptp_acc_step * T)
            if g._ptp_dec_time is not None:
                g.set_ptp_dec_time(gs.ptp_dec_step * T)

    @_api
    def MCC_GetInterpolationTime(self) -> int:
        """The interpolation time in ms."""
        self._ctl()
        return round(self._period * 1000.0)

    # ------------------------------------------------------------------ coordinates
    @_api
    def MCC_SetAbsolute(self, wGroupIndex: int = 0) -> int:
        self._g(wGroupIndex).coord = D.COORD_ABSOLUTE
        return D.NO_ERR

    @_api
    def MCC_SetIncrease(self, wGroupIndex: int = 0) -> int:
        self._g(wGroupIndex).coord = D.COORD_INCREASE
        return D.NO_ERR

    @_api
    def MCC_GetCoordType(self, wGroupIndex: int = 0) -> int:
        """0 absolute, 1 incremental."""
        return self._g(wGroupIndex).coord

    @_api
    def MCC_SetUnit(self, nUnitMode: int, wGroupIndex: int = 0) -> int:
        """0 mm, 1 inch: positions, feeds and tolerances of the group's calls."""
        u = _int("nUnitMode", nUnitMode, 0, 1)
        self._g(wGroupIndex).unit = u
        return D.NO_ERR

    @_api
    def MCC_GetUnit(self, wGroupIndex: int = 0) -> int:
        return self._g(wGroupIndex).unit

    @_api
    def MCC_GetCurPos(self, wGroupIndex: int = 0) -> tuple[int, float, float, float, float,
                                                          float, float]:
        """(NO_ERR, x, y, z, u, v, w): command position in the group's unit (dry run:
        the planned position)."""
        gs = self._g(wGroupIndex)
        return (D.NO_ERR, *self._out6(gs, gs.group.position))

    @_api
    def MCC_GetPulsePos(self, wGroupIndex: int = 0) -> tuple[int, ...]:
        """(NO_ERR, x, y, z, u, v, w): command position in pulses."""
        gs = self._g(wGroupIndex)
        g = gs.group
        pulses = [0] * D.GROUP_AXES
        for s, a, k in zip(gs.slots, g.axes, g._k, strict=True):
            pos = a.position if not g.dry_run else float(g.position[gs.slots.index(s)] * k)
            pulses[s] = round(pos)
        return (D.NO_ERR, *pulses)

    # ------------------------------------------------------------------ motion
    @_api
    def MCC_PtP(self, dfX: float, dfY: float, dfZ: float, dfU: float, dfV: float,
                dfW: float, wGroupIndex: int = 0) -> int:
        """Point to point (2.6.2 I) at the PtP speed ratio; the command index (>= 0)."""
        gs = self._g(wGroupIndex)
        p, rel = self._target(gs, (dfX, dfY, dfZ, dfU, dfV, dfW))
        return gs.group.ptp(p, relative=rel)

    @_api
    def MCC_Line(self, dfX: float, dfY: float, dfZ: float, dfU: float, dfV: float,
                 dfW: float, wGroupIndex: int = 0) -> int:
        """Linear motion (2.6.2 II A) at the feed speed; the command index (>= 0)."""
        gs = self._g(wGroupIndex)
        p, rel = self._target(gs, (dfX, dfY, dfZ, dfU, dfV, dfW))
        return gs.group.line(p, relative=rel)

    def _plane(self, gs: GroupSlot, a: int, b: int) -> tuple[int, int]:
        if a not in gs.slots or b not in gs.slots:
            raise Refused(D.GROUP_PARAMETER_ERR, f"group axes {'xyzu'[a]}{'xyzu'[b]} are not "
                                                 "both dispatched")
        return gs.slots.index(a), gs.slots.index(b)

    def _arc3(self, gs: GroupSlot, ref: dict[int, float], end: dict[int, float]) -> int:
        """An arc through `ref` to `end` (slot -> value): the other axes stay."""
        g = gs.group
        base = np.zeros(len(gs.slots)) if gs.coord == D.COORD_INCREASE else g.end_point
        via, to = base.copy(), base.copy()
        for s, v in ref.items():
            via[gs.slots.index(s)] = _num("reference", v) * gs.scale
        for s, v in end.items():
            to[gs.slots.index(s)] = _num("end", v) * gs.scale
        return g.arc3d(via, to, relative=gs.coord == D.COORD_INCREASE)

    @_api
    def MCC_ArcXYZ(self, dfRX0: float, dfRY0: float, dfRZ0: float, dfX: float, dfY: float,
                   dfZ: float, wGroupIndex: int = 0) -> int:
        """3-D arc through the reference point (dfRX0, dfRY0, dfRZ0) to (dfX, dfY, dfZ)."""
        gs = self._g(wGroupIndex)
        self._plane(gs, 0, 1)
        self._plane(gs, 1, 2)
        return self._arc3(gs, {0: dfRX0, 1: dfRY0, 2: dfRZ0}, {0: dfX, 1: dfY, 2: dfZ})

    def _arc(self, wGroupIndex: int, a: int, b: int, r0: float, r1: float, e0: float,
             e1: float) -> int:
        gs = self._g(wGroupIndex)
        self._plane(gs, a, b)
        return self._arc3(gs, {a: r0, b: r1}, {a: e0, b: e1})

    @_api
    def MCC_ArcXY(self, dfRX0: float, dfRY0: float, dfX: float, dfY: float,
                  wGroupIndex: int = 0) -> int:
        """Arc in the XY plane through the reference point to the end point (the
        reference point fixes the circle and the direction; 2.6.2 II B)."""
        return self._arc(wGroupIndex, 0, 1, dfRX0, dfRY0, dfX, dfY)

    @_api
    def MCC_ArcYZ(self, dfRY0: float, dfRZ0: float, dfY: float, dfZ: float,
                  wGroupIndex: int = 0) -> int:
        return self._arc(wGroupIndex, 1, 2, dfRY0, dfRZ0, dfY, dfZ)

    @_api
    def MCC_ArcZX(self, dfRZ0: float, dfRX0: float, dfZ: float, dfX: float,
                  wGroupIndex: int = 0) -> int:
        return self._arc(wGroupIndex, 2, 0, dfRZ0, dfRX0, dfZ, dfX)

    def _circle(self, wGroupIndex: int, a: int, b: int, c0: float, c1: float,
                wDir: int) -> int:
        gs = self._g(wGroupIndex)
        plane = self._plane(gs, a, b)
        d = _int("wDir", wDir, 0, 1)
        centre = [_num("centre", c0) * gs.scale, _num("centre", c1) * gs.scale]
        return gs.group.circle(centre, plane=plane, direction="CW" if d == D.CIR_CW else "CCW",
                               relative=gs.coord == D.COORD_INCREASE)

    @_api
    def MCC_CircleXY(self, dfCX: float, dfCY: float, wDir: int = D.CIR_CW,
                     wGroupIndex: int = 0) -> int:
        """Full circle around the centre, wDir CIR_CW (0) / CIR_CCW (1) (2.6.2 II C)."""
        return self._circle(wGroupIndex, 0, 1, dfCX, dfCY, wDir)

    @_api
    def MCC_CircleYZ(self, dfCY: float, dfCZ: float, wDir: int = D.CIR_CW,
                     wGroupIndex: int = 0) -> int:
        return self._circle(wGroupIndex, 1, 2, dfCY, dfCZ, wDir)

    @_api
    def MCC_CircleZX(self, dfCZ: float, dfCX: float, wDir: int = D.CIR_CW,
                     wGroupIndex: int = 0) -> int:
        return self._circle(wGroupIndex, 2, 0, dfCZ, dfCX, wDir)

    @_api
    def MCC_HelicalXY_Z(self, dfCX: float, dfCY: float, dfX: float, dfY: float, dfZ: float,
                        wDir: int = D.CIR_CW, wGroupIndex: int = 0) -> int:
        """Helix (ours, not in the user's manual): an XY arc around the centre to (dfX,
        dfY) while Z moves linearly to dfZ."""
        gs = self._g(wGroupIndex)
        plane = self._plane(gs, 0, 1)
        self._plane(gs, 0, 2)
        d = _int("wDir", wDir, 0, 1)
        rel = gs.coord == D.COORD_INCREASE
        g = gs.group
        end = np.zeros(len(gs.slots)) if rel else g.end_point
        for s, v in ((0, dfX), (1, dfY), (2, dfZ)):
            end[gs.slots.index(s)] = _num("end", v) * gs.scale
        centre = [_num("dfCX", dfCX) * gs.scale, _num("dfCY", dfCY) * gs.scale]
        return g.arc(centre, end, plane=plane, direction="CW" if d == D.CIR_CW else "CCW",
                     relative=rel)

    @_api
    def MCC_ResetCommandIndex(self, wGroupIndex: int = 0) -> int:
        self._g(wGroupIndex).group.reset_command_index()
        return D.NO_ERR

    # ------------------------------------------------------------------ hold / abort / delay
    @_api
    def MCC_HoldMotion(self, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        if gs.group.state is not G.GroupState.MOVING:
            raise Refused(D.HOLD_ILLEGAL_ERR, "hold needs a moving group")
        gs.group.hold()
        return D.NO_ERR

    @_api
    def MCC_ContiMotion(self, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        if gs.group.state is not G.GroupState.HELD:
            raise Refused(D.CONTI_ILLEGAL_ERR, "continue needs a held group")
        gs.group.cont()
        return D.NO_ERR

    @_api
    def MCC_AbortMotion(self, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        if gs.group.state is G.GroupState.ERROR:
            raise Refused(D.ABORT_ILLEGAL_ERR, "the group is in error: MCC_ClearError")
        gs.group.abort()
        return D.NO_ERR

    @_api
    def MCC_DelayMotion(self, dwTime: int, wGroupIndex: int = 0) -> int:
        """Delay dwTime interpolation times before the next command (2.6.3 V)."""
        gs = self._g(wGroupIndex)
        n = _int("dwTime", dwTime, 0, 2**31 - 1)
        return gs.group.delay(n * self._period)

    @_api
    def MCC_CheckDelay(self, wGroupIndex: int = 0) -> int:
        """1 while a delay executes, 0 otherwise."""
        gs = self._g(wGroupIndex)
        r = gs.group._run or gs.group._held
        return int(r is not None and r.kind == "delay")

    @_api
    def MCC_EnableDryRun(self) -> int:
        """Dry run of every group (2.6.3 IV): plan without pulses; only while idle."""
        return self._dry_run(True)

    @_api
    def MCC_DisableDryRun(self) -> int:
        return self._dry_run(False)

    def _dry_run(self, on: bool) -> int:
        self._ctl()
        if not all(self._idle(gs) for gs in self._groups.values()):
            raise Refused(D.COMMAND_NOTACCEPTED_ERR, "dry run is switched while idle")
        for gs in self._groups.values():
            gs.group.enable_dry_run(on)
        self._dry = on
        return D.NO_ERR

    @_api
    def MCC_CheckDryRun(self) -> int:
        self._ctl()
        return int(self._dry)

    # ------------------------------------------------------------------ status
    @_api
    def MCC_GetMotionStatus(self, wGroupIndex: int = 0) -> int:
        """GMS_RUNNING 0, GMS_STOP 1, GMS_HOLD 2, GMS_DELAYING 3 (2.6.5)."""
        g = self._g(wGroupIndex).group
        st = g.state
        if st is G.GroupState.HELD:
            return D.GMS_HOLD
        if st in (G.GroupState.MOVING, G.GroupState.HOLDING):
            r = g._run
            return D.GMS_DELAYING if r is not None and r.kind == "delay" else D.GMS_RUNNING
        busy = g.queue_length > 0 or any(a.is_moving for a in g.axes)
        return D.GMS_RUNNING if busy else D.GMS_STOP

    @_api
    def MCC_GetCurCommand(self, pstCurCommand: D.COMMAND_INFO, wGroupIndex: int = 0) -> int:
        """Fill `pstCurCommand` with the executing command (index -1 when none)."""
        if not isinstance(pstCurCommand, D.COMMAND_INFO):
            raise Refused(D.PARAMETER_ERR, "pstCurCommand must be a COMMAND_INFO")
        gs = self._g(wGroupIndex)
        info = gs.group.current_command
        if info is None:
            pstCurCommand.nType, pstCurCommand.nCommandIndex = D.CMD_PTP, -1
            pstCurCommand.dfFeedSpeed, pstCurCommand.dfPos = 0.0, [0.0] * 6
            return D.NO_ERR
        kind = {"ptp": D.CMD_PTP, "delay": D.CMD_DELAY}.get(info.kind)
        if kind is None:
            kind = D.CMD_LINE if info.element == "Line" else (
                D.CMD_CW if info.direction == "CW" else D.CMD_CCW)
        pstCurCommand.nType = kind
        pstCurCommand.nCommandIndex = info.index
        pstCurCommand.dfFeedSpeed = info.feed if info.kind == "ptp" else info.feed / gs.scale
        pstCurCommand.dfPos = [0.0] * 6 if info.target is None else \
            self._out6(gs, info.target)
        return D.NO_ERR

    @_api
    def MCC_GetCommandCount(self, wGroupIndex: int = 0) -> int:
        """Commands accepted and not yet executed (the executing one not counted)."""
        return self._g(wGroupIndex).group.commands_pending


def _check_mach(p: D.SYS_MACH_PARAM) -> None:
    """The manual's ranges for one SYS_MACH_PARAM (2.4); Refused(PARAMETER_ERR)."""
    for name in ("wPosToEncoderDir",):
        _int(name, getattr(p, name), 0, 1)
    _int("wRPM", p.wRPM, 1, 65535)
    _int("dwPPR", p.dwPPR, 1, 2**31 - 1)
    for name in ("dfPitch", "dfGearRatio"):
        if _num(name, getattr(p, name)) <= 0.0:
            raise Refused(D.PARAMETER_ERR, f"{name} must be > 0, got {getattr(p, name)!r}")
    from openmotion.control.guard.softlimits import working_interval
    from openmotion.errors import MotionError

    try:
        working_interval(_num("dfHighLimit", p.dfHighLimit), _num("dfLowLimit", p.dfLowLimit),
                         _num("dfHighLimitOffset", p.dfHighLimitOffset),
                         _num("dfLowLimitOffset", p.dfLowLimitOffset))
    except MotionError as e:
        raise Refused(D.PARAMETER_ERR, str(e)) from None
    _int("wPulseMode", p.wPulseMode, 0, 2)
    _int("wPulseWidth", p.wPulseWidth, 1, 65535)
    _int("wCommandMode", p.wCommandMode, 0, 0)
    _int("wOverTravelUpSensorMode", p.wOverTravelUpSensorMode, 0, 2)
    _int("wOverTravelDownSensorMode", p.wOverTravelDownSensorMode, 0, 3)
    h = p.stHome
    _int("stHome.wType", h.wType, 0, 2)
    _int("stHome.wPhase0Dir", h.wPhase0Dir, 0, 1)
    _int("stHome.wPhase1Dir", h.wPhase1Dir, 0, 1)
    _int("stHome.wSensorMode", h.wSensorMode, 0, 1)
    _num("stHome.dfOffset", h.dfOffset)
    e = p.stEncoder
    _int("stEncoder.wType", e.wType, 0, 2)
    for name in ("wAInverse", "wBInverse", "wCInverse", "wABSwap"):
        _int(f"stEncoder.{name}", getattr(e, name), 0, 1)
