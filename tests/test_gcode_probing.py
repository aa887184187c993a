"""G38.2-G38.5 and M66: the simulated probe input, the resumable interpreter, the runner."""

from __future__ import annotations

import math

import pytest

from openmotion.control.core.controller import Controller
from openmotion.errors import MotionError
from openmotion.hw.sim.probe import SimProbe
from openmotion.program import (
    GCodeError,
    GCodeOptions,
    Interpreter,
    Message,
    ProgramRunner,
    RunOptions,
    RunState,
    parse_program,
)
from openmotion.program.probing import InputResult, Probe, ProbeResult, WaitInput

XYZ = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
INF = math.inf


def session(text: str, opts: GCodeOptions = XYZ):
    return Interpreter(parse_program(text), opts).session()


def debug(cmds) -> list[str]:
    return [c.text for c in cmds if isinstance(c, Message)]


# -- the resumable interpreter -------------------------------------------------------------
def test_session_stops_at_each_request_and_continues_with_the_answer():
    s = session("G21 G10 L2 P1 X5 Y1 Z2\nG0 X1 Y1 Z5\nG38.2 Z-5 F60\n"
                "(DEBUG, #5061 #5062 #5063 #5070 #<_z>)\nG91 G1 Z1\nG90 M66 P3 L0\n"
                "(DEBUG, in #5399)\nG0 X[#5399 * 10]\nM2\n")
    first = s.advance()
    assert isinstance(first[-1], Probe) and s.request is first[-1]
    probe = first[-1]
    assert probe.end == (6.0, 2.0, -3.0) and probe.contact and probe.must_trip
    assert probe.feed_per_s == pytest.approx(1.0)
    # tripped at machine Z 0.5; the axes came to rest 0.1 lower
    second = s.advance(ProbeResult(True, (6.0, 2.0, 0.5), (6.0, 2.0, 0.4)))
    assert debug(second) == ["1.000000 1.000000 -1.500000 1.000000 -1.600000"]
    assert second[1].end == (6.0, 2.0, 1.4)  # G91 from where the axes rest
    assert isinstance(second[-1], WaitInput) and second[-1].index == 3
    third = s.advance(InputResult(1.0))
    assert debug(third) == ["in 1.000000"] and third[1].end[0] == pytest.approx(15.0)
    assert s.done and s.request is None
    with pytest.raises(GCodeError, match="ended"):
        s.advance()


def test_must_trip_probe_without_contact_is_linuxcncs_error():
    for code, text in (("G38.2", "without making contact"),
                       ("G38.4", "without breaking contact")):
        s = session(f"G0 Z5\n{code} Z-1 F100\nG0 X1\nM2\n")
        s.advance()
        with pytest.raises(GCodeError, match=text) as info:
            s.advance(ProbeResult(False, (0, 0, -1.0), (0, 0, -1.0)))
        assert info.value.line == 2


def test_session_refuses_a_missing_or_wrong_answer():
    s = session("G38.3 Z-1 F100\nM66 P0\nM2\n")
    s.advance()
    with pytest.raises(GCodeError, match="needs the result"):
        s.advance()
    with pytest.raises(GCodeError, match="ProbeResult"):
        s.advance(InputResult(1.0))
    s = session("G38.3 Z-1 F100\nM2\n")
    s.advance()
    with pytest.raises(GCodeError, match="3 finite values"):
        s.advance(ProbeResult(True, (0.0, math.nan, 0.0), (0.0, 0.0, 0.0)))


def test_probe_parameters_are_in_the_rotated_program_frame():
    s = session("G10 L2 P1 X10 R90\nG0 X0 Y0\nG38.3 X5 F100\n(DEBUG, #5061 #5062)\nM2\n")
    probe = s.advance()[-1]
    assert probe.end[:2] == pytest.approx((10.0, 5.0))  # program X+ is machine Y+
    out = s.advance(ProbeResult(True, (10.0, 3.0, 0.0), (10.0, 3.2, 0.0)))
    assert debug(out) == ["3.000000 0.000000"]


