"""Regression: the tail of the corpus's arcspiral.ngc (a spiral of R-format G2 arcs shrinking
to 0.002 in, G64 without P). With unbounded blending, a fillet between two nearly tangent
arcs came out the long way round (a 528 m arc): the chain planned a 14-hour crawl and the
run hung. A fillet is now never longer than the two stretches it replaces."""

from __future__ import annotations

from openmotion.config import default_machine
from openmotion.control import Controller
from openmotion.program import ProgramRunner
from openmotion.program.runjob import work_origin
from openmotion.program.runner import RunState

SPIRAL_TAIL = """\
g20 g64
g0z1
g0 x-0.047136 y-0.067099
g1z-.1f24
g2 r0.080000 x-0.052291 y-0.060544
r0.078000 x-0.056623 y-0.053646
r0.076000 x-0.060114 y-0.046501
r0.074000 x-0.062759 y-0.039208
r0.072000 x-0.064567 y-0.031861
r0.070000 x-0.065552 y-0.024555
r0.068000 x-0.065742 y-0.017377
r0.066000 x-0.065174 y-0.010411
r0.064000 x-0.063891 y-0.003736
r0.062000 x-0.061946 y0.002578
r0.060000 x-0.059400 y0.008467
r0.058000 x-0.056316 y0.013876
r0.055999 x-0.052764 y0.018759
r0.054000 x-0.048820 y0.023079
r0.052000 x-0.044558 y0.026806
r0.050000 x-0.040057 y0.029924
r0.048000 x-0.035395 y0.032422
r0.046000 x-0.030649 y0.034302
r0.044000 x-0.025894 y0.035574
r0.042000 x-0.021204 y0.036255
r0.040000 x-0.016646 y0.036372
r0.038000 x-0.012285 y0.035959
r0.036000 x-0.008179 y0.035059
r0.034000 x-0.004381 y0.033717
r0.032000 x-0.000934 y0.031986
r0.030000 x0.002122 y0.029925
r0.028000 x0.004759 y0.027593
r0.026000 x0.006955 y0.025053
r0.024000 x0.008697 y0.022369
r0.022000 x0.009979 y0.019607
r0.020000 x0.010806 y0.016829
r0.018000 x0.011189 y0.014100
r0.016000 x0.011147 y0.011478
r0.014000 x0.010708 y0.009019
r0.012000 x0.009904 y0.006776
r0.010000 x0.008776 y0.004794
r0.007999 x0.007368 y0.003115
r0.006000 x0.005732 y0.001773
r0.004000 x0.003920 y0.000795
r0.002000 x0.001990 y0.000200
g0z1
m2
"""


def test_spiral_tail_with_unbounded_blending_runs_and_ends_exactly():
    ctl = Controller(default_machine())
    ctl.enable_all()
    run = ProgramRunner(ctl, SPIRAL_TAIL, gcode={"parameters": work_origin(ctl)})
    run.start()
    ctl.run_until(lambda: run.state is not RunState.RUNNING, 60.0, event_driven=True)
    assert run.state is RunState.DONE
    assert ctl.time < 20.0  # about 6 s of machine time: no crawl
    g = run.group
    assert g.error_code == 0
