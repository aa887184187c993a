"""A complete MCCL program ported to openmotion: an XY table with a Z axis on one PCI-4P.

The C original follows the manual's order (2.4-2.10): mechanism parameters for every axis,
the groups, MCC_InitSystem, homing, then a job. Porting changed only the syntax: the
calls, their arguments and their return codes are MCCL's (`from openmotion.compat.mccl
import *` stands for `#include "MCCL.h"`), out-parameters come back as tuples, and the
program lets virtual time pass (`LIBRARY.advance`, `LIBRARY.wait_motion`) where the C
program would poll the card. The machine is simulated: `LIBRARY.simulate` places the home
sensors.

Run: python examples/mccl/xy_table.py
"""

from __future__ import annotations

from openmotion.compat.mccl import *  # noqa: F403
from openmotion.compat.mccl import LIBRARY
from openmotion.config import SwitchConfig

CARD_INDEX = 0
XY, Z = 0, 1                         # group 0: X, Y (channels 0, 1); group 1: Z (channel 2)


def check(rc: int, what: str) -> int:
    """The C program's error check: a negative return code stops the program."""
    if rc < 0:
        raise SystemExit(f"{what} failed: {rc} ({LIBRARY.last_error})")
    return rc


def mechanism() -> None:
    """2.4: 1000 pulses/mm ball screws (dwPPR 1000, pitch 1), 3000 rpm (50 mm/s)."""
    for ch in range(4):
        p = SYS_MACH_PARAM()  # noqa: F405
        p.dwPPR = 1000
        p.wRPM = 3000
        p.dfPitch = 1.0
        p.dfGearRatio = 1.0
        p.dfHighLimit, p.dfHighLimitOffset = 151.0, 1.0    # working interval +150 mm
        p.dfLowLimit, p.dfLowLimitOffset = -11.0, 1.0      # and -10 mm
        p.wOverTravelUpSensorMode = p.wOverTravelDownSensorMode = 2   # no switches
        p.stHome.wType = HOME_ONLY_MODE  # noqa: F405
        p.stHome.wPhase0Dir, p.stHome.wPhase1Dir = 1, 0    # search downwards, leave upwards
        p.stHome.dfOffset = 1.0                            # logical home 1 mm above
        check(MCC_SetMachParam(p, ch, CARD_INDEX), "MCC_SetMachParam")  # noqa: F405


def groups() -> None:
    """2.5.1: group 0 = X, Y on channels 0, 1; group 1 = Z on channel 2."""
    cfg = SYS_GROUP_CONFIG()  # noqa: F405
    cfg.nGroupUsed[XY] = 0
    cfg.stGroupInfo[XY] = SYS_GROUP_INFO(CARD_INDEX, [0, 1, -1, -1, -1, -1])  # noqa: F405
    cfg.nGroupUsed[Z] = 0
    cfg.stGroupInfo[Z] = SYS_GROUP_INFO(CARD_INDEX, [2, -1, -1, -1, -1, -1])  # noqa: F405
    check(MCC_SetGroupConfig(cfg), "MCC_SetGroupConfig")  # noqa: F405


def home_all() -> None:
    """2.7: Z first (order 0), then X and Y together (order 1), at 20 mm/s."""
    check(MCC_SetGoHomeAccStep(10), "MCC_SetGoHomeAccStep")  # noqa: F405
    check(MCC_GoHome(20, 20, 20, 0, 0, 0, 1, 1, 0, -1, -1, -1, CARD_INDEX), "MCC_GoHome")  # noqa: F405
    while MCC_GetGoHomeStatus() == -1:  # noqa: F405
        LIBRARY.advance(0.1)
    if MCC_GetGoHomeStatus() != 1:  # noqa: F405
        raise SystemExit(f"homing failed ({LIBRARY.last_error})")


def retune() -> None:
    """After homing, on the machine at rest: a finer interpolation time (2.6.4 I, "later
    any time": 2 ms; the steps keep their counts), the X encoder read x2 (2.9), and a
    narrower working interval for X set with MCC_SetMachParam + MCC_UpdateMachParam (2.4)."""
    check(MCC_SetInterpolationTime(2), "MCC_SetInterpolationTime")  # noqa: F405
    check(MCC_SetENCInputRate(2, 0, CARD_INDEX), "MCC_SetENCInputRate")  # noqa: F405
    p = SYS_MACH_PARAM()  # noqa: F405
    MCC_GetMachParam(p, 0, CARD_INDEX)  # noqa: F405
    p.dfHighLimitOffset = 11.0                             # X up to 140 mm
    check(MCC_SetMachParam(p, 0, CARD_INDEX), "MCC_SetMachParam")  # noqa: F405
    check(MCC_UpdateMachParam(), "MCC_UpdateMachParam")  # noqa: F405


