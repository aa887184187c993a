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
    assert "--max-vel" in capsys.readouterr().err
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


def test_help_shows_defaults(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = capsys.readouterr().out
    assert "(default: 0.05)" in out and "(default: 100.0)" in out and "(default: out)" in out
    assert "default: None" not in out


def test_errors_name_flags_and_huge_values_keep_columns(capsys):
    assert main(["profile", "t", "--distance", "100", "--max-vel", "-5", "--tacc", "0.1",
                 "--plot", ""]) == 2
    err = capsys.readouterr().err
    assert "--max-vel" in err and "max_vel" not in err
    # beyond the representable speed (docs/ranges.md): refused, naming the flag
    assert main(["profile", "t", "--distance", "100", "--max-vel", "1e30", "--tacc", "0.1",
                 "--plot", ""]) == 2
    err = capsys.readouterr().err
    assert "--max-vel" in err and "pps" in err
    # the largest speeds and distances still print in separate columns
    assert main(["profile", "t", "--distance", "1.3e8", "--max-vel", "9e8", "--tacc", "0.1",
                 "--plot", ""]) == 0
    rows = capsys.readouterr().out.splitlines()[1:3]
    for row in rows:  # 8 columns separated by blanks, never run together
        assert len(row.split()) == 8, row


def test_absurd_jerk_move_is_explained_not_sampled(capsys):
    assert main(["profile", "jerk", "--distance", "1e8", "--v-max", "1e-6", "--a-max", "1",
                 "--j-max", "1", "--plot", ""]) == 0
    out = capsys.readouterr().out
    assert "quantized check skipped: the move lasts 1e+14 s" in out and "--period" in out


def test_unwritable_out_fails_before_the_run(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["run", "examples/gcode/bolt_circle.ngc", "--out", str(blocker / "sub")]) == 2
    captured = capsys.readouterr()
    assert "--out" in captured.err and "not a writable folder" in captured.err
    assert "commands" not in captured.err  # nothing was compiled or run
    assert main(["profile", "t", "--distance", "10", "--max-vel", "10", "--tacc", "0.1",
                 "--plot", str(blocker / "p.png")]) == 2
    assert "--plot" in capsys.readouterr().err


def test_missing_machine_file_names_the_flag(capsys, tmp_path):
    assert main(["run", "examples/gcode/bolt_circle.ngc", "--machine",
                 str(tmp_path / "nope.toml"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--machine" in err and "no such file" in err and "Errno" not in err
    assert main(["run", str(tmp_path / "none.ngc"), "--out", str(tmp_path)]) == 2
    assert "no such file" in capsys.readouterr().err


def test_config_refuses_a_machine_without_axes(tmp_path, capsys):
    m = tmp_path / "m.toml"
    m.write_text('name = "m"\n')
    assert main(["config", str(m)]) == 2
    assert "no axes" in capsys.readouterr().err


def test_empty_program_is_reported(tmp_path, capsys):
    p = tmp_path / "empty.ngc"
    p.write_text("(nothing here)\nM2\n")
    assert main(["run", str(p), "--out", str(tmp_path)]) == 2
    assert "no moves or actions" in capsys.readouterr().err


def test_a_program_without_motion_runs_and_reports(tmp_path, capsys):
    p = tmp_path / "io.ngc"
    p.write_text("G21\nM64 P1\nG4 P0.5\nM65 P1\nM2\n")  # outputs and a dwell only
    assert main(["run", str(p), "--out", str(tmp_path)]) == 0
    assert "report:" in capsys.readouterr().out and (tmp_path / "io.html").exists()


def test_run_options_and_g54_announcement(tmp_path, capsys):
    p = tmp_path / "line.ngc"
    p.write_text("G21 G91 G1 X5 F600\nM2\n")
    assert main(["run", str(p), "--out", str(tmp_path), "--acc-time", "0.2",
                 "--feed-override", "50"]) == 0
    captured = capsys.readouterr()
    assert "acceleration time 0.2 s, feed override 50 %" in captured.err
    assert "G54 origin at the middle" in captured.err
    slow_time = float(captured.out.split("run time")[1].split()[0])
    assert slow_time > 0.95  # 5 mm at 50 % of 10 mm/s: 1 s and the ramps
    own = tmp_path / "own.ngc"
    own.write_text("G10 L2 P1 X0 Y0 Z0\nG21 G91 G1 X2 F600\nM2\n")
    assert main(["run", str(own), "--out", str(tmp_path)]) == 0
    assert "G54 origin at the middle" not in capsys.readouterr().err
    assert main(["run", str(own), "--out", str(tmp_path), "--feed-override", "500"]) == 2
    assert "--feed-override" in capsys.readouterr().err


def test_sets_work_offset():
    from openmotion.program.runjob import sets_work_offset

    assert sets_work_offset("g10 l20 p1 x0\n")
    assert sets_work_offset("#5221 = 10\n")
    assert sets_work_offset("G10 P0 L2 X1\n")
    assert not sets_work_offset("G10 L2 P2 X-60\n")
    assert not sets_work_offset("(G10 L2 P1 X1)\nG1 X1\n")
    assert not sets_work_offset("G110 L2 P1\n")


def test_ctrl_c_stops_decelerating_with_partial_report(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    prog = tmp_path / "long.ngc"
    # the first move lasts 1000 s of machine time, so even a simulation racing far ahead of
    # the wall clock is still inside it when Ctrl-C comes after 1 s
    prog.write_text("G10 L2 P1 X0 Y0 Z0\nG21 G91\nG1 X100 F6\nG1 Y100\nM2\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.Popen([sys.executable, "-m", "openmotion", "run", str(prog), "--out",
                             str(tmp_path)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=env, text=True)
    assert proc.stderr is not None
    assert "commands" in proc.stderr.readline()  # compiled, running now
    time.sleep(0.3)   # (the run races ahead of the wall clock: 0.3 s of CPU, not 1 s)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert "aborted at line 3" in err
    assert "aborted" in out and "report:" in out
    assert (tmp_path / "long.html").exists()
    dist = float(out.split("distance")[1].split()[0])
    assert 0 < dist < 100  # stopped inside the first move


def test_point_table_without_letters_names_the_file(tmp_path, capsys):
    t = tmp_path / "pts.toml"
    t.write_text('[[point]]\nposition = [1, 2]\n')
    assert main(["run", str(t), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "pts.toml" in err and "letters" in err
