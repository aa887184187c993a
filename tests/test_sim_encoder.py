"""Encoder decoding (modes, swap/invert mismatches), EZ index, backlash and pitch error."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.config import AxisConfig, DriveConfig, MachineConfig
from openmotion.errors import MotionError
from openmotion.hw.interface import AxisCommand
from openmotion.hw.sim import EncoderWiring, SimMachine

DT = 0.001


def one_axis(ax: AxisConfig, wiring: EncoderWiring | None = None) -> SimMachine:
    return SimMachine(MachineConfig(axes=(ax,)), wiring={0: wiring} if wiring else None)


def walk(m: SimMachine, targets: list[int]) -> list[int]:
    """Move through integer targets at constant speed, one per cycle; encoder after each."""
    out = []
    p = m.command_position(0)
    for k, tgt in enumerate(targets):
        t = m.time
        m.command(0, AxisCommand(t, DT, p, (tgt - p) / DT))
        m.advance(t + DT)
        out.append(m.read_axis(0).encoder)
        p = tgt
        del k
    return out


X4 = EncoderWiring("ab", 4.0)  # 4 quadrature states per command pulse (x4 reads 4/pulse)


@pytest.mark.parametrize(("mode", "flags", "per_pulse"), [
    ("ab_x4", {}, 4),
    ("ab_x2", {}, 2),
    ("ab_x1", {}, 1),
    ("ab_x4", {"swap_ab": True}, -4),
    ("ab_x4", {"invert_a": True}, -4),
    ("ab_x4", {"invert_b": True}, -4),
    ("ab_x4", {"invert_a": True, "invert_b": True}, 4),
    ("ab_x1", {"swap_ab": True}, -1),
])
def test_board_setting_against_x4_wiring(mode, flags, per_pulse):
    m = one_axis(AxisConfig("x", encoder_mode=mode, **flags), X4)
    enc = walk(m, [100, 250, 40, -30])
    assert enc == [per_pulse * p for p in (100, 250, 40, -30)]


def test_quadrature_read_as_pulses_gives_what_a_board_would():
    # CW/CCW decoding of quadrature: +1 on A rising, -1 on B rising -> stays within +-1
    m = one_axis(AxisConfig("x", encoder_mode="cw_ccw"), X4)
    assert all(abs(c) <= 1 for c in walk(m, [100, 250, 40, -30]))
    # pulse/dir decoding of quadrature: one count per cycle of A, direction from B
    m = one_axis(AxisConfig("x", encoder_mode="pulse_dir"), X4)
    enc = walk(m, [100, 0])
    assert abs(enc[0]) == 100 and enc[1] == 0


@pytest.mark.parametrize("mode", ["cw_ccw", "pulse_dir", "ab_x1", "ab_x2", "ab_x4"])
def test_default_wiring_reads_move_ratio_counts(mode):
    m = one_axis(AxisConfig("x", encoder_mode=mode, move_ratio=2.0, swap_ab=True))
    assert walk(m, [100, 37, -50]) == [200, 74, -100]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(-3000, 3000), min_size=1, max_size=8),
       st.sampled_from([0.5, 1.0, 2.5]))
def test_x4_count_is_quantized_load_times_ratio(targets, ratio):
    m = one_axis(AxisConfig("x", move_ratio=ratio))
    q, prev = 0, 0
    for tgt, enc in zip(targets, walk(m, targets), strict=True):
        x = tgt * ratio  # last integer reached moving toward x
        if tgt > prev:
            q = max(q, math.floor(x + 1e-9))
        elif tgt < prev:
            q = min(q, math.ceil(x - 1e-9))
        prev = tgt
        assert enc == q


def test_ez_once_per_revolution_at_its_positions():
    ax = AxisConfig("x", pulses_per_rev=1000, encoder_lines_per_rev=250)  # window: 1 pulse
    m = one_axis(ax)
    v = 1e6
    m.command(0, AxisCommand(0.0, 0.0035, 0.0, v))
    edges = [e for e in m.advance(0.004) if e.signal == "ez"]
    # starts inside the window at 0 -> leaves at 1, then one pulse per revolution
    assert [(e.level, e.encoders[0]) for e in edges] == [
        (False, 1), (True, 1000), (False, 1001), (True, 2000), (False, 2001),
        (True, 3000), (False, 3001)]
    for e in edges:  # pulse k leaves at command k - 1/2 (half-pulse rule)
        assert abs(e.time - (e.encoders[0] - 0.5) / v) < 1e-9


def test_invert_z_flips_level_when_mismatched():
    ax = AxisConfig("x", invert_z=True)
    m = one_axis(ax, EncoderWiring("ab", 1.0))
    assert m.read_axis(0).inputs["ez"] is False  # in the window, but inverted
    assert one_axis(ax).read_axis(0).inputs["ez"] is True


def test_backlash_load_lags_on_reversal():
    m = one_axis(AxisConfig("x", drive=DriveConfig(backlash=10.0)))
    assert walk(m, [100, 50, 55, 80, 30]) == [100, 60, 60, 80, 40]
    assert m.read_axis(0).pulses_out == 30
    assert m.load_position(0) == 40


def test_pitch_error_table_added_to_load():
    # one screw revolution = 1000 pulses; errors 0, +4, -2 at 0, 1000, 2000
    ax = AxisConfig("x", pulses_per_rev=1000, drive=DriveConfig(pitch_error=(0.0, 4.0, -2.0)))
    m = one_axis(ax, EncoderWiring("ab", 1.0))
    enc = walk(m, [500, 1000, 1500, 2000, 3000, -100])
    assert enc == [502, 1004, 1501, 1998, 2998, -100]


def test_pitch_table_must_stay_monotonic():
    ax = AxisConfig("x", pulses_per_rev=100, drive=DriveConfig(pitch_error=(0.0, -150.0)))
    with pytest.raises(MotionError, match="pitch_error"):
        one_axis(ax)


def test_wiring_validation():
    with pytest.raises(MotionError, match="kind"):
        EncoderWiring("sincos", 1.0)
    with pytest.raises(MotionError, match="units_per_pulse"):
        EncoderWiring("ab", 0.0)
    with pytest.raises(MotionError, match="wiring"):
        SimMachine(MachineConfig(axes=(AxisConfig("x"),)), wiring={3: X4})
