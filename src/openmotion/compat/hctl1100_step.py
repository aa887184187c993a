"""Step response of the HCTL-1100 position loop on the simulated DC motor, and its plot.

`step_response` runs the chip in position control from rest with one command step and
records every sample; `oscillation` measures the tail of a trace (peak-to-peak, sign
changes of the error, growth between the two halves) so tests and users can tell a settled
loop from a limit cycle or a growing oscillation; `plot_step_responses` writes a PNG.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from openmotion.errors import MotionError
from openmotion.hw.sim.dcmotor import DCMotor, DCMotorParams

from . import hctl1100_regs as R
from .hctl1100 import HCTL1100

#: A well-tuned filter for the default `DCMotorParams` (found by a grid search over A, B,
#: K for fast settling without overshoot or limit cycle on 20- and 200-count steps).
TUNED_FILTER = (0xD8, 0x00, 0x10)
DEFAULT_FILTER = (R.DEFAULT_A, R.DEFAULT_B, R.DEFAULT_K)


@dataclass(frozen=True)
class StepResponse:
    """One recorded step: filter, sample timer, step size and the per-sample arrays."""

    a: int
    b: int
    k: int
    sample_timer: int
    step: int
    t: np.ndarray        # s, from the step
    actual: np.ndarray   # counts
    mc: np.ndarray       # motor command (signed 8-bit)

    @property
    def overshoot(self) -> float:
        """Peak overshoot as a fraction of the step."""
        return float((self.actual.max() - self.step) / self.step) if self.step else 0.0

    def settling_samples(self, band: float = 0.02) -> int:
        """Samples until |actual - step| stays within max(1 count, band*step)."""
        tol = max(1.0, band * abs(self.step))
        out = np.nonzero(np.abs(self.actual - self.step) > tol)[0]
        return int(out[-1] + 1) if out.size else 0


@dataclass(frozen=True)
class Oscillation:
    """Tail measures: peak-to-peak (counts), error sign changes, late/early p-p ratio."""

    peak_to_peak: float
    sign_changes: int
    growth: float


def oscillation(actual: np.ndarray, target: float, tail: int) -> Oscillation:
    """Measure the last `tail` samples of a trace around `target`."""
    x = np.asarray(actual, dtype=float)[-tail:] - target
    if x.size < 4:
        raise MotionError(f"tail must cover at least 4 samples, got {x.size}")
    h = x.size // 2
    p1 = float(np.ptp(x[:h]))
    p2 = float(np.ptp(x[h:]))
    s = np.sign(x)
    s = s[s != 0]
    changes = int(np.count_nonzero(s[1:] != s[:-1]))
    return Oscillation(float(np.ptp(x)), changes, p2 / p1 if p1 > 0 else (0.0 if p2 == 0 else
                                                                         np.inf))


def step_response(a: int = R.DEFAULT_A, b: int = R.DEFAULT_B, k: int = R.DEFAULT_K, *,
                  step: int = 200, samples: int = 400, sample_timer: int = R.DEFAULT_SAMPLE_TIMER,
                  motor: DCMotorParams | None = None) -> StepResponse:
    """Run position control from rest with command `step` counts for `samples` samples."""
    if isinstance(step, bool) or not isinstance(step, int) or not 0 < abs(step) <= 0x7FFFFF:
        raise MotionError(f"step must be a nonzero int with |step| <= 0x7fffff, got {step!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise MotionError(f"samples must be an int >= 1, got {samples!r}")
    for name, v in (("a", a), ("b", b), ("k", k), ("sample_timer", sample_timer)):
        R.check_byte(name, v)
    chip = HCTL1100(DCMotor(motor))
    chip.write(R.R_SAMPLE_TIMER, sample_timer)
    chip.write(R.R_FILTER_A, a)
    chip.write(R.R_FILTER_B, b)
    chip.write(R.R_FILTER_K, k)
    chip.write(R.R_PROGRAM, R.PC_CONTROL)
    chip.run_samples(1)  # one sample in position control at 0 before the step
    t0 = chip.time
    for reg, byte in zip((R.R_CMD_POS_MSB, R.R_CMD_POS_MID, R.R_CMD_POS_LSB),
                         R.split24(step), strict=True):
        chip.write(reg, byte)
    tr = chip.run_samples(samples, record=True)
    assert tr is not None
    return StepResponse(a, b, k, sample_timer, step, tr.t - t0, tr.actual.astype(float),
                        tr.mc.astype(float))


def plot_step_responses(responses: list[StepResponse], path: str | Path) -> Path:
    """Write position and motor command against time for each response as a PNG."""
    if not responses:
        raise MotionError("responses must hold at least one StepResponse")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    out = Path(path)
    fig = Figure(figsize=(8, 6))
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for r in responses:
        label = f"A={r.a:02X}h B={r.b:02X}h K={r.k:02X}h"
        ax1.step(r.t * 1e3, r.actual, where="post", label=label)
        ax2.step(r.t * 1e3, r.mc, where="post", label=label)
    ax1.axhline(responses[0].step, color="k", lw=0.6, ls="--")
    ax1.set_ylabel("actual position (counts)")
    ax1.set_title(f"HCTL-1100 position step response, T={responses[0].sample_timer:02X}h")
    ax1.legend(loc="lower right", fontsize=8)
    ax2.set_ylabel("motor command (R09H)")
    ax2.set_xlabel("time (ms)")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    return out
