"""Regression tests for what the fuzz families found after the round-2 merge (issue #12).

Each test reproduces one finding and fails on the code before its fix: unbounded work or
memory for an accepted path, and Python's own exceptions escaping from config and program
entry points instead of a MotionError naming the parameter.
"""

from __future__ import annotations

import numpy as np
import pytest

from openmotion.control import Controller
from openmotion.control.groups.group import Group, GroupError
from openmotion.path import Arc
from openmotion.path.extent import element_extent


def _group() -> tuple[Controller, Group]:
    ctl = Controller()
    ctl.enable_all()
    return ctl, Group(ctl, ["x", "y"], feed=10_000.0, acc_time=0.1)


# -- groups: an arc with many turns --------------------------------------------------------
def test_arc_extent_work_does_not_grow_with_the_turns(monkeypatch):
    """element_extent evaluated every extreme angle of every turn: an arc of 10**9 turns
    (accepted, a legal helix count) built a list of 4e9 angles, 9.5 GB, in the soft-limit
    check of Group.arc. One turn holds every extreme."""
    sizes: list[int] = []
    point = Arc.point

    def spy(self, s):
        sizes.append(int(np.size(s)))
        return point(self, s)

    monkeypatch.setattr(Arc, "point", spy)
    one = element_extent(Arc([0.0, 0.0, 0.0], [500.0, 0.0], [0.0, 0.0, 7.0], turns=0))
    many = element_extent(Arc([0.0, 0.0, 0.0], [500.0, 0.0], [0.0, 0.0, 7.0],
                              turns=10**6))
    assert max(sizes) <= 8
    np.testing.assert_allclose(many[0], one[0], atol=1e-6)
    np.testing.assert_allclose(many[1], one[1], atol=1e-6)


