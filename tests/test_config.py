"""Tests for openmotion.config: validation rules, TOML round trips, unknown keys, examples."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import (
    DRIVE_TYPES,
    ENCODER_MODES,
    LOGIC_SIGNALS,
    PULSE_MODES,
    AxisConfig,
    DriveConfig,
    MachineConfig,
    SwitchConfig,
    default_machine,
    dumps_machine,
    load_machine,
    loads_machine,
    save_machine,
)
from openmotion.errors import MotionError
from openmotion.units import pulses_per_unit

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE_FILES = sorted(EXAMPLES.glob("*.toml"))


# -- default machine and examples ------------------------------------------------------
def test_default_machine_is_xyzu_table():
    m = default_machine()
    assert m.axis_names == ("x", "y", "z", "u")
    assert [a.unit for a in m.axes] == ["mm", "mm", "mm", "degree"]
    x = m.axis("x")
    assert x.mel.position < x.org.position < x.pel.position
    assert x.pel.position == 305_000.0 and x.mel.position == -5_000.0  # 1000 pulses/mm
    assert m.axis("u").pel is None and m.axis("u").org is not None


def test_default_machine_equals_example_file():
    assert load_machine(EXAMPLES / "xyzu.toml") == default_machine()


def test_at_least_three_examples():
    names = {p.name for p in EXAMPLE_FILES}
    assert {"xyzu.toml", "gantry.toml", "rotary_table.toml"} <= names


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_examples_load_and_round_trip(path, tmp_path):
    m = load_machine(path)
    assert isinstance(m, MachineConfig) and m.axes
    assert loads_machine(dumps_machine(m)) == m
    out = tmp_path / "m.toml"
    save_machine(m, out)
    assert load_machine(out) == m


def test_gantry_reversed_axis_switches_convert_with_sign():
    g = load_machine(EXAMPLES / "gantry.toml")
    y2 = g.axis("y2")
    assert y2.reverse and y2.pulses_per_unit == 750.0
    # pel at -5 mm on a reversed axis sits at +3750 pulses, spanning upward in pulses
    assert y2.pel == SwitchConfig(position=3750.0, width=30000.0, hysteresis=0.0)
    assert y2.mel.position == -605 * 750.0
    assert g.axis("x").move_ratio == 2.0 and g.axis("x").drive.type == "servo"


# -- lookups and helpers ----------------------------------------------------------------
def test_axis_lookup_by_name_and_index():
    m = default_machine()
    assert m.axis("z") is m.axes[2] and m.axis(2) is m.axes[2]
    assert m.index("u") == 3
    with pytest.raises(MotionError, match=r"axis 'w' is not on machine 'xyzu'; axes: x, y, z, u"):
        m.axis("w")
    with pytest.raises(MotionError, match=r"axis index must be in \[0, 3\], got 4"):
        m.axis(4)
    with pytest.raises(MotionError, match="axis must be a name or an index"):
        m.axis(True)


def test_with_axis_replaces_or_appends():
    m = default_machine()
    faster = dataclasses.replace(m.axis("x"), max_speed=600.0)
    m2 = m.with_axis(faster)
    assert m2.axis("x").max_speed == 600.0 and m.axis("x").max_speed == 500.0
    m3 = m.with_axis(AxisConfig(name="w"))
    assert m3.axis_names == ("x", "y", "z", "u", "w")
    with pytest.raises(MotionError, match="axis must be an AxisConfig"):
        m.with_axis("w")


def test_sequences_normalised_and_logic_copied():
    logic = {"pel": "nc"}
    ax = AxisConfig(name="x", logic=logic, drive=DriveConfig(pitch_error=[1, 2.5]))
    logic["pel"] = "bogus"
    assert ax.logic == {"pel": "nc"}
    assert ax.drive.pitch_error == (1.0, 2.5)
    m = MachineConfig(axes=[ax])
    assert isinstance(m.axes, tuple)
    assert ax.signal_logic("pel") == "nc" and ax.signal_logic("org") == "no"
    assert ax.encoder_counts_per_rev == 10000
    assert ax.max_speed_pps == 500_000.0


# -- validation: every rule refused with the field path ---------------------------------
AXIS_BAD = [
    ("pulses_per_rev", 0, r"axes\.x\.pulses_per_rev must be an integer >= 1"),
    ("pulses_per_rev", 100.0, r"axes\.x\.pulses_per_rev must be an integer"),
    ("lead", -2, r"axes\.x\.lead must be > 0, got -2"),
    ("lead", math.nan, r"axes\.x\.lead must be finite"),
    ("gear_ratio", 0.0, r"axes\.x\.gear_ratio must be > 0"),
    ("gear_ratio", "2", r"axes\.x\.gear_ratio must be a real number"),
    ("reverse", 1, r"axes\.x\.reverse must be true or false"),
    ("unit", "cm", r"axes\.x\.unit must be one of pulse, mm, inch, degree"),
    ("max_speed", 0.0, r"axes\.x\.max_speed must be > 0"),
    ("max_speed", 10_000.0, r"axes\.x\.max_speed must be <= 6550 mm/s \(pulse output limit"),
    ("pulse_mode", "pwm", r"axes\.x\.pulse_mode must be one of out_dir"),
    ("pulse_width_us", 0.0, r"axes\.x\.pulse_width_us must be > 0"),
    ("pulse_width_us", 5000.0, r"axes\.x\.pulse_width_us must be <= 1000"),
    ("encoder_mode", "ab_x3", r"axes\.x\.encoder_mode must be one of ab_x1"),
    ("encoder_lines_per_rev", -1, r"axes\.x\.encoder_lines_per_rev must be an integer >= 1"),
    ("invert_a", "yes", r"axes\.x\.invert_a must be true or false"),
    ("invert_b", 0, r"axes\.x\.invert_b must be true or false"),
    ("invert_z", None, r"axes\.x\.invert_z must be true or false"),
    ("swap_ab", 1.0, r"axes\.x\.swap_ab must be true or false"),
    ("move_ratio", 0.0, r"axes\.x\.move_ratio must be > 0"),
    ("move_ratio", math.inf, r"axes\.x\.move_ratio must be finite"),
    ("logic", {"pel": "open"}, r"axes\.x\.logic\.pel must be one of no, nc"),
    ("logic", {"xyz": "no"}, r"axes\.x\.logic\.xyz: unknown signal"),
    ("logic", ["pel"], r"axes\.x\.logic must be a table"),
    ("drive", {"type": "servo"}, r"axes\.x\.drive must be a DriveConfig"),
    ("pel", (1.0, 2.0), r"axes\.x\.pel must be a SwitchConfig or None"),
]


@pytest.mark.parametrize(("field", "value", "msg"), AXIS_BAD,
                         ids=[f"{b[0]}={b[1]!r}" for b in AXIS_BAD])
def test_axis_rule_refused(field, value, msg):
    with pytest.raises(MotionError, match=msg):
        AxisConfig(name="x", **{field: value})
    good = AxisConfig(name="x")
    with pytest.raises(MotionError, match=msg):
        dataclasses.replace(good, **{field: value})
    assert good == AxisConfig(name="x")  # invalid input changed nothing


@pytest.mark.parametrize("name", ["", "1x", "x-1", "x y", 3, None])
def test_axis_name_must_be_identifier(name):
    with pytest.raises(MotionError, match="axes name must be an identifier"):
        AxisConfig(name=name)


def test_limit_switches_must_be_ordered():
    with pytest.raises(MotionError, match=r"axes\.x\.pel\.position must be > axes\.x\.mel"):
        AxisConfig(name="x", pel=SwitchConfig(-10.0), mel=SwitchConfig(10.0, width=-5.0))


def test_switch_rules():
    with pytest.raises(MotionError, match=r"switch\.width must be non-zero"):
        SwitchConfig(0.0, width=0.0)
    with pytest.raises(MotionError, match=r"switch\.hysteresis must be >= 0"):
        SwitchConfig(0.0, hysteresis=-1.0)
    with pytest.raises(MotionError, match=r"switch\.position must be finite"):
        SwitchConfig(math.inf)
    with pytest.raises(MotionError, match=r"switch\.position must satisfy .*28-bit"):
        SwitchConfig(2.0**28)


DRIVE_BAD = [
    ({"type": "dc_motor"}, r"drive\.type must be one of ideal_stepper, stepper, servo"),
    ({"type": "stepper"}, r"drive\.pullout_speed must be > 0"),
    ({"type": "stepper", "pullout_speed": 1e4}, r"drive\.pullout_accel must be > 0"),
    ({"pullout_speed": -1.0}, r"drive\.pullout_speed must be >= 0"),
    ({"pullout_accel": -1.0}, r"drive\.pullout_accel must be >= 0"),
    ({"type": "servo", "bandwidth_hz": 0.0}, r"drive\.bandwidth_hz must be > 0"),
    ({"damping": -0.1}, r"drive\.damping must be > 0"),
    ({"inp_band": -1.0}, r"drive\.inp_band must be >= 0"),
    ({"backlash": -1.0}, r"drive\.backlash must be >= 0"),
    ({"pitch_error": (1.0, math.nan)}, r"drive\.pitch_error\[1\] must be finite"),
    ({"pitch_error": "12"}, r"drive\.pitch_error must be a list of numbers"),
]


@pytest.mark.parametrize(("kw", "msg"), DRIVE_BAD, ids=[str(b[0]) for b in DRIVE_BAD])
def test_drive_rule_refused(kw, msg):
    with pytest.raises(MotionError, match=msg):
        DriveConfig(**kw)


def test_every_drive_type_accepted_with_sane_parameters():
    for t in DRIVE_TYPES:
        DriveConfig(type=t, pullout_speed=1e4, pullout_accel=1e5)


MACHINE_BAD = [
    ({"name": ""}, r"name must be a non-empty string"),
    ({"cycle_s": 0.0005}, r"cycle_s must be in \[0\.001, 1\] \(MCCL 1\.\.1000 ms\)"),
    ({"cycle_s": 2.0}, r"cycle_s must be in \[0\.001, 1\]"),
    ({"cycle_s": math.nan}, r"cycle_s must be finite"),
    ({"digital_inputs": -1}, r"digital_inputs must be an integer in \[0, 4096\]"),
    ({"digital_outputs": 1.5}, r"digital_outputs must be an integer"),
    ({"axes": "xyz"}, r"axes must be a sequence of AxisConfig"),
    ({"axes": (1,)}, r"axes\[0\] must be an AxisConfig"),
    ({"axes": (AxisConfig("x"), AxisConfig("x"))}, r"axes\.x: axis names must be unique"),
]


@pytest.mark.parametrize(("kw", "msg"), MACHINE_BAD, ids=[str(b[0]) for b in MACHINE_BAD])
def test_machine_rule_refused(kw, msg):
    with pytest.raises(MotionError, match=msg):
        MachineConfig(**kw)


def test_cycle_bounds_inclusive():
    assert MachineConfig(cycle_s=0.001).cycle_s == 0.001
    assert MachineConfig(cycle_s=1).cycle_s == 1.0


# -- TOML errors -------------------------------------------------------------------------
BASE = """
name = "t"
[axes.x]
lead = 5.0
[axes.x.pel]
position = 100.0
"""


def test_minimal_file_uses_defaults_and_converts_switch_units():
    m = loads_machine(BASE)
    x = m.axis("x")
    assert x.pulses_per_unit == 2000.0
    assert x.pel == SwitchConfig(position=200_000.0)  # width left at its default


@pytest.mark.parametrize(("text", "msg"), [
    ('nmae = "t"\n', r"^nmae: unknown key; did you mean 'name'\?"),
    ("[axes.x]\nleed = 5.0\n", r"^axes\.x\.leed: unknown key; did you mean 'lead'\?"),
    ('[axes.x]\nname = "x"\n', r"axes\.x\.name: unknown key \(the axis name is its table key\)"),
    ("[axes.x.drive]\ntyp = 'servo'\n", r"^axes\.x\.drive\.typ: unknown key; did you mean 'type'"),
    ("[axes.x.org]\nposition = 0.0\nwidht = 1.0\n", r"^axes\.x\.org\.widht: unknown key"),
    ("[axes.x.logic]\npl = 'nc'\n", r"^axes\.x\.logic\.pl: unknown signal"),
    ("[axes.x.ltc]\nposition = 0.0\n", r"^axes\.x\.ltc: unknown key"),
])
def test_unknown_keys_refused_naming_the_key(text, msg):
    with pytest.raises(MotionError, match=msg):
        loads_machine(text)


@pytest.mark.parametrize(("text", "msg"), [
    ("[axes.x.drive]\ntype = 'stepper'\n", r"^axes\.x\.drive\.pullout_speed must be > 0"),
    ("[axes.x.org]\nposition = 0.0\nwidth = 0.0\n", r"^axes\.x\.org\.width must be non-zero"),
    ("[axes.x.org]\nwidth = 1.0\n", r"^axes\.x\.org\.position is required"),
    ("[axes.x.org]\nposition = 'home'\n", r"^axes\.x\.org\.position must be a real number"),
    ("[axes.x]\ndrive = 3\n", r"^axes\.x\.drive must be a table"),
    ("axes = 3\n", r"^axes must be a table"),
    ("[axes.1x]\n", r"axes name must be an identifier"),
    ("[axes.x]\nlead = -2\n", r"^axes\.x\.lead must be > 0, got -2"),
    ("[axes.x]\npulses_per_rev = 1e4\n", r"^axes\.x\.pulses_per_rev must be an integer"),
    ("cycle_s = 5\n", r"^cycle_s must be in"),
    ("name = \n", r"not valid TOML"),
])
def test_bad_values_in_file_name_the_field(text, msg):
    with pytest.raises(MotionError, match=msg):
        loads_machine(text)


def test_load_machine_error_names_file(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[axes.x]\nlead = 0\n")
    with pytest.raises(MotionError, match=r"bad\.toml: axes\.x\.lead must be > 0"):
        load_machine(p)
    # every public entry point raises the project's error, naming the file and the cause
    with pytest.raises(MotionError, match=r"missing\.toml': no such file"):
        load_machine(tmp_path / "missing.toml")
    with pytest.raises(MotionError, match="is a folder"):
        load_machine(tmp_path)
    (tmp_path / "latin1.toml").write_bytes(b"name = '\xe9'\n")
    with pytest.raises(MotionError, match="not a UTF-8"):
        load_machine(tmp_path / "latin1.toml")
    with pytest.raises(MotionError, match="must be a str or path"):
        load_machine(3)
    with pytest.raises(MotionError, match="text must be a str"):
        loads_machine(b"name = 'x'")


def test_save_refuses_non_config_and_writes_nothing(tmp_path):
    p = tmp_path / "out.toml"
    with pytest.raises(MotionError, match="cfg must be a MachineConfig"):
        save_machine({"name": "x"}, p)
    assert not p.exists()


def test_axis_order_preserved():
    m = loads_machine("[axes.z]\n[axes.a]\n[axes.m]\n")
    assert m.axis_names == ("z", "a", "m")
    assert loads_machine(dumps_machine(m)).axis_names == ("z", "a", "m")


# -- property: code -> TOML -> code is exact ---------------------------------------------
finite = st.floats(-1e6, 1e6, allow_nan=False)
switch = st.builds(
    SwitchConfig,
    position=finite,
    width=finite.filter(lambda w: abs(w) >= 1e-3),
    hysteresis=st.floats(0.0, 1e4),
)
drive = st.one_of(
    st.builds(DriveConfig, type=st.sampled_from(["ideal_stepper", "servo"]),
              bandwidth_hz=st.floats(0.1, 500.0), damping=st.floats(0.1, 2.0),
              backlash=st.floats(0.0, 100.0),
              pitch_error=st.lists(st.floats(-50, 50), max_size=5).map(tuple)),
    st.builds(DriveConfig, type=st.just("stepper"), pullout_speed=st.floats(1.0, 1e6),
              pullout_accel=st.floats(1.0, 1e7)),
)


@st.composite
def axes(draw, name):
    ppr, lead, gear = (draw(st.integers(1, 100_000)), draw(st.floats(0.01, 1000.0)),
                       draw(st.floats(0.01, 100.0)))
    unit = draw(st.sampled_from(["pulse", "mm", "inch", "degree"]))
    ax = AxisConfig(
        name=name, pulses_per_rev=ppr, lead=lead, gear_ratio=gear, unit=unit,
        reverse=draw(st.booleans()),
        max_speed=1e6 / pulses_per_unit(ppr, gear, lead, unit),  # 1 Mpps, under the limit
        pulse_mode=draw(st.sampled_from(PULSE_MODES)),
        encoder_mode=draw(st.sampled_from(ENCODER_MODES)),
        invert_a=draw(st.booleans()), swap_ab=draw(st.booleans()),
        move_ratio=draw(st.floats(0.01, 100.0)),
        logic=draw(st.dictionaries(st.sampled_from(LOGIC_SIGNALS), st.sampled_from(["no", "nc"]))),
        drive=draw(drive),
        org=draw(st.none() | switch), sd=draw(st.none() | switch),
    )
    if draw(st.booleans()):
        mel = draw(switch)
        pel = draw(switch.filter(lambda s: s.position > mel.position))
        ax = dataclasses.replace(ax, mel=mel, pel=pel)
    return ax


@st.composite
def machines(draw):
    names = draw(st.lists(st.sampled_from("xyzuabcw"), min_size=1, max_size=4, unique=True))
    return MachineConfig(
        name=draw(st.text("abcdefgh ", min_size=1, max_size=10).filter(str.strip)),
        axes=tuple(draw(axes(n)) for n in names),
        digital_inputs=draw(st.integers(0, 64)), digital_outputs=draw(st.integers(0, 64)),
        cycle_s=draw(st.floats(0.001, 1.0)),
    )


@settings(max_examples=60, deadline=None)
@given(machines())
def test_round_trip_code_toml_code_exact(m):
    assert loads_machine(dumps_machine(m)) == m


def test_switch_values_kept_on_micro_pulse_grid():
    s = SwitchConfig(position=1.23456789, width=3.0000001, hysteresis=2.0000001)
    assert (s.position, s.width, s.hysteresis) == (1.234568, 3.0, 2.0)
    with pytest.raises(MotionError, match=r"switch\.width must be non-zero \(at 1e-6 pulse\)"):
        SwitchConfig(0.0, width=4e-7)


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 100_000), st.floats(0.001, 1000.0), st.floats(0.001, 100.0),
       st.booleans(), st.floats(-1e8, 1e8), st.floats(0.0, 1e6))
def test_switch_file_round_trip_for_awkward_scales(ppr, lead, gear, rev, pos, hyst):
    ax = AxisConfig(name="x", pulses_per_rev=ppr, lead=lead, gear_ratio=gear, reverse=rev,
                    max_speed=1e6 / pulses_per_unit(ppr, gear, lead, "mm"),
                    org=SwitchConfig(pos, width=pos if abs(pos) >= 1e-3 else 1.0,
                                     hysteresis=hyst))
    m = MachineConfig(axes=(ax,))
    assert loads_machine(dumps_machine(m)) == m
