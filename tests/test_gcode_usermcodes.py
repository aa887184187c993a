"""User M-codes M100-M199 as LinuxCNC runs them (program/usermcodes.py): an executable M1nn
on the configured folders, called with P and Q as `%f` arguments (-1.000000 absent) once
the motion before it has ended; the program waits for it; a missing file is refused when
compiling, a failing or hung one stops the run. Tiny shell scripts in tmp_path."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from openmotion.cli import main
from openmotion.config import AxisConfig, MachineConfig
from openmotion.control import Controller
from openmotion.errors import MotionError
from openmotion.program import GCodeError, GCodeOptions, compile_text
from openmotion.program.runner import ProgramRunner, RunOptions, RunState
from openmotion.program.stream import stream_file
from openmotion.program.usermcodes import UserCommand, UserMCode


def script(folder: Path, name: str, body: str, executable: bool = True) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / name
    p.write_text("#!/bin/sh\n" + body + "\n")
    if executable:
        p.chmod(0o755)
    return p


def logger(folder: Path, name: str = "M101", status: int = 0) -> Path:
    """M1nn appending its arguments to folder/log, exiting with `status`."""
    return script(folder, name, f'echo "$0 $1 $2" >> "{folder}/log"\nexit {status}')


def ctl3() -> Controller:
    axes = tuple(AxisConfig(name=c, lead=10.0, max_speed=200.0) for c in "xyz")
    ctl = Controller(MachineConfig(name="iso", axes=axes, digital_outputs=8))
    ctl.enable_all()
    return ctl


def opts(*dirs: Path) -> GCodeOptions:
    return GCodeOptions(axes={"X": 0, "Y": 1}, user_m_path=[str(d) for d in dirs])


def test_compile_finds_the_file_and_keeps_p_and_q(tmp_path):
    m = logger(tmp_path / "a")
    cmds = compile_text("G1 X1 F100\nM101 P2 Q[1/4]\nM101\nM101 G1 X5\nM2", opts(m.parent))
    users = [c for c in cmds if isinstance(c, UserMCode)]
    assert [u.args for u in users] == [[str(m), "2.000000", "0.250000"],
                                       [str(m), "-1.000000", "-1.000000"]] + [
        [str(m), "-1.000000", "-1.000000"]]
    # on one line the M-code comes before the motion (LinuxCNC's order of execution)
    kinds = [type(c).__name__ for c in cmds]
    assert kinds == ["Feed", "UserMCode", "UserMCode", "UserMCode", "Feed", "End"]
    prog = tmp_path / "p.ngc"
    prog.write_text("G1 X1 F100\nM101 P7\nM2\n")
    o = opts(m.parent)
    assert list(stream_file(prog, o)) == compile_text(prog.read_text(), o, str(prog))


def test_search_order_first_folder_wins_and_names_are_exact(tmp_path):
    first, second = tmp_path / "prefix", tmp_path / "user"
    logger(second, "M110")
    logger(first, "M110")
    script(first, "m111", "exit 0")          # lower-case m: not a user M-code
    script(first, "M112.sh", "exit 0")       # an extension: not one either
    script(first, "M113", "exit 0", executable=False)
    script(second, "M113", "exit 0")         # the executable one further on is used
    o = opts(first, second)
    (u,) = [c for c in compile_text("M110", o) if isinstance(c, UserMCode)]
    assert u.path == str(first / "M110")
    (u,) = [c for c in compile_text("M113", o) if isinstance(c, UserMCode)]
    assert u.path == str(second / "M113")
    for code in (111, 112):
        with pytest.raises(GCodeError, match=f"Unknown M code used: M{code}") as e:
            compile_text(f"G1 X1 F9\nM{code} P1", o, "job.ngc")
        assert (e.value.file, e.value.line, e.value.column, e.value.word) == (
            "job.ngc", 2, 1, f"M{code}")
    with pytest.raises(GCodeError, match="is not executable"):
        compile_text("M113", opts(first))
    with pytest.raises(GCodeError, match="no user M-code folders"):
        compile_text("M110", GCodeOptions(axes={"X": 0}))
    with pytest.raises(GCodeError, match="same modal group"):
        compile_text("M110 M113", o)


def test_runner_waits_for_the_motion_then_for_the_program(tmp_path):
    m = logger(tmp_path)
    ctl = ctl3()
    run = ProgramRunner(ctl, "G1 X1 F600\nM101 P2 Q3\nG1 X2\nM101\nM2",
                        options=RunOptions(user_m_path=(str(tmp_path),)))
    run.start()
    run.wait(30)
    assert run.state is RunState.DONE
    assert (tmp_path / "log").read_text().splitlines() == [
        f"{m} 2.000000 3.000000", f"{m} -1.000000 -1.000000"]
    ev = [e for e in run.events if e.kind.startswith("user_mcode")]
    assert [(e.kind, e.line) for e in ev] == [("user_mcode", 2), ("user_mcode_end", 2),
                                              ("user_mcode", 4), ("user_mcode_end", 4)]
    t, _, p = run.trace()
    x_at = float(np.interp(ev[0].t, t, p[:, 0]))
    assert x_at == pytest.approx(1.0, abs=1e-9)  # at rest at the end of the line before
    moving = t[np.abs(np.gradient(p[:, 0])) > 0]
    assert not np.any((moving > ev[0].t) & (moving < ev[1].t))  # nothing moves meanwhile


def test_failing_program_stops_the_run_with_its_status_and_output(tmp_path):
    script(tmp_path, "M150", 'echo "clamp not closed"\nexit 3')
    ctl = ctl3()
    run = ProgramRunner(ctl, "G1 X1 F600\nM150 P1\nG1 X2\nM2",
                        options=RunOptions(user_m_path=(str(tmp_path),)))
    run.start()
    run.wait(30)
    assert run.state is RunState.ERROR
    assert run.error.startswith("line 2: M150") and "exit status 3" in run.error
    assert "clamp not closed" in run.error
    assert run._positions()[0] / run.scales.ppu[0] == pytest.approx(1.0)  # X2 never ran


def test_a_hung_program_is_stopped_after_the_timeout(tmp_path):
    script(tmp_path, "M120", "exec sleep 30")
    ctl = ctl3()
    run = ProgramRunner(ctl, "M120\nG1 X1 F600\nM2",
                        options=RunOptions(user_m_path=(str(tmp_path),),
                                           user_m_timeout=0.2))
    t0 = time.monotonic()
    run.start()
    run.wait(30)
    assert time.monotonic() - t0 < 5.0
    assert run.state is RunState.ERROR and "did not exit within 0.2 s" in run.error
    assert np.allclose(run._positions(), 0.0)


def test_real_time_polls_and_close_interrupts_the_process_group(tmp_path):
    script(tmp_path, "M121", f'sleep 30 &\necho $! > "{tmp_path}/child"\nwait')
    cmd = UserMCode(121, -1.0, -1.0, str(tmp_path / "M121"), 1)
    uc = UserCommand(cmd, 10.0, block=False)
    deadline = time.monotonic() + 30.0  # a loaded machine may start the script late
    while time.monotonic() < deadline:
        if (tmp_path / "child").exists() and (tmp_path / "child").read_text().strip():
            break
        time.sleep(0.01)
    assert uc.poll() is False  # still running: the cycle goes on
    child = int((tmp_path / "child").read_text())
    uc.close()
    deadline = time.monotonic() + 10.0  # well before the child's own 30 s end
    while True:  # the child of the script is gone too (or a zombie, dead)
        try:
            if Path(f"/proc/{child}/stat").read_text().split()[2] == "Z":
                break
        except OSError:
            break
        if time.monotonic() > deadline:
            pytest.fail("the M-code's child process survived close()")
        time.sleep(0.01)


def test_missing_file_refused_before_motion_and_bad_options(tmp_path):
    ctl = ctl3()
    with pytest.raises(GCodeError, match="M105"):
        ProgramRunner(ctl, "G1 X5 F600\nM105\nM2",
                      options=RunOptions(user_m_path=(str(tmp_path),)))
    assert np.allclose([a.position for a in ctl.axes], 0.0)
    with pytest.raises(MotionError, match="user_m_path: .* is not a folder"):
        RunOptions(user_m_path=(str(tmp_path / "nope"),))
    with pytest.raises(MotionError, match="user_m_path must be a list of folders"):
        RunOptions(user_m_path=str(tmp_path))  # type: ignore[arg-type]
    with pytest.raises(MotionError, match="user_m_path must be a list of folders"):
        GCodeOptions(axes={"X": 0}, user_m_path=[3])  # type: ignore[list-item]
    for bad in (0, -1.0, True, "5"):
        with pytest.raises(MotionError, match="user_m_timeout"):
            RunOptions(user_m_timeout=bad)  # type: ignore[arg-type]


def test_cli_flags(tmp_path, capsys):
    prog = tmp_path / "p.ngc"
    prog.write_text("G21 G91 G1 X1 F600\nM101 P4\nM2\n")
    assert main(["run", str(prog), "--user-m-path", str(tmp_path / "nope")]) != 0
    assert "--user-m-path: " in capsys.readouterr().err
    assert main(["run", str(prog), "--user-m-path", str(tmp_path),
                 "--user-m-timeout", "0"]) != 0
    assert "--user-m-timeout must be" in capsys.readouterr().err
    assert main(["run", str(prog)]) != 0
    assert "Unknown M code used: M101" in capsys.readouterr().err
