"""Fuzz the public entry points of openmotion.control (see fuzzkit.py for the oracle):
axes, groups, jog, homing, latch and touch probe, compare, PSO, compensation, servo,
in-position control."""

from __future__ import annotations

from fuzzkit import Entry, examples, run_entries
from openmotion.control.groups.group import Group
from openmotion.control.guard.inposition import InPositionControl
from openmotion.control.home.homing import HomeConfig, Homing
from openmotion.control.home.latch import Latch, TouchProbe
from openmotion.control.loops.compensation import Compensation, PitchCompTable
from openmotion.control.loops.servo import PIDFF, FollowingErrorMonitor, LeadFilter
from openmotion.control.manual import jog
from openmotion.control.trigger.compare import (
    AxisSource,
    CompareEngine,
    LevelJob,
    Pulse,
    SetLevel,
    Toggle,
    VectorSource,
    WindowJob,
    every_distance,
)
from openmotion.control.trigger.pso import ZPso


def _ax(w, **kw):
    return w.ctl.axis("x")


def axis_call(method):
    return lambda w, **kw: getattr(w.ctl.axis("x"), method)(**kw)


def group(w):
    return w.get("group", lambda w: Group(w.ctl, ["x", "y"], feed=10_000.0, acc_time=0.1))


def group_call(method):
    return lambda w, **kw: getattr(group(w), method)(**kw)


def engine(w):
    return w.get("engine", lambda w: CompareEngine(w.ctl))


def pso(w):
    return w.get("pso", lambda w: ZPso(engine(w)))


def comp(w):
    return w.get("comp", lambda w: Compensation(w.ctl.axis("x"), max_accel=1e6))


def inpos(w):
    return w.get("inpos", lambda w: InPositionControl(w.ctl))


def latch(w):
    return w.get("latch", lambda w: Latch(w.ctl))


MOVE = dict(max_vel=20_000.0, str_vel=100.0, tacc=0.05, tdec=None, shape="S", vs_acc=0.0,
            vs_dec=0.0, units=False)

AXES = [
    Entry("Axis.move_relative", axis_call("move_relative"), dict(distance=5000.0, **MOVE),
          aliases={"units": ("units", "max_vel")}),
    Entry("Axis.move_absolute", axis_call("move_absolute"), dict(position=5000.0, **MOVE),
          aliases={"units": ("units", "max_vel")}),
    Entry("Axis.move_velocity", axis_call("move_velocity"),
          dict(velocity=5000.0, str_vel=100.0, tacc=0.05, shape="T", vs_acc=0.0,
               units=False), aliases={"units": ("units", "velocity")}),
    Entry("Axis.move_jerk_limited", axis_call("move_jerk_limited"),
          dict(distance=5000.0, v_max=2e4, a_max=2e5, j_max=2e7, d_max=None, absolute=False,
               units=False), aliases={"units": ("units", "v_max")}),
    Entry("Axis.fix_speed_range", axis_call("fix_speed_range"),
          dict(max_vel=10_000.0, units=False), aliases={"units": ("units", "max_vel")}),
    Entry("Axis.set_move_ratio", axis_call("set_move_ratio"), dict(ratio=2.0)),
    Entry("Axis.set_inp", axis_call("set_inp"), dict(enabled=True)),
    Entry("Axis.stop", axis_call("stop"), dict(tdec=0.1)),
    Entry("Axis.check_speed", axis_call("check_speed"),
          dict(name="v", value=100.0, units=False), aliases={"value": ("v",)}),
    Entry("Controller.axis", lambda w, key: w.ctl.axis(key), dict(key="x"),
          aliases={"key": ("axis",)}),
]

