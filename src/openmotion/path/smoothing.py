"""Jerk-limited path speed: a moving-average (FIR) filter on the path parameter s(t).

The look-ahead plans s(t) with piecewise-constant acceleration (a T-curve in s). Averaging
that motion over a window tj,

    s_f(t) = (1/tj) * integral_{t-tj}^{t} s(tau) dtau,

gives v_f(t) = (s(t) - s(t-tj))/tj, a_f(t) = (v(t) - v(t-tj))/tj and
j_f(t) = (a(t) - a(t-tj))/tj: a piecewise-cubic motion (an S-curve) whose acceleration is
an average of planned accelerations (|a_f| <= max|a|), whose speed is an average of planned
speeds (v_f <= max v) and whose jerk is |delta a|/tj. The total travel is unchanged and the
motion takes tj longer. The breaks of s_f are the breaks of s and those shifted by tj, so
each row below is computed from closed forms (no accumulation): the position from the
antiderivative I(t) of s(t), p_f = (I(b) - I(b - tj))/tj.

A StrVel path (PCL6045: jump to StrVel, S acceleration from a = 0; S deceleration to
StrVel reaching a = 0, jump to rest) is the same average of a raw motion that moved at
StrVel before its start (its start state (p, v) is that history) and keeps its end speed
after its end (`v_after`): at t = 0 the average moves at StrVel with a = 0 and lies
StrVel*tj/2 behind the raw start; a raw that ends with tj/2 at constant speed v_after
gives an average that reaches the raw end point at raw end + tj/2 with v = v_after, a = 0.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import MotionError
from ..profile.segments import Profile, State


def _antiderivative(raw: Profile, t: np.ndarray) -> np.ndarray:
    """I(t) = integral_0^t s, with s extended by the start/end states outside [0, D]."""
    n = raw.n_segments
    dts = raw.dt if raw.dt is not None else np.diff(np.append(raw.t0, raw.duration))
    d = dts
    seg = raw.p0 * d + raw.v0 * d ** 2 / 2 + raw.a0 * d ** 3 / 6 + raw.j * d ** 4 / 24
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    out = np.empty_like(t)
    lo = t < 0.0
    hi = t >= raw.duration
    mid = ~(lo | hi)
    out[lo] = raw.start.p * t[lo] + raw.start.v * t[lo] ** 2 / 2
    e = t[hi] - raw.duration
    out[hi] = cum[-1] + raw.end.p * e + raw.end.v * e ** 2 / 2
    if n and mid.any():
        k = np.clip(np.searchsorted(raw.t0, t[mid], side="right") - 1, 0, n - 1)
        x = t[mid] - raw.t0[k]
        out[mid] = cum[k] + raw.p0[k] * x + raw.v0[k] * x ** 2 / 2 + raw.a0[k] * x ** 3 / 6 \
            + raw.j[k] * x ** 4 / 24
    return out


def fir_smooth(raw: Profile, tj: float, t_out: float = 0.0, *,
               v_after: float = 0.0) -> Profile:
    """The moving average over `tj` of a constant-acceleration Profile `raw` (see the module
    doc), from raw time `t_out` on (rebased to 0) until it rests at raw's end.

    Before its time 0 the raw motion is its start state extended (at rest, or at the speed
    of a StrVel start); with t_out >= tj the window lies inside `raw` (re-planning a
    running S-curve: raw = the old plan up to now, spliced with the new one). `v_after` > 0:
    the raw motion keeps that speed after its end (which it must reach tj/2 before its end
    and hold), and the result ends tj/2 after raw's end, on raw's end point, at speed
    v_after (its last segment; the end state is rest: a StrVel end jumps to it).
    """
    if not tj > 0.0 or not np.isfinite(tj):
        raise MotionError(f"tj must be a finite number > 0, got {tj!r}")
    if raw.n_segments and np.any(raw.j != 0.0):
        raise MotionError("raw must have constant acceleration on every segment")
    if raw.end.v != 0.0:
        raise MotionError("raw must end at rest (a speed after its end is v_after)")
    if not (v_after >= 0.0 and np.isfinite(v_after)):
        raise MotionError(f"v_after must be a finite number >= 0, got {v_after!r}")
    end_t = raw.duration + tj
    if v_after > 0.0:
        _check_cruise_end(raw, tj, v_after)
        raw = replace(raw, end=State(raw.end.p, float(v_after), 0.0))
        end_t = raw.duration + 0.5 * tj
    brk = np.concatenate([raw.t0, raw.t0 + tj, [raw.duration, end_t, t_out]])
    brk = np.unique(brk[(brk >= t_out) & (brk <= end_t)])
    # merge breaks closer than 1e-12 s (float noise of t0 + tj); keep t_out and the end
    keep = np.concatenate([[True], np.diff(brk) > 1e-12])
    brk = brk[keep]
    brk[-1] = end_t
    if len(brk) < 2 or raw.duration <= 0.0 and t_out >= end_t:
        p = raw.end.p
        return Profile(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), 0.0,
                       State(p, 0.0, 0.0), State(p, 0.0, 0.0), (), np.zeros(0))
    b = brk[:-1]
    now = raw.sample(b)
    back = raw.sample(b - tj)
    ii = _antiderivative(raw, b) - _antiderivative(raw, b - tj)
    midt = 0.5 * (brk[:-1] + brk[1:])
    a_now = raw.sample(midt).a
    a_back = raw.sample(midt - tj).a
    p0 = ii / tj
    v0 = (now.p - back.p) / tj
    a0 = (now.v - back.v) / tj
    j = (a_now - a_back) / tj
    dts = np.diff(brk)
    t0 = b - t_out
    return Profile(t0=t0, p0=p0, v0=v0, a0=a0, j=j, duration=float(end_t - t_out),
                   start=State(float(p0[0]), float(v0[0]), float(a0[0])),
                   end=State(float(raw.end.p), 0.0, 0.0),
                   labels=("s-curve",) * len(t0), dt=dts)


def _check_cruise_end(raw: Profile, tj: float, v: float) -> None:
    """raw must move at constant speed v over its last tj/2 (a StrVel end; see the module
    doc), else the average would not end on raw's end point at speed v."""
    h = 0.5 * tj
    st = raw.state_at(raw.duration - h)
    if raw.duration < h * (1.0 - 1e-9) or abs(st.v - v) > 1e-6 * v or \
            abs(st.p + v * h - raw.end.p) > 1e-9 * max(1.0, abs(raw.end.p)):
        raise MotionError(f"raw must move at v_after = {v!r} over its last tj/2")


def jerk_window(accel: float, jerk: float) -> float:
    """Window that keeps |jerk of s| <= `jerk` for any raw motion with |a| <= `accel`:
    tj = 2*accel/jerk, since an acceleration can reverse (+a to -a) inside one window. The
    factor 2 also covers a hold or re-plan spliced in later with the same window."""
    if not jerk > 0.0 or not np.isfinite(jerk):
        raise MotionError(f"jerk must be a finite number > 0, got {jerk!r}")
    return max(2.0 * accel / jerk, 1e-9)
