"""The article's main program: initialise, then run the test subroutine g_cmd selects.

On the controller the `while 1` loop waits for the PC to set g_cmd; here `main(cmds)` sets
it to each value in turn (default: every mode whose subroutine the article gives or whose
TABLE/HW_PSWITCH2/HW_TIMER lines it gives: 1, 3, 25, 26, 35, 36). Modes 4-7 are not in the
article's text (it breaks off at Test_Mode4): g_cmd 4..7 raise.
Run: python examples/zmotion/article.py [outdir]
"""

import sys

from common import OFF, OUT, clean_pos, controller, finish, report
from mode1_table import test_mode1
from mode3_vector import test_mode3
from mode25_26_2d import test_mode25, test_mode26
from mode35_36_3d import test_mode35, test_mode36

SUBS = {1: test_mode1, 3: test_mode3, 25: test_mode25, 26: test_mode26, 35: test_mode35,
        36: test_mode36}


def main(outdir=OUT, cmds=(1, 3, 25, 26, 35, 36)):
    c = controller()                     # RAPIDSTOP(2) ... VECTOR_MOVED = 0
    results = {}
    for g_cmd in cmds:                   # while 1  'test all comparison modes
        if g_cmd not in SUBS:            #   if g_cmd = 1 THEN ... elseif ... endif
            raise ValueError(f"g_cmd {g_cmd}: no subroutine in the article's text")
        clean_pos(c)                     #     Clean_Pos()    'clear position
        job = SUBS[g_cmd](c)             #     Test_ModeN()   'call comparison
        finish(c)
        c.HW_TIMER(0, 10000, 6000, 1, OFF, 0)
        results[g_cmd] = report(c, job, f"article_mode{g_cmd}", outdir)
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