def test_arc_extent_of_a_partial_sweep_is_still_exact():
    lo, hi = element_extent(Arc([0.0, 0.0], [500.0, 0.0], [1000.0, 0.0], direction="CW"))
    np.testing.assert_allclose(lo, [0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(hi, [1000.0, 500.0], atol=1e-9)
    lo, hi = element_extent(Arc([0.0, 0.0], [500.0, 0.0], [1000.0, 0.0], direction="CW",
                                turns=3))
    np.testing.assert_allclose(lo, [0.0, -500.0], atol=1e-9)
    np.testing.assert_allclose(hi, [1000.0, 500.0], atol=1e-9)


@pytest.mark.parametrize("turns", [2**31, 10**30])
def test_arc_turns_beyond_a_count_are_refused(turns):
    with pytest.raises(Exception) as info:
        Arc([0.0, 0.0], [500.0, 0.0], [0.0, 0.0], turns=turns)
    assert type(info.value).__name__ == "MotionError"
    assert "turns" in str(info.value) and "2147483647" in str(info.value)


def test_a_path_longer_than_the_representable_length_is_refused_and_changes_nothing():
    ctl, g = _group()
    with pytest.raises(GroupError) as info:
        g.arc([10_000.0, 0.0], [0.0, 0.0], turns=2**31 - 1)  # 1.3e14 pulses
    msg = str(info.value)
    assert "path length" in msg and "turns=2147483647" in msg and "2^45" in msg
    assert g.queue_length == 0 and g.current_index == -1
    from openmotion.limits import PATH_LENGTH_MAX

    assert PATH_LENGTH_MAX == 2.0**45


def test_the_longest_arcs_run_in_bounded_memory():
    """Legal but enormous paths (a 6.7e12-pulse helix of 2^31 - 1 turns, a circle of
    radius 1.4e12 pulses, a line to (2^40, 2^40)) are accepted and run: their first cycles
    plan one window. A cruise longer than 1e6 s was taken for a stalled speed curve and the
    group faulted at the start ("stalls at rest before its end")."""
    import tracemalloc

    for cmd in (lambda g: g.arc([500.0, 0.0], [0.0, 0.0], turns=2**31 - 1),
                lambda g: g.circle([1e12, 1e12]),
                lambda g: g.line([2.0**40, 2.0**40])):
        ctl, g = _group()
        tracemalloc.start()
        cmd(g)
        ctl.advance(0.01)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert g.state.name == "MOVING", g.error_message
        assert peak < 50e6


# -- config / units / program ---------------------------------------------------------------
def _motion_error(fn, *words):
    """fn() raises a MotionError (no other exception) whose message holds every word."""
    from openmotion.errors import MotionError

    try:
        fn()
    except MotionError as e:
        for w in words:
            assert w in str(e), (w, str(e))
        return
    except Exception as e:  # noqa: BLE001 - what these tests exist to catch
        pytest.fail(f"{type(e).__name__}: {e}")
    pytest.fail("accepted")


@pytest.mark.parametrize("start", [0, 0.0, 5e-324, float("nan"), np.float64(1.0), np.array(1.0),
                                   object()])
def test_gcode_options_start_must_be_a_sequence(start):
    from openmotion.program import GCodeOptions

    _motion_error(lambda: GCodeOptions(axes={"X": 0}, start=start), "start")


@pytest.mark.parametrize("field", ["parameters", "tool_lengths"])
@pytest.mark.parametrize("value", [5, "ab", [1, 2], None])
def test_gcode_options_tables_must_be_mappings(field, value):
    from openmotion.program import GCodeOptions

    _motion_error(lambda: GCodeOptions(axes={"X": 0}, **{field: value}), field)


def _runner(**kw):
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    ctl.enable_all()
    before = (ctl.time, [a.position for a in ctl.axes], len(ctl.events))
    try:
        ProgramRunner(ctl, "G1 X1 F600\n", axes={"X": "x"}, **kw)
    finally:
        assert (ctl.time, [a.position for a in ctl.axes], len(ctl.events)) == before


@pytest.mark.parametrize("file", [0, -1.5, float("inf"), [250.0], np.int64(3), b"x.ngc"])
def test_program_runner_file_must_be_a_name(file):
    _motion_error(lambda: _runner(file=file), "file")


@pytest.mark.parametrize("gcode", [5, -5e-324, "ab", (1, 2, 3), [("a", 1)], {"a": 1},
                                   {"parameters": 5}, {1: 2}])
def test_program_runner_gcode_must_map_option_names(gcode):
    _motion_error(lambda: _runner(gcode=gcode), "gcode")


def test_program_runner_accepts_a_path_as_the_file_name(tmp_path):
    from openmotion.program.runner import ProgramRunner

    ctl = Controller()
    ctl.enable_all()
    r = ProgramRunner(ctl, "G1 X1 F600\n", axes={"X": "x"}, file=tmp_path / "a.ngc",
                      gcode={"parameters": {5221: 0.0}})
    assert r.file == str(tmp_path / "a.ngc")


@pytest.mark.parametrize("kw", [dict(gear_ratio=145), dict(lead=1e-170),
                                dict(pulses_per_rev=2**31)])
def test_axis_config_pulse_rate_names_the_mechanism_values(kw):
    from openmotion.config import AxisConfig

    _motion_error(lambda: AxisConfig("x", **kw), "max_speed", next(iter(kw)))


# -- groups: arguments the round-2 code converted before checking ---------------------------
@pytest.mark.parametrize("kw", [dict(centre=5e-324), dict(centre=10**40), dict(centre="x"),
                                dict(centre=[]), dict(centre=[1.0] * 7), dict(centre={}),
                                dict(plane=0), dict(plane=None), dict(plane="x"),
                                dict(plane=[1.0]), dict(plane=(1, 2, 3)), dict(plane=b"1")])
def test_group_circle_checks_centre_and_plane_before_using_them(kw):
    ctl, g = _group()
    args = dict(centre=[500.0, 0.0], plane=(0, 1), relative=True) | kw
    _motion_error(lambda: g.circle(**args), next(iter(kw)))
    assert g.queue_length == 0


@pytest.mark.parametrize("centre", [[5e-324, 0.0], [1e-300, 0.0], [1e-10, 0.0]])
def test_an_arc_below_the_smallest_radius_is_refused(centre):
    ctl, g = _group()
    _motion_error(lambda: g.circle(centre, relative=True), "centre", "radius")
    _motion_error(lambda: Arc([0.0, 0.0], centre, [0.0, 0.0]), "radius")


@pytest.mark.parametrize("call", ["set_max_pulse_speed", "set_max_pulse_acc"])
@pytest.mark.parametrize("value", [10**400, [10**400, 1], ["1", 2], [True, 1.0]])
def test_group_axis_caps_refuse_what_is_not_a_real_number(call, value):
    ctl, g = _group()
    _motion_error(lambda: getattr(g, call)(value), "pps")


@pytest.mark.parametrize("mode", [np.array([]), np.array(["uniform"]), ["exact"], None, 1])
def test_run_options_feed_mode_must_be_a_name(mode):
    from openmotion.program.runner import RunOptions

    _motion_error(lambda: RunOptions(feed_mode=mode), "feed_mode")


@pytest.mark.parametrize("kw", [dict(subroutine_path=0), dict(subroutine_path=5e-324),
                                dict(subroutine_path=np.float32(1.5)),
                                dict(tool_table="no-such-table.tbl")])
def test_gcode_options_paths_are_checked_and_named(kw):
    from openmotion.program import GCodeOptions

    _motion_error(lambda: GCodeOptions(axes={"X": 0}, **kw), next(iter(kw)))


@pytest.mark.parametrize("value", ["", -1.0, 0.0, 1j, 1e300])
def test_group_acc_time_refusal_names_acc_time(value):
    ctl = Controller()
    ctl.enable_all()
    _motion_error(lambda: Group(ctl, ["x", "y"], acc_time=value), "acc_time")
    Group(ctl, ["x", "y"])  # the refused group took no axis


@pytest.mark.parametrize("centre", ["", None, 0.0, [100.0], [1.0] * 7])
def test_a_refused_group_command_leaves_the_tail_as_it_was(centre):
    ctl, g = _group()
    assert g._tail is None
    _motion_error(lambda: g.arc(centre, [1000.0, 0.0]), "centre")
    assert g._tail is None


@pytest.mark.parametrize("kw", [dict(start=-6.954724257381864e188), dict(end=1e300),
                                dict(start=-(2.0**41))])
def test_every_distance_window_lies_within_the_position_range(kw):
    from openmotion.control.trigger.compare import Toggle, VectorSource, every_distance

    _motion_error(lambda: every_distance(VectorSource((0, 1)), 100.0, Toggle(2), **kw),
                  next(iter(kw)))


@pytest.mark.parametrize("value", [np.array([1.0, 2.0]), np.array(["mm"]), ["mm"]])
def test_choice_arguments_refuse_arrays(value):
    from openmotion.control.home.homing import HomeConfig
    from openmotion.program import GCodeOptions

    _motion_error(lambda: GCodeOptions(axes={"X": 0}, machine_units=value), "machine_units")
    _motion_error(lambda: HomeConfig(mode=value), "mode")
