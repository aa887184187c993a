"""Benchmark: G-code parse and parse+interpret speed, lines per second, against Klipper.

Generates a CAM-like program of N G1 moves (3 axes, literal numbers, some F changes) plus a
program of the same size using named parameters and expressions, then times
`parse_program` and `compile_text` on each (CPU time, best of three runs after a warm-up
run, so the first figure is not a cold one). The G1 program also runs through Klipper's
`GCodeDispatch` and gcode_move's `cmd_G1` (moves handed to a list instead of the toolhead):
the same lines parsed into positions and speeds. Klipper is read from a checkout given by
`--klipper PATH` or KLIPPER_PATH (klippy/gcode.py and klippy/extras/gcode_move.py, the
printer object stubbed); nothing of Klipper is part of openmotion, and without a checkout
the bench says so and prints ours alone.

    python bench/bench_gcode.py [N] [--klipper PATH]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from typing import Any

from openmotion.program import GCodeOptions, compile_text, parse_program
from openmotion.program.stream import stream_file


def cam_program(n: int) -> str:
    lines = ["G21 G90 G64 P0.01", "G0 X0 Y0 Z5", "G1 Z-1 F300"]
    for k in range(n):
        t = k * 0.001
        x = 50.0 * math.cos(t) + 0.01 * k
        y = 50.0 * math.sin(3 * t)
        z = -1.0 - 0.5 * math.sin(t)
        f = f" F{1200 + (k % 7) * 10}" if k % 50 == 0 else ""
        lines.append(f"N{k + 10} G1 X{x:.4f} Y{y:.4f} Z{z:.4f}{f}")
    lines.append("M2")
    return "\n".join(lines)


def param_program(n: int) -> str:
    lines = ["G21 G90", "#<s> = 1.5", "G0 X0 Y0", "G1 F600"]
    for k in range(n):
        lines.append(f"X[#<s>*{k % 100}.5] Y[SIN[{k % 360}]*10]")
    lines.append("M2")
    return "\n".join(lines)


def timed(fn: Callable[..., Any], *args: Any, runs: int = 3) -> tuple[Any, float]:
    """(result, best CPU time of `runs` runs after one warm-up run)."""
    out = fn(*args)
    best = math.inf
    for _ in range(runs):
        t0 = time.process_time()
        out = fn(*args)
        best = min(best, time.process_time() - t0)
    return out, best


class _Printer:
    """Just enough of Klipper's printer object for GCodeDispatch and GCodeMove."""

    def __init__(self) -> None:
        self.objects: dict[str, Any] = {}
        self.handlers: dict[str, list[Any]] = {}

    def get_start_args(self) -> dict[str, Any]:
        return {}

    def register_event_handler(self, event: str, cb: Any) -> None:
        self.handlers.setdefault(event, []).append(cb)

    def get_reactor(self) -> Any:
        return self

    def mutex(self) -> Any:
        return None

    def lookup_object(self, name: str) -> Any:
        return self.objects[name]

    def get_printer(self) -> Any:  # the config object of GCodeMove
        return self


def klipper_dispatch(path: str) -> Callable[[list[str]], list[Any]]:
    """A function running lines through Klipper's GCodeDispatch + cmd_G1."""
    klippy = os.path.join(path, "klippy")
    if not os.path.isfile(os.path.join(klippy, "gcode.py")):
        raise SystemExit(f"no klippy/gcode.py under {path!r}")
    sys.path.insert(0, klippy)
    sys.path.insert(0, os.path.join(klippy, "extras"))
    import gcode  # type: ignore[import-not-found]
    import gcode_move  # type: ignore[import-not-found]

    def run(lines: list[str]) -> list[Any]:
        printer = _Printer()
        dispatch = gcode.GCodeDispatch(printer)
        printer.objects["gcode"] = dispatch
        move = gcode_move.GCodeMove(printer)
        moves: list[Any] = []
        move.move_with_transform = lambda pos, speed: moves.append((tuple(pos), speed))
        move.is_printer_ready = True
        dispatch._handle_ready()
        dispatch._process_commands(lines, need_ack=False)
        return moves
    return run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", nargs="?", type=int, default=100_000, help="lines (default 100000)")
    ap.add_argument("--klipper", default=os.environ.get("KLIPPER_PATH"),
                    help="path of a Klipper checkout (default: $KLIPPER_PATH)")
    args = ap.parse_args()
    n = args.n
    opts = GCodeOptions(axes={"X": 0, "Y": 1, "Z": 2})
    klipper = klipper_dispatch(args.klipper) if args.klipper else None
    if klipper is None:
        print("no Klipper checkout given (--klipper PATH or KLIPPER_PATH): openmotion alone")
    for name, make in (("G1 literal", cam_program), ("params+expr", param_program)):
        text = make(n)
        _, tp = timed(parse_program, text)
        cmds, tc = timed(compile_text, text, opts)
        print(f"{name:12s} {n} lines: parse {tp:.3f} s ({n / tp:,.0f} lines/s), "
              f"compile_text (parse+interpret) {tc:.3f} s ({n / tc:,.0f} lines/s), "
              f"{len(cmds)} commands")
        tracemalloc.start()
        compile_text(text, opts)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"{'':12s} peak {peak / 2**20:.0f} MiB traced ({peak / n:.0f} B/line, "
              "the command list included)")
        if klipper is not None and make is cam_program:
            lines = text.split("\n")
            moves, tk = timed(klipper, lines)
            print(f"{'':12s} Klipper GCodeDispatch + cmd_G1 {tk:.3f} s ({n / tk:,.0f} "
                  f"lines/s, {len(moves)} moves); ratio {tk / tc:.2f}x; goal >= 1.0x: "
                  f"{'met' if tk >= tc else 'not met'}")
        if make is cam_program:
            stream_row(text, opts, n)


def stream_row(text: str, opts: GCodeOptions, n: int) -> None:
    """program.stream.stream_file on the same program as a file: speed and traced peak
    while the commands are consumed one by one (none kept)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cam.ngc")
        with open(path, "w") as fh:
            fh.write(text)
        count, ts = timed(lambda: sum(1 for _ in stream_file(path, opts)))
        tracemalloc.start()
        sum(1 for _ in stream_file(path, opts))
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    print(f"{'':12s} stream_file {ts:.3f} s ({n / ts:,.0f} lines/s, {count} commands), "
          f"peak {peak / 2**20:.1f} MiB traced ({peak / n:.0f} B/line; flat in the length)")


if __name__ == "__main__":
    main()
