"""Fuzz the public entry points of openmotion.config, openmotion.units and
openmotion.program (see fuzzkit.py for the oracle), and compile mutated G-code lines."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from fuzzkit import TOTALS, Entry, examples, run_entries
from openmotion import config as C
from openmotion.config_toml import loads_machine, machine_from_dict
from openmotion.errors import MotionError
from openmotion.program import GCodeError, GCodeOptions, PointTable, compile_text
from openmotion.program.runner import ProgramRunner, RunOptions
from openmotion.units import AxisUnits

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})


def _f(fn):
    return lambda w, **kw: fn(**kw)


ENTRIES = [
    Entry("AxisConfig", _f(C.AxisConfig),
          dict(name="x", pulses_per_rev=10000, lead=10.0, gear_ratio=1.0, reverse=False,
               unit="mm", max_speed=500.0, pulse_mode="out_dir", pulse_width_us=2.0,
               encoder_mode="ab_x4", encoder_lines_per_rev=2500, move_ratio=1.0)),
    Entry("DriveConfig", _f(C.DriveConfig),
          dict(type="stepper", pullout_speed=5e5, pullout_accel=1e8, bandwidth_hz=30.0,
               damping=0.9, inp_band=5.0, backlash=0.0, pitch_error=())),
    Entry("SwitchConfig", _f(C.SwitchConfig), dict(position=10.0, width=100.0,
                                                   hysteresis=0.0)),
    Entry("LoopConfig", _f(C.LoopConfig),
          dict(compensator="pid", a=229, b=64, k=64, kp=1.0, ki=0.0, kd=0.0, kvff=0.0,
               kaff=0.0, samples_per_cycle=1, following_error=1000.0)),
    Entry("DCMotorConfig", _f(C.DCMotorConfig),
          dict(supply_v=24.0, resistance=4.0, kt=0.03, ke=0.0, inertia=2e-6, viscous=1e-5,
               current_limit=1.0, load_torque=0.0)),
    Entry("MachineConfig", _f(C.MachineConfig),
          dict(name="m", axes=(C.AxisConfig("x"),), digital_inputs=16, digital_outputs=16,
               cycle_s=1e-3)),
    Entry("machine_from_dict", lambda w, name, cycle_s: machine_from_dict(
        {"name": name, "cycle_s": cycle_s, "axes": {"x": {}}}), dict(name="m", cycle_s=1e-3)),
    Entry("loads_machine", lambda w, text: loads_machine(text),
          dict(text='name = "m"\n[axes.x]\nmax_speed = 100.0\n'),
          aliases={"text": ("text", "machine file")}),
    Entry("AxisUnits", _f(AxisUnits), dict(axis="x", unit="mm", pulses_per_unit=1000.0,
                                          sign=1, max_speed=500.0)),
    Entry("AxisUnits.to_pulses", lambda w, x: AxisUnits("x", "mm", 1000.0).to_pulses(x),
          dict(x=[1.0, 2.0])),
    Entry("AxisUnits.validate_speed", lambda w, **kw: AxisUnits(
        "x", "mm", 1000.0, max_speed=10.0).validate_speed(**kw),
          dict(speed=5.0, name="speed")),
    Entry("GCodeOptions", _f(GCodeOptions),
          dict(axes={"X": 0}, n_axes=None, machine_units="mm", start=None, soft_limits=None,
               n_outputs=16, block_delete=True, keep_comments=False, max_call_depth=64,
               max_blocks=100_000, max_loop_iterations=1000, max_line_length=256,
               max_bytes=1_000_000, parameters={5221: 1.0}, tool_lengths={1: 2.0},
               spindle_output=None, subroutine_path=(), tool_table=None)),
    Entry("compile_text", _f(compile_text), dict(text="G1 X1 F100\n", options=OPTS),
          aliases={"text": ("text", "program", "line "), "options": ("options",)}),
    Entry("RunOptions", _f(RunOptions),
          dict(rapid_ratio=1.0, feed_mode="uniform", chord_tol=1e-3, acc_time=0.05,
               window=1024, repeat=1, single_block=False, optional_stop=False)),
    Entry("ProgramRunner", lambda w, **kw: ProgramRunner(w.ctl, **kw),
          dict(program="G1 X1 F600\n", axes={"X": "x"}, options=None, gcode=None, file=""),
          aliases={"program": ("program", "line ")}),
    Entry("PointTable.add", lambda w, **kw: PointTable("XY").add(**kw),
          dict(name="p1", position=[1.0, 2.0], speed=600.0, kind="line")),
]


def test_fuzz_config_units_program(fuzz_long: bool) -> None:
    stats = run_entries(ENTRIES, examples(fuzz_long, 500), cycles=0.0)
    print(stats.report())
    assert stats.clean, stats.report()


_WORDS = st.sampled_from(["G0", "G1", "G2", "G3", "G4", "G90", "G91", "G20", "G21", "X",
                          "Y", "Z", "I", "J", "R", "F", "P", "M3", "M5", "S", "#1=", "#<a>=",
                          "[", "]", "+", "-", "*", "/", "1", "0.5", "1e3", ".", "(c)", ";",
                          "O1", " while ", " endwhile", " if ", " endif", " sub", " call",
                          "sqrt[", "atan[1]/[", "5e-324", "99999999999999999999", "nan",
                          "#5420", "N10", "%", "\t", "\n"])


def test_fuzz_gcode_lines(fuzz_long: bool) -> None:
    """Mutated G-code: only GCodeError/MotionError, never a crash, always in bounded work."""
    n = examples(fuzz_long, 300)
    bad: list[str] = []
    count = [0]
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2}, max_blocks=20_000,
                        max_loop_iterations=2000)

    @settings(max_examples=n, derandomize=True, database=None, deadline=None)
    @given(st.lists(_WORDS, max_size=30).map("".join))
    def one(text: str) -> None:
        count[0] += 1
        try:
            compile_text(text, opts)
        except (GCodeError, MotionError):
            pass
        except Exception as e:  # noqa: BLE001 - the finding
            bad.append(f"{text!r} -> {type(e).__name__}: {e}")

    one()
    TOTALS.inputs += count[0]
    TOTALS.unexpected.extend(bad)
    print(f"gcode lines {count[0]}, unexpected {len(bad)}")
    assert not bad, "\n".join(bad[:30])
