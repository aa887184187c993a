"""Step responses of a closed-loop dc_servo axis for several lead-filter settings.

The axis of examples/dc_servo.toml (a DC motor with a 1000-line encoder on a PWM amplifier,
the loop sampled twice per 1 ms cycle) holds still, then a 200-count step is added to the
loop's set-point (`ServoLoop.inject_step`, a tuning tool's step test). The plot shows the
encoder position for the tuned filter, the HCTL-1100 reset filter and two gains K around
them; the printed table gives overshoot and 2 % settling time.

    python examples/servo_tuning.py [out.png]
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from openmotion.config import load_machine  # noqa: E402
from openmotion.control import Controller  # noqa: E402

HERE = Path(__file__).parent
STEP = 200
FILTERS = [  # (label, a, b, k)
    ("tuned A=D8h B=00h K=10h", 0xD8, 0x00, 0x10),
    ("chip reset A=E5h B=40h K=40h", 0xE5, 0x40, 0x40),
    ("low gain A=D8h B=00h K=06h", 0xD8, 0x00, 0x06),
    ("far too high A=E5h B=40h K=FFh", 0xE5, 0x40, 0xFF),
]


def step_response(a: int, b: int, k: int, duration: float = 0.08) -> tuple[np.ndarray, ...]:
    """(t, feedback - start) of a STEP-count set-point step, t = 0 at the step."""
    cfg = load_machine(HERE / "dc_servo.toml")
    ax = cfg.axes[0]
    cfg = cfg.with_axis(replace(ax, loop=replace(ax.loop, a=a, b=b, k=k,
                                                  following_error=float("inf"))))
    ctl = Controller(cfg)
    ctl.axes[0].enable()
    loop = ctl.servo_loops[ax.name]
    ctl.advance(0.005)
    loop.start_trace()
    loop.inject_step(STEP)
    ctl.advance(duration)
    tr = loop.trace()
    return tr["t"] - tr["t"][0], tr["feedback"] - tr["feedback"][0]


def main(out: str) -> None:
    fig, ax = plt.subplots(figsize=(8, 4.5))
    print(f"{'filter':34s} {'overshoot':>9s} {'settling':>9s}")
    for label, a, b, k in FILTERS:
        t, x = step_response(a, b, k)
        over = max(0.0, (x.max() - STEP) / STEP)
        bad = np.nonzero(np.abs(x - STEP) > max(1.0, 0.02 * STEP))[0]
        settle = f"{t[bad[-1] + 1] * 1e3:.1f} ms" if bad.size and bad[-1] + 1 < t.size \
            else ("0 ms" if not bad.size else "never")
        print(f"{label:34s} {over:9.1%} {settle:>9s}")
        ax.step(t * 1e3, x, where="post", label=label)
    ax.axhline(STEP, color="k", lw=0.6, ls="--")
    ax.set_xlabel("time after the step (ms)")
    ax.set_ylabel("encoder position (counts)")
    ax.set_title(f"dc_servo closed loop: {STEP}-count step, 0.5 ms sample")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/servo_tuning.png")
