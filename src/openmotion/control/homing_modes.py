"""Home-return sequences as data: every mode is a tuple of `Phase`s run by control.homing.

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

`mark` flags the edge that defines the mechanical home: its exact command position (the
position at the edge's exact time) is where the counters read zero at completion.

The [low] rows and the EZ-count convention below are assumptions, not vendor text: they
live here, in one table, so that they are easy to correct.
"""

from __future__ import annotations

from dataclasses import dataclass

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
    phase 2 from rest in wPhase1Dir, relative here to the homing direction (+1).
    """
    d1 = 1 if same_direction else -1
    p0 = P("phase 0: enter home sensor", "org", "on", 1, "max", "stop", must_stay_on=True)
    if kind == "normal":
        return (p0, P("phase 1: leave home sensor", "org", "off", d1, "creep", "pass"),
                _ez("phase 2: index", d1, "creep", counted=False))
    if kind == "home_only":
        return (p0, P("phase 1: leave home sensor", "org", "off", d1, "creep", "stop",
                      mark=True))
    if kind == "index_only":
        return (_ez("phase 2: index", 1, "creep", counted=False),)
    raise ValueError(kind)


def uses(phases: tuple[Phase, ...], signal: str) -> bool:
    """Whether any phase waits for `signal`."""
    return any(ph.signal == signal for ph in phases)