def job() -> list[tuple[float, ...]]:
    """A plate: rapid to the start, a blended contour with an arc and a circle (S-curve
    acceleration, T deceleration: MCC_SetAccType / MCC_SetDecType), a dwell, a hold and a
    continue, a feed override, in-position checked at the end."""
    out = []
    for g in (XY, Z):
        check(MCC_SetOverTravelCheck(1, 1, 1, 1, 0, 0, g), "MCC_SetOverTravelCheck")  # noqa: F405
    check(MCC_SetPtPSpeed(50, XY), "MCC_SetPtPSpeed")  # noqa: F405
    check(MCC_PtP(10, 10, 0, 0, 0, 0, XY), "MCC_PtP")  # noqa: F405
    check(MCC_PtP(-5, 0, 0, 0, 0, 0, Z), "MCC_PtP")            # tool down  # noqa: F405
    LIBRARY.wait_motion(Z)
    check(MCC_SetFeedSpeed(20, XY), "MCC_SetFeedSpeed")  # noqa: F405
    check(MCC_SetAccStep(20, XY), "MCC_SetAccStep")  # noqa: F405
    check(MCC_SetDecStep(40, XY), "MCC_SetDecStep")  # noqa: F405
    check(MCC_SetAccType("S", XY), "MCC_SetAccType")  # noqa: F405
    check(MCC_SetDecType("T", XY), "MCC_SetDecType")  # noqa: F405
    check(MCC_EnableBlend(XY), "MCC_EnableBlend")     # the next starts as one decelerates  # noqa: F405
    check(MCC_Line(60, 10, 0, 0, 0, 0, XY), "MCC_Line")  # noqa: F405
    check(MCC_ArcXY(70, 20, 60, 30, XY), "MCC_ArcXY")     # half circle through (70, 20)  # noqa: F405
    check(MCC_Line(10, 30, 0, 0, 0, 0, XY), "MCC_Line")  # noqa: F405
    check(MCC_Line(10, 10, 0, 0, 0, 0, XY), "MCC_Line")  # noqa: F405
    check(MCC_DelayMotion(250, XY), "MCC_DelayMotion")    # 250 x 2 ms dwell  # noqa: F405
    check(MCC_CircleXY(20, 10, CIR_CCW, XY), "MCC_CircleXY")  # noqa: F405
    LIBRARY.advance(2.0)
    check(MCC_HoldMotion(XY), "MCC_HoldMotion")  # noqa: F405
    LIBRARY.advance(1.0)
    out.append(MCC_GetCurPos(XY)[1:3])  # noqa: F405
    check(MCC_ContiMotion(XY), "MCC_ContiMotion")  # noqa: F405
    check(MCC_SetOverSpeed(150, XY), "MCC_SetOverSpeed")  # noqa: F405
    LIBRARY.wait_motion(XY, 120)
    check(MCC_SetInPosTolerance([0.01, 0.01, 0, 0, 0, 0], XY), "MCC_SetInPosTolerance")  # noqa: F405
    check(MCC_EnableInPos(XY), "MCC_EnableInPos")  # noqa: F405
    check(MCC_PtP(0, 0, 0, 0, 0, 0, XY), "MCC_PtP")  # noqa: F405
    check(MCC_PtP(0, 0, 0, 0, 0, 0, Z), "MCC_PtP")              # tool up  # noqa: F405
    LIBRARY.wait_motion(XY)
    LIBRARY.wait_motion(Z)
    out.append(MCC_GetCurPos(XY)[1:3])  # noqa: F405
    out.append((float(MCC_GetInPosStatus(XY)), float(MCC_GetErrorCode(XY))))  # noqa: F405
    return out


def main() -> dict:
    LIBRARY.simulate(lambda card, ch: {"org": SwitchConfig(position=-3000.0, width=2000.0)})
    MCC_CloseSystem()  # noqa: F405 - a clean library state
    mechanism()
    groups()
    cards = [SYS_CARD_CONFIG()]  # noqa: F405
    check(MCC_InitSystem(5, cards, 1), "MCC_InitSystem")  # noqa: F405
    home_all()
    retune()
    held, end, status = job()
    period = MCC_GetInterpolationTime()  # noqa: F405
    refused = MCC_PtP(145, 10, 0, 0, 0, 0, XY)   # X beyond 151 - 11 = 140 mm  # noqa: F405
    result = {"held_at": held, "end": end, "in_position": status[0], "error": status[1],
              "pulses": MCC_GetPulsePos(XY)[1:3], "time": LIBRARY.controller.time,  # noqa: F405
              "period_ms": period, "refused_at_145": refused}
    check(MCC_CloseSystem(), "MCC_CloseSystem")  # noqa: F405
    return result


if __name__ == "__main__":
    r = main()
    print(f"held at X={r['held_at'][0]:.3f} Y={r['held_at'][1]:.3f} mm "
          f"(interpolation time {r['period_ms']} ms; PtP to X=145 mm: {r['refused_at_145']})")
    print(f"end at X={r['end'][0]:.3f} Y={r['end'][1]:.3f} mm, pulses {r['pulses']}, "
          f"in position {r['in_position']:.0f}, error {r['error']:.0f}, "
          f"{r['time']:.2f} s")
