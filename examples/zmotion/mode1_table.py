"""Test_Mode1: 1-D table compare (HW_PSWITCH2 mode 1) on axis 0, as in the article.

TABLE 100, 150, 250, 300, 400, 450 in the positive direction during MOVE(500): OUT0 goes ON
at 100, OFF at 150, ON at 250, ... - three ON stretches of 50 units, 0.5 s each at SPEED 100.
Run: python examples/zmotion/mode1_table.py [outdir]
"""

import sys

from common import OUT, clean_pos, controller, finish, report


def test_mode1(c):
    """GLOBAL SUB Test_Mode1()"""
    c.TABLE(0, 100, 150, 250, 300, 400, 450)   # TABLE(0,100,150,250,300,400,450)
    c.BASE(0)                                  # BASE(0)
    c.HW_PSWITCH2(2)                           # HW_PSWITCH2(2)  'stop and delete ...
    job = c.HW_PSWITCH2(1, 0, 1, 0, 5, 1)      # HW_PSWITCH2(1, 0, 1, 0, 5,1)
    c.TRIGGER()                                # TRIGGER          'trigger the oscilloscope
    c.MOVE(500)                                # MOVE(500)
    return job


def main(outdir=OUT):
    c = controller()
    clean_pos(c)
    job = test_mode1(c)
    finish(c)
    return report(c, job, "mode1", outdir)


if __name__ == "__main__":
    main(*sys.argv[1:2])
