"""Oscilloscope capture for compare outputs: axis positions and output levels against time.

What the ZDevelop oscilloscope shows in the ZMotion PSO article (TRIGGER starts it): from
`trigger()` on, every control cycle records each watched axis's command position (DPOS)
and feedback position (MPOS), divided by the axis's `scale` (pulses per unit: UNITS), and
the watched compare outputs are read from their exact waveforms (compare_io.OutputLine),
so a 50 us pulse keeps its width however long the cycle. `plot_scope` draws both panels.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ...errors import MotionError, check_int, check_positive

if TYPE_CHECKING:
    from ..core.controller import Controller
    from .compare import CompareEngine

Array = NDArray[np.float64]


class Scope:
    """Records `axes` (positions / `scale`) and compare `outputs` from `trigger()` on.

    capacity: cycles kept (the oldest are dropped beyond it, as a scope's memory).
    """

    def __init__(self, engine: CompareEngine, axes: Sequence[int], outputs: Sequence[int], *,
                 scale: Sequence[float] | None = None, capacity: int = 200_000) -> None:
        n = len(engine.ctl.axes)
        self.axes = tuple(check_int("axis", a, 0, n - 1) for a in axes)
        if not self.axes:
            raise MotionError("axes must name at least one axis")
        self.outputs = tuple(engine.check_output(o) for o in outputs)
        sc = [1.0] * len(self.axes) if scale is None else list(scale)
        if len(sc) != len(self.axes):
            raise MotionError(f"scale must give one value per axis ({len(self.axes)}), "
                              f"got {len(sc)}")
        self.scale = tuple(check_positive(f"scale[{i}]", s) for i, s in enumerate(sc))
        self.capacity = check_int("capacity", capacity, 2)
        self.eng = engine
        self.t_trigger: float | None = None
        self._rows: list[tuple[float, ...]] = []
        self._hooked = False

    @property
    def running(self) -> bool:
        return self._hooked

    def trigger(self) -> None:
        """Start a new capture now (the previous one is discarded)."""
        ctl = self.eng.ctl
        with ctl.lock:
            self._rows = []
            self.t_trigger = ctl.time
            for o in self.outputs:
                self.eng.output(o)  # the waveform exists from the trigger on
            self._sample(ctl, ctl.time)
            if not self._hooked:
                ctl.add_cycle_hook(self._sample)
                self._hooked = True

    def stop(self) -> None:
        """Stop capturing (the data stays readable)."""
        if self._hooked:
            self.eng.ctl.remove_cycle_hook(self._sample)
            self._hooked = False

    def _sample(self, ctl: Controller, t: float) -> None:
        row = [t]
        for a, s in zip(self.axes, self.scale, strict=True):
            ax = ctl.axes[a]
            row.append(ax.position / s)
            row.append(ax.counters.feedback_unwrapped() / s)
        self._rows.append(tuple(row))
        if len(self._rows) > self.capacity:
            del self._rows[: len(self._rows) - self.capacity]

    def arrays(self) -> dict[str, NDArray]:
        """time (s since the trigger), dpos / mpos (cycles x axes, in units), and for each
        output `do<n>`: its level just before the trigger and its exact edges from it on."""
        if self.t_trigger is None:
            raise MotionError("the scope was never triggered (call trigger() first)")
        r = np.array(self._rows, dtype=np.float64).reshape(len(self._rows), -1)
        out: dict[str, NDArray] = {
            "time": r[:, 0] - self.t_trigger,
            "dpos": r[:, 1::2],
            "mpos": r[:, 2::2],
        }
        t0 = self.t_trigger
        for o in self.outputs:
            line = self.eng.output(o)
            edges = [(t - t0, lv) for t, lv in line.edges if t >= t0]
            out[f"do{o}_start"] = np.array([line.level_at(math.nextafter(t0, -math.inf))],
                                           dtype=bool)
            out[f"do{o}_edges"] = np.array([t for t, _ in edges], dtype=np.float64)
            out[f"do{o}_levels"] = np.array([lv for _, lv in edges], dtype=bool)
        return out

    def pulse_widths(self, output: int, active: bool = True) -> Array:
        """Durations of the `active`-level stretches of `do<output>` that began and ended
        after the trigger (what the scope's cursors would measure)."""
        if output not in self.outputs:
            raise MotionError(f"output must be one of the scope's outputs {self.outputs}, "
                              f"got {output!r}")
        a = self.arrays()
        t, lv = a[f"do{output}_edges"], a[f"do{output}_levels"]
        starts = np.flatnonzero(lv == active)
        starts = starts[starts + 1 < t.size]
        return t[starts + 1] - t[starts]

    def level_trace(self, output: int) -> tuple[Array, Array]:
        """(times, levels) of output `do<output>` as a step trace from the trigger to the
        last sample, with both sides of every edge (for plots)."""
        if output not in self.outputs:
            raise MotionError(f"output must be one of the scope's outputs {self.outputs}, "
                              f"got {output!r}")
        a = self.arrays()
        t_end = float(a["time"][-1]) if a["time"].size else 0.0
        lv = float(a[f"do{output}_start"][0])
        ts, ls = [0.0], [lv]
        for t, new in zip(a[f"do{output}_edges"], a[f"do{output}_levels"], strict=True):
            if t > t_end:
                break
            ts += [float(t), float(t)]
            ls += [lv, float(new)]
            lv = float(new)
        ts.append(t_end)
        ls.append(lv)
        return np.array(ts), np.array(ls)


def plot_scope(scope: Scope, path: str | Path, *, title: str = "scope",
               names: Sequence[str] | None = None) -> Path:
    """Axis positions (DPOS) over time above the outputs' levels, as the ZDevelop scope."""
    from matplotlib.figure import Figure  # optional heavy import, only when plotting

    p = Path(path)
    if p.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise MotionError(f"path must end with .png, .svg or .pdf, got {str(path)!r}")
    a = scope.arrays()
    labels = list(names) if names is not None else [f"DPOS({k})" for k in scope.axes]
    fig = Figure(figsize=(9, 6))
    top = fig.add_subplot(2, 1, 1)
    for k, lab in enumerate(labels):
        top.plot(a["time"], a["dpos"][:, k], lw=1.0, label=lab)
    top.set_ylabel("position (units)")
    top.legend(loc="best", fontsize=8)
    top.grid(True, lw=0.3)
    top.set_title(title)
    bot = fig.add_subplot(2, 1, 2, sharex=top)
    for k, o in enumerate(scope.outputs):
        t, lv = scope.level_trace(o)
        bot.plot(t, lv * 0.8 + 1.1 * k, lw=1.0, label=f"OP({o})")
    bot.set_yticks([1.1 * k + 0.4 for k in range(len(scope.outputs))],
                   [f"OP({o})" for o in scope.outputs])
    bot.set_xlabel("time since TRIGGER (s)")
    bot.grid(True, lw=0.3)
    p.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(p, dpi=100)
    return p
