"""The `openmotion` command line."""

import pytest

from openmotion.cli import main


def test_profile_t_prints_phases_and_writes_plots(tmp_path, capsys):
    png = tmp_path / "t.png"
    rc = main(["profile", "t", "--distance", "10000", "--max-vel", "1000", "--tacc", "0.1",
               "--plot", str(png)])
    out = capsys.readouterr().out
    assert rc == 0
    assert "cruise" in out and "total duration 10.100000000 s" in out
    assert "last count 10000" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "t.html").exists()


def test_profile_s_and_jerk(capsys):
    assert main(["profile", "s", "--distance", "-3000", "--str-vel", "100", "--max-vel", "5000",
                 "--tacc", "0.2", "--vs-acc", "1000", "--plot", ""]) == 0
    assert "end position -3000.000000" in capsys.readouterr().out
    assert main(["profile", "jerk", "--distance", "9846.652521797609",
                 "--v-max", "442.65611753961855", "--a-max", "98221.75531948937",
                 "--j-max", "48860762.86873084", "--plot", ""]) == 0
    assert "total duration 22.2509" in capsys.readouterr().out


def test_profile_bad_input_is_a_clear_error(capsys):
    assert main(["profile", "t", "--distance", "100", "--max-vel", "-5", "--tacc", "0.1",
                 "--plot", ""]) == 2
    assert "max_vel" in capsys.readouterr().err
    assert main(["profile", "jerk", "--distance", "100", "--plot", ""]) == 2
    assert "--v-max" in capsys.readouterr().err


def test_unknown_command_exits():
    with pytest.raises(SystemExit):
        main(["fly"])


def test_config_validates_and_prints(capsys, tmp_path):
    assert main(["config", "examples/xyzu.toml"]) == 0
    captured = capsys.readouterr()
    assert "[axes.x]" in captured.out and "is valid" in captured.err
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "m"\n[axes.x]\nlead = -2\n')
    assert main(["config", str(bad)]) == 2
    assert "axes.x.lead" in capsys.readouterr().err
    assert main(["config", str(tmp_path / "missing.toml")]) == 2
    assert "missing.toml" in capsys.readouterr().err
