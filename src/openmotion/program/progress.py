"""Progress of `openmotion run` on a terminal (rich): executed line, machine time, %, ETA.

The fraction counts what the machine has *executed*, not what was handed to the group's
queue: each operation of a pass is weighted by its estimated time (path length - straight,
or along the arc or helix with all its turns - / programmed feed, rapids at the program's
highest feed, dwells by their seconds), and the operation executing now (the group's
current command) splits the pass there, plus the share of it its machine time so far
covers (at most all but 1 %, until the next command starts). With
`--repeat N` the passes add up. Shown only when the stream is a terminal; otherwise silent
(logs and pipes get the summary only).
"""

from __future__ import annotations

import time
from typing import TextIO

import numpy as np

from . import canon
from .runner import ProgramRunner, RunState


def op_weights(ops: list, ppu: np.ndarray | None = None) -> tuple[dict[int, int], np.ndarray]:
    """(id(op) -> position, cumulative estimated time before each op and at the end).
    `ppu`: pulses per machine unit of each axis (the ops' targets are in pulses, their
    feeds in machine units/s); None: targets taken as machine units."""
    scale = np.ones(1) if ppu is None else np.asarray(ppu, dtype=float)
    feeds = [op.feed for op in ops if op.feed > 0 and not op.rapid]
    fast = max(feeds) if feeds else 1.0
    w = np.zeros(len(ops))
    prev = None
    first = None  # the first move's start is unknown here: it weighs as an average move
    for i, op in enumerate(ops):
        if op.kind == "delay":
            w[i] = op.seconds
        elif op.kind in ("line", "arc") and op.target is not None:
            if isinstance(op.source, canon.ArcMove):   # the arc's length, every turn
                w[i] = op.source.length / (op.feed if op.feed > 0 and not op.rapid else fast)
            elif prev is not None:
                dist = float(np.linalg.norm(np.asarray(op.target) / scale - prev))
                w[i] = dist / (op.feed if op.feed > 0 and not op.rapid else fast)
            else:
                first = i
            prev = np.asarray(op.target, dtype=float) / scale
    moves = [x for j, x in enumerate(w) if j != first and x > 0 and ops[j].kind != "delay"]
    if first is not None:
        w[first] = float(np.mean(moves)) if moves else 1.0
    w += 1e-3 * (w.sum() / max(1, len(ops)) + 1e-9)  # every op counts a little
    return {id(op): i for i, op in enumerate(ops)}, np.concatenate(([0.0], np.cumsum(w)))


def executed_fraction(run: ProgramRunner, index: dict[int, int], cum: np.ndarray,
                      last: float = 0.0, within: float = 0.0) -> float:
    """Fraction of the whole job (all passes) the machine has executed (0..1): the pass's
    weight before the op executing now, plus `within` (0..1) of that op's weight; when the
    group is idle with an empty queue, all that was handed over has run; otherwise
    (between two commands) `last`."""
    if run.state is RunState.DONE:
        return 1.0
    reps = run.passes  # None: endless (M99 in the main program): the pass's own share
    total = cum[-1]
    g = run.group
    part = None
    if g is not None and total > 0:
        op = run.op_of.get(g.current_index)
        if op is not None and id(op) in index:
            k = index[id(op)]
            part = (cum[k] + min(max(within, 0.0), 0.99) * (cum[k + 1] - cum[k])) / total
        elif g.current_index < 0 and g.queue_length == 0:
            part = cum[min(round(run.progress * (len(cum) - 1)), len(cum) - 1)] / total
    if part is None:
        return last
    if reps is None:
        return part
    return max(last, min(1.0, (run.passes_done + part) / reps))


class RunProgress:
    """A rich progress line for a ProgramRunner; `update()` between controller chunks."""

    def __init__(self, ctl, run: ProgramRunner, stream: TextIO | None = None, *,
                 force_terminal: bool | None = None) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn

        self.run = run
        self._ctl = ctl
        self._last = 0.0
        self.console = Console(file=stream, stderr=stream is None,
                               force_terminal=force_terminal)
        self.enabled = self.console.is_terminal
        self._index, self._cum = op_weights(list(run.ops), run.scales.ppu)
        self._op = (-1, 0.0)   # the op executing (its place) and the machine time it began
        self._t0 = time.monotonic()
        self._progress = Progress(TextColumn("[bold]line {task.fields[line]:>6}"), BarColumn(),
                                  TaskProgressColumn(),
                                  TextColumn("machine {task.fields[machine]} s"),
                                  TextColumn("{task.fields[pass_]}"),
                                  TextColumn("ETA {task.fields[eta]}"),
                                  console=self.console, transient=False,
                                  auto_refresh=False)
        self._task = self._progress.add_task("run", total=1.0, line=0, machine="0.000",
                                             pass_="", eta="--")
        if self.enabled:
            self._progress.start()

    def fraction(self) -> float:
        run, now = self.run, self._ctl.time
        g = run.group
        within = 0.0
        if g is not None:
            op = run.op_of.get(g.current_index)
            k = self._index.get(id(op)) if op is not None else None
            if k is not None and k != self._op[0]:   # (an arc may run as many commands)
                self._op = (k, now)
            if k is not None:
                est = self._cum[k + 1] - self._cum[k]   # s at the programmed feed
                ovr = g.override / 100.0 if g.override > 0 else 1.0
                within = (now - self._op[1]) * ovr / est if est > 0 else 0.0
        self._last = executed_fraction(run, self._index, self._cum, self._last, within)
        return self._last

    def update(self) -> None:
        if not self.enabled:
            return
        run = self.run
        f = self.fraction()
        wall = time.monotonic() - self._t0
        eta = "--" if f < 0.02 else _clock(wall * (1.0 - f) / f)
        reps = run.passes
        if reps is None:  # endless (M99): no end to estimate
            eta, label = "--", f"pass {run.passes_done + 1} (M99: until stopped)"
        else:
            label = f"pass {min(run.passes_done + 1, reps)}/{reps}" if reps > 1 else ""
        self._progress.update(
            self._task, completed=f, line=run.current_line,
            machine=f"{self._ctl.time - run.t_start:.3f}", pass_=label, eta=eta)
        self._progress.refresh()

    def status(self, text: str) -> None:
        """A line under the bar (e.g. 'writing the report ...')."""
        if self.enabled:
            self.console.print(text)

    def close(self) -> None:
        """Draw the final state and release the terminal line (idempotent)."""
        if self.enabled:
            self.update()
            self._progress.stop()
            self.enabled = False


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"