GROUPS = [
    Entry("Group", lambda w, **kw: Group(w.ctl, **kw),
          dict(axes=["z", "u"], feed=10_000.0, acc_time=0.1, queue_size=16, units=False),
          aliases={"axes": ("axes", "axis")}),
    Entry("Group.line", group_call("line"), dict(target=[1000.0, 500.0], relative=False)),
    Entry("Group.ptp", group_call("ptp"), dict(target=[1000.0, 500.0], relative=True)),
    Entry("Group.arc", group_call("arc"),
          dict(centre=[500.0, 0.0], end=[1000.0, 0.0], plane=(0, 1), direction="CW",
               relative=False, turns=0)),
    Entry("Group.circle", group_call("circle"),
          dict(centre=[500.0, 0.0], plane=(0, 1), direction="CCW", relative=True)),
    Entry("Group.arc3d", group_call("arc3d"),
          dict(via=[500.0, 500.0], end=[1000.0, 0.0], relative=False)),
    Entry("Group.delay", group_call("delay"), dict(seconds=0.01)),
    Entry("Group.enable_blend", group_call("enable_blend"), dict(tolerance=5.0)),
    Entry("Group.enable_dry_run", group_call("enable_dry_run"), dict(on=True)),
    Entry("Group.set_feed", group_call("set_feed"), dict(feed=5000.0)),
    Entry("Group.set_acc_time", group_call("set_acc_time"), dict(seconds=0.2)),
    Entry("Group.set_override", group_call("set_override"), dict(percent=50.0)),
    Entry("Group.set_ptp_override", group_call("set_ptp_override"), dict(percent=50.0)),
    Entry("Group.set_max_pulse_speed", group_call("set_max_pulse_speed"),
          dict(pps=[2e5, 2e5])),
    Entry("Group.set_max_pulse_acc", group_call("set_max_pulse_acc"), dict(pps2=[2e6, 2e6])),
    Entry("Group.set_path_shape", group_call("set_path_shape"), dict(shape="S", jerk=None)),
    Entry("Group.set_ptp_speed", group_call("set_ptp_speed"), dict(ratio=50.0, shape="T")),
    Entry("Group.set_str_vel", group_call("set_str_vel"), dict(speed=10.0)),
    Entry("Group.set_sys_max_speed", group_call("set_sys_max_speed"), dict(speed=1e5)),
    Entry("Group.set_corner_velocity", group_call("set_corner_velocity"),
          dict(velocity=100.0)),
    Entry("Group.set_min_cruise_ratio", group_call("set_min_cruise_ratio"),
          dict(ratio=0.5)),
    Entry("Group.set_axis_limit_policy", group_call("set_axis_limit_policy"),
          dict(policy="slow")),
]

JOG_HOME_LATCH = [
    Entry("jog_pulse", lambda w, **kw: jog.jog_pulse(w.ctl, **kw),
          dict(axis="x", pulses=10, speed=None, tacc=0.01)),
    Entry("jog_space", lambda w, **kw: jog.jog_space(w.ctl, **kw),
          dict(axis="x", distance=100.0, ratio=0.5, tacc=0.05)),
    Entry("jog_conti", lambda w, **kw: jog.jog_conti(w.ctl, **kw),
          dict(axis=0, direction=1, ratio=0.5, tacc=0.05, border=None)),
    Entry("HomeConfig", lambda w, **kw: HomeConfig(**kw),
          dict(mode=0, direction=-1, str_vel=500.0, max_vel=5000.0, tacc=0.1, jerk=None,
               ez_count=0, org_offset=0.0, home_offset=0.0, final="mark",
               el_stop="decel", auto_search=False, search_range=2.0**27,
               max_overrun=None, settle_s=0.0, timeout_s=600.0)),
    Entry("Homing", lambda w, **kw: Homing(w.ctl, **kw).start(),
          dict(axis="x", config=HomeConfig(mode=0, str_vel=2000.0, max_vel=20000.0,
                                            tacc=0.05), escape_only=False)),
    Entry("Latch.set_edge", lambda w, **kw: latch(w).set_edge(**kw),
          dict(axis="x", edge="off")),
    Entry("Latch.data", lambda w, **kw: latch(w).data(**kw), dict(axis=1)),
    Entry("TouchProbe", lambda w, **kw: TouchProbe(w.ctl, **kw),
          dict(axis="x", trigger=("x", "ltc"), edge="on", window=(0.0, 1000.0),
               mode="single", capacity=100)),
]

