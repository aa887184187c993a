"""The README's demo: every step runs and ends where it should."""

from openmotion.cli import main
from openmotion.control import Controller
from openmotion.demo import run_steps


def test_demo_steps_end_on_their_targets():
    ctl = Controller()
    steps = run_steps(ctl)
    assert len(steps) == 6
    x, y, z, u = (ctl.axis(n) for n in "xyzu")
    assert x.counters.command == round(x.units.to_pulses(30.0))   # after the go-back
    assert z.counters.command == round(z.units.to_pulses(20.0))
    assert "changed at" in steps[4].note
    # y stopped immediately mid-move: short of the 80 mm target, and at rest.
    assert 30.0 < y.units.to_units(y.position) < 80.0
    assert all(not a.is_moving for a in ctl.axes)
    for a in ctl.axes:
        assert a.counters.error == 0            # ideal steppers follow every pulse


def test_demo_command_writes_plots(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "Standstill" in out
    assert (tmp_path / "demo_trace.png").stat().st_size > 1000
    assert (tmp_path / "demo_trace.html").exists()
    assert "faults         0" in out and "state          done" in out   # the G-code job
    assert "Plotly.newPlot" in (tmp_path / "demo_laser.html").read_text()
    # G64 P0.01: the executed contour (rapid-to-cut blends included) stays within 0.01 mm
    err = float(out.split("contour error")[1].split()[0])
    assert err <= 0.01 + 1e-9


def test_realtime_demo_prints_statistics(capsys):
    # long enough for every axis to reverse several times (a shared direction once let
    # axes drift onto their -EL after about a second)
    assert main(["demo", "--realtime", "--seconds", "1.5"]) == 0
    out = capsys.readouterr().out
    assert "jitter" in out and "overruns" in out
