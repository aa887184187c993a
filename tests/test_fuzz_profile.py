"""Fuzz every public entry point of openmotion.profile (see fuzzkit.py for the oracle)."""

from __future__ import annotations

from fuzzkit import Entry, examples, run_entries
from openmotion import profile as P
from openmotion.profile.batch import jerk_limited_durations, jerk_limited_phases

SPEC = P.MoveSpec("S", 100.0, 10_000.0, 0.1, 0.1, 1000.0, 1000.0)
PROF = P.trapezoid(5000.0, 0.0, 10_000.0, 0.1, 0.1)


def _f(fn):
    return lambda w, **kw: fn(**kw)


ENTRIES = [
    Entry("jerk_limited", _f(P.jerk_limited), dict(distance=1000.0, v_max=1e4, a_max=1e5,
                                                   j_max=1e7, d_max=None, start=0.0)),
    Entry("jerk_limited_duration", _f(P.jerk_limited_duration),
          dict(distance=1000.0, v_max=1e4, a_max=1e5, j_max=1e7, d_max=2e5)),
    Entry("jerk_limited_sync", _f(P.jerk_limited_sync),
          dict(distances=[1000.0, -50.0], v_max=1e4, a_max=[1e5, 2e5], j_max=1e7,
               d_max=None, starts=None)),
    Entry("jerk_limited_durations", _f(jerk_limited_durations),
          dict(distance=[1000.0, 5.0], v_max=1e4, a_max=1e5, j_max=1e7, d_max=None)),
    Entry("jerk_limited_phases", _f(jerk_limited_phases),
          dict(distance=1000.0, v_max=[1e4, 2e4], a_max=1e5, j_max=1e7, d_max=None)),
    Entry("trapezoid", _f(P.trapezoid), dict(distance=5000.0, str_vel=100.0, max_vel=1e4,
                                             tacc=0.1, tdec=0.2, start=0.0)),
    Entry("scurve", _f(P.scurve), dict(distance=5000.0, str_vel=100.0, max_vel=1e4,
                                       tacc=0.1, tdec=0.2, vs_acc=100.0, vs_dec=0.0,
                                       start=0.0)),
    Entry("MoveSpec", _f(P.MoveSpec), dict(shape="S", str_vel=100.0, max_vel=1e4, tacc=0.1,
                                           tdec=0.1, vs_acc=10.0, vs_dec=10.0)),
    Entry("MoveSpec.plan", lambda w, spec, **kw: spec.plan(**kw),
          dict(spec=SPEC, distance=2000.0, start=0.0), fixed=("spec",)),
    Entry("retarget", _f(P.retarget), dict(state=P.State(0.0, 100.0, 0.0), target=1000.0,
                                           v_max=1e4, a_max=1e5, j_max=1e7, d_max=None),
          aliases={"state": ("state",)}),
    Entry("retarget_velocity", _f(P.retarget_velocity),
          dict(state=P.State(0.0, 100.0, 0.0), v_target=500.0, a_max=1e5, j_max=1e7)),
    Entry("velocity_ramp", _f(P.velocity_ramp),
          dict(state=P.State(0.0), target_v=1000.0, t_ramp=0.1, shape="S", vs=10.0,
               str_vel=10.0)),
    Entry("velocity_move", _f(P.velocity_move), dict(spec=SPEC, direction=-1.0, start=0.0)),
    Entry("quantize", _f(P.quantize), dict(profile=PROF, period=1e-3)),
    Entry("check_quantized", _f(P.check_quantized),
          dict(counts=P.quantize(PROF, 1e-3), profile=PROF, period=1e-3),
          aliases={"period": ("period", "counts must have")}),
    Entry("change_speed", _f(P.change_speed),
          dict(profile=PROF, t=0.2, spec=P.MoveSpec("T", 0.0, 1e4, 0.1, 0.1), new_vel=5000.0,
               tacc=0.05)),
    Entry("change_position", _f(P.change_position),
          dict(profile=PROF, t=0.2, spec=P.MoveSpec("T", 0.0, 1e4, 0.1, 0.1),
               new_target=8000.0)),
    Entry("decel_stop", _f(P.decel_stop), dict(profile=PROF, t=0.2, spec=SPEC)),
    Entry("immediate_stop", _f(P.immediate_stop), dict(profile=PROF, t=0.2)),
    Entry("stop_distance", _f(P.stop_distance), dict(spec=SPEC, v=5000.0, a=0.0)),
    Entry("empty_profile", _f(P.empty_profile), dict(p=3.0)),
    Entry("Profile.sample", lambda w, t: PROF.sample(t), dict(t=[0.0, 0.1])),
    Entry("Profile.state_at", lambda w, t: PROF.state_at(t), dict(t=0.1)),
]


def test_fuzz_profile(fuzz_long: bool) -> None:
    stats = run_entries(ENTRIES, examples(fuzz_long, 500), cycles=0.0)
    print(stats.report())
    assert stats.clean, stats.report()
