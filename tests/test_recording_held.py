"""Recorder.hold (an idle jump's rows kept as one run, written into the ring when read or
about to be overwritten) stores the very rows m `record` calls would: random mixes of rows,
blocks, compiled-style fills and held runs, rings shorter than the run (wrap-around),
reads in between, channel subsets; a spilling recorder refuses, bad calls change nothing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from openmotion.errors import MotionError
from openmotion.recording import CHANNELS, Recorder

ORIGIN = 0.25


def values(c: int, n: int) -> dict[str, np.ndarray]:
    """The channel values of a non-held row of cycle c (distinct per cycle and axis)."""
    ax = np.arange(n)
    return {"cmd_pos": c + ax + 0.25, "fb_pos": c - ax - 0.5, "cmd_vel": 10.0 * c + ax,
            "state": ((c + ax) % 7).astype(np.int32), "io": ((c << 4) | ax).astype(np.int64)}


class Twin:
    """The recorder under test and a reference fed the same rows one `record` at a time."""

    def __init__(self, n: int, capacity: int, channels: tuple[str, ...]) -> None:
        self.n = n
        self.rec = Recorder(n, capacity, channels)
        self.ref = Recorder(n, capacity, channels)
        self.c = 0  # cycles on the grid so far
        self.period = 1e-3
        self.origin = ORIGIN
        self.last: dict[str, np.ndarray] | None = None

    def t(self, c: int) -> float:
        return self.origin + c * self.period

    def rows(self, k: int, how: str) -> None:
        cs = range(self.c + 1, self.c + k + 1)
        vals = [values(c, self.n) for c in cs]
        for c, v in zip(cs, vals, strict=True):
            self.ref.record(self.t(c), **v)
        if how == "record":
            for c, v in zip(cs, vals, strict=True):
                self.rec.record(self.t(c), **v)
        elif how == "block" and k:
            self.rec.record_block([self.t(c) for c in cs],
                                  **{ch: np.array([v[ch] for v in vals]) for ch in CHANNELS})
        elif how == "into":  # as _kernel.record_rows fills: last min(k, rows - 1) from head
            def fill(rt, rf, rstate, rio, head, slots):  # noqa: ANN001, ANN202
                rows = len(rt)
                keep = min(k, rows - 1)
                for r in range(k - keep, k):
                    i = (head + r) % rows
                    rt[i] = self.t(cs[r])
                    for name, s in zip(("cmd_pos", "fb_pos", "cmd_vel"), slots, strict=True):
                        if s >= 0:
                            rf[i, s] = vals[r][name]
                    if len(rstate):
                        rstate[i] = vals[r]["state"]
                    if len(rio):
                        rio[i] = vals[r]["io"]
            if k:
                assert self.rec.record_into(k, self.t(cs[0]), self.t(cs[-1]), fill)
        if k:
            self.last = vals[-1]
        self.c += k

    def hold(self, k: int, gap: int, regrid: bool) -> None:
        assert self.last is not None
        if regrid:  # another grid from here on (a period change): a new run
            self.origin = self.t(self.c)
            self.period = 5e-4 if self.period == 1e-3 else 1e-3
            self.c = 0
        self.c += gap  # cycles not recorded (the next run is not contiguous)
        assert self.rec.hold(k, self.origin, self.period, self.c)
        for r in range(k):
            self.ref.record(self.origin + (self.c + 1 + r) * self.period, **self.last)
        self.c += k

    def check(self) -> None:
        got, want = self.rec.arrays(), self.ref.arrays()
        assert got.keys() == want.keys()
        for key in want:
            assert got[key].dtype == want[key].dtype
            assert got[key].tobytes() == want[key].tobytes(), key
        assert (len(self.rec), self.rec.total, self.rec.dropped) == \
            (len(self.ref), self.ref.total, self.ref.dropped)


op = st.one_of(
    st.tuples(st.just("rows"), st.integers(0, 25), st.sampled_from(["record", "block", "into"])),
    st.tuples(st.just("hold"), st.integers(0, 40), st.integers(0, 2), st.booleans()),
    st.tuples(st.just("read")),
)


@settings(max_examples=150, deadline=None)
@given(capacity=st.integers(1, 30), n=st.integers(1, 3),
       channels=st.sets(st.sampled_from(CHANNELS), min_size=1),
       ops=st.lists(op, max_size=25))
def test_held_rows_are_the_rows_recorded_one_by_one(capacity, n, channels, ops) -> None:
    tw = Twin(n, capacity, tuple(channels))
    tw.rows(1, "record")
    for o in ops:
        if o[0] == "rows":
            tw.rows(o[1], o[2])
        elif o[0] == "hold":
            tw.hold(o[1], o[2], o[3])
        else:
            tw.check()
    tw.check()


def test_a_long_idle_stretch_is_one_run_until_read() -> None:
    tw = Twin(2, 50_000, CHANNELS)
    tw.rows(1, "into")
    for _ in range(20):  # a jump's chunks: contiguous holds of the same readback
        tw.hold(2048, 0, False)
    assert len(tw.rec._held) == 1  # one run, nothing written yet
    tw.rows(1, "into")  # the landing row
    tw.check()
    assert not tw.rec._held


def test_a_ring_shorter_than_the_stretch_keeps_its_newest_rows() -> None:
    tw = Twin(3, 100, CHANNELS)
    tw.rows(5, "record")
    tw.hold(1000, 0, False)  # wraps the ring ten times over, itself
    assert len(tw.rec._held) == 1
    tw.rows(3, "block")  # overwrites the run's oldest kept rows: written first
    tw.hold(250, 1, False)
    tw.rows(120, "record")  # every held row leaves the window
    tw.check()


def test_many_runs_are_written_before_they_pile_up() -> None:
    tw = Twin(1, 10_000, CHANNELS)
    for _ in range(200):
        tw.rows(1, "record")
        tw.hold(3, 0, False)
        assert len(tw.rec._held) <= 64
    tw.check()


def test_spilling_recorder_refuses_and_bad_calls_change_nothing(tmp_path) -> None:
    sp = Recorder(2, 8, spill_path=tmp_path / "s.bin")
    with pytest.raises(MotionError, match="recorded row"):
        sp.hold(3, 0.0, 1e-3, 0)
    sp.record(0.0, **values(0, 2))
    assert sp.hold(3, 0.0, 1e-3, 0) is False
    assert sp.total == 1 and len(sp.arrays()["t"]) == 1

    tw = Twin(2, 16, CHANNELS)
    tw.rows(2, "record")
    tw.hold(5, 0, False)
    before = (tw.rec.total, len(tw.rec), list(tw.rec._held[-1][:2]))
    with pytest.raises(MotionError, match="non-decreasing"):
        tw.rec.hold(4, ORIGIN, 1e-3, 0)  # before the newest row
    with pytest.raises(MotionError, match="m"):
        tw.rec.hold(-1, ORIGIN, 1e-3, 100)
    with pytest.raises(MotionError, match="finite"):
        tw.rec.hold(2, float("nan"), 1e-3, 100)
    assert (tw.rec.total, len(tw.rec), list(tw.rec._held[-1][:2])) == before
    assert tw.rec.hold(0, ORIGIN, 1e-3, tw.c)
    tw.check()
    tw.rec.clear()
    assert not tw.rec._held and tw.rec.arrays()["t"].size == 0


@pytest.mark.parametrize("how", ["record", "block", "into"])
@pytest.mark.parametrize("capacity", [1, 2, 3, 5])
def test_rows_after_a_run_overwrite_it_row_by_row(how: str, capacity: int) -> None:
    for m in (1, capacity, capacity + 2):
        for k in (1, 2):
            tw = Twin(2, capacity, CHANNELS)
            tw.rows(1, "record")
            tw.hold(m, 0, False)
            for _ in range(capacity + 3):  # through the whole ring, k rows at a time
                tw.rows(k, how)
                tw.check()
                tw.hold(1, 0, False)


def test_a_held_readback_trace_is_the_repeated_rows() -> None:
    from openmotion.hw.sim.kernel import joined_trace

    rng = np.random.default_rng(5)
    a = rng.integers(-9, 9, (1, 3, 3))
    b = a.copy()
    other = a + 1
    block = rng.integers(-9, 9, (4, 3, 3))
    for parts in ([a], [(a, 5)], [a, (b, 7)], [(a, 2), b, (b, 3)], [a, (other, 4)],
                  [block], [a, block, (b, 2)], [(other, 3), a]):
        want = np.concatenate([np.repeat(p[0], p[1], axis=0) if type(p) is tuple else p
                               for p in parts])
        got = joined_trace(list(parts), 3)
        assert got.shape == want.shape and (got == want).all()
        held = all(type(p) is tuple or len(p) == 1 for p in parts) and \
            len({p[0].tobytes() if type(p) is tuple else p.tobytes() for p in parts}) == 1
        assert (got.strides[0] == 0) == (held and len(got) > 1)
        if got.strides[0] == 0:
            assert not got.flags.writeable
    assert joined_trace([], 3).shape == (0, 3, 3)
