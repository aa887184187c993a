"""Streaming compile (program/stream.py): the same commands or error as compile_file, one
at a time, with memory that does not grow with the file."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from openmotion.program import GCodeError, GCodeOptions, compile_file, stream
from openmotion.program.stream import stream_file
from test_gcode_fastpath import ORACLE, ROOT, _oracle_opts, long_programs, mixed

OPTS = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2, "A": 3}, tool_table=ORACLE / "tools.tbl")


def outcome(fn, path, opts):
    try:
        return ("ok", list(fn(path, opts)))
    except GCodeError as exc:
        return ("error", str(exc))


def assert_same(path, opts=OPTS):
    assert outcome(stream_file, path, opts) == outcome(compile_file, path, opts)


PROGRAMS = (sorted((ROOT / "examples" / "programs").glob("*.ngc"))
            + sorted(Path("/work/shared/gcode-corpus").glob("*.ngc"))
            + sorted(ORACLE.glob("*.ngc")) + sorted((ORACLE / "bad").glob("*.ngc")))


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_example_corpus_and_oracle_programs(path):
    assert_same(path, _oracle_opts())


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(mixed, long_programs), st.sampled_from(["\n", "\r\n", "\r"]),
       st.sampled_from([5, 64, 1 << 20]), st.booleans())
def test_random_programs_same_as_compile_file(tmp_path, monkeypatch, lines, eol, chunk,
                                              utf8):
    """Line ends of every kind, chunk boundaries anywhere (also inside a UTF-8 character
    or a CR LF), the dialect and refused lines of the fast path's tests."""
    monkeypatch.setattr(stream, "CHUNK", chunk)
    body = ["G1 F600", *lines, "(é ü — comment)" if utf8 else "", "M2"]
    path = tmp_path / "p.ngc"
    path.write_bytes(eol.join(body).encode())
    assert_same(path)


@pytest.mark.parametrize("data", [
    b"G1 X1 F100\nG1 X\x002\n", b"G1 X1 F100\n(\xff)\n", b"G1 X1 F100\nG1 Q[1\nM2\n",
    b"G1 X1 F100\nO100 sub\nG1 X2\nO100 endsub\nO100 call\nM2\n", b"G1 X1 F100\nM98 P3\n",
    b"G1 X1 F100\nG1 X200\n", b"%\nG1 X1 F100\n%\nthis is not G-code\n",
    b"G1 X1 F100\n" * 50 + b"M2\n", b"G1 X1 F100\nM99\n", b"G1 X1 F100\n\xe2\x82",
])
def test_refusals_and_fallbacks(tmp_path, monkeypatch, data):
    monkeypatch.setattr(stream, "CHUNK", 8)
    path = tmp_path / "p.ngc"
    path.write_bytes(data)
    opts = GCodeOptions(axes={"X": 0, "Y": 1}, soft_limits=[(-100, 100)] * 2, max_blocks=40)
    assert_same(path, opts)


def test_size_limit_and_missing_file(tmp_path):
    path = tmp_path / "p.ngc"
    path.write_text("G1 X1 F100\n" * 10)
    small = GCodeOptions(axes={"X": 0}, max_bytes=50)
    assert_same(path, small)
    assert_same(tmp_path / "none.ngc", small)
    with pytest.raises(GCodeError, match="options must be GCodeOptions"):
        stream_file(path, {"axes": {"X": 0}})


def test_memory_stays_flat(tmp_path, long_run):
    """5k lines (200k with --long): the stream's traced peak stays a small fraction of
    compile_file's (about 1.0 MB against 67 MB at 5k lines, 1.7 MB at 10k; tracemalloc
    makes each line costly, so the normal run keeps to 5k)."""
    path = tmp_path / "big.ngc"
    with path.open("w") as fh:
        fh.write("G21 G90 G1 F1200\n")
        for k in range(200_000 if long_run else 5_000):
            fh.write(f"N{k} G1 X{k % 100}.25 Y{k % 37}.5 Z-1.{k % 9}\n")
        fh.write("M2\n")
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
    tracemalloc.start()
    try:
        n = 0
        last = None
        for cmd in stream_file(path, opts):
            n += 1
            last = cmd
        flat = tracemalloc.get_traced_memory()[1]
        tracemalloc.reset_peak()
        whole = compile_file(path, opts)
        held = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert n == len(whole) and last == whole[-1]
    assert flat < 4 * 1024 * 1024 < held
    assert flat < held / 10
