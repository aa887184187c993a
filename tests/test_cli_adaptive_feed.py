"""`openmotion run --adaptive-feed-input ai<n> --analog-input ai<n>=V[@T]`: M52 P1 on the CLI."""

from __future__ import annotations

import pytest

from openmotion.cli import main

JOB = "G21 G91\nM52 P1\nG1 X6 F600\nM2\n"


def run_time(tmp_path, capsys, *flags: str) -> float:
    p = tmp_path / "job.ngc"
    p.write_text(JOB)
    assert main(["run", str(p), "--out", str(tmp_path), *flags]) == 0
    return float(capsys.readouterr().out.split("run time")[1].split()[0])


def test_the_input_scales_the_feed_from_its_time(tmp_path, capsys):
    full = run_time(tmp_path, capsys, "--adaptive-feed-input", "ai1", "--analog-input", "ai1=1")
    # 6 mm at 10 mm/s: 0.6 s plus the ramps; at half feed from 0.3 s the last 3 mm take 0.3 s more
    half = run_time(tmp_path, capsys, "--adaptive-feed-input", "ai1", "--analog-input",
                    "ai1=1", "--analog-input", "ai1=0.5@0.3")
    assert half - full == pytest.approx(0.3, abs=0.06)


@pytest.mark.parametrize("flags, named", [
    (["--adaptive-feed-input", "do1"], "--adaptive-feed-input"),
    (["--analog-input", "ai0"], "--analog-input"),
    (["--analog-input", "ai0=nan"], "--analog-input"),
    (["--analog-input", "ai0=1@-2"], "--analog-input"),
    (["--analog-input", "ai77=1"], "--analog-input ai77"),
    ([], "--adaptive-feed-input"),  # M52 P1 without an input: refused, the flag named
])
def test_bad_flags_are_named(tmp_path, capsys, flags, named):
    p = tmp_path / "job.ngc"
    p.write_text(JOB)
    assert main(["run", str(p), "--out", str(tmp_path), *flags]) == 2
    assert named in capsys.readouterr().err
