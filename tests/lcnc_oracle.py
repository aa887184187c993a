"""LinuxCNC's `rs274` as a differential oracle for openmotion.program.

`rs274_motions(text)` runs LinuxCNC's standalone interpreter (set up by
tools/setup_rs274.sh) on a program and turns its canonical-command listing into `Motion`
records in machine coordinates (mm, degrees): the listing is in program units with the
offsets applied by the canon layer, so this module replays what LinuxCNC's emccanon.cc does
(USE_LENGTH_UNITS scaling, SET_G92_OFFSET, SET_XY_ROTATION about the G5x origin,
SET_G5X_OFFSET, USE_TOOL_LENGTH_OFFSET; feeds set in the units active when F was set,
angular feeds never scaled). `openmotion_motions(text)` gives the same records from
`compile_text`; `compare` lists the differences. rs274 prints 4 decimals in program units,
so positions agree within 1e-4 program units (`Motion.tol`, mm).

Run as a script for the figures: `python tests/lcnc_oracle.py tests/gcode_oracle/*.ngc`.
"""

from __future__ import annotations

import fcntl
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from openmotion.program import (
    ArcMove,
    Feed,
    GCodeError,
    GCodeOptions,
    Rapid,
    SyncedFeed,
    compile_text,
)
from openmotion.program.probing import Probe
from openmotion.program.rigidtap import RigidTap
from openmotion.program.splines import SplineFeed

DEFAULT_RS274 = "/opt/linuxcnc-rs274/rs274"
LETTERS = "XYZABC"
ROTARY = (3, 4, 5)
#: The tool table both interpreters use (machine units, mm).
TOOLS = Path(__file__).parent / "gcode_oracle" / "tools.tbl"
#: Machine for both interpreters: XYZABC in mm, like LinuxCNC's sim configurations.
OPTIONS = GCodeOptions(axes={L: k for k, L in enumerate(LETTERS)}, max_blocks=2_000_000,
                       tool_table=TOOLS)


def rs274_path() -> str | None:
    """The rs274 command, or None when it is not installed (OPENMOTION_RS274 overrides)."""
    cand = os.environ.get("OPENMOTION_RS274") or DEFAULT_RS274
    if os.path.isfile(cand) and os.access(cand, os.X_OK):
        return cand
    return shutil.which("rs274") if cand == DEFAULT_RS274 else None


@dataclass
class Motion:
    """One motion in machine coordinates: kind "rapid" / "feed" / "arc" / "probe"."""

    kind: str
    end: tuple[float, ...]
    feed: float | None = None  # mm/min or deg/min (rapids: None); "sync": mm/revolution
    plane: str = ""  # arcs: "XY", "YZ" or "XZ" (LinuxCNC's first/second axis order)
    centre: tuple[float, float] = (0.0, 0.0)  # arcs: first, second axis of the plane
    rotation: int = 0  # arcs: +turns CCW, -turns CW (LinuxCNC's ARC_FEED rotation)
    tol: float = 1e-4  # position tolerance, mm (1e-4 program units)
    line: str = ""


@dataclass
class Rs274Result:
    motions: list[Motion]
    error: str | None  # rs274's error text when it stopped with an error
    messages: list[str] = field(default_factory=list)
    listing: str = ""


_CALL = re.compile(r"^\s*\d+\s+N\S*\s+([A-Z_0-9.]+)\((.*)\)\s*$")
_PLANES = {"CANON_PLANE_XY": ("XY", 0, 1, 2), "CANON_PLANE_YZ": ("YZ", 1, 2, 0),
           "CANON_PLANE_XZ": ("XZ", 2, 0, 1)}
INI = "[TRAJ]\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n"


def _nums(args: str) -> list[float]:
    return [float(x) for x in re.split(r"[,\s]+", args.strip()) if x]