def test_compile_without_machine_answers_as_rs274():
    from openmotion.program import compile_text

    cmds = compile_text("G21 G0 X0 Y0 Z2\nG38.2 Z-2 F100\n(DEBUG, #5063 #5070 #<_z>)\n"
                        "M66 P1 L3 Q5\n(DEBUG, #5399)\nM2\n", XYZ)
    assert debug(cmds) == ["-2.000000 0.000000 -1.746000", "0.000000"]


@pytest.mark.parametrize("text, msg", [
    ("G38.2 Z-1\n", "zero feed rate"),
    ("F10 G38.2 Z0\n", "Start point too close"),
    ("G93 G38.2 Z-1 F5\n", "inverse time"),
    ("F10 G38.6 Z-1\n", "unsupported G-code G38.6"),
    ("M66 P1 L5 Q1\n", "M66 L must be one of"),
    ("M66 P16\n", "input number must be < 16"),
    ("M66 E4\n", "input number must be < 4"),
    ("M66 P-1\n", "integer >= 0"),
    ("M66 P1.5\n", "integer >= 0"),
])
def test_bad_probe_and_wait_lines(text, msg):
    from openmotion.program import compile_text

    with pytest.raises(GCodeError, match=msg):
        compile_text("G21 G0 X0\n" + text + "M2\n", XYZ)


# -- the simulated probe -----------------------------------------------------------------
def _ctl():
    ctl = Controller()
    probe = SimProbe.attach(ctl.hardware, "di0")
    ctl.enable_all()
    return ctl, probe


def test_sim_probe_edge_is_exact_and_latches_every_axis():
    from openmotion.control.home.latch import TouchProbe

    ctl, probe = _ctl()
    probe.place([{0: (3000.0, 9000.0), 2: (-INF, -5000.0)}])  # a block: X 3..9 mm
    # continuous: a single-mode TouchProbe detaches inside the controller's hook loop,
    # which skips the next hook on that edge (noted for control/home/latch.py)
    tps = [TouchProbe(ctl, a, "di0", mode="continuous") for a in (0, 2)]
    z = ctl.axes[2]
    z.move_absolute(-8000, max_vel=20000)  # beside the block: no contact
    ctl.run_until(lambda: not z.is_moving, 10)
    assert not ctl.hardware.read_input("di0") and not any(t.done for t in tps)
    z.move_absolute(0, max_vel=20000)
    ctl.run_until(lambda: not z.is_moving, 10)
    ctl.axes[0].move_absolute(5000, max_vel=20000)
    ctl.run_until(lambda: not ctl.axes[0].is_moving, 10)
    z.move_absolute(-8000, max_vel=20000)
    ctl.run_until(lambda: not z.is_moving, 10)
    assert ctl.hardware.read_input("di0") and probe.in_contact
    assert tps[1].records[0].position == pytest.approx(-5000.5)  # the pulse that crosses
    assert tps[0].records[0].position == pytest.approx(5000.0)
    probe.remove()
    ctl.run_until(lambda: False, 0.01)
    assert not ctl.hardware.read_input("di0")


def test_sim_probe_normally_closed_and_bad_arguments():
    ctl = Controller()
    probe = SimProbe.attach(ctl.hardware, "di1", normally_closed=True)
    assert ctl.hardware.read_input("di1")  # closed while not touching
    probe.place([{2: (-INF, INF)}])
    ctl.run_until(lambda: False, 0.01)
    assert not ctl.hardware.read_input("di1")
    with pytest.raises(MotionError, match="already wired"):
        SimProbe.attach(ctl.hardware, "di1")
    with pytest.raises(MotionError, match="di0"):
        SimProbe.attach(ctl.hardware, "do1")
    for bad in ({2: (0, 1)}, [{}], [{2: (1, 0)}], [{9: (0, 1)}], [{2: (0, math.nan)}],
                [{2: 5}]):
        with pytest.raises(MotionError):
            probe.place(bad)  # type: ignore[arg-type]


# -- the runner ----------------------------------------------------------------------------
PROBE_PROG = """G21 G90 G0 X1 Y2 Z5
G38.2 Z-4.5 F60
(DEBUG, trip #5063 ok #5070)
G91 G0 Z1
G90 G1 X[#5061 + 1] F300
G38.3 X20 F120
(DEBUG, second #5070)
G0 Z0
M2
"""


