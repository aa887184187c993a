"""Survey: LinuxCNC's own sample programs and interpreter tests through both interpreters.

    python tests/lcnc_survey.py /path/to/linuxcnc-checkout [--rev HEAD] [--jobs 2]

Every nc_files/**/*.ngc and tests/interp/**/*.ngc of a LinuxCNC git checkout (read with
`git show`, nothing is copied into this repository) is run in a scratch folder holding all
files of its own folder (so its subroutine files are found by both), through rs274 (20 s
limit) and `compile_text` with that folder as the subroutine path; the motions are
compared as tests/test_gcode_linuxcnc.py does. Printed: each program's class and the
totals (docs/gcode.md "LinuxCNC's programs" quotes them):

- `same`: both run it and every motion agrees within 1e-4;
- `differ`: both run it, motions differ (the first differences are shown);
- `refused`: rs274 runs it, openmotion refuses it (the reason names the feature);
- `empty`: both run it and neither makes any motion (subroutine files): not counted;
- `rs274-error` / `rs274-hang`: LinuxCNC's standalone interpreter does not run it (not
  counted: tests of error messages, programs needing a configuration, endless loops).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path, PurePosixPath

sys.path.insert(0, str(Path(__file__).parent))

from lcnc_oracle import OPTIONS, compare, openmotion_motions, run_rs274  # noqa: E402
from openmotion.program import GCodeError  # noqa: E402


def _git(repo: str, *args: str) -> bytes:
    return subprocess.run(["git", "--git-dir", repo, *args], capture_output=True,
                          check=True).stdout


def _one(job: tuple[str, str, str, list[str]]) -> tuple[str, str, str]:
    repo, rev, path, siblings = job
    with tempfile.TemporaryDirectory() as tmp:
        extra = {}
        for s in siblings:
            try:
                extra[PurePosixPath(s).name] = _git(repo, "show", f"{rev}:{s}").decode()
            except UnicodeDecodeError:
                continue
        text = extra.pop(PurePosixPath(path).name)
        try:
            theirs = run_rs274(text, extra_files=extra, timeout=20.0)
        except subprocess.TimeoutExpired:
            return path, "rs274-hang", ""
        if theirs.error is not None:
            return path, "rs274-error", theirs.error.splitlines()[0][:100]
        d = Path(tmp)
        for name, body in extra.items():
            (d / name).write_text(body)
        try:
            ours = openmotion_motions(text, replace(OPTIONS, subroutine_path=(str(d),)))
        except GCodeError as exc:
            return path, "refused", str(exc)[:160]
        except Exception as exc:  # noqa: BLE001 - a survey reports, it does not stop
            return path, "refused", f"{type(exc).__name__}: {exc}"[:160]
        if not theirs.motions and not ours:
            return path, "empty", "no motion (a subroutine file, a parameter test)"
        diffs = compare(ours, theirs.motions)
        if diffs:
            return path, "differ", "; ".join(diffs[:2])[:200]
        return path, "same", f"{len(theirs.motions)} motions"


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkout", help="a LinuxCNC checkout (its .git, or a bare git dir)")
    ap.add_argument("--rev", default="HEAD")
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args(argv)
    repo = a.checkout if (Path(a.checkout) / "objects").is_dir() else str(
        Path(a.checkout) / ".git")
    files = _git(repo, "ls-tree", "-r", "--name-only", a.rev).decode().splitlines()
    jobs = []
    for area in ("nc_files/", "tests/interp/"):
        for f in files:
            if f.startswith(area) and f.endswith(".ngc"):
                parent = PurePosixPath(f).parent
                sib = [s for s in files if PurePosixPath(s).parent == parent
                       and not s.endswith((".sh", ".py", "expected"))]
                jobs.append((repo, a.rev, f, sib))
    totals: dict[str, dict[str, int]] = {}
    with ProcessPoolExecutor(a.jobs) as pool:
        for path, cls, why in pool.map(_one, jobs):
            area = path.split("/")[0]
            totals.setdefault(area, {}).setdefault(cls, 0)
            totals[area][cls] += 1
            print(f"{cls:12s} {path}  {why}", flush=True)
    for area, t in totals.items():
        ran = sum(v for k, v in t.items() if k in ("same", "differ", "refused"))
        print(f"{area}: rs274 runs {ran}: same {t.get('same', 0)}, differ "
              f"{t.get('differ', 0)}, refused {t.get('refused', 0)}; no motion "
              f"{t.get('empty', 0)}; rs274 does not run "
              f"{t.get('rs274-error', 0) + t.get('rs274-hang', 0)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
