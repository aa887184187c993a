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
- `both-refuse`: rs274 stops with an error and openmotion refuses it too (tests of error
  messages); `rs274-error`: rs274 stops with an error, openmotion runs it (each one is a
  difference to explain); `rs274-hang`: rs274 loops (endless programs).

An interpreter test (a tests/interp folder with a test.sh) runs as its test.sh runs it: the
folder with its sub-folders, rs274 with the test's INI file (`-i`, merged after our [TRAJ]),
tool table (`-t`) and other flags (`-n 0`), openmotion with the INI's SUBROUTINE_PATH and the
same tool table (converted from rs274's inches to mm).
"""

from __future__ import annotations

import argparse
import configparser
import subprocess
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path, PurePosixPath

sys.path.insert(0, str(Path(__file__).parent))

from lcnc_oracle import (  # noqa: E402
    OPTIONS,
    compare,
    openmotion_motions,
    run_rs274,
    scale_tool_table,
)
from openmotion.program import GCodeError  # noqa: E402


def _git(repo: str, *args: str) -> bytes:
    return subprocess.run(["git", "--git-dir", repo, *args], capture_output=True,
                          check=True).stdout


def _test_sh_runs(repo: str, rev: str, folder: str, files: list[str]
                  ) -> dict[str, tuple[str | None, str | None, tuple[str, ...]]]:
    """The programs a LinuxCNC interpreter test runs through rs274, from its test.sh:
    {program path: (its INI file, its tool table, other flags)}. Empty without a test.sh."""
    sh = f"{folder}/test.sh"
    if sh not in files:
        return {}
    runs = {}
    for line in _git(repo, "show", f"{rev}:{sh}").decode().splitlines():
        words = line.split("|")[0].replace("!", " ").split()
        if "rs274" not in words:
            continue
        words = words[words.index("rs274") + 1:]
        ini = tbl = None
        flags: list[str] = []
        prog = None
        k = 0
        while k < len(words):
            w = words[k]
            if w in ("-i", "-t", "-n", "-v") and k + 1 < len(words):
                if w == "-i":
                    ini = words[k + 1]
                elif w == "-t":
                    tbl = words[k + 1]
                else:
                    flags += [w, words[k + 1]]
                k += 2
                continue
            if w.endswith(".ngc") and prog is None:
                prog = w
            k += 1
        if prog is not None:
            runs[f"{folder}/{prog}"] = (ini, tbl, tuple(flags))
    return runs


def _ini_value(ini: str, section: str, key: str) -> str | None:
    parser = configparser.ConfigParser(strict=False, interpolation=None,
                                       inline_comment_prefixes=("#", ";"))
    parser.optionxform = str  # type: ignore[assignment, method-assign]
    try:
        parser.read_string(ini)
        return parser.get(section, key, fallback=None)
    except configparser.Error:
        return None


def _one(job: tuple[str, str, str, list[str], tuple | None]) -> tuple[str, str, str]:
    repo, rev, path, siblings, run = job
    folder = PurePosixPath(path).parent
    with tempfile.TemporaryDirectory() as tmp:
        extra = {}
        for s in siblings:
            try:
                extra[str(PurePosixPath(s).relative_to(folder))] = _git(
                    repo, "show", f"{rev}:{s}").decode()
            except UnicodeDecodeError:
                continue
        text = extra.pop(PurePosixPath(path).name)
        extra.pop("test.ngc", None)  # rs274 reads the program as test.ngc: keep it ours
        ini_name, tbl_name, flags = run or (None, None, ())
        ini = extra.get(ini_name, "") if ini_name else ""
        tbl = extra.get(tbl_name) if tbl_name else None
        d = Path(tmp)
        for name, body in extra.items():
            (d / name).parent.mkdir(parents=True, exist_ok=True)
            (d / name).write_text(body)
        subs = [str(d)]
        sub_path = _ini_value(ini, "RS274NGC", "SUBROUTINE_PATH") if ini else None
        if sub_path:
            subs = [str((d / p).resolve()) for p in sub_path.split(":")]
        options = replace(OPTIONS, subroutine_path=tuple(subs), require_end=True)
        if tbl is not None:
            (d / "mm.tbl").write_text(scale_tool_table(tbl, 25.4))
            options = replace(options, tool_table=d / "mm.tbl")
        ours: list = []
        try:
            ours = openmotion_motions(text, options)
            our_error = None
        except GCodeError as exc:
            our_error = str(exc)
        except Exception as exc:  # noqa: BLE001 - a survey reports, it does not stop
            our_error = f"{type(exc).__name__}: {exc}"
        # rs274 2.9.0~pre1 under load was seen to miss a tool table or die: a result that
        # disagrees with ours is taken again (at most 3 runs), and the tries are reported
        tries = 0
        while True:
            tries += 1
            try:
                theirs = run_rs274(text, extra_files=extra, timeout=20.0,
                                   ini="\n" + ini, flags=flags, tool_table=tbl)
            except subprocess.TimeoutExpired:
                return path, "rs274-hang", ""
            cls, why = _classify(theirs, ours, our_error)
            if cls in ("same", "both-refuse", "empty") or tries == 3:
                break
        if tries > 1:
            why += f" (rs274 run {tries} times)"
        return path, cls, why


def _classify(theirs, ours: list, our_error: str | None) -> tuple[str, str]:
    if theirs.error is not None:
        why = theirs.error.splitlines()[0][:100]
        if our_error is not None:
            return "both-refuse", f"{why} | ours: {our_error.splitlines()[0][:100]}"
        return "rs274-error", f"{why} | ours runs it ({len(ours)} motions)"
    if our_error is not None:
        return "refused", our_error[:160]
    if not theirs.motions and not ours:
        return "empty", "no motion (a subroutine file, a parameter test)"
    diffs = compare(ours, theirs.motions)
    if diffs:
        return "differ", "; ".join(diffs[:2])[:200]
    return "same", f"{len(theirs.motions)} motions"


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
                runs = _test_sh_runs(repo, a.rev, str(parent), files)
                # a test's folder goes with its sub-folders (subs/), a sample's alone
                sib = [s for s in files if (PurePosixPath(s).parent == parent or (
                       runs and parent in PurePosixPath(s).parents))
                       and not s.endswith((".sh", ".py", "expected"))]
                jobs.append((repo, a.rev, f, sib, runs.get(f)))
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
              f"{t.get('empty', 0)}; rs274 refuses "
              f"{t.get('both-refuse', 0) + t.get('rs274-error', 0)}"
              f" (openmotion refuses {t.get('both-refuse', 0)} of them), rs274 hangs "
              f"{t.get('rs274-hang', 0)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
