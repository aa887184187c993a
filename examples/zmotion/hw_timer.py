"""HW_TIMER: one hardware timer giving the pulses of the timer modes, edited while a
comparison runs (the article: "HW_TIMER can be edited independently to adjust parameters
dynamically"; "reptimes=0, HW_TIMER will be softly closed, and uncompleted pulses will keep
outputting"; "when comparison completes, use HW_TIMER(0, 10000, 6000, 1, OFF, 0)").

The article's 2-D table in mode 26 (HW_PSWITCH2 first, then HW_TIMER), traced as in
mode25_26_2d.py:
- points 0-3: HW_TIMER(2, 100000, 50000, 2, OFF, 0): 2 pulses of 50 ms each (8 pulses);
- then HW_TIMER(2, 20000, 5000, 3, OFF, 0): points 4 and 5 give 3 pulses of 5 ms (6);
- right after point 5 fires, HW_TIMER(2, 20000, 5000, 0, OFF, 0) soft-closes the timer:
  point 5's train still finishes, points 6 and 7 fire no pulse (counted as ignored);
- HW_TIMER(0, 10000, 6000, 1, OFF, 0) when the comparison completes.
14 pulses in all. Run: python examples/zmotion/hw_timer.py [outdir]
"""

import sys

from common import OFF, OUT, clean_pos, controller, finish, report
from mode25_26_2d import table_2d, trace_points


def main(outdir=OUT):
    c = controller()
    clean_pos(c)
    table_2d(c)
    c.BASE(0, 1)
    c.HW_PSWITCH2(2)
    job = c.HW_PSWITCH2(26, 0, 1, 10, 8, 0)
    c.HW_TIMER(2, 100000, 50000, 2, OFF, 0)
    c.TRIGGER()
    trace_points(c)
    size = c.HW_PSWITCH2_FREE() + 8                     # buffer size: 8 points loaded
    c.WAIT_UNTIL(lambda: c.HW_PSWITCH2_FREE() >= size - 4)   # points 0-3 fired
    c.run(0.2)                                          # point 3's train is over
    c.HW_TIMER(2, 20000, 5000, 3, OFF, 0)               # edited while the job runs
    c.WAIT_UNTIL(lambda: c.HW_PSWITCH2_FREE() >= size - 2)   # point 5 fired
    c.HW_TIMER(2, 20000, 5000, 0, OFF, 0)               # soft close
    finish(c)
    c.HW_TIMER(0, 10000, 6000, 1, OFF, 0)               # comparison complete
    r = report(c, job, "hw_timer", outdir)
    r["ignored"] = c.pso.timer.ignored
    print(f"  firings without a pulse (timer soft-closed): {r['ignored']}")
    return r


if __name__ == "__main__":
    main(*sys.argv[1:2])
