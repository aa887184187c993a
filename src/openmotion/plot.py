"""Plots of profiles and recorded traces (matplotlib, no display needed).

`plot_profile` draws a Profile's position, velocity, acceleration and jerk stacked on one
time axis, sampled with the vectorized `Profile.sample`. `plot_trace` draws a Recorder's
arrays as the seed's "velocity curve" (velocity against time, HSL-4XMO manual ch. 5,
Operation Menu, "Show Velocity Curve", Figure 5-6) with position and I/O lanes below it.

Figures are built with `matplotlib.figure.Figure` directly (the Agg canvas), never pyplot,
so nothing opens a window or touches global pyplot state. Every function returns the paths
it wrote: the image (.png/.svg/.pdf), and an interactive .html page (plotly, plot_html.py:
zoom, pan, hover, the run report's style) when the path ends with .html or `html=True`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from .config import MachineConfig
from .errors import MotionError, check_int
from .profile.segments import Profile
from .recording import Recorder

IMAGE_SUFFIXES = (".png", ".svg", ".pdf")
MAX_TRACE_POINTS = 20_000  # per line; longer traces are reduced to a min/max envelope
MAX_IO_LANES = 16


def _check_path(path: str | Path) -> Path:
    p = Path(path)
    if p.suffix.lower() not in IMAGE_SUFFIXES + (".html",):
        raise MotionError(
            f"path must end with one of {IMAGE_SUFFIXES + ('.html',)}, got {str(path)!r}"
        )
    return p


def _write(fig: Figure, path: Path, html: bool, page: Callable[[Path], Path]) -> list[Path]:
    """Save `fig` as the image `path` and/or, through `page`, the interactive .html page
    (plot_html.py: plotly, in the run report's style)."""
    written: list[Path] = []
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() != ".html":
        fig.savefig(path, dpi=100)
        written.append(path)
    if html or path.suffix.lower() == ".html":
        written.append(page(path.with_suffix(".html")))
    return written


# ---------------------------------------------------------------------------- profiles
def profile_times(profile: Profile, n: int = 2000) -> NDArray[np.float64]:
    """Sample times for `profile`: an even grid, every segment start, and the instant just
    before each (so velocity and acceleration jumps draw as vertical edges)."""
    d = profile.duration
    span = d if d > 0 else 1e-3
    grid = np.linspace(-0.05 * span, d + 0.05 * span, n)
    edges = np.append(profile.t0, d)
    left = np.nextafter(edges, -np.inf)
    return np.unique(np.concatenate([grid, edges, left]))


def plot_profile(profile: Profile, path: str | Path, title: str | None = None, *,
                 html: bool = False, n: int = 2000) -> list[Path]:
    """Position, velocity, acceleration and jerk of `profile`, stacked; returns paths written.

    Time is the profile's own (0 at its start); a margin of 5% shows the held states.
    """
    if not isinstance(profile, Profile):
        raise MotionError(f"profile must be a Profile, got {type(profile).__name__}")
    p = _check_path(path)
    check_int("n", n, 2)
    title = "Motion profile" if title is None else str(title)
    t = profile_times(profile, n)
    s = profile.sample(t)
    rows = (("position [pulse]", s.p), ("velocity [pulse/s]", s.v),
            ("acceleration [pulse/s²]", s.a), ("jerk [pulse/s³]", s.j))
    subtitle = f"distance {profile.distance:g} pulses, duration {profile.duration:g} s"

    def page(out: Path) -> Path:
        from .plot_html import profile_page

        return profile_page(t, rows, profile.t0[1:], out, title, subtitle)

    if p.suffix.lower() == ".html":
        return [page(p)]
    fig = Figure(figsize=(9, 8), layout="constrained")
    axs = fig.subplots(4, 1, sharex=True)
    for ax, (label, y) in zip(axs, rows, strict=True):
        ax.plot(t, y, lw=1.2)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        for tk in profile.t0[1:]:
            ax.axvline(tk, color="0.85", lw=0.6, zorder=0)
    axs[-1].set_xlabel("time [s]")
    fig.suptitle(f"{title} — distance {profile.distance:g}, duration {profile.duration:g} s")
    return _write(fig, p, html, page)


# ---------------------------------------------------------------------------- traces
def envelope(t: NDArray[Any], y: NDArray[Any],
             max_points: int = MAX_TRACE_POINTS) -> tuple[NDArray[Any], NDArray[Any]]:
    """Reduce a long line to at most ~max_points points keeping each bucket's min and max
    (so short spikes survive), vectorized."""
    n = t.size
    if n <= max_points:
        return t, y
    per = int(np.ceil(n / (max_points // 2)))
    m = n // per
    tb = t[: m * per].reshape(m, per)
    yb = y[: m * per].reshape(m, per)
    i_min, i_max = yb.argmin(axis=1), yb.argmax(axis=1)
    lo, hi = np.minimum(i_min, i_max), np.maximum(i_min, i_max)  # keep time order
    rows = np.arange(m)
    tt = np.column_stack([tb[rows, lo], tb[rows, hi]]).reshape(-1)
    yy = np.column_stack([yb[rows, lo], yb[rows, hi]]).reshape(-1)
    return np.append(tt, t[m * per:]), np.append(yy, y[m * per:])


def _check_arrays(arrays: Mapping[str, Any]) -> tuple[NDArray[Any], int]:
    if not isinstance(arrays, Mapping) or "t" not in arrays:
        raise MotionError("recorder_arrays must be a mapping with a 't' array (Recorder.arrays())")
    t = np.asarray(arrays["t"], dtype=np.float64)
    if t.ndim != 1:
        raise MotionError(f"recorder_arrays['t'] must be 1-D, got shape {t.shape}")
    n_axes = 0
    for key in ("cmd_pos", "fb_pos", "cmd_vel", "state", "io"):
        if key in arrays:
            a = np.asarray(arrays[key])
            if a.ndim != 2 or a.shape[0] != t.size:
                raise MotionError(
                    f"recorder_arrays[{key!r}] must have shape ({t.size}, n_axes), got {a.shape}"
                )
            n_axes = max(n_axes, a.shape[1])
    if n_axes == 0:
        raise MotionError("recorder_arrays has no per-axis channel to plot")
    return t, n_axes


def plot_trace(recorder_arrays: Mapping[str, Any] | Recorder, path: str | Path,
               axes: Sequence[int] | None = None, *, title: str | None = None,
               html: bool = False, machine: MachineConfig | None = None) -> list[Path]:
    """Velocity curve (velocity vs time) of a recorded trace, with position and I/O lanes.

    `recorder_arrays` is `Recorder.arrays()`, `recording.load_trace(...)` or a Recorder;
    `axes` selects axes
    (default all). Velocity is `cmd_vel`, or the gradient of `cmd_pos` when it was not
    recorded. I/O lanes show each bit of the `io` word that is ever set (off/on), and the
    axis state. With `machine` (the recorded machine) axes are named and drawn in their
    user units (mm, deg), signals by name (X pel, Y org); without it in pulses, "axis 0".
    Returns the paths written.
    """
    if isinstance(recorder_arrays, Recorder):
        recorder_arrays = recorder_arrays.arrays()
    t, n_axes = _check_arrays(recorder_arrays)
    p = _check_path(path)
    if axes is None:
        sel = list(range(n_axes))
    else:
        sel = list(axes)
        for a in sel:
            if not isinstance(a, int | np.integer) or isinstance(a, bool) or not 0 <= a < n_axes:
                raise MotionError(f"axes must be integers in [0, {n_axes - 1}], got {a!r}")
        if not sel:
            raise MotionError("axes must name at least one axis")
    title = "Velocity curve" if title is None else str(title)
    arr = {k: np.asarray(v) for k, v in recorder_arrays.items()}

    has_io = "io" in arr or "state" in arr
    n_rows = 2 + int(has_io)
    fig = Figure(figsize=(10, 2.6 * n_rows + 0.6), layout="constrained")
    axs = np.atleast_1d(fig.subplots(n_rows, 1, sharex=True, height_ratios=[3, 2, 2][:n_rows]))
    ax_v, ax_p = axs[0], axs[1]

    names, scale, units = _axis_labels(machine, n_axes)
    for a in sel:
        color = f"C{a % 10}"
        k, u = scale[a], units[a]
        if "cmd_vel" in arr:
            v = arr["cmd_vel"][:, a]
        elif "cmd_pos" in arr and t.size > 1:
            v = np.gradient(arr["cmd_pos"][:, a], t)
        else:
            v = None
        if v is not None:
            ax_v.plot(*envelope(t, v / k), lw=1.2, color=color, label=f"{names[a]} [{u}/s]")
        if "cmd_pos" in arr:
            ax_p.plot(*envelope(t, arr["cmd_pos"][:, a] / k), lw=1.2, color=color,
                      label=f"{names[a]} command [{u}]")
        if "fb_pos" in arr:
            ax_p.plot(*envelope(t, arr["fb_pos"][:, a] / k), lw=0.9, ls="--", color=color,
                      alpha=0.7, label=f"{names[a]} feedback [{u}]")
    one = len({units[a] for a in sel}) == 1
    ax_v.set_ylabel(f"velocity [{units[sel[0]]}/s]" if one else "velocity [unit/s]")
    ax_p.set_ylabel(f"position [{units[sel[0]]}]" if one else "position [unit]")
    for ax in (ax_v, ax_p):
        ax.grid(True, alpha=0.3)
        if ax.lines:
            ax.legend(loc="upper right", fontsize="small")

    if has_io:
        _io_lanes(axs[2], t, arr, sel, names)
    axs[-1].set_xlabel("time [s]")
    fig.suptitle(title)

    def page(out: Path) -> Path:
        from .plot_html import trace_page

        vel, pos = {}, {}
        for a in sel:
            k, u = scale[a], units[a]
            if "cmd_vel" in arr:
                vel[f"{names[a]} [{u}/s]"] = arr["cmd_vel"][:, a] / k
            elif "cmd_pos" in arr and t.size > 1:
                vel[f"{names[a]} [{u}/s]"] = np.gradient(arr["cmd_pos"][:, a], t) / k
            if "cmd_pos" in arr:
                pos[f"{names[a]} command [{u}]"] = arr["cmd_pos"][:, a] / k
            if "fb_pos" in arr:
                pos[f"{names[a]} feedback [{u}]"] = arr["fb_pos"][:, a] / k
        return trace_page(t, vel, pos, _lanes(arr, sel, names),
                          (ax_v.get_ylabel(), ax_p.get_ylabel()), out, title)

    return _write(fig, p, html, page)


def _axis_labels(machine: MachineConfig | None, n: int
                 ) -> tuple[list[str], list[float], list[str]]:
    """(names, pulses per unit, unit names) of the recorded axes."""
    if machine is None or len(machine.axes) != n:
        return [f"axis {a}" for a in range(n)], [1.0] * n, ["pulse"] * n
    unit = {"degree": "deg"}
    return ([a.name.upper() for a in machine.axes], [a.pulses_per_unit for a in machine.axes],
            [unit.get(a.unit, a.unit) for a in machine.axes])


def _lanes(arr: Mapping[str, NDArray[Any]], sel: list[int], names: list[str]
           ) -> list[tuple[str, NDArray[Any], list[str]]]:
    """The I/O and state lanes as data: (label, level index per sample, level names)."""
    from .control.core.controller import IO_BITS, STATE_CODES

    signal = {bit: sig for sig, bit in IO_BITS}
    state_name = {code: st.value for st, code in STATE_CODES.items()}
    out: list[tuple[str, NDArray[Any], list[str]]] = []
    if "io" in arr:
        for a in sel:
            word = arr["io"][:, a].astype(np.int64)
            used = int(np.bitwise_or.reduce(word)) if word.size else 0
            for b in range(64):
                if used >> b & 1 and len(out) < MAX_IO_LANES:
                    out.append((f"{names[a]} {signal.get(b, f'bit {b}')}", (word >> b) & 1,
                                ["off", "on"]))
    if "state" in arr:
        for a in sel:
            s = arr["state"][:, a].astype(int)
            codes = sorted(set(s.tolist()))
            rank = {c: i for i, c in enumerate(codes)}
            out.append((f"{names[a]} state", np.array([rank[c] for c in s]),
                        [state_name.get(c, str(c)) for c in codes]))
    return out


def _io_lanes(ax: Any, t: NDArray[Any], arr: Mapping[str, NDArray[Any]],
              sel: list[int], names: list[str]) -> None:
    """Digital lanes: one per set bit of each axis's io word (off/on), then the states."""
    from .control.core.controller import IO_BITS, STATE_CODES

    signal = {bit: sig for sig, bit in IO_BITS}
    state_name = {code: st.value for st, code in STATE_CODES.items()}
    labels: list[str] = []
    lane = 0
    if "io" in arr:
        for a in sel:
            word = arr["io"][:, a].astype(np.int64)
            used = int(np.bitwise_or.reduce(word)) if word.size else 0
            for b in range(64):
                if lane >= MAX_IO_LANES:
                    break
                if used >> b & 1:
                    bit = (word >> b) & 1
                    ax.step(*envelope(t, lane + 0.8 * bit), where="post", lw=1.0)
                    labels.append(f"{names[a]} {signal.get(b, f'bit {b}')} (off/on)")
                    lane += 1
    if "state" in arr:
        for a in sel:
            s = arr["state"][:, a].astype(int)
            # one lane per axis: the state as a bar that changes height with each state,
            # its name written where it begins
            codes = sorted(set(s.tolist()))
            rank = {c: i for i, c in enumerate(codes)}
            h = np.array([rank[c] for c in s]) / max(len(codes) - 1, 1)
            ax.step(*envelope(t, lane + 0.8 * h), where="post", lw=1.0, color="k")
            starts = np.nonzero(np.diff(s, prepend=s[0] - 1))[0] if s.size else []
            for i in starts[:12]:
                ax.text(t[i], lane + 0.8 * h[i] + 0.05, state_name.get(int(s[i]), str(s[i])),
                        fontsize="x-small")
            labels.append(f"{names[a]} state")
            lane += 1
    ax.set_yticks(np.arange(lane) + 0.4, labels)
    ax.set_ylim(-0.3, max(lane, 1) + 0.1)
    ax.set_ylabel("I/O and state")
    ax.grid(True, axis="x", alpha=0.3)
