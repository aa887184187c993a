"""Test_Mode35 / Test_Mode36: 3-D comparison (HW_PSWITCH2 modes 35 and 36), the article's
TABLE of 6 XYZ points on the diagonal, maxerr 10 pulses, HW_TIMER(2, 100000, 50000, 1,
OFF, 0): "output pulses once of each comparison", 50 ms wide.

The moves are ours (the article omits them): one MOVEABS along the diagonal past the last
point. Mode 35 with the timer running gives the timer's pulse at each point (the article:
"the pulse output width is determined by HW_TIMER"); mode 36 calls HW_PSWITCH2 first and
HW_TIMER after it, as the article does. Both: 6 firings, 6 pulses of 50 ms.
Run: python examples/zmotion/mode35_36_3d.py [outdir]
"""

import sys

from common import OFF, OUT, clean_pos, controller, finish, report


def table_3d(c):
    # TABLE(0 20 20 20 40 40 40 70 70 70 100 100 100 140 140 140 180 180 180)
    c.TABLE(0, 20, 20, 20, 40, 40, 40, 70, 70, 70, 100, 100, 100, 140, 140, 140, 180, 180,
            180)


def test_mode35(c):
    """Test_Mode35"""
    table_3d(c)
    c.BASE(0, 1, 2)                            # BASE(0,1,2)
    c.HW_PSWITCH2(2)                           # HW_PSWITCH2(2)
    job = c.HW_PSWITCH2(35, 0, 1, 10, 6, 0)    # HW_PSWITCH2(35, 0, 1, 10, 6, 0)
    c.HW_TIMER(2, 100000, 50000, 1, OFF, 0)    # HW_TIMER(2, 100000, 50000, 1, OFF, 0)
    c.TRIGGER()                                # TRIGGER
    c.MOVEABS(200, 200, 200)                   # ours: along the diagonal past every point
    return job


def test_mode36(c):
    """Test_Mode36"""
    table_3d(c)
    c.BASE(0, 1, 2)                            # BASE(0,1,2)
    c.HW_PSWITCH2(2)                           # HW_PSWITCH2(2)
    job = c.HW_PSWITCH2(36, 0, 1, 10, 6, 0)    # HW_PSWITCH2 (36, 0, 1, 10, 6, 0)
    c.HW_TIMER(2, 100000, 50000, 1, OFF, 0)    # HW_TIMER(2, 100000, 50000, 1, OFF, 0)
    c.TRIGGER()                                # TRIGGER
    c.MOVEABS(200, 200, 200)                   # ours
    return job


def main(outdir=OUT):
    results = {}
    for name, sub in (("mode35", test_mode35), ("mode36", test_mode36)):
        c = controller()
        clean_pos(c)
        job = sub(c)
        finish(c)
        c.HW_TIMER(0, 10000, 6000, 1, OFF, 0)
        results[name] = report(c, job, name, outdir, xy=(0, 1))
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
