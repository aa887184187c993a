"""`openmotion examples`: shipped examples listed and copied out."""

import tomllib
from pathlib import Path, PurePosixPath

from openmotion.cli import main
from openmotion.examples_cmd import examples_root, list_examples

ROOT = Path(__file__).resolve().parent.parent


def test_lists_programs_and_machines(capsys):
    assert main(["examples"]) == 0
    out = capsys.readouterr().out
    assert "gcode/bolt_circle.ngc" in out and "six holes" in out
    assert "xyzu.toml" in out and "programs/pick_place.toml" in out


def test_copy_out_and_use_it(tmp_path, capsys):
    assert main(["examples", "xyzu.toml", "--to", str(tmp_path)]) == 0
    assert "wrote" in capsys.readouterr().out
    assert main(["config", str(tmp_path / "xyzu.toml")]) == 0
    assert main(["examples", "bolt_circle", "--to", str(tmp_path)]) == 0
    assert (tmp_path / "bolt_circle.ngc").read_text() == \
        (ROOT / "examples/gcode/bolt_circle.ngc").read_text()
    capsys.readouterr()
    assert main(["examples", "xyzu.toml", "--to", str(tmp_path)]) == 2  # never overwrites
    assert "exists already" in capsys.readouterr().err
    assert main(["examples", "nothing.ngc"]) == 2
    assert "openmotion examples" in capsys.readouterr().err


def test_every_listed_example_is_in_the_wheel():
    """pyproject's package-data globs must cover every file `openmotion examples` lists."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    globs = cfg["tool"]["setuptools"]["package-data"]["openmotion"]
    for name, _ in list_examples():
        assert any(PurePosixPath("examples/" + name).match(g) for g in globs), name
    assert (examples_root() / "xyzu.toml").is_file()


def test_descriptions_are_whole_first_sentences_of_a_line_at_most():
    from openmotion.examples_cmd import DESCRIBE_WIDTH, list_examples

    got = dict(list_examples())
    assert got["lathe_xz.toml"].endswith("G7 programs diameters) and Z (carriage).")
    for name, text in got.items():
        assert text and len(text) <= DESCRIBE_WIDTH, name
        assert not text.endswith((",", ";", " and", " the", " on")), (name, text)
