"""Recorder: ring order across wrap-around, channels, files, spill, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.recording import CHANNELS, Recorder, load_trace, save_arrays


def fill(rec: Recorder, n: int, start: int = 0) -> None:
    """Record n cycles whose values encode the cycle number k (checkable after the fact)."""
    for k in range(start, start + n):
        ax = np.arange(rec.n_axes)
        rec.record(k * 1e-3, k + ax, k - ax + 0.5, 10.0 * k + ax, (k + ax) % 7, (k << 4) | ax)


def check_rows(a: dict, ks: np.ndarray, n_axes: int) -> None:
    ax = np.arange(n_axes)
    np.testing.assert_array_equal(a["t"], ks * 1e-3)
    np.testing.assert_array_equal(a["cmd_pos"], ks[:, None] + ax)
    np.testing.assert_array_equal(a["fb_pos"], ks[:, None] - ax + 0.5)
    np.testing.assert_array_equal(a["cmd_vel"], 10.0 * ks[:, None] + ax)
    np.testing.assert_array_equal(a["state"], (ks[:, None] + ax) % 7)
    np.testing.assert_array_equal(a["io"], (ks[:, None] << 4) | ax)


@settings(max_examples=40, deadline=None)
@given(capacity=st.integers(1, 17), n=st.integers(0, 60), n_axes=st.integers(1, 4))
def test_ring_keeps_newest_rows_in_time_order(capacity: int, n: int, n_axes: int) -> None:
    rec = Recorder(n_axes, capacity)
    fill(rec, n)
    kept = min(n, capacity)
    assert len(rec) == kept
    assert rec.total == n and rec.dropped == n - kept
    a = rec.arrays()
    assert set(a) == {"t", *CHANNELS}
    assert a["cmd_pos"].shape == (kept, n_axes)
    check_rows(a, np.arange(n - kept, n), n_axes)


def test_arrays_are_copies_and_dtypes() -> None:
    rec = Recorder(2, 4)
    fill(rec, 3)
    a = rec.arrays()
    a["cmd_pos"][:] = -1.0
    assert rec.arrays()["cmd_pos"][0, 0] == 0.0
    assert a["state"].dtype == np.int32 and a["io"].dtype == np.int64
    assert a["cmd_pos"].dtype == np.float64


def test_channel_subset_ignores_others() -> None:
    rec = Recorder(2, 3, channels=("io", "cmd_pos"))
    assert rec.channels == ("cmd_pos", "io")  # canonical order
    rec.record(0.0, [1, 2], None, None, None, [3, 4])
    rec.record(0.1, cmd_pos=[5, 6], io=[7, 8])
    a = rec.arrays()
    assert set(a) == {"t", "cmd_pos", "io"}
    np.testing.assert_array_equal(a["io"], [[3, 4], [7, 8]])


def test_clear() -> None:
    rec = Recorder(1, 3)
    fill(rec, 5)
    rec.clear()
    assert len(rec) == 0 and rec.total == 0
    assert rec.arrays()["t"].size == 0
    rec.record(-5.0, [1.0], [1.0], [0.0], [0], [0])  # time may restart after clear
    assert rec.arrays()["t"].tolist() == [-5.0]


@pytest.mark.parametrize("suffix", [".npz", ".csv"])
def test_save_and_load_round_trip(tmp_path, suffix: str) -> None:
    rec = Recorder(3, 10)
    fill(rec, 14)
    path = rec.save(tmp_path / f"trace{suffix}")
    assert path.stat().st_size > 0
    back = load_trace(path)
    want = rec.arrays()
    assert set(back) == set(want)
    for k in want:
        np.testing.assert_array_equal(back[k], want[k])
        assert back[k].dtype == want[k].dtype
    if suffix == ".csv":
        header = path.read_text().splitlines()[0]
        assert header.startswith("t,cmd_pos[0],cmd_pos[1],cmd_pos[2],fb_pos[0]")


def test_save_arrays_refuses_other_suffix(tmp_path) -> None:
    rec = Recorder(1, 2)
    with pytest.raises(MotionError, match="path"):
        rec.save(tmp_path / "trace.txt")
    with pytest.raises(MotionError, match="path"):
        save_arrays(rec.arrays(), tmp_path / "trace")
    assert not list(tmp_path.iterdir())


def test_spill_keeps_everything_in_flat_memory(tmp_path) -> None:
    rec = Recorder(2, 8, spill_path=tmp_path / "spill" / "trace.bin")
    sizes = set()
    n = 1000
    for k in range(n):
        fill(rec, 1, start=k)
        sizes.add(rec._f.nbytes)
    assert sizes == {rec._f.nbytes}  # buffers never grow
    assert len(rec) <= 8 and rec.dropped == 0
    assert rec.spilled + len(rec) == n
    check_rows(rec.all_arrays(), np.arange(n), 2)
    check_rows(rec.load_spill(), np.arange(rec.spilled), 2)
    check_rows(rec.arrays(), np.arange(rec.spilled, n), 2)
    rec.clear()
    assert rec.load_spill()["t"].size == 0


def test_load_spill_without_spill_path() -> None:
    with pytest.raises(MotionError, match="spill_path"):
        Recorder(1, 2).load_spill()


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((math.nan, [0, 0], [0, 0], [0, 0], [0, 0], [0, 0]), "t"),
        (("soon", [0, 0], [0, 0], [0, 0], [0, 0], [0, 0]), "t"),
        ((0.0005, [0, 0], [0, 0], [0, 0], [0, 0], [0, 0]), "previous"),  # backwards
        ((1.0, [0, 0, 0], [0, 0], [0, 0], [0, 0], [0, 0]), "per axis"),
        ((1.0, [0, 0], [0], [0, 0], [0, 0], [0, 0]), "per axis"),
        ((1.0, [0, 0], [0, 0], [0, math.inf], [0, 0], [0, 0]), "finite"),
        ((1.0, [0, 0], [0, 0], [0, 0], ["a", 0], [0, 0]), "per axis"),
        ((1.0, [0, 0], [0, 0], [0, 0], [0, 0], None), "per axis"),
    ],
)
def test_bad_record_changes_nothing(args, match) -> None:
    rec = Recorder(2, 3)
    fill(rec, 5)  # full: the next write targets the scratch row, never a live row
    before = rec.arrays()
    with pytest.raises(MotionError, match=match):
        rec.record(*args)
    after = rec.arrays()
    for k in before:
        np.testing.assert_array_equal(before[k], after[k])
    assert rec.total == 5
    fill(rec, 1, start=5)  # still usable
    check_rows(rec.arrays(), np.arange(3, 6), 2)


@pytest.mark.parametrize(
    "kwargs",
    [{"n_axes": 0, "capacity": 1}, {"n_axes": 1, "capacity": 0},
     {"n_axes": 1, "capacity": 2.5}, {"n_axes": 1, "capacity": 2, "channels": ("speed",)},
     {"n_axes": 1, "capacity": 2, "channels": ()},
     {"n_axes": 1, "capacity": 2, "channels": "io"},
     {"n_axes": 1, "capacity": 2, "channels": ("io", "io")}],
)
def test_bad_construction(kwargs) -> None:
    with pytest.raises(MotionError):
        Recorder(**kwargs)


@settings(max_examples=60, deadline=None)
@given(capacity=st.integers(1, 30), before=st.integers(0, 40), m=st.integers(0, 70),
       seed=st.integers(0, 2**32 - 1))
def test_record_block_stores_what_row_by_row_records_store(capacity, before, m, seed):
    rng = np.random.default_rng(seed)
    n = 2
    t = np.cumsum(rng.uniform(0.0, 1.0, before + m))
    rows = before + m
    data = {"cmd_pos": rng.normal(size=(rows, n)), "fb_pos": rng.normal(size=(rows, n)),
            "cmd_vel": rng.normal(size=(rows, n)), "state": rng.integers(0, 5, (rows, n)),
            "io": rng.integers(0, 9999, (rows, n))}
    a, b = Recorder(n, capacity), Recorder(n, capacity)
    for r in range(before + m):
        a.record(t[r], **{c: v[r] for c, v in data.items()})
    for r in range(before):
        b.record(t[r], **{c: v[r] for c, v in data.items()})
    b.record_block(t[before:], **{c: v[before:] for c, v in data.items()})
    assert (len(a), a.total, a.dropped) == (len(b), b.total, b.dropped)
    for k, v in a.arrays().items():
        assert v.tobytes() == b.arrays()[k].tobytes()


def test_record_block_refuses_bad_rows_and_stores_nothing():
    rec = Recorder(2, 10)
    rec.record(1.0, cmd_pos=[0, 0], fb_pos=[0, 0], cmd_vel=[0, 0], state=[0, 0], io=[0, 0])
    ok = {c: np.zeros((3, 2)) for c in ("cmd_pos", "fb_pos", "cmd_vel", "state", "io")}
    for t, chans, match in (
            ([0.5, 2.0, 3.0], ok, "non-decreasing"),
            ([2.0, 1.5, 3.0], ok, "non-decreasing"),
            ([2.0, 3.0], ok, r"\(m, 2\)"),
            ([2.0, 3.0, 4.0], {**ok, "cmd_pos": np.full((3, 2), np.nan)}, "finite"),
            ([2.0, 3.0, 4.0], {c: v for c, v in ok.items() if c != "io"}, "every recorded")):
        with pytest.raises(MotionError, match=match):
            rec.record_block(t, **chans)
        assert (len(rec), rec.total) == (1, 1)