def _runner(text: str, surface_mm: float = -2.0, **opts):
    ctl, probe = _ctl()
    run = ProgramRunner(ctl, text, options=RunOptions(probe_input="di0", **opts))
    kz = run.letters.index("Z")
    probe.place([{run.axis_indices[kz]: (-INF, surface_mm * run.scales.ppu[kz])}])
    return ctl, probe, run


def test_runner_probes_the_simulated_surface_and_continues_with_it():
    ctl, probe, run = _runner(PROBE_PROG)
    run.start()
    run.wait(120)
    assert run.state is RunState.DONE, run.error
    msgs = [e.text for e in run.events if e.kind == "message"]
    # Z trips when the pulse at -2 mm - half a pulse (4000 pulses/mm) leaves
    assert msgs == ["debug: trip -2.000125 ok 1.000000", "debug: second 0.000000"]
    trip = next(e for e in run.events if e.kind == "probe_trip")
    assert trip.line == 2
    # the G91 Z1 starts where the probe move came to rest (past the surface)
    ops = [o for o in run.ops if o.line == 4]
    assert ops and ops[0].end[2] > -2.0 + 1.0 - 0.1 and ops[0].end[2] < -1.0
    assert ctl.axes[2].position == 0.0


@pytest.mark.parametrize("text, surface_mm", [
    (PROBE_PROG.replace("F60", "F600").replace("F120", "F900"), -2.0),  # (shorter)
    ("G0 Z5\nG38.2 Z-1 F600\nG0 X5\nM2\n", -2.0),  # no contact: the run faults
    ("G38.4 Z5 F200\n(DEBUG, #5063 #5070)\nG38.5 Z4 F100\n(DEBUG, #5063 #5070)\nM2\n", 1.0),
], ids=["G38.2 G38.3", "no contact", "G38.4 G38.5"])
def test_a_probe_move_jumps_to_its_edge_like_cycle_by_cycle(text, surface_mm):
    """Before its trip a probe move waits on its edge hook (ProgramRunner._due): virtual
    time jumps over it and lands in the edge's cycle; events, trace, ops and every axis
    end as in the cycle-by-cycle run."""
    from test_jump_equivalence import observe

    out = []
    for jumping in (False, True):
        ctl, probe, run = _runner(text, surface_mm)
        ctl.virtual_jumps = jumping
        ctl.hardware.record_pulses(True)
        steps = 0
        real = ctl._finish_cycle

        def counting(n, edges, real=real) -> None:  # noqa: ANN001
            nonlocal steps
            steps += 1
            real(n, edges)

        ctl._finish_cycle = counting  # type: ignore[method-assign]
        run.start()
        run.wait(60)
        t, idx, p = run.trace()
        events = [(e.t, e.kind, e.line, e.text) for e in run.events]
        ops = [(o.line, None if o.end is None else tuple(o.end)) for o in run.ops]
        out.append(((run.state, run.error, events, ops, t.tolist(), idx.tolist(), p.tolist(),
                     run.actual_trace().tolist()), observe(ctl)))
        if jumping:
            assert steps < 0.2 * ctl.cycles  # most of the probe move jumped
    assert out[0] == out[1]
    state, _, events = out[0][0][:3]
    assert (state is RunState.DONE) == any(e[1] == "probe_trip" for e in events)


def test_runner_g38_2_without_contact_faults_with_linuxcncs_message():
    ctl, probe, run = _runner("G0 Z5\nG38.2 Z-1 F200\nG0 X5\nM2\n")
    run.start()
    run.wait(60)
    assert run.state is RunState.ERROR
    assert "G38.2 move finished without making contact." in run.error
    assert ctl.axes[0].position == 0.0  # the line after it never ran


