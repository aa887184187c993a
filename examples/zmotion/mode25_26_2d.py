"""Test_Mode25 / Test_Mode26: 2-D comparison (HW_PSWITCH2 modes 25 and 26), the article's
TABLE of 8 XY points with maxerr 10 pulses.

The article gives the TABLE, HW_PSWITCH2 and HW_TIMER lines; the moves are ours: MOVEABS
through the 8 points in table order and back to the first (the article's figure: the path
passes every point; the blue stretches are where OP is on). The axes start on point 0, so
it fires at once.
- mode 25: OUT0 inverts at each point: ON on (0,0)-(50,50), (100,100)-(50,150),
  (0,200)-(-50,150), (-100,100)-(-50,50): 8 firings, 4 ON stretches.
- mode 26, HW_PSWITCH2 first, then HW_TIMER(2, 100000, 50000, 2, OFF, 0): each point gives
  2 pulses of 50 ms, 100 ms apart: 8 firings, 16 pulses.
Run: python examples/zmotion/mode25_26_2d.py [outdir]  (main(modes=...) runs one of them)
"""

import sys

from common import OFF, OUT, clean_pos, controller, finish, report

POINTS = [(0, 0), (50, 50), (100, 100), (50, 150), (0, 200), (-50, 150), (-100, 100),
          (-50, 50)]


def table_2d(c):
    # TABLE(0, 0 0 50 50 100 100 50 150 0 200 -50 150 -100 100 -50 50)
    c.TABLE(0, 0, 0, 50, 50, 100, 100, 50, 150, 0, 200, -50, 150, -100, 100, -50, 50)


def trace_points(c):
    """MOVEABS through points 1..7 and back to point 0 (ours: the article omits it)."""
    for x, y in [*POINTS[1:], POINTS[0]]:
        c.MOVEABS(x, y)


def test_mode25(c):
    """Test_Mode25"""
    table_2d(c)
    c.BASE(0, 1)                               # BASE(0,1)
    c.HW_PSWITCH2(2)                           # HW_PSWITCH2(2)
    job = c.HW_PSWITCH2(25, 0, 1, 10, 8, 0)    # HW_PSWITCH2 (25, 0, 1, 10, 8, 0)
    c.TRIGGER()                                # TRIGGER
    trace_points(c)
    return job


def test_mode26(c):
    """Test_Mode26"""
    table_2d(c)
    c.BASE(0, 1)                               # BASE(0,1)
    c.HW_PSWITCH2(2)                           # HW_PSWITCH2(2)
    job = c.HW_PSWITCH2(26, 0, 1, 10, 8, 0)    # HW_PSWITCH2 (26, 0, 1, 10, 8, 0)
    c.HW_TIMER(2, 100000, 50000, 2, OFF, 0)    # HW_TIMER(2, 100000, 50000, 2, OFF, 0)
    c.TRIGGER()                                # TRIGGER
    trace_points(c)
    return job


def main(outdir=OUT, modes=("mode25", "mode26")):
    results = {}
    subs = {"mode25": test_mode25, "mode26": test_mode26}
    for name in modes:
        sub = subs[name]
        c = controller()
        clean_pos(c)
        job = sub(c)
        finish(c)
        c.HW_TIMER(0, 10000, 6000, 1, OFF, 0)  # "when comparison completes"
        results[name] = report(c, job, name, outdir, xy=(0, 1))
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