class _Canon:
    """Replays emccanon.cc's conversion of program coordinates to machine coordinates."""

    def __init__(self) -> None:
        self.scale = 1.0  # program length unit -> mm
        self.g5x = [0.0] * 6
        self.g92 = [0.0] * 6
        self.rot = 0.0
        self.tool = [0.0] * 6
        self.linear_feed = 0.0
        self.angular_feed = 0.0
        self.plane = _PLANES["CANON_PLANE_XY"]
        self.pos = [0.0] * 6
        self.sync: float | None = None  # START_SPEED_FEED_SYNC pitch, mm per revolution
        self.per_rev = False  # SET_FEED_MODE(0, 1): G95, feeds per spindle revolution
        self.rpm = 0.0
        self.css_max = 0.0  # SET_SPINDLE_MODE(0 D): G96 at most D rpm (0: G97)
        self.css_mm = 0.0  # G96 surface speed, mm/min (S in m/min in G21, ft/min in G20)

    def mm(self, vals: list[float]) -> list[float]:
        return [v if k in ROTARY else v * self.scale for k, v in enumerate(vals)]

    def machine(self, prog: list[float]) -> list[float]:
        p = [v + g for v, g in zip(self.mm(prog), self.g92, strict=True)]
        t = math.radians(self.rot)
        x, y = p[0], p[1]
        p[0] = x * math.cos(t) - y * math.sin(t)
        p[1] = x * math.sin(t) + y * math.cos(t)
        return [v + g + o for v, g, o in zip(p, self.g5x, self.tool, strict=True)]

    def feed_for(self, end: list[float]) -> float:
        """Feed of a move to `end` per minute (G95: per revolution x the commanded S)."""
        k = self.rpm if self.per_rev else 1.0
        if self.per_rev and self.css_max > 0:  # G96: the rpm at the move's start X
            r = abs(self.pos[0] - self.g5x[0] - self.g92[0] - self.tool[0])
            k = self.css_max if r == 0 else min(self.css_max, self.css_mm / (2 * math.pi * r))
        return k * self._feed_for(end)

    def _feed_for(self, end: list[float]) -> float:
        linear = any(abs(e - s) > 1e-12 for k, (s, e) in enumerate(zip(self.pos, end,
                                                                       strict=True))
                     if k not in ROTARY)
        return self.linear_feed if linear else self.angular_feed


def parse_listing(listing: str) -> list[Motion]:
    """rs274's canonical-command listing -> motions in machine coordinates."""
    c = _Canon()
    out: list[Motion] = []
    for raw in listing.splitlines():
        m = _CALL.match(raw)
        if m is None:
            continue
        name, args = m.groups()
        tol = 1e-4 * c.scale
        if name == "USE_LENGTH_UNITS":
            c.scale = 25.4 if "INCHES" in args else 1.0
        elif name == "SET_G5X_OFFSET":
            c.g5x = c.mm(_nums(args)[1:7])
        elif name == "SET_G92_OFFSET":
            c.g92 = c.mm(_nums(args)[:6])
        elif name == "SET_XY_ROTATION":
            c.rot = _nums(args)[0]
        elif name == "USE_TOOL_LENGTH_OFFSET":
            c.tool = c.mm(_nums(args)[:6])
        elif name == "SET_FEED_RATE":
            f = _nums(args)[0]
            c.linear_feed, c.angular_feed = f * c.scale, f
        elif name == "SET_FEED_MODE":
            c.per_rev = _nums(args)[1] == 1
        elif name == "SET_SPINDLE_SPEED":
            c.rpm = _nums(args)[1]
            c.css_mm = c.rpm * (12 * 25.4 if c.scale != 1.0 else 1000.0)
        elif name == "SET_SPINDLE_MODE":
            c.css_max = _nums(args)[1]
        elif name == "START_SPEED_FEED_SYNC":
            c.sync = _nums(args)[0] * c.scale
        elif name == "STOP_SPEED_FEED_SYNCH":
            c.sync = None
        elif name == "SELECT_PLANE":
            c.plane = _PLANES[args.strip()]
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "STRAIGHT_PROBE"):
            end = c.machine(_nums(args)[:6])
            kind = {"STRAIGHT_TRAVERSE": "rapid", "STRAIGHT_FEED": "feed"}.get(name, "probe")
            feed = None if kind == "rapid" else c.feed_for(end)
            if kind == "feed" and c.sync is not None:
                kind, feed = "sync", c.sync
            out.append(Motion(kind, tuple(end), feed, tol=tol, line=raw.strip()))
            c.pos = end
        elif name == "RIGID_TAP":  # to X Y Z synchronised and back: the position stays
            v = _nums(args)
            end = c.machine([*v[:3], 0.0, 0.0, 0.0])
            end[3:] = c.pos[3:]
            out.append(Motion("tap", tuple(end), c.sync, tol=tol, line=raw.strip()))
        elif name == "NURBS_FEED":
            # rs274 prints only the number of control points: the end is unknown here
            # (programs print it with DEBUG #<_x> #<_y>); the feed is the current one
            n = int(_nums(args.split(",")[0])[0])
            out.append(Motion("spline", (math.nan,) * 6, c.linear_feed * (
                c.rpm if c.per_rev else 1.0), rotation=n, tol=tol, line=raw.strip()))
        elif name == "ARC_FEED":
            v = _nums(args)
            pname, i1, i2, ih = c.plane
            prog = [0.0] * 6
            prog[i1], prog[i2], prog[ih] = v[0], v[1], v[5]
            prog[3:6] = v[6:9]
            end = c.machine(prog)
            cen = list(prog)
            cen[i1], cen[i2] = v[2], v[3]
            cm = c.machine(cen)
            out.append(Motion("arc", tuple(end), c.linear_feed * (c.rpm if c.per_rev else 1.0),
                              pname, (cm[i1], cm[i2]),
                              int(v[4]), tol=tol, line=raw.strip()))
            c.pos = end
    return out