COMPARE = [
    Entry("CompareEngine", lambda w, **kw: CompareEngine(w.ctl, **kw),
          dict(buffer_size=1000, outputs=None)),
    Entry("AxisSource", lambda w, **kw: AxisSource(**kw), dict(axis=0, kind="dpos")),
    Entry("VectorSource", lambda w, **kw: VectorSource(**kw), dict(axes=(0, 1), scale=None)),
    Entry("Pulse", lambda w, **kw: Pulse(**kw), dict(output=0, width=1e-4, active=True)),
    Entry("Toggle", lambda w, **kw: Toggle(**kw), dict(output=0, first=True)),
    Entry("SetLevel", lambda w, **kw: SetLevel(**kw), dict(output=0, level=True)),
    Entry("LevelJob", lambda w, **kw: engine(w).add(LevelJob(**kw)),
          dict(source=AxisSource(0), levels=[100.0, 200.0], action=Toggle(0), direction=1,
               repeat=False, after_final=None, monotonic=True, name="j"),
          aliases={"direction": ("direction", "levels")}),
    Entry("WindowJob", lambda w, **kw: engine(w).add(WindowJob(**kw)),
          dict(axes=(0, 1), points=[[100.0, 0.0]], maxerr=5.0, action=Toggle(1),
               kind="dpos", name="w")),
    Entry("every_distance", lambda w, **kw: engine(w).add(every_distance(**kw)),
          dict(source=VectorSource((0, 1)), interval=100.0, action=Toggle(2), start=None,
               end=1000.0),
          aliases={k: (k, "table too long") for k in ("start", "end", "interval")}),
    Entry("CompareEngine.output", lambda w, **kw: engine(w).output(**kw), dict(number=1),
          aliases={"number": ("output",)}),
    Entry("CompareEngine.remove", lambda w, **kw: engine(w).remove(**kw), dict(job_id=0),
          aliases={"job_id": ("job",)}),
    Entry("CompareEngine.set_vector_moved", lambda w, **kw: engine(w).set_vector_moved(**kw),
          dict(source=VectorSource((0, 1)), value=0.0)),
    Entry("CompareEngine.add_speed_pwm", lambda w, **kw: engine(w).add_speed_pwm(**kw),
          dict(source=VectorSource((0, 1)), output=3, full_speed=1e4, per_cycle=1)),
    Entry("ZPso.hw_pswitch2", lambda w, mode, p1, p2: pso(w).hw_pswitch2(mode, p1, p2),
          dict(mode=2, p1=0, p2=0), aliases={"p1": ("op", "p", "table", "mode"),
                                             "p2": ("op", "p", "table", "mode")}),
    Entry("ZPso.hw_timer", lambda w, **kw: pso(w).hw_timer(**kw),
          dict(mode=2, cycle_us=100.0, on_us=50.0, reptimes=3, opstate=True, opnum=0)),
    Entry("ZPso.table", lambda w, start, v1, v2: pso(w).table(start, v1, v2),
          dict(start=0, v1=100.0, v2=200.0), aliases={"v1": ("value", "table"),
                                                      "v2": ("value", "table")}),
    Entry("ZPso.set_units", lambda w, **kw: pso(w).set_units(**kw), dict(axis=0, units=1.0)),
    Entry("ZPso.source", lambda w, **kw: pso(w).source(**kw), dict(axis=0, kind="dpos")),
    Entry("ZPso.base", lambda w, a, b: pso(w).base(a, b), dict(a=0, b=1),
          aliases={"a": ("ax",), "b": ("ax",)}),
]

