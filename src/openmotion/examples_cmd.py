"""`openmotion examples`: list the example programs and machine files shipped in the package
and copy one out, so the README's commands work outside a source checkout."""

from __future__ import annotations

import re
import shutil
from importlib import resources
from pathlib import Path

from .errors import MotionError

#: What `openmotion examples` offers: G-code programs, point tables and machine files.
SUFFIXES = (".ngc", ".nc", ".toml", ".csv")


def examples_root() -> Path:
    """The folder of shipped examples (inside the installed package)."""
    return Path(str(resources.files("openmotion") / "examples"))


def list_examples() -> list[tuple[str, str]]:
    """(name relative to the examples folder, one-line description), sorted by name."""
    root = examples_root()
    out = []
    for p in sorted(root.rglob("*")):
        if p.is_file() and p.suffix in SUFFIXES and "__pycache__" not in p.parts:
            out.append((p.relative_to(root).as_posix(), _describe(p)))
    return out


#: A comment line ending in one of these goes on in the next line (a sentence cut).
_GOES_ON = re.compile(r"(?:[,;]|\b(?:and|or|the|a|an|on|of|in|with|to|for|by|from))$",
                      re.IGNORECASE)
#: The longest description `openmotion examples` prints (cut at a word, with "...").
DESCRIBE_WIDTH = 100


def _describe(path: Path) -> str:
    """The first sentence of the file's leading comment (`(name: what it is)` lines in
    G-code, `# ...` in TOML), joined over lines that break it, at most DESCRIBE_WIDTH."""
    try:
        head = path.read_text(encoding="utf-8", errors="replace")[:2000]
    except OSError:
        return ""
    parts: list[str] = []
    for line in head.splitlines():
        m = re.match(r"\s*\(([^)]*)\)\s*$", line) or re.match(r"\s*#\s*(.*)", line)
        if not m or not m.group(1).strip():
            break
        parts.append(m.group(1).strip())
        if not _GOES_ON.search(parts[-1]):
            break
    text = " ".join(parts)
    if text.lower().startswith(path.name.lower() + ":"):
        text = text.split(":", 1)[1].strip()
    end = re.search(r"\.(?:\s|$)", text)
    if end:
        text = text[:end.start() + 1]
    if len(text) > DESCRIBE_WIDTH:
        text = text[:DESCRIBE_WIDTH - 3].rsplit(" ", 1)[0].rstrip(",;:") + "..."
    return text


def find_example(name: str) -> Path:
    """The shipped example `name` (e.g. 'gcode/bolt_circle.ngc' or just 'bolt_circle.ngc')."""
    root = examples_root()
    names = [n for n, _ in list_examples()]
    if name in names:
        return root / name
    matches = [n for n in names if n.split("/")[-1] == name or n.split("/")[-1].split(".")[0]
               == name]
    if len(matches) == 1:
        return root / matches[0]
    if matches:
        raise MotionError(f"example {name!r} is ambiguous: {', '.join(matches)}")
    raise MotionError(f"no example named {name!r}; `openmotion examples` lists them")


def copy_example(name: str, to: str | Path) -> Path:
    """Copy the example `name` into the folder `to` (created); the new file's path. An
    existing file is never overwritten."""
    src = find_example(name)
    folder = Path(to)
    dest = folder / src.name
    if dest.exists():
        raise MotionError(f"{dest} exists already; remove it or pass another --to folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, dest)
    except OSError as exc:
        raise MotionError(f"--to {str(folder)!r}: cannot write ({exc.strerror or exc})") from None
    return dest