def test_runner_probe_already_tripped_and_g38_4_leaves_contact():
    ctl, probe, run = _runner("G38.2 Z-1 F200\nM2\n", surface_mm=1.0)
    run.start()
    run.wait(60)
    assert run.state is RunState.ERROR and "already tripped" in run.error
    ctl, probe, run = _runner("G38.4 Z5 F200\n(DEBUG, #5063 #5070)\nG38.5 Z4 F100\n"
                              "(DEBUG, at once #5063 #5070)\nM2\n", surface_mm=1.0)
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    msgs = [e.text for e in run.events if e.kind == "message"]
    # contact is lost when pulse 4000 (1 mm) leaves, at the command 3999.5
    assert msgs[0] == "debug: 0.999875 1.000000"
    assert msgs[1].startswith("debug: at once 1.0") and msgs[1].endswith(" 1.000000")


def test_runner_needs_a_probe_input():
    ctl, probe = _ctl()
    with pytest.raises(MotionError, match="probe_input"):
        ProgramRunner(ctl, "G38.3 Z-1 F100\nM2\n")
    with pytest.raises(MotionError, match="probe_input"):
        RunOptions(probe_input="X")
    with pytest.raises(MotionError, match="di"):
        ProgramRunner(ctl, "G38.3 Z-1 F100\nM2\n", options=RunOptions(probe_input="di99"))


def test_runner_m66_waits_for_inputs_and_times_out():
    ctl = Controller()
    ctl.enable_all()
    sc = ctl.hardware.scenario
    sc.set_input("di2", True, at=0.5)
    sc.set_input("di3", True, at=0.2)
    sc.set_input("di3", False, at=0.3)
    text = ("M66 P2 L0\n(DEBUG, now #5399)\nM66 P2 L1 Q5\n(DEBUG, rise #5399 #<_x>)\n"
            "M66 P2 L3 Q1\n(DEBUG, high #5399)\nM66 P3 L1 Q0.5\n(DEBUG, late #5399)\n"
            "G0 X[#5399 + 2]\nM2\n")
    run = ProgramRunner(ctl, text)
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE, run.error
    msgs = [e.text for e in run.events if e.kind == "message"]
    assert msgs == ["debug: now 0.000000", "debug: rise 1.000000 0.000000",
                    "debug: high 1.000000", "debug: late -1.000000"]
    rise = [e for e in run.events if e.kind == "input"]
    assert rise[1].t == pytest.approx(0.5, abs=2 * ctl.period)
    assert rise[3].t == pytest.approx(rise[2].t + 0.5, abs=2 * ctl.period)
    assert ctl.axes[0].position == pytest.approx(1.0 * run.scales.ppu[0])


def test_runner_m66_analog_is_refused_without_analog_inputs():
    ctl = Controller()
    ctl.hardware.configure_analog_inputs(0)
    with pytest.raises(GCodeError, match="analog input number must be < 0"):
        ProgramRunner(ctl, "M66 E0\nM2\n")


def test_runner_contact_during_a_non_probe_move_stops_the_run():
    ctl, probe, run = _runner("G0 Z5\nG1 Z-4 F300\nG0 X5\nM2\n")
    run.start()
    run.wait(60)
    assert run.state is RunState.ERROR
    assert "Probe tripped during non-probe move." in run.error and "line 2" in run.error
    assert ctl.axes[0].position == 0.0
    # without a probe input configured nothing watches it
    ctl, probe = _ctl()
    probe.place([{2: (-INF, -8000.0)}])
    run = ProgramRunner(ctl, "G1 Z-4 F300\nM2\n")
    run.start()
    run.wait(60)
    assert run.state is RunState.DONE


def test_probe_example_finds_the_block_corner():
    import runpy
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "gcode_probe.py"
    run = runpy.run_path(str(path))["main"]()
    assert run.state is RunState.DONE
    corner = [e.text for e in run.events if e.kind == "message"][-1]
    import re

    x, y, z = (float(v) for v in re.findall(r"[XYZ](-?[\d.]+)", corner))
    # within one pulse of X 10, Y 8, Z 20 (1000, 2000, 4000 pulses per mm)
    assert x == pytest.approx(10.0, abs=1e-3) and y == pytest.approx(8.0, abs=5e-4)
    assert z == pytest.approx(20.0, abs=2.5e-4)
