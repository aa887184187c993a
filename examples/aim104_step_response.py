"""Step response of the simulated DC servo under the HCTL-1100 position loop: the chip's
reset filter (A=E5h, B=40h, K=40h), a well-tuned one, and a gain far too high (K=FFh),
plotted into the PNG path given on the command line (default out/aim104_step_response.png)."""

import sys

from openmotion.compat.hctl1100_step import (
    DEFAULT_FILTER,
    TUNED_FILTER,
    oscillation,
    plot_step_responses,
    step_response,
)


def main(path: str = "out/aim104_step_response.png", step: int = 200) -> dict:
    filters = {"default": DEFAULT_FILTER, "tuned": TUNED_FILTER, "gain too high": (0xE5, 0x40,
                                                                                  0xFF)}
    runs = {name: step_response(*f, step=step, samples=600) for name, f in filters.items()}
    out = plot_step_responses(list(runs.values()), path)
    summary = {}
    for name, r in runs.items():
        osc = oscillation(r.actual, r.step, 200)
        summary[name] = {"overshoot": round(r.overshoot, 3),
                         "settling_samples": r.settling_samples(),
                         "tail_peak_to_peak": osc.peak_to_peak}
        print(f"{name:14s} {summary[name]}")
    print(f"plot written to {out}")
    return {"path": str(out), "summary": summary}


if __name__ == "__main__":
    main(*sys.argv[1:2])
