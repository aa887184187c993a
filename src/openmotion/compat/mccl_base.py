"""The plumbing of `openmotion.compat.mccl`: library state, groups, argument checks and
the mapping of core refusals to the header's return codes.

`MCCLBase` holds what MCCL keeps between calls (cards, mechanism parameters, groups, their
coordinate mode and unit) and the simulated machine (`controller`) built by
MCC_InitSystem. Every MCC_* function runs through `_api`: a MotionError from the core (or
a bad argument) becomes the library's negative return code and changes nothing; no
exception leaves a call. The text of the last refusal is in `last_error`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import wraps
from typing import TYPE_CHECKING, Any, TypeVar

from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.control import Controller
from openmotion.control.groups import group as G
from openmotion.control.groups.group import Group, GroupError
from openmotion.control.guard.inposition import InPositionControl
from openmotion.control.guard.softlimits import working_interval
from openmotion.errors import MotionError
from openmotion.units import AxisUnits

from . import mccl_defs as D

if TYPE_CHECKING:
    from openmotion.control.core.axis import Axis
    from openmotion.control.home.homing_sequence import HomeSequence
    from openmotion.control.loops.compensation import Compensation

F = TypeVar("F", bound=Callable[..., Any])

#: core refusal code -> MCCL return code
_CODES = {
    G.ERR_ARGUMENT: D.PARAMETER_ERR, G.ERR_QUEUE_FULL: D.COMMAND_BUFFER_FULL_ERR,
    G.ERR_AXIS_BUSY: D.COMMAND_NOTACCEPTED_ERR, G.ERR_AXIS_STATE: D.COMMAND_NOTACCEPTED_ERR,
    G.ERR_SPEED: D.FEED_RATE_ERR, G.ERR_ACCEL: D.FEED_RATE_ERR, G.ERR_ARC: D.PARAMETER_ERR,
    G.ERR_GROUP: D.COMMAND_NOTACCEPTED_ERR, G.ERR_LIMIT: D.COMMAND_NOTACCEPTED_ERR,
    G.ERR_STATE: D.COMMAND_NOTACCEPTED_ERR,
}


class Refused(Exception):
    """Raised inside a facade function: return `code` (the call changes nothing)."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


def _api(fn: F) -> F:
    """Run an MCC_* body: core refusals and bad arguments become return codes."""

    @wraps(fn)
    def wrapper(self: MCCLBase, *args: Any, **kwargs: Any) -> Any:
        try:
            return fn(self, *args, **kwargs)
        except Refused as r:
            self.last_error = str(r)
            return r.code
        except GroupError as e:
            self.last_error = str(e)
            return _CODES.get(e.code, D.COMMAND_NOTACCEPTED_ERR)
        except (MotionError, TypeError, ValueError, IndexError, KeyError,
                OverflowError, AttributeError) as e:
            self.last_error = f"{type(e).__name__}: {e}"
            return D.PARAMETER_ERR

    return wrapper  # type: ignore[return-value]


