"""Renew the README's run-report screenshots (docs/img/report-*.png) from a real run.

Runs a program through `openmotion run` into a scratch folder, opens the written report in
headless Chromium (Playwright) and photographs its sections: the summary on top, the path with
one listing line selected, the per-axis panels, and the contour/following error panels.

    python tools/report_screenshots.py [PROGRAM] [--line N] [--out docs/img]
    python tools/report_screenshots.py examples/programs/helix_drill.ngc --only path \
        --prefix report-3d-

Needs Playwright and a Chromium (`/usr/bin/chromium` on Debian, else Playwright's own).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = Path("/usr/bin/chromium")

#: shot name -> (heading of the section to photograph, how many headings it spans)
SHOTS = {
    "summary": (None, 0),
    "path": ("Path", 1),
    "axes": ("Axes (only those that move)", 1),
    "errors": ("Contour error", 2),
}


def run_report(program: Path, folder: Path) -> Path:
    """`openmotion run PROGRAM --out FOLDER`; the report's path."""
    shown = program.relative_to(ROOT) if program.is_relative_to(ROOT) else program
    cmd = [sys.executable, "-m", "openmotion", "run", str(shown), "--out", str(folder)]
    subprocess.run(cmd, check=True, cwd=ROOT)
    page = folder / f"{program.stem}.html"
    if not page.exists():
        raise SystemExit(f"no report written at {page}")
    return page


def photograph(page: Path, out: Path, line: int, shots: list[str],
               prefix: str) -> list[Path]:
    """Screenshots of the report's sections `shots` into `out` as `<prefix><shot>.png`;
    the files written."""
    from playwright.sync_api import sync_playwright

    written = []
    with sync_playwright() as pw:
        kw = {"executable_path": str(CHROMIUM)} if CHROMIUM.exists() else {}
        browser = pw.chromium.launch(**kw)
        tab = browser.new_page(viewport={"width": 1280, "height": 900})
        tab.goto(page.as_uri())
        # openmotionPick is set once plotly.js is inflated, every figure drawn and the
        # listing built (report_page.py)
        tab.wait_for_function("() => !!window.openmotionPick", timeout=30_000)
        tab.evaluate(f"window.openmotionPick({line})")
        tab.wait_for_timeout(500)
        for name in shots:
            heading, span = SHOTS[name]
            target = out / f"{prefix}{name}.png"
            if heading is None:  # title, options, summary and extents
                box = tab.evaluate("""() => {
                    const end = document.querySelector('h2');
                    return {x: 0, y: 0, width: 1280,
                            height: end.getBoundingClientRect().top + window.scrollY};}""")
            else:
                box = tab.evaluate("""([h, span]) => {
                    const hs = [...document.querySelectorAll('h2')];
                    const i = hs.findIndex(e => e.textContent === h);
                    if (i < 0) return null;
                    const top = hs[i].getBoundingClientRect().top + window.scrollY;
                    const next = hs[i + span];
                    const bottom = next ? next.getBoundingClientRect().top + window.scrollY
                                        : document.body.scrollHeight;
                    return {x: 0, y: top, width: 1280, height: bottom - top};}""",
                                   [heading, span])
                if box is None:
                    raise SystemExit(f"the report has no section {heading!r}")
            tab.screenshot(path=str(target), clip=box, full_page=True)
            written.append(target)
        browser.close()
    return written


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("program", nargs="?", type=Path,
                    default=ROOT / "examples" / "programs" / "laser_contour.ngc")
    ap.add_argument("--line", type=int, default=8,
                    help="listing line selected on the path (default: %(default)s)")
    ap.add_argument("--only", action="append", choices=sorted(SHOTS),
                    help="photograph only this section (repeatable; default: all)")
    ap.add_argument("--prefix", default="report-",
                    help="file name prefix (default: %(default)s)")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "img",
                    help="folder for the png files (default: %(default)s)")
    a = ap.parse_args(argv)
    if a.line < 1:
        ap.error("--line must be >= 1")
    a.out.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix="om-report-"))
    try:
        page = run_report(a.program.resolve(), scratch)
        for f in photograph(page, a.out, a.line, a.only or list(SHOTS), a.prefix):
            print(f)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
