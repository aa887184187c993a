"""Browser front end benchmark: the controller's busy time per cycle with and without the
Motion Creator page attached and charting (issue 20: at most +10 %).

The same machine and load as bench/bench_remote.py (1 ms real-time cycle, the four axes of
the XYZU table repeating moves inside the cycle, the scope recording 8 channels at the
control period), but the client is the real page in Debian's chromium (driven by Playwright
in a separate process): the scope page charting the server's pushes (25 Hz) with the live
status (20 Hz), then the operation page with its velocity curve. Arms alternate (idle,
browser, idle, browser). Busy = the real-time thread's CPU time inside each cycle
(time.thread_time), as in bench_remote.

    python bench/bench_ui.py [--seconds 6] [--rounds 2]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from bench_remote import GOAL, TimedService, start_busy_machine

CHROMIUM = "/usr/bin/chromium"

BROWSER = textwrap.dedent("""
    import sys
    from playwright.sync_api import sync_playwright
    url, seconds = sys.argv[1], float(sys.argv[2])
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=sys.argv[3], args=["--no-sandbox"])
        p = b.new_page(viewport={"width": 1400, "height": 1000})
        p.goto(url + "#scope")
        p.wait_for_selector("#conn[data-state=open]", timeout=20000)
        p.wait_for_function("() => window.openmotion.scopeChart", timeout=20000)
        p.wait_for_timeout(seconds * 500)
        rate = p.get_attribute("#scope-info", "data-rate")
        samples = p.evaluate("window.openmotion.scopeChart.t.length")
        p.evaluate("location.hash = '#operation'")
        p.wait_for_timeout(seconds * 500)
        print(rate or 0, samples)
        b.close()
""")


def arm(svc: TimedService, url: str, seconds: float, browser: bool) -> tuple[float, str]:
    n0 = len(svc.cpu)
    info = ""
    if browser:
        out = subprocess.run([sys.executable, "-c", BROWSER, url, str(seconds), CHROMIUM],
                             capture_output=True, text=True, timeout=seconds + 120)
        rate, samples = (out.stdout.split() + ["?", "?"])[:2]
        info = (f"{float(rate):.1f} updates/s, {samples} samples" if rate != "?"
                else out.stderr[-300:])
    else:
        time.sleep(seconds)
    cpu = svc.cpu[n0:]
    return sum(cpu) / max(1, len(cpu)), info


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=6.0)
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args()
    if not Path(CHROMIUM).exists():
        print(f"bench_ui: {CHROMIUM} is missing (apt-get install chromium)")
        return 1
    svc, th = start_busy_machine()
    rows: dict[str, list[tuple[float, str]]] = {"idle": [], "browser": []}
    try:
        for _ in range(args.rounds):
            rows["idle"].append(arm(svc, th.url + "/", args.seconds, False))
            rows["browser"].append(arm(svc, th.url + "/", args.seconds, True))
    finally:
        th.stop()
        svc.shutdown()
    print(f"browser front end: controller busy per cycle, 1 ms cycle, 4 axes repeating moves, "
          f"scope 8 channels, {args.rounds} x {args.seconds:g} s per arm")
    means = {}
    for name, rs in rows.items():
        means[name] = sum(r[0] for r in rs) / len(rs)
        extra = "; ".join(r[1] for r in rs if r[1])
        print(f"{name:<8}{means[name] * 1e6:>10.1f} us cpu busy   {extra}")
    ratio = means["browser"] / means["idle"] - 1.0
    print(f"page attached and charting: {ratio * 100:+.1f} % cpu busy per cycle "
          f"(goal <= +{GOAL * 100:.0f} %) {'ok' if ratio <= GOAL else 'OVER'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
