"""Progress of `openmotion run` on a terminal (rich): executed line, machine time, %, ETA.

The fraction counts what the machine has *executed*, not what was handed to the group's
queue: each operation of a pass is weighted by its estimated time (straight distance /
programmed feed, rapids at the program's highest feed, dwells by their seconds), and the
operation executing now (the group's current command) splits the pass there. With
`--repeat N` the passes add up. Shown only when the stream is a terminal; otherwise silent
(logs and pipes get the summary only).
"""

from __future__ import annotations

import time
from typing import TextIO

import numpy as np

from .runner import ProgramRunner, RunState


def op_weights(ops: list) -> tuple[dict[int, int], np.ndarray]:
    """(id(op) -> position, cumulative estimated time before each op and at the end)."""
    feeds = [op.feed for op in ops if op.feed > 0 and not op.rapid]
    fast = max(feeds) if feeds else 1.0
    w = np.zeros(len(ops))
    prev = None
    first = None  # the first move's start is unknown here: it weighs as an average move
    for i, op in enumerate(ops):
        if op.kind == "delay":
            w[i] = op.seconds
        elif op.kind in ("line", "arc") and op.target is not None:
            if prev is not None:
                dist = float(np.linalg.norm(np.asarray(op.target) - prev))
                w[i] = dist / (op.feed if op.feed > 0 and not op.rapid else fast)
            else:
                first = i
            prev = np.asarray(op.target, dtype=float)
    moves = [x for j, x in enumerate(w) if j != first and x > 0 and ops[j].kind != "delay"]
    if first is not None:
        w[first] = float(np.mean(moves)) if moves else 1.0
    w += 1e-3 * (w.sum() / max(1, len(ops)) + 1e-9)  # every op counts a little
    return {id(op): i for i, op in enumerate(ops)}, np.concatenate(([0.0], np.cumsum(w)))


def executed_fraction(run: ProgramRunner, index: dict[int, int], cum: np.ndarray,
                      last: float = 0.0) -> float:
    """Fraction of the whole job (all passes) the machine has executed (0..1): the pass's
    weight before the op executing now; when the group is idle with an empty queue, all
    that was handed over has run; otherwise (between two commands) `last`."""
    if run.state is RunState.DONE:
        return 1.0
    reps = run.options.repeat
    total = cum[-1]
    g = run.group
    part = None
    if g is not None and total > 0:
        op = run.op_of.get(g.current_index)
        if op is not None and id(op) in index:
            part = cum[index[id(op)]] / total
        elif g.current_index < 0 and g.queue_length == 0:
            part = cum[min(round(run.progress * (len(cum) - 1)), len(cum) - 1)] / total
    if part is None:
        return last
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
        self._index, self._cum = op_weights(list(run.ops))
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
        self._last = executed_fraction(self.run, self._index, self._cum, self._last)
        return self._last

    def update(self) -> None:
        if not self.enabled:
            return
        run = self.run
        f = self.fraction()
        wall = time.monotonic() - self._t0
        eta = "--" if f < 0.02 else _clock(wall * (1.0 - f) / f)
        reps = run.options.repeat
        self._progress.update(
            self._task, completed=f, line=run.current_line,
            machine=f"{self._ctl.time - run.t_start:.3f}",
            pass_=f"pass {min(run.passes_done + 1, reps)}/{reps}" if reps > 1 else "",
            eta=eta)
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
