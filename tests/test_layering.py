"""The control layer's import direction (issue 13 item 5; docs/architecture.md "Layout").

Membership comes from tools/relayout.py's table, so these tests hold both before the lead
runs the script (control/ flat) and after it (control/<package>/<module>.py):

- every control module is in the table, and (after the move) in the package it names;
- a module imports only its own package and the packages the table allows it
  (`PACKAGES[p][1]`): the core imports no capability, capabilities one way;
- no control module imports the simulator (the default back end is registered one level
  up, in openmotion/control/__init__.py) or a layer above control (program, compat, cli,
  remote);
- every form counts: top-level, inside functions, under TYPE_CHECKING.

And the script's rewriting itself, on samples.
"""

from __future__ import annotations

import ast
import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CONTROL = ROOT / "src" / "openmotion" / "control"


def _load_relayout():
    spec = importlib.util.spec_from_file_location("relayout", ROOT / "tools" / "relayout.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["relayout"] = mod
    spec.loader.exec_module(mod)
    return mod


R = _load_relayout()
UPPER = ("openmotion.program", "openmotion.compat", "openmotion.cli", "openmotion.remote",
         "openmotion.hw.sim")


def control_files() -> dict[str, tuple[Path, str | None]]:
    """module -> (file, the package folder it sits in: None while control/ is flat)."""
    out = {}
    for p in CONTROL.glob("*.py"):
        if p.stem != "__init__":
            out[p.stem] = (p, None)
    for pkg in R.PACKAGES:
        for p in (CONTROL / pkg).glob("*.py") if (CONTROL / pkg).is_dir() else ():
            if p.stem != "__init__":
                out[p.stem] = (p, pkg)
    return out


def imported(path: Path, package: str) -> set[str]:
    """Absolute names of everything the file imports (modules and `from X import name`
    candidates), in any position."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = R.resolve(package, node.level, node.module)
            assert base is not None, (path, ast.dump(node))
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)
    return out


def control_module_of(name: str) -> str | None:
    """The control module an absolute name refers to (None: not a control module)."""
    parts = name.split(".")
    if parts[:2] != ["openmotion", "control"] or len(parts) < 3:
        return None
    if parts[2] in R.PACKAGES:
        return parts[3] if len(parts) > 3 and parts[3] in R.MAPPING else None
    return parts[2] if parts[2] in R.MAPPING else None


def test_every_control_module_is_in_the_table_and_its_package():
    files = control_files()
    assert set(files) == set(R.MAPPING), (
        "tools/relayout.py MAPPING must name every control module: missing "
        f"{sorted(set(files) - set(R.MAPPING))}, stale {sorted(set(R.MAPPING) - set(files))}")
    for mod, (_, pkg) in files.items():
        assert pkg in (None, R.MAPPING[mod]), (mod, pkg)
    assert not set(R.PACKAGES) & set(R.MAPPING)  # package names never shadow modules


def test_imports_point_one_way():
    bad = []
    for mod, (path, folder) in sorted(control_files().items()):
        package = "openmotion.control" + (f".{folder}" if folder else "")
        mine = R.MAPPING[mod]
        allowed = {mine, *R.PACKAGES[mine][1]}
        for name in sorted(imported(path, package)):
            target = control_module_of(name)
            if target is not None and R.MAPPING[target] not in allowed:
                bad.append(f"{mod} ({mine}) imports {target} ({R.MAPPING[target]})")
            if name.startswith(UPPER):
                bad.append(f"{mod} ({mine}) imports {name}")
    assert not bad, "imports against the layering:\n" + "\n".join(bad)


def test_the_package_dependencies_have_no_cycle():
    deps = {p: set(d) for p, (_, d) in R.PACKAGES.items()}
    assert deps["core"] == set()
    done: set[str] = set()
    while deps:
        free = [p for p, d in deps.items() if d <= done]
        assert free, f"cycle among {sorted(deps)}"
        for p in free:
            done.add(p)
            del deps[p]


def test_the_core_gets_back_end_and_capabilities_registered_from_above():
    from openmotion.control import Controller
    from openmotion.hw.sim import SimMachine

    ctl = Controller()
    assert isinstance(ctl.hardware, SimMachine)
    assert ctl.safety is not None and Controller(safety=False).safety is None


# -------------------------------------------------------------------- the script itself
def test_the_table_check_names_missing_and_stale_modules(tmp_path):
    for m in [*R.MAPPING, "brand_new"]:
        if m != "jog":
            (tmp_path / f"{m}.py").write_text("")
    problems = R.check_table(tmp_path)
    assert any("missing" in p and "brand_new" in p for p in problems)
    assert any("not in control" in p and "jog" in p for p in problems)
    (tmp_path / "brand_new.py").unlink()
    (tmp_path / "jog.py").write_text("")
    assert R.check_table(tmp_path) == []
    (tmp_path / "core").mkdir()
    assert any("exist already" in p for p in R.check_table(tmp_path))


@pytest.mark.parametrize(("pkg", "stem", "before", "after"), [
    ("openmotion.control", "group", "from .axis import Axis\n",
     "from ..core.axis import Axis\n"),
    ("openmotion.control", "group", "from . import pathrun\n", "from . import pathrun\n"),
    ("openmotion.control", "homing", "from . import planning\n",
     "from ..core import planning\n"),
    ("openmotion.control", "group", "from ..errors import MotionError\n",
     "from ...errors import MotionError\n"),
    ("openmotion.control", "jog", "def f():\n    from .groupexec import OWNERS as _OWNERS\n",
     "def f():\n    from ..groups.groupexec import OWNERS as _OWNERS\n"),
    ("openmotion.control", "__init__", "from .compare_io import (\n    plot_firings,  # x\n)\n",
     "from .trigger.compare_io import (\n    plot_firings,  # x\n)\n"),
    ("openmotion.program", "runner", "from ..control.group import Group\n",
     "from ..control.groups.group import Group\n"),
    ("openmotion.compat", "mccl", "from openmotion.control import group as G\n",
     "from openmotion.control.groups import group as G\n"),
    (None, "test_x", "from openmotion.control import Controller, jog\n",
     "from openmotion.control import Controller\n"
     "from openmotion.control.manual import jog\n"),
    (None, "test_x", "import openmotion.control.jump as J\n",
     "import openmotion.control.core.jump as J\n"),
    (None, "test_x", "from openmotion.errors import MotionError\n",
     "from openmotion.errors import MotionError\n"),
])
def test_imports_are_rewritten_from_the_new_place(pkg, stem, before, after):
    new_pkg = R.moved_package(pkg, Path(f"{stem}.py"))
    assert R.rewrite_imports(before, pkg, new_pkg) == after


def test_text_references_are_rewritten_once():
    text = ("see control/jump.py and `openmotion.control.speed_range.SpeedModel`, "
            "control.pulserule.pulse_count; ctl = control.axis(0); control/core/x.py")
    assert R.rewrite_text(text) == (
        "see control/core/jump.py and `openmotion.control.cards.speed_range.SpeedModel`, "
        "control.home.pulserule.pulse_count; ctl = control.axis(0); control/core/x.py")
    assert R.rewrite_text(R.rewrite_text(text)) == R.rewrite_text(text)
