"""MCC_* speed, acceleration, profile shape, blending and override functions (manual
2.6.2-2.6.4): feed, PtP ratio, acc/dec steps, maximum pulse speed and acceleration, T/S
types. The values go to the core group's settings (control/groups/group_settings.py)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from openmotion.control.groups import group as G

from . import mccl_defs as D
from .mccl_base import GroupSlot, MCCLBase, Refused, _api, _int, _num


class MCCLSpeed(MCCLBase):
    """Speeds, accelerations, shapes, blending and override."""

    # ------------------------------------------------------------------ speeds
    @_api
    def MCC_SetFeedSpeed(self, dfFeedSpeed: float, wGroupIndex: int = 0) -> int:
        """Feed of the following general motions (unit/s), <= MCC_SetSysMaxSpeed."""
        gs = self._g(wGroupIndex)
        f = _num("dfFeedSpeed", dfFeedSpeed) * gs.scale
        gs.group.set_feed(f)
        return D.NO_ERR

    @_api
    def MCC_GetFeedSpeed(self, wGroupIndex: int = 0) -> float:
        gs = self._g(wGroupIndex)
        return gs.group._feed / gs.scale

    @_api
    def MCC_GetCurFeedSpeed(self, wGroupIndex: int = 0) -> float:
        """The present vector speed of the group (unit/s)."""
        gs = self._g(wGroupIndex)
        v = [a.velocity / k for a, k in zip(gs.group.axes, gs.group._k, strict=True)]
        return float(np.hypot.reduce(v)) / gs.scale if v else 0.0

    @_api
    def MCC_GetSpeed(self, wGroupIndex: int = 0) -> tuple[int, ...]:
        """(NO_ERR, vx, vy, vz, vu, vv, vw): each axis's speed component (unit/s)."""
        gs = self._g(wGroupIndex)
        v = [a.velocity / k for a, k in zip(gs.group.axes, gs.group._k, strict=True)]
        return (D.NO_ERR, *self._out6(gs, v))

    @_api
    def MCC_SetSysMaxSpeed(self, dfMaxSpeed: float, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        v = _num("dfMaxSpeed", dfMaxSpeed) * gs.scale
        if v <= 0.0:
            raise Refused(D.PARAMETER_ERR, f"dfMaxSpeed must be > 0, got {dfMaxSpeed!r}")
        gs.group.set_sys_max_speed(v)
        return D.NO_ERR

    @_api
    def MCC_GetSysMaxSpeed(self, wGroupIndex: int = 0) -> float:
        gs = self._g(wGroupIndex)
        return gs.group._sys_max / gs.scale

    @_api
    def MCC_SetPtPSpeed(self, dfRatio: float, wGroupIndex: int = 0) -> int:
        """PtP feed = maximum safe speed (wRPM x pitch / (gear x 60)) x ratio / 100."""
        gs = self._g(wGroupIndex)
        r = _num("dfRatio", dfRatio)
        gs.group.set_ptp_speed(r)
        return D.NO_ERR

    @_api
    def MCC_GetPtPSpeed(self, wGroupIndex: int = 0) -> float:
        return self._g(wGroupIndex).group.ptp_settings[0]

    def _cap_values(self, wCardIndex: int, values: Sequence[int]) -> tuple[int, list[float]]:
        card = _int("wCardIndex", wCardIndex, 0, max(0, self._n_cards - 1))
        vals = [float(_int(f"nPulse{k}", v, 1, G.PERIOD_PULSES_MAX))
                for k, v in enumerate(values)]
        return card, vals

    def _set_caps(self, wCardIndex: int, values: Sequence[int], which: int) -> int:
        self._ctl()
        card, vals = self._cap_values(wCardIndex, values)
        old = dict(self._pulse_caps)
        for ch in range(D.CHANNELS_PER_CARD):
            cur = list(self._pulse_caps.get((card, ch), (30000.0, 30000.0)))
            cur[which] = vals[ch]
            self._pulse_caps[(card, ch)] = (cur[0], cur[1])
        try:
            for gs in self._groups.values():
                if gs.card == card:
                    self._apply_caps(gs)
        except BaseException:
            self._pulse_caps = old
            for gs in self._groups.values():
                if gs.card == card:
                    self._apply_caps(gs)
            raise
        return D.NO_ERR

    @_api
    def MCC_SetMaxPulseSpeed(self, nPulse0: int, nPulse1: int, nPulse2: int, nPulse3: int,
                             nPulse4: int = 30000, nPulse5: int = 30000,
                             wCardIndex: int = 0) -> int:
        """Most pulses a channel sends per interpolation time, 1..32768 (default 30000;
        2.6.4 II): the channel's speed cap is nPulse / interpolation time."""
        return self._set_caps(wCardIndex, (nPulse0, nPulse1, nPulse2, nPulse3, nPulse4,
                                           nPulse5), 0)

    @_api
    def MCC_GetMaxPulseSpeed(self, wCardIndex: int = 0) -> tuple[int, ...]:
        self._ctl()
        card = _int("wCardIndex", wCardIndex, 0, self._n_cards - 1)
        return (D.NO_ERR, *(round(self._pulse_caps.get((card, ch), (30000.0, 0))[0])
                            for ch in range(D.CHANNELS_PER_CARD)), 0, 0)

    @_api
    def MCC_SetMaxPulseAcc(self, nPulse0: int, nPulse1: int, nPulse2: int, nPulse3: int,
                           nPulse4: int = 30000, nPulse5: int = 30000,
                           wCardIndex: int = 0) -> int:
        """Largest change of the pulses sent between two neighbouring interpolation times,
        1..32768 (default 30000; 2.6.4 III)."""
        return self._set_caps(wCardIndex, (nPulse0, nPulse1, nPulse2, nPulse3, nPulse4,
                                           nPulse5), 1)

    @_api
    def MCC_GetMaxPulseAcc(self, wCardIndex: int = 0) -> tuple[int, ...]:
        self._ctl()
        card = _int("wCardIndex", wCardIndex, 0, self._n_cards - 1)
        return (D.NO_ERR, *(round(self._pulse_caps.get((card, ch), (0, 30000.0))[1])
                            for ch in range(D.CHANNELS_PER_CARD)), 0, 0)

    def _step(self, name: str, value: int) -> int:
        return _int(name, value, 1, 100_000)

    @_api
    def MCC_SetAccStep(self, wStep: int, wGroupIndex: int = 0) -> int:
        """General motion: acceleration time = wStep x interpolation time (default 20)."""
        gs = self._g(wGroupIndex)
        n = self._step("wStep", wStep)
        gs.group.set_acc_time(n * self._period)
        gs.acc_step = n
        return D.NO_ERR

    @_api
    def MCC_SetDecStep(self, wStep: int, wGroupIndex: int = 0) -> int:
        """General motion: deceleration time = wStep x interpolation time (default 20)."""
        gs = self._g(wGroupIndex)
        n = self._step("wStep", wStep)
        gs.group.set_dec_time(n * self._period)
        gs.dec_step = n
        return D.NO_ERR

    @_api
    def MCC_GetAccStep(self, wGroupIndex: int = 0) -> int:
        return self._g(wGroupIndex).acc_step

    @_api
    def MCC_GetDecStep(self, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        return round(gs.group.dec_time / self._period)

    @_api
    def MCC_SetPtPAccStep(self, wStep: int, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        n = self._step("wStep", wStep)
        gs.group.set_ptp_acc_time(n * self._period)
        gs.ptp_acc_step = n
        return D.NO_ERR

    @_api
    def MCC_SetPtPDecStep(self, wStep: int, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        n = self._step("wStep", wStep)
        gs.group.set_ptp_dec_time(n * self._period)
        gs.ptp_dec_step = n
        return D.NO_ERR

    def _type(self, name: str, c: object) -> str:
        if c not in ("T", "S", "t", "s"):
            raise Refused(D.PARAMETER_ERR, f"{name} must be 'T' or 'S', got {c!r}")
        return str(c).upper()

    def _update_shapes(self, gs: GroupSlot) -> None:
        """The group's path shapes from its acc and dec types: S = s-factor 1 (2.6.3 I: a
        triangular acceleration lasting the acceleration / deceleration time); a
        deceleration type apart makes each command one move of its own (core pathmove)."""
        if gs.acc_type == "S":
            gs.group.set_path_shape("S", s_factor=1.0)
        else:
            gs.group.set_path_shape("T")
        gs.group.set_path_dec_shape(None if gs.dec_type == gs.acc_type else gs.dec_type)

    def _set_type(self, gs: GroupSlot, acc: str, dec: str) -> int:
        old = gs.acc_type, gs.dec_type
        gs.acc_type, gs.dec_type = acc, dec
        try:
            self._update_shapes(gs)
        except BaseException:
            gs.acc_type, gs.dec_type = old
            self._update_shapes(gs)
            raise
        return D.NO_ERR

    @_api
    def MCC_SetAccType(self, cType: str, wGroupIndex: int = 0) -> int:
        """General motion acceleration 'T' (trapezoid) or 'S' (S-curve, s-factor 1);
        2.6.3 I. The deceleration keeps its own type (MCC_SetDecType, default 'T')."""
        gs = self._g(wGroupIndex)
        return self._set_type(gs, self._type("cType", cType), gs.dec_type)

    @_api
    def MCC_SetDecType(self, cType: str, wGroupIndex: int = 0) -> int:
        """General motion deceleration 'T' or 'S' (2.6.3 I), for line, arc and circle
        commands queued after it. When it differs from the acceleration type each command
        runs as one move along its length with its two ramp shapes (core
        `Group.set_path_dec_shape`)."""
        gs = self._g(wGroupIndex)
        return self._set_type(gs, gs.acc_type, self._type("cType", cType))

    @_api
    def MCC_GetAccType(self, wGroupIndex: int = 0) -> str:
        return self._g(wGroupIndex).acc_type

    @_api
    def MCC_GetDecType(self, wGroupIndex: int = 0) -> str:
        return self._g(wGroupIndex).dec_type

    @_api
    def MCC_SetPtPAccType(self, cType0: str, cType1: str, cType2: str, cType3: str,
                          cType4: str = "T", cType5: str = "T", wGroupIndex: int = 0) -> int:
        """PtP acceleration shape of each axis x..w ('T' or 'S'; 2.6.3 I)."""
        gs = self._g(wGroupIndex)
        types = tuple(self._type(f"cType{k}", c) for k, c in
                      enumerate((cType0, cType1, cType2, cType3, cType4, cType5)))
        gs.group.set_ptp_shapes([types[s] for s in gs.slots],
                                [gs.ptp_dec_types[s] for s in gs.slots])
        gs.ptp_acc_types = types
        return D.NO_ERR

    @_api
    def MCC_SetPtPDecType(self, cType0: str, cType1: str, cType2: str, cType3: str,
                          cType4: str = "T", cType5: str = "T", wGroupIndex: int = 0) -> int:
        """PtP deceleration shape of each axis x..w ('T' or 'S'; 2.6.3 I), apart from the
        acceleration's (`Group.set_ptp_shapes(shapes, dec_shapes)`)."""
        gs = self._g(wGroupIndex)
        types = tuple(self._type(f"cType{k}", c) for k, c in
                      enumerate((cType0, cType1, cType2, cType3, cType4, cType5)))
        gs.group.set_ptp_shapes([gs.ptp_acc_types[s] for s in gs.slots],
                                [types[s] for s in gs.slots])
        gs.ptp_dec_types = types
        return D.NO_ERR

    @_api
    def MCC_GetPtPAccType(self, wGroupIndex: int = 0) -> tuple[str, ...]:
        return self._g(wGroupIndex).ptp_acc_types

    @_api
    def MCC_GetPtPDecType(self, wGroupIndex: int = 0) -> tuple[str, ...]:
        return self._g(wGroupIndex).ptp_dec_types

    # ------------------------------------------------------------------ blending, override
    @_api
    def MCC_EnableBlend(self, wGroupIndex: int = 0) -> int:
        """Velocity blending (2.6.3 II) of the commands queued after it: the next command
        starts when the running one begins to decelerate and the speeds add (line-line,
        line-arc, arc-arc, point-to-point; core `Group.enable_overlap_blend`)."""
        gs = self._g(wGroupIndex)
        gs.group.enable_overlap_blend()
        gs.blend = True
        return D.NO_ERR

    @_api
    def MCC_DisableBlend(self, wGroupIndex: int = 0) -> int:
        """Each command from rest to rest again (the running blend finishes)."""
        gs = self._g(wGroupIndex)
        gs.group.disable_blend()
        gs.blend = False
        return D.NO_ERR

    @_api
    def MCC_CheckBlend(self, wGroupIndex: int = 0) -> int:
        """1 when blending is enabled, 0 otherwise."""
        return int(self._g(wGroupIndex).blend)

    @_api
    def MCC_SetOverSpeed(self, dfRate: float, wGroupIndex: int = 0) -> int:
        """Feed override, % of MCC_SetFeedSpeed (1..200): applies at once (figure 11)."""
        gs = self._g(wGroupIndex)
        gs.group.set_override(_num("dfRate", dfRate))
        return D.NO_ERR

    @_api
    def MCC_GetOverSpeed(self, wGroupIndex: int = 0) -> float:
        return self._g(wGroupIndex).group.override

    @_api
    def MCC_SetPtPOverSpeed(self, dfRate: float, wGroupIndex: int = 0) -> int:
        gs = self._g(wGroupIndex)
        gs.group.set_ptp_override(_num("dfRate", dfRate))
        return D.NO_ERR

    @_api
    def MCC_GetPtPOverSpeed(self, wGroupIndex: int = 0) -> float:
        return self._g(wGroupIndex).group._ptp_override * 100.0