def _int(name: str, value: object, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise Refused(D.PARAMETER_ERR, f"{name} must be an integer in {lo}..{hi}, "
                                       f"got {value!r}")
    return value


def _num(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise Refused(D.PARAMETER_ERR, f"{name} must be a number, got {value!r}")
    x = float(value)
    if x != x or x in (float("inf"), float("-inf")):
        raise Refused(D.PARAMETER_ERR, f"{name} must be finite, got {value!r}")
    return x


@dataclass
class GroupSlot:
    """What MCCL keeps per group besides the core Group."""

    group: Group
    card: int
    channels: tuple[int, ...]          # channel of x, y, z, u (-1: not used)
    slots: tuple[int, ...]             # which of the 6 arguments each logical axis takes
    coord: int = D.COORD_ABSOLUTE
    unit: int = D.UNIT_MM
    acc_step: int = 20
    dec_step: int = 20
    ptp_acc_step: int = 20
    ptp_dec_step: int = 20
    acc_type: str = "T"
    dec_type: str = "T"
    ptp_acc_types: tuple[str, ...] = ("T",) * 6
    ptp_dec_types: tuple[str, ...] = ("T",) * 6
    blend: bool = False
    ot_check: tuple[int, ...] = (0,) * 6

    @property
    def scale(self) -> float:
        """mm per user unit (1, or 25.4 for inch)."""
        return 25.4 if self.unit == D.UNIT_INCH else 1.0


class MCCLBase:
    """Library state and plumbing (see the module doc)."""

    def __init__(self, axis_setup: Callable[[int, int], dict[str, Any]] | None = None) -> None:
        """axis_setup(card, channel): extra AxisConfig fields of the simulated machine
        (switch positions, drive), applied at MCC_InitSystem."""
        self._axis_setup = axis_setup
        self.last_error = ""
        self._reset()

    def simulate(self, axis_setup: Callable[[int, int], dict[str, Any]] | None) -> None:
        """Describe the simulated machine before MCC_InitSystem: axis_setup(card, channel)
        gives extra AxisConfig fields (home sensor and limit switch positions, drive)."""
        if axis_setup is not None and not callable(axis_setup):
            raise MotionError(f"axis_setup must be callable or None, got {axis_setup!r}")
        self._axis_setup = axis_setup

    def _reset(self) -> None:
        self.controller: Controller | None = None
        self._period = 0.0
        self._n_cards = 0
        self._mach: dict[tuple[int, int], D.SYS_MACH_PARAM] = {}
        self._group_cfg: D.SYS_GROUP_CONFIG | None = None
        self._groups: dict[int, GroupSlot] = {}
        self._enc_rate: dict[tuple[int, int], int] = {}
        self._comp_params: dict[tuple[int, int], D.SYS_COMP_PARAM] = {}
        self._comp: dict[int, Compensation] = {}
        self._inpos: InPositionControl | None = None
        self._home: HomeSequence | None = None
        self._home_acc_step = 20
        self._home_dec_step = 20
        self._limit_check = False
        self._pulse_caps: dict[tuple[int, int], tuple[float, float]] = {}
        self._dry = False

    # ------------------------------------------------------------------ lookups
    def _ctl(self) -> Controller:
        if self.controller is None:
            raise Refused(D.INITIAL_MOTION_ERR, "MCC_InitSystem has not been called")
        return self.controller

    def _g(self, index: object) -> GroupSlot:
        self._ctl()
        if isinstance(index, bool) or not isinstance(index, int) or index not in self._groups:
            raise Refused(D.GROUP_PARAMETER_ERR, f"group {index!r} is not a configured group "
                                                 f"(configured: {sorted(self._groups)})")
        return self._groups[index]

    def _axis(self, channel: object, card: object) -> Axis:
        ctl = self._ctl()
        c = _int("wCardIndex", card, 0, self._n_cards - 1)
        ch = _int("wChannel", channel, 0, D.CHANNELS_PER_CARD - 1)
        return ctl.axes[c * D.CHANNELS_PER_CARD + ch]

    def _param(self, channel: int, card: int) -> D.SYS_MACH_PARAM:
        return self._mach.get((card, channel)) or D.SYS_MACH_PARAM()

    def _units(self, param: D.SYS_MACH_PARAM, name: str) -> AxisUnits:
        """AxisUnits (mm) of an axis: pulses per mm = PPR x gear / pitch (2.4)."""
        ppu = param.dwPPR * param.dfGearRatio / param.dfPitch
        return AxisUnits(name, "mm", ppu, -1 if param.wPosToEncoderDir else 1,
                         param.wRPM * param.dfPitch / (param.dfGearRatio * 60.0))

    def _interval_pulses(self, axis: Axis) -> tuple[float, float]:
        """The working interval (2.4) of a controller axis in command pulses."""
        card, ch = divmod(axis.index, D.CHANNELS_PER_CARD)
        p = self._param(ch, card)
        lo, hi = working_interval(p.dfHighLimit, p.dfLowLimit, p.dfHighLimitOffset,
                                  p.dfLowLimitOffset)
        a, b = axis.units.to_pulses(lo), axis.units.to_pulses(hi)
        return min(a, b), max(a, b)

    # ------------------------------------------------------------------ argument helpers
    def _six(self, gs: GroupSlot, values: Sequence[float]) -> list[float]:
        """The six x..w arguments -> the group's logical coordinates (mm)."""
        vals = [_num(f"argument {k}", v) for k, v in enumerate(values)]
        return [vals[s] * gs.scale for s in gs.slots]

    def _target(self, gs: GroupSlot, values: Sequence[float]) -> tuple[list[float], bool]:
        return self._six(gs, values), gs.coord == D.COORD_INCREASE

    def _out6(self, gs: GroupSlot, logical: Sequence[float]) -> list[float]:
        """Logical coordinates (mm) -> the six x..w values in the group's unit."""
        out = [0.0] * D.GROUP_AXES
        for s, v in zip(gs.slots, logical, strict=True):
            out[s] = float(v) / gs.scale
        return out

    def _idle(self, gs: GroupSlot) -> bool:
        g = gs.group
        return g.state is G.GroupState.IDLE and g.queue_length == 0 and \
            not any(a.is_moving for a in g.axes)

    # ------------------------------------------------------------------ building
    def _axis_config(self, card: int, ch: int) -> AxisConfig:
        p = self._param(ch, card)
        rate = self._enc_rate.get((card, ch), 4)
        enc = {0: f"ab_x{rate}", 1: "cw_ccw", 2: "pulse_dir"}.get(p.stEncoder.wType)
        pulse = {0: "out_dir", 1: "cw_ccw", 2: "ab_phase"}.get(p.wPulseMode)
        if enc is None or pulse is None:
            raise Refused(D.PARAMETER_ERR, f"card {card} channel {ch}: wPulseMode "
                                           f"{p.wPulseMode!r} / stEncoder.wType "
                                           f"{p.stEncoder.wType!r} must be 0, 1 or 2")
        logic = {"org": "nc" if p.stHome.wSensorMode == 1 else "no",
                 "pel": "nc" if p.wOverTravelUpSensorMode == 1 else "no",
                 "mel": "nc" if p.wOverTravelDownSensorMode == 1 else "no"}
        lines = max(1, round(p.dwPPR / rate)) if p.stEncoder.wType == 0 else p.dwPPR
        fields: dict[str, Any] = dict(
            name=f"c{card}ch{ch}", pulses_per_rev=p.dwPPR, lead=p.dfPitch,
            gear_ratio=p.dfGearRatio, reverse=bool(p.wPosToEncoderDir), unit="mm",
            max_speed=p.wRPM * p.dfPitch / (p.dfGearRatio * 60.0), pulse_mode=pulse,
            pulse_width_us=p.wPulseWidth * 0.025, encoder_mode=enc,
            encoder_lines_per_rev=lines, invert_a=bool(p.stEncoder.wAInverse),
            invert_b=bool(p.stEncoder.wBInverse), invert_z=bool(p.stEncoder.wCInverse),
            swap_ab=bool(p.stEncoder.wABSwap), logic=logic, drive=DriveConfig())
        if self._axis_setup is not None:
            extra = dict(self._axis_setup(card, ch) or {})
            if "logic" in extra:
                extra["logic"] = {**logic, **extra["logic"]}
            fields.update(extra)
        return AxisConfig(**fields)

    def _build_groups(self, ctl: Controller) -> dict[int, GroupSlot]:
        cfg = self._group_cfg
        if cfg is None:  # the default: group 0 on channels 0..3 of card 0
            cfg = D.SYS_GROUP_CONFIG()
            cfg.nGroupUsed[0] = 0
            cfg.stGroupInfo[0] = D.SYS_GROUP_INFO(0, [0, 1, 2, 3, -1, -1])
        out: dict[int, GroupSlot] = {}
        used: set[int] = set()
        try:
            for g in range(D.MAX_GROUP):
                if cfg.nGroupUsed[g] != 0:
                    continue
                info = cfg.stGroupInfo[g]
                card = _int(f"stGroupInfo[{g}].nCardIndex", info.nCardIndex, 0,
                            self._n_cards - 1)
                chans = [_int(f"stGroupInfo[{g}].nChannel[{k}]", c, -1,
                              D.CHANNELS_PER_CARD - 1) for k, c in enumerate(info.nChannel)]
                if len(chans) != 6 or chans[4] != -1 or chans[5] != -1:
                    raise Refused(D.GROUP_PARAMETER_ERR, f"stGroupInfo[{g}].nChannel must "
                                                         "be 6 values, [4] and [5] -1")
                slots = tuple(k for k in range(4) if chans[k] >= 0)
                axes = [card * D.CHANNELS_PER_CARD + chans[k] for k in slots]
                if not axes or len(set(axes)) != len(axes) or used & set(axes):
                    raise Refused(D.GROUP_PARAMETER_ERR, f"group {g}: channels must be "
                                                         "distinct and in no other group")
                used |= set(axes)
                names = {"xyzu"[k]: ctl.axes[i].name for k, i in zip(slots, axes,
                                                                       strict=True)}
                units = [AxisUnits.from_axis(ctl.axes[i].config) for i in axes]
                # feed 10 % of the maximum speed (as the PtP default), acc 20 periods
                grp = Group(ctl, names, units=units, acc_time=20 * ctl.period,
                            feed=0.1 * max(u.max_speed for u in units))
                out[g] = GroupSlot(grp, card, tuple(chans[:4]), slots)
        except BaseException:
            for gs in out.values():
                gs.group.close()
            raise
        return out

    def _apply_caps(self, gs: GroupSlot) -> None:
        """MCC_SetMaxPulseSpeed/Acc values of the group's channels -> the core caps."""
        sp, ac = [], []
        for k in gs.slots:
            v, a = self._pulse_caps.get((gs.card, gs.channels[k]), (30000.0, 30000.0))
            sp.append(v)
            ac.append(a)
        gs.group.set_period_pulse_caps(sp, ac)

    @staticmethod
    def _copy(obj: Any) -> Any:
        return dataclasses.replace(obj) if not dataclasses.is_dataclass(obj) else \
            type(obj)(**{f.name: _deep(getattr(obj, f.name)) for f in dataclasses.fields(obj)})

    def _machine(self, n_cards: int, period: float) -> Controller:
        axes = tuple(self._axis_config(c, ch) for c in range(n_cards)
                     for ch in range(D.CHANNELS_PER_CARD))
        cfg = MachineConfig("mccl", axes, cycle_s=period)
        ctl = Controller(cfg, period=period)
        ctl.enable_all()
        return ctl


def _deep(value: Any) -> Any:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return MCCLBase._copy(value)
    if isinstance(value, list):
        return [_deep(v) for v in value]
    return value
