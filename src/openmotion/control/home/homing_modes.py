"""Home-return sequences as data: every mode is a tuple of `Phase`s run by control.home.homing.

Sources: HSL-4XMO manual 4.1.8 "Home Return Mode" (one-line text for modes 0, 1, 6, 8..12;
figures only for 2..5 and 7), seed-facts 1.1 (modes 2, 3, 4, 5 and 7 are a [low] inference
from the PCL6045B origin-return table), MCCL manual 2.7 (phases 0-3, NORMAL / HOME_ONLY /
INDEX_ONLY). Directions are relative: +1 is the home direction (the sign of the search
speed), -1 the opposite. A phase moves in its direction at its speed until its signal makes
the wanted edge (`count` times), then reacts (`then`):

- "stop": decelerate to rest (the next phase starts from rest);
- "el":   the end-limit reaction configured in HomeConfig.el_stop (decelerate or immediate);
- "slow": decelerate to StrVel and keep going (the next phase continues this motion);
- "pass": keep going (the next phase continues this motion).

`mark` flags the edge that defines the mechanical home: its exact command position is
where the counters read zero at completion. On a stepper that is the pulse count that
tripped the switch (its pulse left half a pulse before the planned position got there, see
control.home.pulserule); on a servo, the planned position at the edge's exact time.

The [low] rows and the EZ-count convention below are assumptions, not vendor text: they
live here, in one table, so that they are easy to correct.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import MotionError, check_int, show
from ...limits import check_pulses, check_quantity

#: ez_count n waits for n + EZ_COUNT_BASE index edges ([low]: PCL6045B counts 1..16 with
#: a 0..15 register; seed-facts 1.1).
EZ_COUNT_BASE = 1
EZ_COUNT_MAX = 15
SIGNALS = ("org", "el", "ez")
SPEEDS = ("max", "str", "creep")
REACTIONS = ("stop", "el", "slow", "pass")


@dataclass(frozen=True)
class Phase:
    """One phase of a home sequence (see the module doc)."""

    name: str
    signal: str             # "org", "el" (the limit ahead), "ez"
    edge: str               # "on": becomes active, "off": becomes inactive
    direction: int          # +1 home direction, -1 opposite
    speed: str              # "max" MaxVel, "str" StrVel, "creep" MaxVel/10 (MCCL phases 1-3)
    then: str               # "stop", "el", "slow", "pass"
    mark: bool = False      # this edge is the mechanical home
    ez_counted: bool = False  # wait for ez_count + EZ_COUNT_BASE edges instead of one
    must_stay_on: bool = False  # at rest, the signal must still be active (MCCL phase 0)

    def __post_init__(self) -> None:
        assert self.signal in SIGNALS and self.speed in SPEEDS and self.then in REACTIONS
        assert self.edge in ("on", "off") and self.direction in (1, -1)


P = Phase
_ORG_STOP = P("search ORG", "org", "on", 1, "max", "stop")
_EL = P("search EL", "el", "on", 1, "max", "el")


def _ez(name: str, d: int, speed: str, then: str = "stop", *, mark: bool = True,
        counted: bool = True) -> Phase:
    return P(name, "ez", "on", d, speed, then, mark=mark, ez_counted=counted)


#: HSL / PCL6045 home_mode -> phases. Comments: seed wording; [low] = assumption.
HSL_MODES: dict[int, tuple[Phase, ...]] = {
    # 0: ORG -> slow down -> stop (home = the ORG edge met at MaxVel)
    0: (P("search ORG", "org", "on", 1, "max", "stop", mark=True),),
    # 1: ORG -> slow down -> stop at end of ORG (continues at StrVel until ORG releases)
    1: (P("search ORG", "org", "on", 1, "max", "slow"),
        P("end of ORG", "org", "off", 1, "str", "stop", mark=True)),
    # 2 [low]: ORG -> EZ count -> stop (no slow-down on ORG)
    2: (P("search ORG", "org", "on", 1, "max", "pass"), _ez("count EZ", 1, "max")),
    # 3 [low]: ORG -> slow down -> EZ count -> stop
    3: (P("search ORG", "org", "on", 1, "max", "slow"), _ez("count EZ", 1, "str")),
    # 4 [low]: ORG -> stop -> reverse -> EZ count (counting from the reversal) -> stop
    4: (_ORG_STOP, _ez("count EZ back", -1, "str")),
    # 5 [low]: ORG -> stop -> reverse -> leave ORG -> EZ count -> stop
    5: (_ORG_STOP, P("leave ORG", "org", "off", -1, "str", "pass"),
        _ez("count EZ back", -1, "str")),
    # 6: EL only (home = the limit edge)
    6: (P("search EL", "el", "on", 1, "max", "el", mark=True),),
    # 7 [low]: EL -> reverse -> EZ count -> stop
    7: (_EL, _ez("count EZ back", -1, "str")),
    # 8: EL -> go back -> accelerate to MaxVel -> EZ -> slow down -> stop
    8: (_EL, _ez("EZ back", -1, "max")),
    # 9: ORG -> slow down -> go back -> stop at the beginning edge of ORG
    9: (_ORG_STOP, P("back to ORG edge", "org", "off", -1, "str", "stop", mark=True)),
    # 10: ORG -> EZ -> slow down -> go back -> stop at the beginning edge of EZ
    10: (P("search ORG", "org", "on", 1, "max", "pass"),
         _ez("EZ", 1, "max", mark=False),
         _ez("back to EZ edge", -1, "str", counted=False)),
    # 11: ORG -> slow down -> go back -> MaxVel -> EZ -> slow down -> forward -> EZ edge
    11: (_ORG_STOP, _ez("EZ back", -1, "max", mark=False),
         _ez("forward to EZ edge", 1, "str", counted=False)),
    # 12: as 11, starting from EL
    12: (_EL, _ez("EZ back", -1, "max", mark=False),
         _ez("forward to EZ edge", 1, "str", counted=False)),
}
LOW_CONFIDENCE_MODES = (2, 3, 4, 5, 7)

MCCL_TYPES = ("normal", "home_only", "index_only")


def mccl_phases(kind: str, same_direction: bool) -> tuple[Phase, ...]:
    """MCCL homing (manual 2.7) as phases; `same_direction`: wPhase1Dir == wPhase0Dir.

    Phase 0 searches the sensor at the homing speed and must stop on it; phase 1 leaves it
    in wPhase1Dir at 1/10 speed; phase 2 goes on in wPhase1Dir to the nearest index; phase 3
    (the offset move to the logical home) is the engine's final move. INDEX_ONLY runs
    phase 2 from rest in wPhase1Dir (the manual's phase 2 direction). Phases
    1, 2 and 3 run at about 1/10 of the phase-0 speed (HomeConfig.speed: "creep").
    """
    d1 = 1 if same_direction else -1
    p0 = P("phase 0: enter home sensor", "org", "on", 1, "max", "stop", must_stay_on=True)
    if kind == "normal":
        return (p0, P("phase 1: leave home sensor", "org", "off", d1, "creep", "pass"),
                _ez("phase 2: index", d1, "creep", counted=False))
    if kind == "home_only":
        return (p0, P("phase 1: leave home sensor", "org", "off", d1, "creep", "stop",
                      mark=True))
    if kind == "index_only":  # phase 2 moves in wPhase1Dir (manual 2.7), as in NORMAL
        return (_ez("phase 2: index", d1, "creep", counted=False),)
    raise ValueError(kind)


def uses(phases: tuple[Phase, ...], signal: str) -> bool:
    """Whether any phase waits for `signal`."""
    return any(ph.signal == signal for ph in phases)


EL_STOPS = ("decel", "immediate")
FINALS = ("mark", "stay")


@dataclass(frozen=True)
class HomeConfig:
    """Home settings of one axis (HSL set_home_config + home_move speeds, MCCL HOME_CONFIG).

    mode: 0..12 (HSL home_mode) or "mccl_normal" / "mccl_home_only" / "mccl_index_only".
    direction: +1/-1 home direction (HSL: the sign of MaxVel; MCCL: wPhase0Dir).
    phase1_same_direction: MCCL wPhase1Dir == wPhase0Dir. str_vel, max_vel (pps), tacc (s),
    jerk (pps^3, None = T-curve). ez_count 0..15. org_offset: back-off after leaving ORG
    (HSL ORG_ESC_Offset). home_offset: final position relative to the mechanical home (MCCL
    dfOffset; where the counters read 0). final: "mark" = move to home_offset and clear the
    counters there; "stay" = stop where the mode stops, counters set so the home reads 0.
    el_stop: reaction to an end limit used by the mode. auto_search: reverse on an end limit
    (HSL home_search). max_overrun: deceleration budget after any trigger (pulses).
    """

    mode: int | str = 0
    direction: int = -1
    str_vel: float = 500.0
    max_vel: float = 5000.0
    tacc: float = 0.1
    jerk: float | None = None
    ez_count: int = 0
    org_offset: float = 0.0
    home_offset: float = 0.0
    final: str = "mark"
    el_stop: str = "decel"
    auto_search: bool = False
    phase1_same_direction: bool = False
    search_range: float = 2.0**27
    max_overrun: float | None = None
    settle_s: float = 0.0
    timeout_s: float = 600.0
    tdec: float | None = None   # deceleration time (MCC_SetGoHomeDecStep); None: tacc

    def __post_init__(self) -> None:
        m = self.mode
        if not (isinstance(m, int) and not isinstance(m, bool) and m in HSL_MODES) and \
                not (isinstance(m, str) and m in tuple(f"mccl_{k}" for k in MCCL_TYPES)):
            raise MotionError(f"mode must be 0..12 or mccl_normal/mccl_home_only/"
                              f"mccl_index_only, got {m!r}")
        if not isinstance(self.direction, int) or isinstance(self.direction, bool) \
                or self.direction not in (1, -1):
            raise MotionError(f"direction must be +1 or -1, got {show(self.direction)}")
        # every number is checked and stored as a float, so a str or Decimal that would
        # break Homing.start() (TypeError, axis left in Homing) is refused here
        vals: dict[str, float | None] = {
            "str_vel": check_quantity("str_vel", self.str_vel, "pps"),
            "max_vel": check_quantity("max_vel", self.max_vel, "pps"),
            "tacc": check_quantity("tacc", self.tacc, "seconds"),
            "tdec": None if self.tdec is None else check_quantity("tdec", self.tdec, "seconds"),
            "jerk": None if self.jerk is None else check_quantity("jerk", self.jerk, "pps3"),
            "org_offset": check_quantity("org_offset", self.org_offset, "pulses", zero=True),
            "home_offset": check_pulses("home_offset", self.home_offset),
            "search_range": check_quantity("search_range", self.search_range, "pulses"),
            "max_overrun": None if self.max_overrun is None else
            check_quantity("max_overrun", self.max_overrun, "pulses"),
            "settle_s": check_quantity("settle_s", self.settle_s, "seconds", zero=True),
            "timeout_s": check_quantity("timeout_s", self.timeout_s, "seconds"),
        }
        sv, mv = vals["str_vel"], vals["max_vel"]
        assert sv is not None and mv is not None
        if sv > mv:
            raise MotionError(f"str_vel must be <= max_vel ({mv!r}), got {sv!r}")
        check_int("ez_count", self.ez_count, 0, EZ_COUNT_MAX)
        if vals["home_offset"] != round(vals["home_offset"] or 0.0):
            raise MotionError(f"home_offset must be a whole number of pulses, got "
                              f"{self.home_offset!r}")
        if not isinstance(self.final, str) or self.final not in FINALS:
            raise MotionError(f"final must be one of {FINALS}, got {show(self.final)}")
        if not isinstance(self.el_stop, str) or self.el_stop not in EL_STOPS:
            raise MotionError(f"el_stop must be one of {EL_STOPS}, got {show(self.el_stop)}")
        for name in ("auto_search", "phase1_same_direction"):
            if not isinstance(getattr(self, name), bool):
                raise MotionError(f"{name} must be True or False, got "
                                  f"{show(getattr(self, name))}")
        for name, x in vals.items():
            object.__setattr__(self, name, x)

    @property
    def mccl(self) -> bool:
        """An MCCL mode: no StrVel; phases 1-3 (and any escape) run at MaxVel/10."""
        return isinstance(self.mode, str)

    @property
    def accel(self) -> float:
        """Ramp acceleration (pps^2): (MaxVel - StrVel) / Tacc, or MaxVel/Tacc if equal;
        MCCL modes: MaxVel / Tacc (MCC_SetGoHomeAccStep: the time from rest to MaxVel)."""
        dv = self.max_vel - self.str_vel
        return (dv if dv > 0.0 and not self.mccl else self.max_vel) / self.tacc

    @property
    def decel(self) -> float:
        """Ramp deceleration (pps^2): as `accel` with tdec (default tacc)."""
        if self.tdec is None:
            return self.accel
        dv = self.max_vel - self.str_vel
        return (dv if dv > 0.0 and not self.mccl else self.max_vel) / self.tdec

    def phases(self) -> tuple[Phase, ...]:
        if isinstance(self.mode, int):
            return HSL_MODES[self.mode]
        return mccl_phases(self.mode[5:], self.phase1_same_direction)

    def speed(self, name: str) -> float:
        """A phase speed (pps). MCCL modes have no StrVel: their slow moves (escape, the
        phase 3 move to the logical home) creep at MaxVel/10 like phases 1 and 2."""
        creep = self.max_vel / 10.0
        return {"max": self.max_vel, "str": creep if self.mccl else self.str_vel,
                "creep": creep}[name]


@dataclass
class HomeStatus:
    """Where a homing run is. `code` is MCC_GetGoHomeStatus-like: -1 running, 1 done,
    0 not started / failed."""

    state: str = "idle"          # idle, running, done, error, aborted
    phase: str = ""
    mark: float | None = None    # mechanical home, command-counter frame before the reset
    #                              (stepper: the count of the pulse that hit the edge)
    mark_time: float | None = None
    mark_encoder: int | None = None
    reason: str | None = None
    history: list[str] = field(default_factory=list)

    @property
    def code(self) -> int:
        return -1 if self.state == "running" else 1 if self.state == "done" else 0