COMP_SERVO = [
    Entry("Compensation", lambda w, **kw: Compensation(w.ctl.axis("y"), **kw),
          dict(max_accel=1e6, max_vel=None, comp_vel=None, comp_accel=None)),
    Entry("Compensation.backlash_comp", lambda w, **kw: comp(w).backlash_comp(**kw),
          dict(pulses=10, mode=1)),
    Entry("Compensation.suppress_vibration",
          lambda w, **kw: comp(w).suppress_vibration(**kw), dict(t1=0.01, t2=0.02)),
    Entry("Compensation.set_pitch_table", lambda w, **kw: comp(w).set_pitch_table(**kw),
          dict(interval=1000, home_index=0, forward=[0, 1, 2], backward=None, stroke=None),
          aliases={"interval": ("interval", "table covers"),
                   "home_index": ("home_index", "home point")}),
    Entry("PitchCompTable.make", lambda w, **kw: PitchCompTable.make(**kw),
          dict(interval=1000, home_index=1, forward=[0, 1, 2], backward=[0, 1, 1]),
          aliases={"interval": ("interval", "home point")}),
    Entry("LeadFilter", lambda w, **kw: LeadFilter(**kw),
          dict(a=229, b=64, k=64, limit=None, quantize=False)),
    Entry("LeadFilter.step", lambda w, **kw: LeadFilter().step(**kw),
          dict(command=10.0, feedback=0.0)),
    Entry("PIDFF", lambda w, **kw: PIDFF(**kw),
          dict(kp=1.0, ki=0.1, kd=0.0, dt=1e-3, kvff=0.0, kaff=0.0, output_limit=10.0,
               integral_limit=5.0)),
    Entry("PIDFF.step", lambda w, **kw: PIDFF(1.0, dt=1e-3).step(**kw),
          dict(command=10.0, feedback=0.0)),
    Entry("FollowingErrorMonitor", lambda w, **kw: FollowingErrorMonitor(**kw),
          dict(limit=100.0)),
    Entry("FollowingErrorMonitor.check", lambda w, **kw: FollowingErrorMonitor(10.0).check(
        **kw), dict(command=5.0, feedback=0.0)),
    Entry("InPositionControl.set_tolerance", lambda w, **kw: inpos(w).set_tolerance(**kw),
          dict(axis="x", tolerance=5.0, units=False)),
    Entry("InPositionControl.set_check_time",
          lambda w, **kw: inpos(w).set_check_time(**kw), dict(axis="y", seconds=0.01)),
    Entry("InPositionControl.enable", lambda w, **kw: inpos(w).enable(**kw),
          dict(axes=["x"]), aliases={"axes": ("axes", "axis")}),
]


_PREP = {"Group.": group, "CompareEngine.": engine, "LevelJob": engine, "WindowJob": engine,
         "every_distance": engine, "ZPso.": pso, "Compensation.": comp,
         "InPositionControl.": inpos, "Latch.": latch}


def _run(entries, fuzz_long, normal):
    for e in entries:
        for prefix, prep in _PREP.items():
            if e.name.startswith(prefix):
                e.prepare = prep
    stats = run_entries(entries, examples(fuzz_long, normal))
    print(stats.report())
    assert stats.clean, stats.report()


def test_fuzz_axes(fuzz_long: bool) -> None:
    _run(AXES, fuzz_long, 300)


def test_fuzz_groups(fuzz_long: bool) -> None:
    _run(GROUPS, fuzz_long, 300)


def test_fuzz_jog_homing_latch(fuzz_long: bool) -> None:
    _run(JOG_HOME_LATCH, fuzz_long, 300)


def test_fuzz_compare_pso(fuzz_long: bool) -> None:
    _run(COMPARE, fuzz_long, 300)


def test_fuzz_compensation_servo(fuzz_long: bool) -> None:
    _run(COMP_SERVO, fuzz_long, 300)
