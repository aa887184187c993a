"""Re-planning from any state against ruckig (bench/bench_retarget.py's cases): no failure
of ours, and ruckig's duration wherever both planners plan the same problem.

The normal run takes 4000 cases; `--long` takes the issue's 1e6. Ours may be longer than
ruckig only in the a_max > d_max gap (ours stops and comes back: its limits are in the
frame of the final approach, ruckig's are signed, see profile/retarget.py; ruckig's plan
arrives there from the other side, a different problem), and shorter only where ruckig's
brake ends early by its eps or it plans a slower profile than the optimum (ours is
checked valid: limits, continuity, exact end). On the same problem ours is longer only in
about 3 of 100,000 cases."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
import bench_retarget as br  # noqa: E402

pytest.importorskip("ruckig")


def test_no_failures_and_ruckig_durations(long_run):
    n = 1_000_000 if long_run else 4000
    st = br.run(n, seed=7)
    br.report(st)
    assert st.our_fail == {}
    assert st.compared >= 0.99 * n
    gap = "a_max > d_max gap (stop, come back)"
    assert set(st.longer) <= {gap, "start above v_max"}
    assert st.longer.get(gap, 0) <= 0.01 * st.compared
    # braking from above v_max, ours was longer than ruckig's in 19 of 1e6 cases (seed 1):
    # rare, open (issue #14 note)
    assert st.longer.get("start above v_max", 0) <= 1e-4 * st.compared
    assert st.within_1e9 >= 0.97 * st.compared
    # on the same problem (ruckig's plan arriving from our approach side) longer only
    # rarely: 26 in 1e6 (seed 1): 19 start above v_max, longer by <= 1.5e-8 (ruckig ends
    # its brake 2.2e-14 s early under a jerk of ~5e6), 7 in the a_max > d_max gap
    assert st.same_longer <= 1e-4 * st.same and st.same >= 0.99 * st.compared
    assert st.same_1e9 >= 0.995 * st.same
    # ours shorter than ruckig outside the braking-from-above case: ruckig's own slack
    # (e.g. braking at 138 where 21983 is allowed), a handful per 10,000
    assert st.shorter.get("other", 0) <= 1e-3 * st.compared


def test_checker_sees_a_bad_profile():
    """The validity check can fail: a plan with a too-low limit is refused."""
    c = br.cases(50, seed=3)[5]
    prof = br.ours(c)
    tight = br.Case(c.state, c.target, c.v_max, c.a_max, c.j_max / 10, c.d_max, c.v_target)
    assert br.invalid(prof, c) == ""
    assert br.invalid(prof, tight) != ""
