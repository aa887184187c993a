"""Test_Mode3: vector-distance table compare (HW_PSWITCH2 mode 3), as in the article.

BASE(0) with MOVEABS(300,200) then MOVEABS(400,0): the interpolation of axes 0 and 1 (the
BASE list extends to the next axis), 360.6 + 223.6 = 584.2 units of path. OUT0 goes ON at
100, OFF at 150, ... of VECTOR_MOVED: three ON stretches of 50 units of path.
Run: python examples/zmotion/mode3_vector.py [outdir]
"""

import sys

from common import OFF, OUT, clean_pos, controller, finish, report


def test_mode3(c):
    """GLOBAL SUB Test_Mode3()"""
    c.TABLE(0, 100, 150, 250, 300, 400, 450)   # TABLE(0,100,150,250,300,400,450)
    c.HW_TIMER(0, 10000, 6000, 1, OFF, 0)      # HW_TIMER(0, 10000, 6000, 1, OFF, 0)
    c.BASE(0)                                  # BASE(0)
    c.VECTOR_MOVED[0] = 0                      # VECTOR_MOVED(0) = 0
    c.HW_PSWITCH2(2)                           # HW_PSWITCH2(2)
    job = c.HW_PSWITCH2(3, 0, 1, 0, 5)         # HW_PSWITCH2(3, 0, 1, 0, 5)
    c.TRIGGER()                                # TRIGGER
    c.MOVEABS(300, 200)                        # MOVEABS(300,200)
    c.MOVEABS(400, 0)                          # MOVEABS(400,0)
    return job


def main(outdir=OUT):
    c = controller()
    clean_pos(c)
    job = test_mode3(c)
    finish(c)
    r = report(c, job, "mode3", outdir, xy=(0, 1))
    r["vector_moved"] = c.VECTOR_MOVED[0]
    print(f"  VECTOR_MOVED(0) = {r['vector_moved']:.4f}")
    return r


if __name__ == "__main__":
    main(*sys.argv[1:2])