def inch_tool_table(path: Path = TOOLS) -> str:
    """A mm tool table as rs274 reads it: the standalone interpreter takes tool table
    lengths and diameters in inches whatever the machine units."""
    return scale_tool_table(path.read_text(), 1.0 / 25.4)


def scale_tool_table(text: str, factor: float) -> str:
    """A LinuxCNC tool table with its lengths and diameters (X Y Z U V W D) times `factor`
    (1/25.4: mm to rs274's inches; 25.4: a LinuxCNC test's table to mm)."""
    out = []
    for raw in text.splitlines():
        body, sep, comment = raw.partition(";")
        words = []
        for w in body.split():
            letter, v = w[0].upper(), w[1:]
            if letter in "XYZUVWD":
                v = f"{float(v) * factor:.9f}"
            words.append(letter + v)
        out.append(" ".join(words) + f" {sep}{comment}")
    return "\n".join(out) + "\n"


def run_rs274(text: str, rs274: str | None = None, tool_table: str | None = None,
              extra_files: dict[str, str] | None = None, timeout: float = 60.0,
              ini: str = "", flags: tuple[str, ...] = ()) -> Rs274Result:
    """Run rs274 on program text (in a scratch folder, with `extra_files` next to it: names
    may hold sub-folders). `ini`: more INI sections after ours (a test's own INI file);
    `flags`: more rs274 options (`-n 0`)."""
    tool_table = inch_tool_table() if tool_table is None else tool_table
    exe = rs274 or rs274_path()
    if exe is None:
        raise RuntimeError("rs274 is not installed (tools/setup_rs274.sh)")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "test.ngc").write_text(text)
        (d / "tool.tbl").write_text(tool_table)
        (d / "test.ini").write_text(INI + ini)
        for name, body in (extra_files or {}).items():
            (d / name).parent.mkdir(parents=True, exist_ok=True)
            (d / name).write_text(body)
        # One rs274 at a time on this machine: two at once were seen to lose their tool
        # tables ("Requested tool N not found") or die by a signal (SIGBUS), as if they
        # shared their tool data; a lock file serialises the test workers and survey jobs.
        with open(os.path.join(tempfile.gettempdir(), "openmotion-rs274.lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            for _ in range(2):  # a signal death is retried once
                proc = subprocess.run([exe, "-i", "test.ini", "-t", "tool.tbl", *flags,
                                       "-g", "test.ngc"], cwd=d, capture_output=True,
                                      text=True, timeout=timeout,
                                      env={**os.environ, "TMPDIR": tmp})
                if proc.returncode >= 0:
                    break
    listing = proc.stdout
    msgs = re.findall(r'MESSAGE\("(.*)"\)', listing)
    error = None
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.splitlines() if ln.strip() != "executing"]
        error = "\n".join(lines).strip() or f"rs274 exit status {proc.returncode}"
    return Rs274Result(parse_listing(listing), error, msgs, listing)


def openmotion_motions(text: str, options: GCodeOptions = OPTIONS) -> list[Motion]:
    """openmotion's motions for the same program (GCodeError propagates)."""
    out: list[Motion] = []
    scale_of = _units_tracker(text)
    for cmd in compile_text(text, options):
        tol = 1e-4 * scale_of(cmd.line) if hasattr(cmd, "line") else 1e-4
        if isinstance(cmd, Rapid):
            out.append(Motion("rapid", tuple(cmd.end[:6]), tol=tol))
        elif isinstance(cmd, Feed):
            out.append(Motion("feed", tuple(cmd.end[:6]), cmd.feed_per_s * 60.0, tol=tol))
        elif isinstance(cmd, SyncedFeed):
            out.append(Motion("sync", tuple(cmd.end[:6]), cmd.pitch, tol=tol))
        elif isinstance(cmd, RigidTap):
            out.append(Motion("tap", tuple(cmd.end[:6]), cmd.pitch, tol=tol))
        elif isinstance(cmd, SplineFeed):
            out.append(Motion("spline", tuple(cmd.end[:6]), cmd.feed_per_s * 60.0,
                              rotation=len(cmd.points), tol=tol))
        elif isinstance(cmd, Probe):
            out.append(Motion("probe", tuple(cmd.end[:6]), cmd.feed_per_s * 60.0, tol=tol))
        elif isinstance(cmd, ArcMove):
            i, j = cmd.plane
            name = LETTERS[i] + LETTERS[j]
            first, second = i, j  # G18: Z first, X second, as ARC_FEED
            name = "XZ" if name == "ZX" else name
            sign = 1 if cmd.direction.name == "CCW" else -1
            out.append(Motion("arc", tuple(cmd.end[:6]), cmd.feed_per_s * 60.0, name,
                              (cmd.centre[first], cmd.centre[second]),
                              sign * (cmd.turns + 1), tol=tol))
    return out


def _units_tracker(text: str):
    """Line -> 25.4 if a G20 is in effect there (tolerance in program units), else 1."""
    inch_lines: dict[int, float] = {}
    inch = False
    for k, ln in enumerate(text.splitlines(), 1):
        code = re.sub(r"\(.*?\)|;.*", "", ln).upper().replace(" ", "")
        if re.search(r"G20(?!\d)", code):
            inch = True
        elif re.search(r"G21(?!\d)", code):
            inch = False
        inch_lines[k] = 25.4 if inch else 1.0
    return lambda line: inch_lines.get(line, 1.0)


def _moving(ms: list[Motion]) -> list[Motion]:
    """Drop straight moves that end where the last motion ended (LinuxCNC emits some,
    e.g. G28's intermediate leg without axis words; the planner discards them)."""
    out: list[Motion] = []
    last: tuple[float, ...] = (0.0,) * 6  # both start at the machine origin
    for m in ms:
        # rs274 does not print where a NURBS ends: a move after it is never dropped
        after_spline = bool(out) and out[-1].kind == "spline"
        if m.kind not in ("arc", "spline", "tap") and not after_spline and all(  # 4 decimals
                abs(x - y) <= m.tol for x, y in zip(m.end, last, strict=True)):
            continue
        out.append(m)
        last = m.end
    return out


def compare(ours: list[Motion], theirs: list[Motion], feed_rel: float = 1e-6) -> list[str]:
    """Differences between two motion lists (empty when they agree); zero-length
    straight moves are left out of both."""
    diffs: list[str] = []
    ours, theirs = _moving(ours), _moving(theirs)
    if len(ours) != len(theirs):
        diffs.append(f"{len(ours)} motions from openmotion, {len(theirs)} from rs274")
    for n, (a, b) in enumerate(zip(ours, theirs, strict=False)):
        tol = max(a.tol, b.tol) + 1e-9
        where = f"motion {n} ({b.line})"
        if a.kind != b.kind:
            diffs.append(f"{where}: kind {a.kind} != {b.kind}")
            continue
        if any(abs(x - y) > tol for x, y in zip(a.end, b.end, strict=True)):
            diffs.append(f"{where}: end {a.end} != {b.end}")
        if a.kind == "spline" and a.rotation != b.rotation:
            diffs.append(f"{where}: {a.rotation} control points != {b.rotation}")
        if a.kind == "arc":
            if a.plane != b.plane or a.rotation != b.rotation:
                diffs.append(f"{where}: arc {a.plane} {a.rotation} != {b.plane} {b.rotation}")
            if any(abs(x - y) > tol for x, y in zip(a.centre, b.centre, strict=True)):
                diffs.append(f"{where}: centre {a.centre} != {b.centre}")
        if a.feed is not None and b.feed is not None:
            ftol = max(feed_rel * abs(b.feed), 1e-4 * max(a.tol, b.tol) / 1e-4) + 1e-9
            if abs(a.feed - b.feed) > ftol:
                diffs.append(f"{where}: feed {a.feed:.6g} != {b.feed:.6g} per min")
    return diffs


def main(paths: list[str]) -> int:
    """Print the oracle's figures for the given programs."""
    progs = motions = arcs = bad = 0
    for p in paths:
        text = Path(p).read_text()
        theirs = run_rs274(text)
        try:
            ours = openmotion_motions(text)
            ours_err = None
        except GCodeError as exc:
            ours, ours_err = [], str(exc)
        progs += 1
        if theirs.error or ours_err:
            same = bool(theirs.error) == bool(ours_err)
            print(f"{p}: rs274 error={bool(theirs.error)} openmotion error={bool(ours_err)}"
                  f"{'' if same else '  MISMATCH'}")
            bad += 0 if same else 1
            continue
        d = compare(ours, theirs.motions)
        motions += len(_moving(theirs.motions))
        arcs += sum(m.kind == "arc" for m in theirs.motions)
        bad += len(d)
        print(f"{p}: {len(theirs.motions)} motions, {len(d)} differences")
        for line in d[:5]:
            print("   ", line)
    print(f"programs {progs}, motions {motions} (arcs {arcs}), mismatches {bad}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
