"""Lay out openmotion/control by capability: move each module into its sub-package and
rewrite every reference to it (issue 13 item 5).

Run on a clean checkout of merged main, from the repository root:

    python tools/relayout.py            # check, git mv, rewrite, ruff --fix the imports
    python tools/relayout.py --check    # only check that the table covers control/

What it does:

1. checks that MAPPING names every module in src/openmotion/control/ (a module from a
   newer branch that is missing fails loudly with the list, so it can be added) and no
   module that is not there, and that no sub-package exists yet;
2. `git mv`s control/<module>.py to control/<package>/<module>.py and writes each
   package's __init__.py (a docstring: what the capability is, what it may import);
3. rewrites, in src/, tests/, bench/, examples/, docs/, README.md and pyproject.toml:
   - every Python import of a control module, relative (`from .axis import`,
     `from ..control.group import`, `from . import pathrun`) or absolute
     (`from openmotion.control.compare import`, `from openmotion.control import group`,
     `import openmotion.control.jump`), re-emitted in the same style from the file's new
     place;
   - dotted references in text (`openmotion.control.jump`, `control.speed_range.x` in
     docstrings, patch targets) and file paths (`control/jump.py`);
   openmotion/control/__init__.py keeps re-exporting the very names it exports today;
4. runs `ruff check --select I --fix` on the changed Python files (import order).

Package names differ from every module name, so a rewritten reference is never rewritten
again and `openmotion.control.<package>` is never mistaken for a module.
tests/test_layering.py reads MAPPING and DEPENDS to check the import direction, before and
after the move.
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONTROL = ROOT / "src" / "openmotion" / "control"
BASE = "openmotion.control"

#: sub-package -> (docstring, the sub-packages its modules may import besides itself)
PACKAGES: dict[str, tuple[str, tuple[str, ...]]] = {
    "core": ("The core: the controller and its cycle, the clock, axes and their motion "
             "execution, counters, events, PLCopen states, virtual-time jumps. Imports no "
             "capability and no back end; capabilities register hooks on it.", ()),
    "guard": ("Safety reactions: end limits, slow-down, alarm, ERC, soft limits, "
              "comparators (error counter), in-position control.", ("core",)),
    "loops": ("Servo loops closed in the control layer, filters, compensation (pitch "
              "tables, backlash).", ("core",)),
    "cards": ("Card models: the HSL network (rings, slaves, axes) and the PCL6045 speed "
              "range grid.", ("core",)),
    "trigger": ("Position compare and PSO: the compare engine, its jobs, solvers, outputs "
                "and scope, ZMotion PSO, HSL triggers.", ("core",)),
    "home": ("Homing (HSL modes, MCCL phases, sequences) and position latch / touch "
             "probe.", ("core", "guard")),
    "groups": ("Groups and path execution: group commands, streaming look-ahead, joins, "
               "blending, path-to-axis profiles, pulse accuracy.", ("core", "guard")),
    "manual": ("Manual motion: jogging (continuous, pulse, space).", ("core", "groups")),
}

#: control module -> sub-package (every module of src/openmotion/control/ must be here)
MAPPING: dict[str, str] = {
    # core
    "axis": "core", "axisexec": "core", "axisrunning": "core", "clock": "core",
    "controller": "core", "controller_hooks": "core", "controller_settings": "core",
    "counters": "core", "events": "core", "jump": "core", "motion": "core",
    "planning": "core", "realtime": "core", "states": "core",
    # safety reactions
    "safety": "guard", "softlimits": "guard", "comparators": "guard", "inposition": "guard",
    "responses": "guard",
    # servo and compensation
    "servo": "loops", "servoloop": "loops", "compensation": "loops",
    # card models
    "network": "cards", "speed_range": "cards",
    # compare and PSO
    "compare": "trigger", "compare_due": "trigger", "compare_io": "trigger",
    "compare_jobs": "trigger", "compare_math": "trigger", "compare_replan": "trigger",
    "compare_scope": "trigger", "compare_tracks": "trigger", "pso": "trigger",
    "hsl_trigger": "trigger", "analog": "trigger",
    # homing and latch
    "homing": "home", "homing_modes": "home", "homing_sequence": "home", "latch": "home",
    "pulserule": "home", "homeconf": "home",
    # groups and path execution
    "group": "groups", "group_checks": "groups", "group_corners": "groups",
    "group_settings": "groups", "group_status": "groups", "groupdue": "groups",
    "groupexec": "groups", "groupstream": "groups", "groupfaults": "groups",
    "grouptypes": "groups",
    "groupjoin": "groups", "joinhandoff": "groups", "pathaxes": "groups", "pathexec": "groups",
    "pathpoints": "groups", "pathrun": "groups", "accuracy": "groups", "ptpblend": "groups",
    "overlap": "groups", "pathmove": "groups",
    # manual motion
    "jog": "manual",
}

TEXT_DIRS = ("src", "tests", "bench", "examples", "docs")
TEXT_FILES = ("README.md", "pyproject.toml")
TEXT_SUFFIXES = (".py", ".md", ".toml", ".txt", ".rst", ".cfg", ".ini")
#: files left as they are: this table, and the layering test's samples of old references
SKIP = {Path(__file__).resolve(), ROOT / "tests" / "test_layering.py"}


class RelayoutError(Exception):
    pass


# ------------------------------------------------------------------------------- checks
def flat_modules(control: Path = CONTROL) -> list[str]:
    """The modules directly in control/ (not __init__)."""
    return sorted(p.stem for p in control.glob("*.py") if p.stem != "__init__")


def check_table(control: Path = CONTROL) -> list[str]:
    """Problems with MAPPING against control/ as it is (empty: ready to run)."""
    problems = []
    mods = flat_modules(control)
    missing = [m for m in mods if m not in MAPPING]
    if missing:
        problems.append("control modules missing from MAPPING in tools/relayout.py "
                        "(add each with its sub-package): " + ", ".join(missing))
    gone = [m for m in MAPPING if m not in mods]
    if gone:
        problems.append("MAPPING names modules that are not in control/ (renamed or "
                        "removed? fix the table): " + ", ".join(gone))
    bad = sorted({p for p in MAPPING.values() if p not in PACKAGES})
    if bad:
        problems.append("MAPPING uses unknown sub-packages: " + ", ".join(bad))
    clash = sorted(set(PACKAGES) & (set(MAPPING) | set(mods)))
    if clash:
        problems.append("sub-package names must differ from module names: " + ", ".join(clash))
    there = [p for p in PACKAGES if (control / p).exists()]
    if there:
        problems.append("sub-packages exist already (relayout ran?): " + ", ".join(there))
    return problems


# ------------------------------------------------------------------------------ imports
def new_module(absolute: str) -> str:
    """openmotion.control.<mod>[.rest] -> openmotion.control.<pkg>.<mod>[.rest]."""
    parts = absolute.split(".")
    if len(parts) >= 3 and ".".join(parts[:2]) == BASE and parts[2] in MAPPING:
        return ".".join([*parts[:2], MAPPING[parts[2]], *parts[2:]])
    return absolute


def file_package(path: Path, src: Path) -> str | None:
    """The dotted package a file under src/ belongs to (None: not under src/)."""
    try:
        rel = path.relative_to(src)
    except ValueError:
        return None
    parts = list(rel.with_suffix("").parts)
    parts.pop()  # the module's own name, or __init__: the package is the folder
    return ".".join(parts)


def moved_package(pkg: str | None, path: Path) -> str | None:
    """The package of a file after the move (a control module goes down one level)."""
    if pkg == BASE and path.stem in MAPPING:
        return f"{BASE}.{MAPPING[path.stem]}"
    return pkg


def resolve(pkg: str | None, level: int, module: str | None) -> str | None:
    if level == 0:
        return module
    if pkg is None:
        return None
    parts = pkg.split(".")
    if level - 1 > len(parts) - 1:
        return None
    base = parts[:len(parts) - (level - 1)]
    return ".".join(base + ([module] if module else []))


def relative(pkg: str, absolute: str) -> tuple[int, str]:
    """(level, module) of a relative import of `absolute` from package `pkg`."""
    a, b = pkg.split("."), absolute.split(".")
    k = 0
    while k < min(len(a), len(b)) and a[k] == b[k]:
        k += 1
    if k == 0:
        raise RelayoutError(f"no relative form for {absolute} from {pkg}")
    return len(a) - k + 1, ".".join(b[k:])


def emit_from(level: int, module: str, names: list[ast.alias], indent: str) -> str:
    mod = "." * level + module
    items = [a.name if a.asname is None else f"{a.name} as {a.asname}" for a in names]
    line = f"{indent}from {mod} import {', '.join(items)}"
    if len(line) <= 99:
        return line
    inner = "".join(f"{indent}    {i},\n" for i in items)
    return f"{indent}from {mod} import (\n{inner}{indent})"


def rewrite_imports(text: str, pkg: str | None, new_pkg: str | None) -> str:
    """Every import statement of a control module, re-emitted from the file's new place."""
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return text
    lines = text.splitlines(keepends=True)
    offsets = [0]
    for ln in lines:
        offsets.append(offsets[-1] + len(ln))
    edits: list[tuple[int, int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            new = _rewrite_from(node, pkg, new_pkg, lines)
        elif isinstance(node, ast.Import):
            new = _rewrite_import(node, lines)
        else:
            continue
        if new is not None:
            start = offsets[node.lineno - 1] + node.col_offset
            end = offsets[node.end_lineno - 1] + node.end_col_offset  # type: ignore[operator]
            edits.append((start, end, new))
    for start, end, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[end:]
    return text


def _rewrite_from(node: ast.ImportFrom, pkg: str | None, new_pkg: str | None,
                  lines: list[str]) -> str | None:
    absolute = resolve(pkg, node.level, node.module)
    if absolute is None:
        return None
    # group the imported names by the module they come from after the move
    groups: dict[str, list[ast.alias]] = {}
    for a in node.names:
        if absolute == BASE and a.name in MAPPING:  # `from openmotion.control import group`
            target = f"{BASE}.{MAPPING[a.name]}"
        else:
            target = new_module(absolute)
        groups.setdefault(target, []).append(a)
    if list(groups) == [absolute] and (new_pkg == pkg or node.level == 0):
        return None  # nothing moved, or an absolute import of something that did not
    if len(groups) == 1:  # one source: change only the module spec, keep the rest as is
        (target,) = groups
        if node.level == 0:
            spec = target
        else:
            assert new_pkg is not None
            level, mod = relative(new_pkg, target)
            spec = "." * level + mod
        seg = ast.get_source_segment("".join(lines), node)
        assert seg is not None
        return re.sub(r"^from\s+[.\w]*\s+import", f"from {spec} import", seg, count=1)
    indent = ""  # the statement starts at col_offset: continuation keeps the original
    out = []
    for target, names in groups.items():
        if node.level == 0:
            out.append(emit_from(0, target, names, indent))
        else:
            assert new_pkg is not None
            level, mod = relative(new_pkg, target)
            out.append(emit_from(level, mod, names, indent))
    col = " " * node.col_offset
    return ("\n" + col).join(s.replace("\n", "\n" + col) for s in out)


def _rewrite_import(node: ast.Import, lines: list[str]) -> str | None:
    names = []
    changed = False
    for a in node.names:
        n = new_module(a.name)
        changed |= n != a.name
        names.append(n if a.asname is None else f"{n} as {a.asname}")
    return f"import {', '.join(names)}" if changed else None


# --------------------------------------------------------------------------------- text
_MODS = "|".join(sorted(MAPPING, key=len, reverse=True))
_DOTTED_FULL = re.compile(rf"\b{re.escape(BASE)}\.({_MODS})\b")
_DOTTED = re.compile(rf"(?<![\w.])control\.({_MODS})\b(?!\.py|\s*\()")
_PATH = re.compile(rf"\bcontrol/({_MODS})\.py\b")


def rewrite_text(text: str) -> str:
    """Dotted names and file paths of control modules in any text."""
    text = _DOTTED_FULL.sub(lambda m: f"{BASE}.{MAPPING[m.group(1)]}.{m.group(1)}", text)
    text = _DOTTED.sub(lambda m: f"control.{MAPPING[m.group(1)]}.{m.group(1)}", text)
    return _PATH.sub(lambda m: f"control/{MAPPING[m.group(1)]}/{m.group(1)}.py", text)


def text_files(root: Path) -> list[Path]:
    out = []
    for d in TEXT_DIRS:
        base = root / d
        if base.exists():
            out += [p for p in base.rglob("*") if p.is_file() and p.suffix in TEXT_SUFFIXES
                    and "__pycache__" not in p.parts and ".egg-info" not in str(p)]
    out += [root / f for f in TEXT_FILES if (root / f).exists()]
    return sorted(set(out) - SKIP)


# ---------------------------------------------------------------------------------- run
def git(*args: str, root: Path) -> None:
    subprocess.run(["git", *args], cwd=root, check=True)


def relayout(root: Path = ROOT) -> list[Path]:
    """Move and rewrite (see the module docstring); returns the files changed."""
    control = root / "src" / "openmotion" / "control"
    src = root / "src"
    problems = check_table(control)
    if problems:
        raise RelayoutError("\n".join(problems))
    files = text_files(root)
    new_texts: dict[Path, str] = {}
    for path in files:
        text = path.read_text(encoding="utf-8")
        new = text
        if path.suffix == ".py":
            pkg = file_package(path, src)
            new = rewrite_imports(new, pkg, moved_package(pkg, path))
        new = rewrite_text(new)
        if new != text:
            new_texts[path] = new
    for pkg, (doc, deps) in PACKAGES.items():
        (control / pkg).mkdir()
        may = ", ".join(deps) if deps else "no other sub-package"
        init = control / pkg / "__init__.py"
        init.write_text(f'"""{_wrap(doc)}\n\nMay import: {may} (tests/test_layering.py)."""\n',
                        encoding="utf-8")
    moved: dict[Path, Path] = {}
    for mod, pkg in MAPPING.items():
        old, new_path = control / f"{mod}.py", control / pkg / f"{mod}.py"
        git("mv", str(old), str(new_path), root=root)
        moved[old] = new_path
    for path, text in new_texts.items():
        moved.get(path, path).write_text(text, encoding="utf-8")
    git("add", *[str(control / p / "__init__.py") for p in PACKAGES], root=root)
    changed = [moved.get(p, p) for p in new_texts]
    py = [str(p) for p in changed if p.suffix == ".py"] + \
        [str(control / p / "__init__.py") for p in PACKAGES]
    subprocess.run([sys.executable, "-m", "ruff", "check", "--select", "I", "--fix", "-q",
                    *py], cwd=root, check=False)
    return changed


def _wrap(doc: str, width: int = 88) -> str:
    words, out, line = doc.split(), [], ""
    for w in words:
        if line and len(line) + 1 + len(w) > width:
            out.append(line)
            line = w
        else:
            line = f"{line} {w}" if line else w
    out.append(line)
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only check the table")
    ap.add_argument("--root", type=Path, default=ROOT, help="repository root")
    args = ap.parse_args()
    control = args.root / "src" / "openmotion" / "control"
    problems = check_table(control)
    if problems:
        print("relayout: refused\n  " + "\n  ".join(problems), file=sys.stderr)
        return 1
    if args.check:
        print(f"relayout: table covers all {len(flat_modules(control))} control modules")
        return 0
    changed = relayout(args.root)
    print(f"relayout: moved {len(MAPPING)} modules into {len(PACKAGES)} sub-packages, "
          f"rewrote {len(changed)} files; review `git status`, run the tests, commit")
    return 0


if __name__ == "__main__":
    sys.exit(main())
